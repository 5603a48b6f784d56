"""HRDF -> MJCF: every feature checked on the compiled MuJoCo model."""

from __future__ import annotations

import dataclasses
import warnings
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionError, ConversionWarning, GeneratorError, HRDFError
from robotwright.generators import DEFAULT_SCENE, MJCFHumanoidGenerator, SceneDefaults
from robotwright.hrdf.model import ImuConfig, Meta

J = mujoco.mjtJoint


def _model(hrdf, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        return MJCFHumanoidGenerator.from_hrdf(hrdf).to_model(**kw)


def _xml(hrdf, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        return MJCFHumanoidGenerator.from_hrdf(hrdf).export(**kw)


def test_bodies_and_inertials_exact(synth):
    m = _model(synth)
    for b in synth.bodies:
        i = m.body(b.name).id
        assert m.body_mass[i] == b.mass
        np.testing.assert_array_equal(m.body_pos[i], b.pos) if b.parent != -1 else None
        np.testing.assert_allclose(m.body_ipos[i], b.inertial_pos, atol=1e-12)
        np.testing.assert_allclose(m.body_inertia[i], b.diag_inertia, atol=1e-12)
        assert m.body_parentid[i] == (
            0 if b.parent == -1 else m.body(synth.bodies[b.parent].name).id
        )


def test_joints_types_axes_ranges_and_dynamics(synth):
    m = _model(synth)
    assert m.jnt_type[m.joint("root").id] == J.mjJNT_FREE
    j1a = m.joint("j1a")
    assert j1a.type[0] == J.mjJNT_HINGE and j1a.limited[0] == 1
    np.testing.assert_array_equal(j1a.range, [-1.0, 1.0])
    np.testing.assert_array_equal(j1a.pos, [0, 0, 0.05])
    assert m.dof_armature[j1a.dofadr[0]] == 0.02
    assert m.dof_damping[j1a.dofadr[0]] == 0.3
    assert m.dof_frictionloss[j1a.dofadr[0]] == 0.1
    assert j1a.stiffness[0] == 2.0 and m.qpos_spring[j1a.qposadr[0]] == 0.1
    j1b = m.joint("j1b")
    assert j1b.limited[0] == 0  # range None = unlimited
    np.testing.assert_array_equal(j1b.axis, [1, 0, 0])
    assert m.jnt_bodyid[j1a.id] == m.jnt_bodyid[j1b.id]  # two joints on one body
    assert m.jnt_type[m.joint("j2").id] == J.mjJNT_SLIDE
    assert m.dof_damping[m.joint("j2").dofadr[0]] == 1.0
    j3 = m.joint("j3")
    assert j3.type[0] == J.mjJNT_BALL and j3.range[1] == 0.5
    assert m.body("tool").jntnum[0] == 0  # welded body


def test_fixed_base_has_no_free_joint(synth_fixed):
    m = _model(synth_fixed)
    assert J.mjJNT_FREE not in set(m.jnt_type)
    np.testing.assert_array_equal(m.body("base").pos, [0, 0, 1])


def test_actuators_real_type_gains_ranges_in_order(synth):
    m = _model(synth)
    assert [m.actuator(i).name for i in range(m.nu)] == ["j1a_motor", "j1b_servo", "j2_vel"]
    motor, servo, vel = (m.actuator(i) for i in range(3))
    assert motor.gear[0] == 2.0 and motor.ctrllimited[0]
    np.testing.assert_array_equal(motor.ctrlrange, [-5, 5])
    assert motor.biastype[0] == mujoco.mjtBias.mjBIAS_NONE
    assert servo.gainprm[0] == 50.0 and servo.biasprm[1] == -50.0 and servo.biasprm[2] == -2.0
    np.testing.assert_array_equal(servo.forcerange, [-3, 3])
    np.testing.assert_array_equal(servo.ctrlrange, [-1, 1])
    assert vel.gainprm[0] == 4.0 and vel.biasprm[2] == -4.0
    assert m.actuator_trnid[1, 0] == m.joint("j1b").id


def test_geoms_contact_friction_rgba_group_meshes(synth):
    m = _model(synth)
    caps = m.geom("link2_caps")
    assert caps.type[0] == mujoco.mjtGeom.mjGEOM_CAPSULE
    assert (caps.contype[0], caps.conaffinity[0], caps.group[0], caps.condim[0]) == (2, 3, 2, 4)
    np.testing.assert_array_equal(caps.friction, [0.8, 0.01, 0.001])
    np.testing.assert_allclose(caps.rgba, [0.9, 0.1, 0.1, 1.0], atol=1e-7)
    np.testing.assert_array_equal(caps.size[:2], [0.02, 0.08])
    assert m.nmesh == 2  # same file, two scales -> two assets
    base_geom = next(i for i in range(m.ngeom) if m.geom_bodyid[i] == m.body("base").id)
    assert m.geom_contype[base_geom] == 0 and m.geom_conaffinity[base_geom] == 0
    scaled = m.mesh_vert[m.mesh_vertadr[0] : m.mesh_vertadr[0] + m.mesh_vertnum[0]]
    # MuJoCo re-aligns mesh vertices to principal axes: compare the sorted extents.
    extents = sorted(float(v) for v in np.ptp(scaled, axis=0))
    np.testing.assert_allclose(extents, [0.06, 0.1, 0.16], atol=1e-6)  # 0.08 * scale 2
    assert m.geom("link1_shell").type[0] == mujoco.mjtGeom.mjGEOM_MESH


def test_sites_sensors_and_imu(synth):
    m = _model(synth)
    np.testing.assert_array_equal(m.site("tool_tip").pos, [0, 0, 0.1])
    imu = m.site("imu")
    assert m.site_bodyid[imu.id] == m.body("base").id
    np.testing.assert_array_equal(imu.pos, [0, 0, 0.02])
    S = mujoco.mjtSensor
    types = {m.sensor(i).name: m.sensor_type[i] for i in range(m.nsensor)}
    assert types["imu_quat"] == S.mjSENS_FRAMEQUAT
    assert types["imu_angvel"] == S.mjSENS_GYRO
    assert types["imu_linacc"] == S.mjSENS_ACCELEROMETER
    assert types["tip_pos"] == S.mjSENS_FRAMEPOS
    assert types["j1a_pos"] == S.mjSENS_JOINTPOS and m.sensor("j1a_pos").noise[0] == 0.01
    assert types["tip_touch"] == S.mjSENS_TOUCH


def test_imu_at_a_site_reuses_it(synth):
    imu = ImuConfig("tool", position=(0, 0, 0.1), orientation=synth.sites[0].quat)
    h = dataclasses.replace(synth, meta=dataclasses.replace(synth.meta, imu_config_list=[imu]))
    m = _model(h)
    assert m.nsite == 1
    assert m.sensor_objid[m.sensor("tool_tip_quat").id] == m.site("tool_tip").id


def test_simulator_config_option_and_scene(synth):
    m = _model(synth)
    assert m.opt.timestep == 0.001
    np.testing.assert_array_equal(m.opt.gravity, [0, 0, -9.8])
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    floor = m.geom("floor")
    assert floor.type[0] == mujoco.mjtGeom.mjGEOM_PLANE and floor.friction[0] == 0.7
    assert m.nlight == 1
    assert mujoco.MjModel.from_xml_string(_xml(synth, add_scene=False)).ngeom == m.ngeom - 1


def test_scene_defaults_constant_is_frozen_and_unchanged(synth):
    before = dataclasses.asdict(DEFAULT_SCENE)
    _xml(synth)
    assert dataclasses.asdict(DEFAULT_SCENE) == before
    with pytest.raises(dataclasses.FrozenInstanceError):
        DEFAULT_SCENE.floor_name = "x"  # type: ignore[misc]
    assert SceneDefaults() == DEFAULT_SCENE


def test_scene_without_ground_config_uses_defaults(synth):
    meta = Meta(simulator_config=None)
    h = dataclasses.replace(synth, meta=meta)
    m = _model(h)
    assert m.geom("floor").friction[0] == DEFAULT_SCENE.ground_friction[0]
    assert m.opt.timestep == 0.002  # MuJoCo's own default: nothing invented


def test_prefix_applies_to_every_name_and_reference(synth):
    m = _model(synth, prefix="r1")
    scene = {"floor", "groundplane", ""}
    for objtype, count in [
        (mujoco.mjtObj.mjOBJ_BODY, m.nbody), (mujoco.mjtObj.mjOBJ_JOINT, m.njnt),
        (mujoco.mjtObj.mjOBJ_GEOM, m.ngeom), (mujoco.mjtObj.mjOBJ_SITE, m.nsite),
        (mujoco.mjtObj.mjOBJ_MESH, m.nmesh), (mujoco.mjtObj.mjOBJ_ACTUATOR, m.nu),
        (mujoco.mjtObj.mjOBJ_SENSOR, m.nsensor), (mujoco.mjtObj.mjOBJ_TENDON, m.ntendon),
        (mujoco.mjtObj.mjOBJ_EQUALITY, m.neq),
    ]:  # fmt: skip
        for i in range(count):
            name = mujoco.mj_id2name(m, objtype, i) or ""
            if objtype == mujoco.mjtObj.mjOBJ_BODY and i == 0:
                continue
            if name in scene:
                continue
            assert name.startswith("r1_"), (objtype, name)
    # references resolved to the prefixed objects
    assert m.actuator_trnid[0, 0] == m.joint("r1_j1a").id
    assert m.sensor_objid[m.sensor("r1_tip_pos").id] == m.site("r1_tool_tip").id
    assert m.exclude_signature[0] == (m.body("r1_base").id << 16) + m.body("r1_link1").id


def test_no_default_classes_and_radian_compiler(synth):
    root = ET.fromstring(_xml(synth))
    assert root.find(".//default") is None
    assert root.find("compiler").get("angle") == "radian"


def test_mjcf_extra_sections_merged(synth):
    m = _model(synth)
    assert m.ntendon == 1 and m.tendon("couple").id == 0
    assert m.neq == 1 and m.nexclude == 1


def test_restitution_warns_and_strict_raises(synth):
    with pytest.warns(ConversionWarning, match="restitution"):
        MJCFHumanoidGenerator.from_hrdf(synth).export()
    with pytest.raises(ConversionError, match="restitution"):
        MJCFHumanoidGenerator.from_hrdf(synth).export(strict=True)


def test_no_warning_when_nothing_is_lost(synth_urdf_safe):
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConversionWarning)
        MJCFHumanoidGenerator.from_hrdf(synth_urdf_safe).export()


def test_name_clash_is_a_clear_error(synth):
    bad = dataclasses.replace(
        synth, sites=[*synth.sites, dataclasses.replace(synth.sites[0], body="base")]
    )
    with pytest.raises(Exception, match="tool_tip"):
        MJCFHumanoidGenerator.from_hrdf(bad).export()


def test_bad_mjcf_extra_is_a_clear_error(synth):
    bad = dataclasses.replace(synth, mjcf_extra="<robot/>")
    with pytest.raises(HRDFError, match=r"extra\.xml: root element <robot>: expected <mujoco>"):
        MJCFHumanoidGenerator.from_hrdf(bad)
    gen = MJCFHumanoidGenerator().load(bad, validate=False)
    with pytest.raises(GeneratorError, match="mjcf_extra: expected a <mujoco> element"):
        gen.export()


def test_to_spec_and_to_model(synth):
    gen = MJCFHumanoidGenerator.from_hrdf(synth)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        spec = gen.to_spec()
        assert isinstance(spec, mujoco.MjSpec)
        assert spec.compile().nbody == gen.to_model().nbody == 6


@pytest.mark.parametrize("name", ["mini_humanoid", "arm6"])
def test_bundled_robots_compile_and_step(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        m = MJCFHumanoidGenerator.from_robot_name(name).to_model()
    d = mujoco.MjData(m)
    for _ in range(200):
        mujoco.mj_step(m, d)
    assert np.isfinite(d.qpos).all()


def test_unknown_imu_value_is_a_clear_error(synth_urdf_safe):
    imu = ImuConfig("base", value=["linacc", "magnetic"])
    meta = dataclasses.replace(synth_urdf_safe.meta, imu_config_list=[imu])
    h = dataclasses.replace(synth_urdf_safe, meta=meta)
    with pytest.raises(GeneratorError, match="IMU value 'magnetic'"):
        MJCFHumanoidGenerator.from_hrdf(h).export()
