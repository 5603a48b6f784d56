"""Every physics field MuJoCo compiles for a robot survives MJCF -> HRDF folder -> MJCF.

Each test writes a source MJCF whose fields are set to values other than MuJoCo's
defaults, converts it, saves the HRDF folder, loads it back, generates MJCF, compiles both
and compares the compiled ``MjModel`` arrays (exactly: values are written in their
shortest round-trip form).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.generators.mjcf import MJCFHumanoidGenerator
from robotwright.hrdf import HRDF
from robotwright.hrdf.options import FLAGS, OPTION_FIELDS
from robotwright.parsers import mjcf_to_hrdf_with_warnings

#: Every <option> attribute of the vocabulary, with a value that is not MuJoCo's default.
OPTION_VALUES = {
    "impratio": "5",
    "tolerance": "1e-7",
    "ls_tolerance": "0.02",
    "noslip_tolerance": "1e-5",
    "ccd_tolerance": "1e-5",
    "sleep_tolerance": "0.002",
    "density": "1.2",
    "viscosity": "2e-05",
    "o_margin": "0.01",
    "wind": "1 0.5 0",
    "magnetic": "0 0.3 0",
    "o_solref": "0.03 1.1",
    "o_solimp": "0.8 0.9 0.002 0.4 3",
    "o_friction": "0.9 0.8 0.004 0.0002 0.0003",
    "iterations": "20",
    "ls_iterations": "7",
    "noslip_iterations": "3",
    "ccd_iterations": "40",
    "sdf_iterations": "12",
    "sdf_initpoints": "30",
    "cone": "elliptic",
    "jacobian": "sparse",
    "solver": "CG",
}

_DEFAULT_OPT = mujoco.MjModel.from_xml_string("<mujoco/>").opt

ROBOT = """
  <size nuser_body="3" nuser_jnt="2" nuser_geom="4" nuser_site="1" nuser_sensor="2"
        nuser_actuator="2" nuser_tendon="3"/>
  <worldbody>
    <body name="base" pos="0 0 1" gravcomp="0.5" user="1 2 3">
      <joint name="root" type="free" damping="2" armature="0.1" frictionloss="0.3"
             user="4"/>
      <geom name="g0" type="box" size="0.1 0.1 0.1" solref="0.05 0.8"
            solimp="0.7 0.8 0.003 0.6 4" margin="0.02" gap="0.01" priority="2" condim="6"
            friction="0.7 0.01 0.001" solmix="0.3" user="5 6"/>
      <site name="s0" user="9"/>
      <body name="arm" pos="0.2 0 0">
        <joint name="j1" type="hinge" axis="0 1 0" range="-1 1" stiffness="3"
               springref="0.2" margin="0.05" actuatorfrcrange="-4 5" actuatorgravcomp="true"
               solreflimit="0.03 0.9" solimplimit="0.8 0.9 0.01 0.4 3"
               solreffriction="0.04 1.2" solimpfriction="0.85 0.9 0.002 0.5 2"
               frictionloss="0.1" damping="0.3" armature="0.01" user="7 8"/>
        <geom name="g1" type="capsule" size="0.05 0.1" solref="-1000 -20"/>
        <body name="ball" pos="0.3 0 0" gravcomp="1">
          <joint name="b1" type="ball" damping="0.4" armature="0.02" frictionloss="0.05"
                 stiffness="0.7" margin="0.01"/>
          <geom name="g2" type="sphere" size="0.05" margin="0.003"/>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="t1" user="2 3"><joint joint="j1" coef="1"/></fixed></tendon>
  <actuator><motor name="m1" joint="j1" user="1 1"/></actuator>
  <sensor><jointpos name="p1" joint="j1" user="3"/></sensor>
