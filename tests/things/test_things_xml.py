"""MJCF writing and reading: defaults omitted, classes picked, round trips, export."""

from __future__ import annotations

import os
import warnings

import mujoco
import numpy as np
import pytest
import trimesh

from robotwright.errors import ConversionError, ConversionWarning
from robotwright.things import (
    Accelerometer,
    Ball,
    Body,
    Box,
    Capsule,
    Cylinder,
    Ellipsoid,
    FramePos,
    Free,
    General,
    Hinge,
    JointPos,
    Material,
    Mesh,
    Motor,
    Plane,
    Position,
    Site,
    Slide,
    Sphere,
    Velocity,
    World,
)
from robotwright.things.xml_reader import ThingXMLError

from ._compare import assert_same_model


def _world(*things, **kw):
    world = World("test", **kw)
    world.attach(*things)
    return world


def test_attributes_equal_to_mujoco_defaults_are_omitted():
    geom = Sphere("ball", radius=0.1)
    world = _world(Body("b").attach(geom))
    line = next(s.strip() for s in world.to_xml_string().splitlines() if "<geom" in s)
    assert line == '<geom name="ball" size="0.1"/>'
    geom.condim = 6
    geom.rgba = [1, 0, 0, 1]
    line = next(s.strip() for s in world.to_xml_string().splitlines() if "<geom" in s)
    assert line == '<geom name="ball" size="0.1" condim="6" rgba="1 0 0 1"/>'


def test_declared_defaults_match_mujoco():
    """Every _DEFAULT_VALS entry equals what MuJoCo compiles when the attribute is absent."""
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body()
    checks = [
        (
            Sphere,
            body.add_geom(),
            {
                "contype": "contype",
                "conaffinity": "conaffinity",
                "condim": "condim",
                "friction": "friction",
                "solref": "solref",
                "solimp": "solimp",
                "density": "density",
                "margin": "margin",
                "priority": "priority",
                "solmix": "solmix",
                "fluidcoef": "fluid_coefs",
            },
        ),
        (
            Hinge,
            body.add_joint(),
            {
                "axis": "axis",
                "solreflimit": "solref_limit",
                "solimplimit": "solimp_limit",
                "solreffriction": "solref_friction",
                "solimpfriction": "solimp_friction",
                "damping": "damping",
                "stiffness": "stiffness",
                "armature": "armature",
            },
        ),
        (Site, body.add_site(), {"size": "size"}),
        (
            Motor,
            spec.add_actuator(),
            {"gear": "gear", "ctrlrange": "ctrlrange", "forcerange": "forcerange"},
        ),
    ]
    for cls, element, names in checks:
        for ours, theirs in names.items():
            np.testing.assert_allclose(
                cls._DEFAULT_VALS[ours], getattr(element, theirs), err_msg=f"{cls.__name__}.{ours}"
            )
    np.testing.assert_allclose(
        Sphere._DEFAULT_VALS["rgba"], np.float32(body.add_geom().rgba), rtol=1e-6
    )


def _mixed_world() -> World:
    base = Body("base", pos=[0, 0, 0.5])
    base.attach(
        Free("root"),
        Box("torso", size=[0.2, 0.1, 0.05], material=Material("red", rgba=[1, 0, 0, 1])),
    )
    arm = Body("arm", pos=[0.2, 0, 0])
    arm.rotate([0, 0, 1], 0.3)
    hinge = Hinge("shoulder", axis=[0, 1, 0], range=[-1.2, 0.8], damping=[0.1])
    hinge.attach(Position("servo", kp=50, kv=2, ctrlrange=[-1, 1]), JointPos("q"))
    slide = Slide("extend", axis=[1, 0, 0], range=[0, 0.1])
    slide.attach(Velocity("speed", kv=5))
    site = Site("imu", pos=[0.1, 0, 0])
    site.attach(Accelerometer("acc"), FramePos("where"))
    arm.attach(
        hinge,
        slide,
        Capsule(radius=0.03, half_length=0.1),
        Cylinder(radius=0.02, half_length=0.05, pos=[0.1, 0, 0]),
        site,
    )
    wrist = Body("wrist", pos=[0.2, 0, 0])
    ball = Ball("wrist_ball", range=[0, 0.7], armature=0.01)
    hinge2 = Hinge("twist", armature=0.01)
    wrist.attach(hinge2, ball, Ellipsoid(size=[0.03, 0.02, 0.01], mass=0.2))
    hinge2.attach(
        General(
            "gen",
            gainprm=[3],
            biastype="affine",
            biasprm=[0, -1, -0.1],
            dyntype="filter",
            dynprm=[0.05],
        ),
        Motor("direct", gear=[2]),
    )
    arm.attach(wrist)
    base.attach(arm)
    world = _world(
        Plane("floor", size=[5, 5, 0.1]), base, timestep=0.001, integrator="implicitfast"
    )
    world.disabled.add("warmstart")
    return world


