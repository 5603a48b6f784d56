"""MJCF -> HRDF on a hand-written model using classes, fromto, euler, several joints per
body, every HRDF actuator type, sensors, tendons, equality, excludes and keyframes."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionError
from robotwright.hrdf.model import HRDF
from robotwright.parsers import mjcf_to_hrdf, mjcf_to_hrdf_with_warnings
from robotwright.parsers.reference import view_from_model
from robotwright.proof.roundtrip.run import compare_views, our_mjcf_model


def test_records_hold_resolved_values(probe: Path) -> None:
    hrdf, warnings = mjcf_to_hrdf_with_warnings(probe)
    assert [b.name for b in hrdf.bodies] == ["torso", "hip", "shin", "ankle", "arm"]
    joints = {j.name: j for j in hrdf.joints}
    assert [j.type for j in hrdf.joints] == ["free", "hinge", "hinge", "slide", "ball", "hinge"]
    assert joints["hip_x"].range == pytest.approx((-np.pi / 4, np.pi / 4))  # degrees resolved
    assert joints["hip_y"].pos == (0.0, 0.0, 0.01)
    assert (joints["hip_x"].viscous_friction, joints["hip_x"].dynamic_friction) == (0.3, 0.2)
    assert joints["shoulder"].ref == pytest.approx(np.radians(5))
    acts = {a.name: a for a in hrdf.actuators}
    assert (acts["m_hip"].type, acts["m_hip"].gear, acts["m_hip"].ctrl_range) == (
        "motor",
        40.0,
        (-1.0, 1.0),
    )
    assert (acts["p_knee"].p_gain, acts["p_knee"].d_gain, acts["p_knee"].force_range) == (
        300.0,
        5.0,
        (-90.0, 90.0),
    )
    assert (acts["v_sh"].type, acts["v_sh"].d_gain) == ("velocity", 12.0)
    (mesh,) = hrdf.meshes
    assert mesh.scale == (0.5, 0.5, 2.0) and mesh.rgba == pytest.approx((0.9, 0.8, 0.7, 1.0))
    box = next(g for g in hrdf.simple_geoms if g.type == "box")
    assert (box.condim, box.group, box.static_friction) == (4, 1, 0.8)
    assert [s.type for s in hrdf.sensors] == ["gyro", "framequat", "jointpos", "touch"]
    assert hrdf.meta.simulator_config.timestep == 0.004
    text = " ".join(str(w) for w in warnings)
    assert "worldbody dropped" in text and "light" in text
    for section in ("<tendon>", "<equality>", "<exclude", "<keyframe>"):
        assert section in hrdf.mjcf_extra


def test_compiled_roundtrip_is_exact(probe: Path) -> None:
    source = mujoco.MjModel.from_xml_path(str(probe))
    hrdf = mjcf_to_hrdf(probe)
    ours = our_mjcf_model(hrdf)
    rows = compare_views(view_from_model(source), view_from_model(ours), configs=30)
    assert all(r.ok for r in rows), "\n".join(f"{r.check} {r.value} {r.note}" for r in rows)
    # Values not covered by the table.
    assert np.array_equal(source.key_qpos, ours.key_qpos)
    assert np.array_equal(source.key_ctrl, ours.key_ctrl)
    assert np.array_equal(source.tendon_range, ours.tendon_range)
    # Exact to the last digit (MuJoCo's own XML writer keeps only 6 significant digits).
    assert np.array_equal(source.wrap_prm, ours.wrap_prm)
    assert np.array_equal(source.eq_data, ours.eq_data)
    assert np.array_equal(source.eq_solref, ours.eq_solref)
    assert np.array_equal(source.tendon_stiffness, ours.tendon_stiffness)
    assert np.array_equal(source.tendon_lengthspring, ours.tendon_lengthspring)
    assert np.array_equal(source.tendon_rgba[1], ours.tendon_rgba[1])
    assert np.array_equal(source.jnt_stiffness, ours.jnt_stiffness)
    assert np.array_equal(source.qpos_spring, ours.qpos_spring)
    assert np.array_equal(source.dof_armature, ours.dof_armature)
    assert np.array_equal(source.sensor_noise, ours.sensor_noise)


def test_strict_raises_listing_drops(probe: Path) -> None:
    # strict=True: the notes that change the physics (the floor dropped), not the light.
    with pytest.raises(ConversionError) as err:
        mjcf_to_hrdf(probe, strict=True)
    assert "worldbody" in str(err.value) and "light" not in str(err.value)
    # strict="all": every note, the cosmetic light too, marked so.
    with pytest.raises(ConversionError) as err:
        mjcf_to_hrdf(probe, strict="all")
    assert "worldbody" in str(err.value) and "(cosmetic) 1 light(s)" in str(err.value)


def test_several_top_level_bodies_are_a_scene_of_several_roots(tmp_path: Path) -> None:
    """A world of several top-level bodies converts whole (issue 40, item 5): each is a
    root, fixed ('a') or free ('b'); ``root_body`` still takes one out alone."""
    path = tmp_path / "two.xml"
    path.write_text(
        '<mujoco><worldbody><body name="a"><geom size=".1"/></body>'
        '<body name="b" pos="1 0 0"><freejoint name="b_free"/><geom size=".1"/></body>'
        "</worldbody></mujoco>"
    )
    hrdf, warnings = mjcf_to_hrdf_with_warnings(path)
    assert [b.name for b in hrdf.bodies] == ["a", "b"] and hrdf.root_indices == [0, 1]
    assert not hrdf.floating_base  # the first root, 'a', is fixed
    assert [(j.name, j.body, j.type) for j in hrdf.joints] == [("b_free", "b", "free")]
    assert not any("dropped" in str(w) for w in warnings)
    # Written and read back, the second root's free joint is a row of joint.csv.
    hrdf.save(tmp_path / "scene")
    back = HRDF.from_dir(tmp_path / "scene")
    assert [(j.name, j.body, j.type) for j in back.joints] == [("b_free", "b", "free")]
    hrdf, warnings = mjcf_to_hrdf_with_warnings(path, root_body="b")
    assert [b.name for b in hrdf.bodies] == ["b"] and hrdf.floating_base
    assert any("'a'" in str(w) for w in warnings)


def test_model_mujoco_rejects_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "bad.xml"
    path.write_text(
        '<mujoco><worldbody><body><joint type="hinge" range="1 0"/></body></worldbody></mujoco>'
    )
    with pytest.raises(ConversionError, match="bad.xml: MuJoCo cannot load it"):
        mjcf_to_hrdf(path)


def test_entity_expansion_refused(tmp_path: Path) -> None:
    path = tmp_path / "bomb.xml"
    path.write_text('<!DOCTYPE m [<!ENTITY a "x">]><mujoco model="&a;"/>')
    with pytest.raises(ConversionError, match="unsafe XML"):
        mjcf_to_hrdf(path)


def test_saved_folder_holds_meshes_and_reloads(probe: Path, tmp_path: Path) -> None:
    from robotwright.hrdf.model import HRDF

    hrdf = mjcf_to_hrdf(probe)
    out = hrdf.save(tmp_path / "probe_hrdf")
    assert (out / hrdf.meshes[0].file).is_file()
    again = HRDF.from_dir(out)
    a = view_from_model(our_mjcf_model(hrdf))
    b = view_from_model(our_mjcf_model(again))
    assert all(r.ok for r in compare_views(a, b, configs=5))


def test_massless_frame_becomes_site(tmp_path: Path) -> None:
    path = tmp_path / "frame.xml"
    path.write_text(
        '<mujoco><worldbody><body name="base"><geom size=".1" mass="1"/>'
        '<body name="link" pos="0 0 .2"><joint name="j" axis="0 1 0"/><geom size=".05"/>'
        '<body name="cam_frame" pos=".1 0 .05" euler="0.3 0.2 0.1">'
        '<site name="lens" pos="0 0 .01"/><geom type="box" size=".01 .01 .01" mass="0"'
        ' contype="0" conaffinity="0"/></body></body></body></worldbody></mujoco>'
    )
    kept, warnings = mjcf_to_hrdf_with_warnings(path)
    # By default the massless frame stays a (welded, massless) body: nothing to report.
    assert not any("cam_frame" in str(w) for w in warnings)
    assert kept.body("cam_frame").mass == 0.0
    hrdf = mjcf_to_hrdf(path, massless_frames="site")
    assert [b.name for b in hrdf.bodies] == ["base", "link"]
    assert {s.name: s.body for s in hrdf.sites} == {"lens": "link", "cam_frame": "link"}
    source = mujoco.MjModel.from_xml_path(str(path))
    rows = compare_views(view_from_model(source), view_from_model(our_mjcf_model(hrdf)), configs=10)
    assert all(r.ok for r in rows), rows
    with pytest.raises(ValueError, match="massless_frames"):
        mjcf_to_hrdf(path, massless_frames="merge")


def test_a_frame_a_sensor_or_weld_names_stays_a_body(tmp_path: Path) -> None:
    """massless_frames='site' turns a massless leaf body into a site, except one that a
    body sensor or a weld names (MuJoCo's object types read as numpy integers, compared
    as plain ints: never ``in`` a tuple of enum members)."""
    path = tmp_path / "frames.xml"
    path.write_text(
        """<mujoco><worldbody><body name="base"><joint name="j" axis="0 0 1"/>
        <geom size=".1" mass="1"/>
        <body name="camera_frame" pos="0 0 .2"/>
        <body name="sensed" pos="0 0 .3"/>
        <body name="welded" pos="0 0 .4"/>
        </body><body name="anchor" pos="1 0 0"><geom size=".1" mass="1"/></body></worldbody>
        <equality><weld body1="welded" body2="anchor"/></equality>
        <sensor><framepos objtype="body" objname="sensed"/></sensor></mujoco>"""
    )
    hrdf = mjcf_to_hrdf(path, massless_frames="site")
    bodies = {b.name for b in hrdf.bodies}
    assert {"sensed", "welded"} <= bodies
    assert "camera_frame" not in bodies and "camera_frame" in {s.name for s in hrdf.sites}