"""

#: Compiled arrays that carry the fields above.
FIELDS = [
    "geom_solref",
    "geom_solimp",
    "geom_margin",
    "geom_gap",
    "geom_priority",
    "geom_condim",
    "geom_friction",
    "geom_solmix",
    "jnt_stiffness",
    "qpos_spring",
    "jnt_margin",
    "jnt_actfrcrange",
    "jnt_actfrclimited",
    "jnt_actgravcomp",
    "jnt_solref",
    "jnt_solimp",
    "dof_solref",
    "dof_solimp",
    "dof_damping",
    "dof_armature",
    "dof_frictionloss",
    "body_gravcomp",
    "body_user",
    "jnt_user",
    "geom_user",
    "site_user",
    "sensor_user",
    "actuator_user",
    "nuser_body",
    "nuser_jnt",
    "nuser_geom",
    "nuser_site",
    "nuser_sensor",
    "nuser_actuator",
    "tendon_user",
    "nuser_tendon",
]


def _through_folder(source: Path, tmp_path: Path) -> tuple[mujoco.MjModel, HRDF]:
    """The source converted, saved as a folder, loaded back and compiled from our MJCF."""
    hrdf, notes = mjcf_to_hrdf_with_warnings(source)
    folder = tmp_path / "robot"
    hrdf.save(folder)
    loaded = HRDF.from_dir(folder)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the MJCF writer holds every value: no loss note
        model = MJCFHumanoidGenerator.from_hrdf(loaded).to_model(add_scene=False)
    return model, loaded


def _write(tmp_path: Path, option: str, body: str = ROBOT) -> Path:
    path = tmp_path / "source.xml"
    path.write_text(f'<mujoco model="phys">{option}{body}</mujoco>')
    return path


def _option_xml() -> str:
    attrs = " ".join(f'{k}="{v}"' for k, v in OPTION_VALUES.items() if hasattr(_DEFAULT_OPT, k))
    return f'<option timestep="0.001" integrator="implicitfast" {attrs}/>'


def test_every_field_survives_the_folder(tmp_path: Path) -> None:
    source = _write(tmp_path, _option_xml())
    want = mujoco.MjModel.from_xml_path(str(source))
    got, _ = _through_folder(source, tmp_path)
    for field in FIELDS:
        assert np.array_equal(getattr(want, field), getattr(got, field)), field
    for name in OPTION_FIELDS:
        if hasattr(want.opt, name):
            assert np.array_equal(getattr(want.opt, name), getattr(got.opt, name)), name
    for name in ("timestep", "gravity", "integrator", "disableflags", "enableflags"):
        assert np.array_equal(getattr(want.opt, name), getattr(got.opt, name)), name


def test_the_source_sets_non_default_values() -> None:
    # Guards the test above: each option value differs from MuJoCo's default.
    for name, text in OPTION_VALUES.items():
        if not hasattr(_DEFAULT_OPT, name):
            continue
        model = mujoco.MjModel.from_xml_string(f'<mujoco><option {name}="{text}"/></mujoco>')
        assert not np.array_equal(getattr(model.opt, name), getattr(_DEFAULT_OPT, name)), name


def _flag_model(name: str, kind: str) -> str:
    value = "disable" if kind == "disable" else "enable"
    return f'<option><flag {name}="{value}"/></option>'


# ipc needs integrator="discrete" (a MuJoCo 4 integrator HRDF does not name).
@pytest.mark.parametrize("name", sorted(n for n in FLAGS if n != "ipc"))
def test_every_flag_survives_the_folder(tmp_path: Path, name: str) -> None:
    kind = FLAGS[name][0]
    source = _write(tmp_path, _flag_model(name, kind))
    want = mujoco.MjModel.from_xml_path(str(source))
    assert (want.opt.disableflags, want.opt.enableflags) != (0, 0)
    got, loaded = _through_folder(source, tmp_path)
    assert loaded.meta.simulator_config.flag == {name: kind}
    assert got.opt.disableflags == want.opt.disableflags
    assert got.opt.enableflags == want.opt.enableflags


def _travel(model: mujoco.MjModel, seconds: float = 1.0) -> float:
    """Distance (m) the free base travels in ``seconds`` from 1 m/s along x, no gravity."""
    model.opt.gravity[:] = 0
    data = mujoco.MjData(model)
    data.qvel[0] = 1.0
    start = data.qpos[:3].copy()
    while data.time < seconds - 1e-12:
        mujoco.mj_step(model, data)
    return float(np.linalg.norm(data.qpos[:3] - start))


def test_free_base_damping_moves_the_same(tmp_path: Path) -> None:
    # The robot: a free base with damping 2 travelled 0.584 m in 1 s in the
    # source and 1.000 m after going through a folder (damping dropped silently).
    source = tmp_path / "free.xml"
    source.write_text(
        '<mujoco><option timestep="0.001"/><worldbody><body name="base">'
        '<joint name="root" type="free" damping="2"/>'
        '<geom type="sphere" size="0.1" mass="1"/></body></worldbody></mujoco>'
    )
    want = mujoco.MjModel.from_xml_path(str(source))
    got, loaded = _through_folder(source, tmp_path)
    assert loaded.joints[0].type == "free" and loaded.joints[0].viscous_friction == 2.0
    assert np.array_equal(got.dof_damping, want.dof_damping)
    travelled, expected = _travel(got), _travel(want)
    assert expected < 0.7  # damped: 0.58 m, not the undamped 1 m
    assert travelled == pytest.approx(expected, abs=1e-9)


def test_free_and_ball_dof_properties_in_meta_and_table(tmp_path: Path) -> None:
    source = _write(tmp_path, "")
    _, loaded = _through_folder(source, tmp_path)
    meta = (tmp_path / "robot" / "meta.yaml").read_text()
    assert "base_joint:" in meta and "viscous_friction: 2.0" in meta
    free = loaded.joints[0]
    assert (free.armature, free.dynamic_friction, free.user) == (0.1, 0.3, (4.0,))
    ball = next(j for j in loaded.joints if j.type == "ball")
    assert (ball.viscous_friction, ball.armature, ball.dynamic_friction) == (0.4, 0.02, 0.05)


def test_defaults_write_no_new_columns(tmp_path: Path) -> None:
    # A robot using none of the fields gives the tables it gave before (hurodes reads them).
    source = tmp_path / "plain.xml"
    source.write_text(
        '<mujoco><worldbody><body name="a"><joint name="j"/><geom size="0.1"/>'
        "</body></worldbody></mujoco>"
    )
    _through_folder(source, tmp_path)
    header = (tmp_path / "robot" / "simple_geom.csv").read_text().splitlines()[0]
    for column in ("solref0", "solimp0", "margin", "gap", "priority", "solmix", "user"):
        assert column not in header.split(",")
    meta = (tmp_path / "robot" / "meta.yaml").read_text()
    for key in ("option:", "flag:", "mjcf_size", "base_joint:"):
        assert key not in meta


URDF_ARM = """<robot name="arm">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="upper"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="{effort}" velocity="2"/></joint>
  <joint name="slide" type="prismatic"><parent link="upper"/><child link="tip"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="0.5" velocity="1"/></joint>