def test_round_trip_is_stable_and_compiles_to_the_same_model():
    world = _mixed_world()
    xml = world.to_xml_string()
    again = World.from_xml_string(xml)
    assert again.to_xml_string() == xml
    assert_same_model(world.model, again.model)
    assert again.model.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert again.model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_WARMSTART


def test_reading_picks_classes_from_derived_attributes():
    world = World.from_xml_string(_mixed_world().to_xml_string())
    kinds = {t.name: type(t) for t in world.walk() if t._NAMESPACE and t.name}
    assert kinds["floor"] is Plane and kinds["torso"] is Box and kinds["root"] is Free
    assert kinds["shoulder"] is Hinge and kinds["extend"] is Slide and kinds["wrist_ball"] is Ball
    assert kinds["servo"] is Position and kinds["speed"] is Velocity
    assert kinds["gen"] is General and kinds["direct"] is Motor
    assert kinds["q"] is JointPos and kinds["acc"] is Accelerometer and kinds["where"] is FramePos
    servo = world.find("servo")
    assert servo.kp == 50 and servo.kv == 2 and servo.parent is world.find("shoulder")
    geoms = [type(g) for g in world.all_geoms()]
    assert geoms == [Plane, Box, Capsule, Cylinder, Ellipsoid]
    torso = world.find("torso")
    assert isinstance(torso.material, Material) and torso.material.name == "red"


_AUTHORED = """
<mujoco model="authored">
  <compiler angle="degree" eulerseq="zyx"/>
  <default>
    <geom rgba="0 1 0 1" density="500"/>
    <default class="leg"><joint damping="0.5" range="-45 45"/><geom type="capsule" size="0.02"/></default>
  </default>
  <worldbody>
    <frame pos="0 0 1" euler="0 0 30">
      <body name="torso" euler="10 20 30" childclass="leg">
        <freejoint/>
        <geom type="box" size="0.1 0.1 0.1"/>
        <body name="thigh" pos="0 0 -0.1" axisangle="1 0 0 20">
          <joint name="hip" axis="1 0 0"/>
          <geom fromto="0 0 0 0 0.05 -0.3"/>
          <site name="s" xyaxes="0 1 0 -1 0 0"/>
          <body name="shin" pos="0 0.05 -0.3" zaxis="0 1 1">
            <joint name="knee" type="slide" axis="0 0 1" range="0 0.1"/>
            <geom fromto="0 0 0 0 0 -0.2" type="cylinder"/>
            <inertial pos="0 0 -0.1" mass="0.3" fullinertia="0.03 0.02 0.04 0.001 0 0"/>
          </body>
        </body>
      </body>
    </frame>
  </worldbody>
  <actuator><position joint="hip" kp="20" ctrlrange="-30 30"/></actuator>
</mujoco>
"""


def test_reading_resolves_defaults_degrees_euler_fromto_and_frames():
    original = mujoco.MjModel.from_xml_string(_AUTHORED)
    world = World.from_xml_string(_AUTHORED)
    xml = world.to_xml_string()
    assert "class=" not in xml and "euler" not in xml and "fromto" not in xml
    assert world.find("hip").range[1] == pytest.approx(np.pi / 4)
    assert_same_model(original, world.model)
    assert World.from_xml_string(xml).to_xml_string() == xml


def test_export_copies_meshes_and_the_file_compiles(tmp_path):
    mesh_file = tmp_path / "src" / "finger.stl"
    mesh_file.parent.mkdir()
    trimesh.creation.box(extents=[0.02, 0.02, 0.06]).export(mesh_file)
    finger = Body("finger")
    finger.attach(Hinge("j"), Mesh("shell", file=str(mesh_file), scale=[1, 1, 2]))
    world = _world(finger, finger.copy(pos=[0.1, 0, 0]))
    out = world.export(tmp_path / "out" / "model.xml")
    assert (tmp_path / "out" / "assets" / "finger.stl").is_file()
    text = out.read_text()
    assert 'file="assets/finger.stl"' in text and text.count("<mesh ") == 1  # shared asset
    exported = mujoco.MjModel.from_xml_path(str(out))
    assert exported.nmesh == 1 and exported.ngeom == 2
    assert_same_model(world.model, exported)
    reread = World.from_xml_path(out)
    assert os.path.samefile(reread.all_geoms()[0].file, tmp_path / "out" / "assets" / "finger.stl")
    assert_same_model(exported, reread.model)


def test_from_xml_string_resolves_relative_files_against_base_dir(tmp_path):
    trimesh.creation.icosphere().export(tmp_path / "ball.obj")
    xml = '<mujoco><asset><mesh file="ball.obj"/></asset><worldbody><body><geom type="mesh" mesh="ball"/></body></worldbody></mujoco>'
    world = World.from_xml_string(xml, base_dir=tmp_path)
    assert world.all_geoms()[0].file == str(tmp_path / "ball.obj")
    assert world.model.nmesh == 1


def test_failed_export_leaves_no_file(tmp_path):
    world = _world(Body("b").attach(Mesh(file=str(tmp_path / "missing.stl"))))
    with pytest.raises(FileNotFoundError, match="missing.stl"):
        world.export(tmp_path / "model.xml")
    assert not (tmp_path / "model.xml").exists()


def test_unsafe_or_invalid_xml_is_rejected_with_a_clear_error(tmp_path):
    bomb = '<?xml version="1.0"?><!DOCTYPE x [<!ENTITY a "aaaa">]><mujoco model="&a;"/>'
    with pytest.raises(ThingXMLError, match="safe XML"):
        World.from_xml_string(bomb)
    with pytest.raises(ThingXMLError, match="MuJoCo rejected"):
        World.from_xml_string(
            "<mujoco><worldbody><geom type='sphere' size='-1'/><bogus/></worldbody></mujoco>"
        )
    with pytest.raises(ThingXMLError, match="no such MJCF file"):
        World.from_xml_path(tmp_path / "none.xml")


_HFIELD = """<mujoco><asset><hfield name="terrain" nrow="3" ncol="2" size="1 1 0.1 0.1"
 elevation="0 1 2 3 4 5"/><hfield name="unused" nrow="2" ncol="2" size="1 1 1 1"/></asset>
<custom><numeric name="gain" data="3"/></custom>
<worldbody><geom name="ground" type="hfield" hfield="terrain"/><body><geom size="0.1"/></body>
</worldbody></mujoco>"""


def test_height_fields_round_trip_and_unrepresentable_parts_are_named():
    from robotwright.things import HField

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        world = World.from_xml_string(_HFIELD)
    messages = [str(w.message) for w in caught if issubclass(w.category, ConversionWarning)]
    assert any('<hfield name="unused">' in m and "no geom uses it" in m for m in messages)
    assert any("custom" in m for m in messages)
    ground = world.find("ground")
    assert isinstance(ground, HField) and (ground.nrow, ground.ncol) == (3, 2)
    original = mujoco.MjModel.from_xml_string(_HFIELD)
    model = world.model
    assert model.nhfield == 1 and model.ngeom == original.ngeom
    np.testing.assert_allclose(model.hfield_size[0], original.hfield_size[0])
    np.testing.assert_allclose(model.hfield_data, original.hfield_data[: model.hfield_data.size])
    xml = world.to_xml_string()
    assert World.from_xml_string(xml).to_xml_string() == xml
    with pytest.raises(ConversionError, match="unused"):
        World.from_xml_string(_HFIELD, strict=True)


_TENDONS = """<mujoco>
  <default><tendon width="0.01"/><general gear="3"/></default>
  <worldbody><body name="a"><joint name="j1"/><geom size="0.1"/><body name="b" pos="0 0 -0.3">
    <joint name="j2"/><geom size="0.1"/></body></body></worldbody>
  <tendon><fixed name="t"><joint joint="j1" coef="1"/><joint joint="j2" coef="-1"/></fixed></tendon>
  <equality><joint joint1="j1" joint2="j2"/></equality>
  <contact><exclude body1="a" body2="b"/></contact>
  <actuator><motor joint="j1"/><general tendon="t"/><motor joint="j2" gear="7"/></actuator>
  <sensor><jointpos joint="j2"/><tendonpos tendon="t"/><jointvel joint="j1"/></sensor>
  <keyframe><key name="home" qpos="0.1 0.2" ctrl="1 2 3"/></keyframe>
</mujoco>"""


def test_unmodelled_sections_are_carried_and_keep_actuator_and_sensor_order():
    original = mujoco.MjModel.from_xml_string(_TENDONS)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing may be dropped
        world = World.from_xml_string(_TENDONS)
    assert_same_model(original, world.model)
    np.testing.assert_allclose(
        world.model.actuator_gear[:, 0], [3, 3, 7]
    )  # motor takes general defaults
    np.testing.assert_allclose(world.model.tendon_width, original.tendon_width)
    np.testing.assert_allclose(world.model.key_ctrl, original.key_ctrl)
    xml = world.to_xml_string()
    assert World.from_xml_string(xml).to_xml_string() == xml


def test_inline_mesh_round_trips_and_foreign_references_are_clear_errors():
    tet = Mesh("tet", vertex=[0, 0, 0, 0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1])
    world = _world(Body("b").attach(tet))
    assert world.model.nmesh == 1 and world.model.mesh_vertnum[0] == 4
    xml = world.to_xml_string()
    assert '<mesh name="tet" vertex=' in xml
    assert World.from_xml_string(xml).to_xml_string() == xml
    from robotwright.things import Camera, ThingAttributeError

    outsider = Body("outsider")
    world.attach(Body("c").attach(Camera(mode="targetbody", target=outsider)))
    with pytest.raises(ThingAttributeError, match="Body 'outsider' .* not part of this World"):
        world.to_xml_string()