</robot>"""


@pytest.mark.parametrize("effort", ["7", "-3", "0.25"])
def test_urdf_effort_is_the_joint_force_range(tmp_path: Path, effort: str) -> None:
    from robotwright.parsers import urdf_to_hrdf_with_warnings

    source = tmp_path / "arm.urdf"
    source.write_text(URDF_ARM.format(effort=effort))
    hrdf, notes = urdf_to_hrdf_with_warnings(source)
    folder = tmp_path / "robot"
    hrdf.save(folder)
    loaded = HRDF.from_dir(folder)
    limit = abs(float(effort))
    byname = {j.name: j for j in loaded.joints}
    assert byname["shoulder"].actuatorfrcrange == (-limit, limit)
    assert byname["slide"].actuatorfrcrange is None  # no effort: unclamped
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ours = MJCFHumanoidGenerator.from_hrdf(loaded).to_model(add_scene=False)
    np.testing.assert_array_equal(ours.jnt_actfrcrange[0], [-limit, limit])
    assert ours.jnt_actfrclimited.tolist() == [True, False]
    mujoco_import = mujoco.MjModel.from_xml_path(str(source))
    noted = any("actuatorfrcrange +-effort set" in str(n) and "shoulder" in str(n) for n in notes)
    if mujoco_import.jnt_actfrclimited.any():
        # MuJoCo's own URDF import (3.11 and 4.x) gives the same joint force ranges.
        np.testing.assert_array_equal(mujoco_import.jnt_actfrcrange, ours.jnt_actfrcrange)
        np.testing.assert_array_equal(mujoco_import.jnt_actfrclimited, ours.jnt_actfrclimited)
        assert not noted, notes
    else:
        # An import that ignores effort: the difference is a note naming the joint.
        assert noted, notes


def test_urdf_export_carries_options_and_effort(tmp_path: Path) -> None:
    from robotwright.generators.urdf import URDFHumanoidGenerator

    source = _write(tmp_path, _option_xml().replace("/>", "><flag energy='enable'/></option>"))
    hrdf, _ = mjcf_to_hrdf_with_warnings(source)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        text = URDFHumanoidGenerator.from_hrdf(hrdf).export(None, add_mujoco_tag=True)
    lost = "\n".join(str(w.message) for w in caught)
    # URDF holds no contact or solver parameters: each is named as not written.
    for name in ("solref", "solimp", "margin", "gap", "priority", "solmix", "gravcomp"):
        assert name in lost, name
    urdf = tmp_path / "out.urdf"
    urdf.write_text(text)
    want = mujoco.MjModel.from_xml_path(str(source))
    got = mujoco.MjModel.from_xml_path(str(urdf))
    for name in ("impratio", "cone", "o_solref", "wind", "enableflags", "iterations"):
        assert np.array_equal(getattr(want.opt, name), getattr(got.opt, name)), name
    assert got.nuser_body == want.nuser_body
    # (-4, 5) is not symmetric: URDF cannot hold it, reported above.
    assert "actuatorfrcrange (-4.0, 5.0)" in lost
