"""URDF -> HRDF on small hand-written URDFs, checked against MuJoCo's compile."""

from __future__ import annotations

import logging
from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from robotwright.errors import ConversionError
from robotwright.parsers import urdf_to_hrdf, urdf_to_hrdf_with_warnings
from robotwright.parsers.reference import urdf_mujoco_view, view_from_model
from robotwright.proof.roundtrip.run import compare_views, our_mjcf_model

BOX_STL = (
    "solid b\n"
    + "".join(
        f"facet normal 0 0 0\nouter loop\nvertex {a}\nvertex {b}\nvertex {c}\nendloop\nendfacet\n"
        for a, b, c in [
            ("0 0 0", "1 0 0", "0 1 0"),
            ("0 0 0", "0 0 1", "1 0 0"),
            ("0 0 0", "0 1 0", "0 0 1"),
            ("1 0 0", "0 0 1", "0 1 0"),
        ]
    )
    + "endsolid b\n"
)

ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><inertial><origin xyz="0 0 0.05" rpy="0.1 0.2 0.3"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0.001" ixz="-0.002" iyy="0.03" iyz="0.0015" izz="0.025"/></inertial>
    <visual><geometry><mesh filename="package://armpkg/meshes/tet.stl" scale="1 2 1"/></geometry>
      <material name="red"><color rgba="1 0 0 1"/></material></visual>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="upper"><inertial><origin xyz="0 0 0.2" rpy="0.5 -0.3 0.7"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0.002" ixz="0.001" iyy="0.012" iyz="-0.001" izz="0.005"/></inertial>
    <collision><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.03" length="0.4"/></geometry></collision></link>
  <link name="slider"><inertial><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <link name="finger"><inertial><mass value="0.1"/>
    <inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0001" iyz="0" izz="0.0001"/></inertial></link>
  <link name="tool"><inertial><origin xyz="0.01 0 0" rpy="0 0.4 0"/><mass value="0.3"/>
    <inertia ixx="0.002" ixy="0.0001" ixz="0" iyy="0.001" iyz="0" izz="0.0015"/></inertial></link>
  <link name="tcp"/>
  <joint name="shoulder" type="continuous"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0 0.2 0"/><axis xyz="0 1 1"/><dynamics damping="0.5" friction="0.1"/></joint>
  <joint name="rail" type="prismatic"><parent link="upper"/><child link="slider"/>
    <origin xyz="0 0 0.4" rpy="0.3 0 0"/><axis xyz="1 0 0"/><limit lower="-0.1" upper="0.2" effort="10" velocity="1"/></joint>
  <joint name="finger_joint" type="revolute"><parent link="slider"/><child link="finger"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="rail" multiplier="2.5" offset="0.1"/></joint>
  <joint name="tool_fix" type="fixed"><parent link="slider"/><child link="tool"/>
    <origin xyz="0.1 0.05 0" rpy="0.2 0.9 -0.4"/></joint>
  <joint name="tcp_fix" type="fixed"><parent link="tool"/><child link="tcp"/>
    <origin xyz="0 0 0.07"/></joint>
  <gazebo reference="base"/>
</robot>
"""


@pytest.fixture
def arm(tmp_path: Path) -> Path:
    pkg = tmp_path / "armpkg"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "urdf").mkdir()
    (pkg / "package.xml").write_text("<package><name>armpkg</name></package>")
    (pkg / "meshes" / "tet.stl").write_text(BOX_STL)
    path = pkg / "urdf" / "arm.urdf"
    path.write_text(ARM)
    return path


def test_keep_policy_matches_mujoco_import_except_massless_tcp(arm: Path) -> None:
    hrdf, warnings = urdf_to_hrdf_with_warnings(arm, fixed_joints="site")
    assert any("ASCII STL rewritten as binary STL" in str(w) for w in warnings)
    assert [b.name for b in hrdf.bodies] == ["base", "upper", "slider", "finger", "tool"]
    assert [s.name for s in hrdf.sites] == ["tcp"]
    assert {j.name: j.type for j in hrdf.joints} == {
        "shoulder": "hinge",
        "rail": "slide",
        "finger_joint": "hinge",
    }
    shoulder = next(j for j in hrdf.joints if j.name == "shoulder")
    assert shoulder.range is None
    assert (shoulder.viscous_friction, shoulder.dynamic_friction) == (0.5, 0.1)
    assert any("<gazebo>" in str(w) for w in warnings)
    assert any("effort/velocity" in str(w) for w in warnings)
    ref = urdf_mujoco_view(arm)
    ours = view_from_model(our_mjcf_model(hrdf))
    mimic = {"finger_joint": ("rail", 2.5, 0.1)}
    rows = compare_views(ref, ours, configs=20, mimic=mimic, collision_only=True)
    assert all(r.ok for r in rows if r.check != "actuators (order, type, gains, ranges)"), rows


def test_merge_policy_combines_rotated_fixed_child_exactly(arm: Path) -> None:
    hrdf = urdf_to_hrdf(arm, fixed_joints="merge")
    assert "tool" not in [b.name for b in hrdf.bodies]
    assert {s.name: s.body for s in hrdf.sites} == {"tool": "slider", "tcp": "slider"}
    ref = urdf_mujoco_view(arm)
    ours = view_from_model(our_mjcf_model(hrdf))
    rows = {r.check: r for r in compare_views(ref, ours, configs=20)}
    for key in (
        "body masses max rel.err",
        "inertia tensors max rel.err",
        "centres of mass max err (m)",
    ):
        assert rows[key].ok, rows[key]
    assert next(r for k, r in rows.items() if k.startswith("FK")).ok
    assert ours.mass["slider"] == pytest.approx(0.8, rel=1e-15)


def test_mimic_becomes_joint_equality(arm: Path) -> None:
    hrdf = urdf_to_hrdf(arm, fixed_joints="site")
    model = our_mjcf_model(hrdf)
    assert model.neq == 1
    assert model.eq_type[0] == mujoco.mjtEq.mjEQ_JOINT
    assert model.joint(int(model.eq_obj1id[0])).name == "finger_joint"
    assert model.joint(int(model.eq_obj2id[0])).name == "rail"
    assert np.allclose(model.eq_data[0, :5], [0.1, 2.5, 0, 0, 0])


def test_visual_and_collision_geoms_kept_apart(arm: Path) -> None:
    hrdf = urdf_to_hrdf(arm, fixed_joints="site")
    (mesh,) = hrdf.meshes
    assert (mesh.group, mesh.contact_type, mesh.contact_affinity) == (2, 0, 0)
    assert mesh.rgba == (1.0, 0.0, 0.0, 1.0) and mesh.scale == (1.0, 2.0, 1.0)
    boxes = [g for g in hrdf.simple_geoms if g.type == "box"]
    assert boxes[0].size == (0.1, 0.1, 0.05) and boxes[0].group == 3
    cyl = [g for g in hrdf.simple_geoms if g.type == "cylinder"][0]
    assert cyl.size[:2] == (0.03, 0.2)


def test_package_map_and_ros_package_path(arm: Path, tmp_path: Path, monkeypatch) -> None:
    other = tmp_path / "elsewhere" / "meshes"
    other.mkdir(parents=True)
    (other / "tet.stl").write_text(BOX_STL.replace("vertex 1 0 0", "vertex 2 0 0"))
    hrdf = urdf_to_hrdf(arm, fixed_joints="site", package_map={"armpkg": other.parent})
    staged = trimesh.load(hrdf.mesh_path(hrdf.meshes[0]))
    assert staged.bounds[1][0] == 2.0  # the package_map copy, not the ancestor one
    ws = tmp_path / "ws" / "src" / "renamed_folder"
    (ws / "meshes").mkdir(parents=True)
    (ws / "package.xml").write_text("<package><name>armpkg</name></package>")
    (ws / "meshes" / "tet.stl").write_text(BOX_STL)
    arm.parent.parent.rename(tmp_path / "gone")
    moved = tmp_path / "alone" / "alone.urdf"
    moved.parent.mkdir()
    moved.write_text(ARM)
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    with pytest.raises(ConversionError, match="package 'armpkg' not found"):
        urdf_to_hrdf(moved)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))  # found by package.xml
    assert len(urdf_to_hrdf(moved, fixed_joints="site").meshes) == 1


def test_unresolved_meshes_listed_in_one_error(tmp_path: Path) -> None:
    text = ARM.replace("package://armpkg/meshes/tet.stl", "missing_a.stl").replace(
        '<collision><geometry><box size="0.2 0.2 0.1"/>',
        '<collision><geometry><mesh filename="missing_b.stl"/>',
    )
    path = tmp_path / "r" / "urdf" / "x.urdf"
    path.parent.mkdir(parents=True)
    path.write_text(text)
    with pytest.raises(ConversionError) as err:
        urdf_to_hrdf(path)
    assert "missing_a.stl" in str(err.value) and "missing_b.stl" in str(err.value)
    assert len(err.value.problems) == 2


def test_mesh_path_escaping_robot_folder_rejected(tmp_path: Path) -> None:
    (tmp_path / "secret.stl").write_text(BOX_STL)
    path = tmp_path / "robot" / "urdf" / "x.urdf"
    path.parent.mkdir(parents=True)
    path.write_text(ARM.replace("package://armpkg/meshes/tet.stl", "../../../secret.stl"))
    with pytest.raises(ConversionError, match="outside the robot folder"):
        urdf_to_hrdf(path)


def test_entity_expansion_refused(tmp_path: Path) -> None:
    path = tmp_path / "bomb.urdf"
    path.write_text(
        '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;">]>'
        '<robot name="x"><link name="&b;"/></robot>'
    )
    with pytest.raises(ConversionError, match="unsafe XML"):
        urdf_to_hrdf(path)


def test_strict_lists_every_warning(arm: Path) -> None:
    # strict=True: the notes that change the physics (the ASCII STL rewritten as binary
    # keeps its triangles: cosmetic, not among them).
    with pytest.raises(ConversionError) as err:
        urdf_to_hrdf(arm, strict=True)
    text = str(err.value)
    assert "2 element(s)" in text
    assert "<gazebo>" in text and "effort/velocity" in text and "ASCII STL" not in text
    with pytest.raises(ConversionError) as err:
        urdf_to_hrdf(arm, strict="all")
    text = str(err.value)
    assert "3 element(s)" in text and "(cosmetic) mesh" in text and "ASCII STL" in text


def test_warnings_are_logged(arm: Path, caplog) -> None:
    with caplog.at_level(logging.WARNING, logger="robotwright.parsers"):
        urdf_to_hrdf(arm, fixed_joints="site")
    assert any("gazebo" in r.getMessage() for r in caplog.records)


def test_bad_input_names_file_and_element(tmp_path: Path) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text(
        '<robot name="x"><link name="a"/><joint name="j" type="revolute">'
        '<parent link="a"/><child link="nope"/></joint></robot>'
    )
    with pytest.raises(ConversionError, match=r"bad.urdf.*joint name=\"j\".*'nope' is not defined"):
        urdf_to_hrdf(path)
    with pytest.raises(ValueError, match="fixed_joints"):
        urdf_to_hrdf(path, fixed_joints="glue")


def test_actuators_motor_option_keeps_effort(arm: Path) -> None:
    hrdf = urdf_to_hrdf(arm, fixed_joints="site", actuators="motor")
    rail = next(a for a in hrdf.actuators if a.joint == "rail")
    assert (rail.peak_torque, rail.ctrl_range, rail.peak_velocity) == (10.0, (-10.0, 10.0), 1.0)


def test_negative_scale_kept_matches_mujoco(arm: Path, write_tet) -> None:
    """MuJoCo mirrors a mesh with a negative scale itself; the row keeps that scale and
    the file, and must give the same compiled collision geom (MuJoCo re-centres each mesh
    on its own volume centroid, so the geom pose checks the mirrored triangles)."""
    write_tet(arm.parent.parent / "meshes" / "tetb.stl")  # MuJoCo reads binary STL only
    text = ARM.replace(
        '<collision><geometry><box size="0.2 0.2 0.1"/>',
        '<collision><geometry><mesh filename="package://armpkg/meshes/tetb.stl" scale="1 -2 1"/>',
    )
    path = arm.with_name("mirror.urdf")
    path.write_text(text)
    hrdf, warnings = urdf_to_hrdf_with_warnings(path, fixed_joints="site")
    mirrored = [m for m in hrdf.meshes if m.group == 3]
    assert mirrored[0].scale == (1.0, -2.0, 1.0) and mirrored[0].file.endswith("tetb.stl")
    assert not any("negative scale" in str(w) for w in warnings)
    ref = urdf_mujoco_view(path)
    ours = view_from_model(our_mjcf_model(hrdf))
    row = next(
        r for r in compare_views(ref, ours, configs=3, collision_only=True) if "geoms" in r.check
    )
    assert row.ok, row


def test_saved_hrdf_folder_reloads_to_the_same_model(arm: Path, tmp_path: Path) -> None:
    from robotwright.hrdf.model import HRDF

    hrdf = urdf_to_hrdf(arm, fixed_joints="merge", work_dir=tmp_path / "stage")
    folder = hrdf.save(tmp_path / "arm_hrdf")
    assert all((folder / m.file).is_file() for m in hrdf.meshes)
    again = HRDF.from_dir(folder)
    assert again.mjcf_extra == hrdf.mjcf_extra
    rows = compare_views(
        view_from_model(our_mjcf_model(hrdf)), view_from_model(our_mjcf_model(again)), configs=5
    )
    assert all(r.ok for r in rows), rows


def test_floating_joint_from_world_becomes_free_root(tmp_path: Path) -> None:
    path = tmp_path / "r" / "urdf" / "float.urdf"
    path.parent.mkdir(parents=True)
    path.write_text(
        '<robot name="f"><link name="world"/><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        '<joint name="float" type="floating"><parent link="world"/><child link="base"/>'
        '<origin xyz="0 0 1"/></joint></robot>'
    )
    hrdf = urdf_to_hrdf(path)
    assert hrdf.floating_base and hrdf.joints[0].name == "float"
    assert hrdf.bodies[0].pos == (0.0, 0.0, 1.0)


def test_planar_joint_is_a_clear_error(tmp_path: Path) -> None:
    path = tmp_path / "planar.urdf"
    path.write_text(
        '<robot name="p"><link name="a"/><link name="b"/><joint name="pl" type="planar">'
        '<parent link="a"/><child link="b"/></joint></robot>'
    )
    with pytest.raises(ConversionError, match=r'planar.urdf.*joint name="pl".*planar'):
        urdf_to_hrdf(path)


def test_file_uri_and_ament_prefix_path(arm: Path, tmp_path: Path, monkeypatch) -> None:
    uri = (arm.parent.parent / "meshes" / "tet.stl").as_uri()
    path = arm.with_name("file_uri.urdf")
    path.write_text(ARM.replace("package://armpkg/meshes/tet.stl", uri))
    assert len(urdf_to_hrdf(path, fixed_joints="site").meshes) == 1
    prefix = tmp_path / "install"
    (prefix / "share" / "otherpkg" / "meshes").mkdir(parents=True)
    (prefix / "share" / "otherpkg" / "meshes" / "tet.stl").write_text(BOX_STL)
    path2 = arm.with_name("ament.urdf")
    path2.write_text(ARM.replace("package://armpkg/", "package:///otherpkg/"))
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    assert len(urdf_to_hrdf(path2, fixed_joints="site").meshes) == 1


def test_merge_policy_agrees_with_mujoco_fusestatic(arm: Path) -> None:
    """A second, independent check of merging a rotated fixed child: MuJoCo's own
    importer with fusestatic gives the same mass, centre of mass and world inertia, and
    so does MuJoCo's composite inertia (mj_crb) of the slider and its fixed child."""
    from robotwright.parsers.reference import (
        compile_urdf,
        mujoco_diagonalises_inertia_exactly,
        urdf_for_mujoco,
    )

    text = urdf_for_mujoco(arm)
    fused = view_from_model(compile_urdf(text.replace('fusestatic="false"', 'fusestatic="true"')))
    ours = view_from_model(our_mjcf_model(urdf_to_hrdf(arm, fixed_joints="merge")))
    # MuJoCo's fused inertia goes through its compiler's diagonalisation, which on
    # MuJoCo 3.11 leaves the principal axes up to ~1e-6 rad off (the slider's tensor
    # rebuilt from them is 6.5e-11 off, relative): the inertia comparison with it is
    # exact only where that compiler is (4.x); the mj_crb one below is exact on both.
    exact = mujoco_diagonalises_inertia_exactly()
    # MuJoCo also fuses the fixed root into the world; compare the moving bodies.
    for name in ("upper", "slider", "finger"):
        assert ours.mass[name] == pytest.approx(fused.mass[name], rel=1e-12)
        (c1, i1), (c2, i2) = ours.inertia_world[name], fused.inertia_world[name]
        assert np.abs(c1 - c2).max() <= 1e-12
        if exact:
            assert np.abs(i1 - i2).max() <= 1e-12 * np.abs(i2).max()
    # The slider and its fixed child summed by MuJoCo's composite rigid-body algorithm
    # (no diagonalisation): crb(slider) - crb(finger), about the com-based origin.
    model = compile_urdf(text)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    mujoco.mj_crb(model, data)
    crb = data.crb[model.body("slider").id] - data.crb[model.body("finger").id]
    about_origin = np.array(
        [[crb[0], crb[3], crb[4]], [crb[3], crb[1], crb[5]], [crb[4], crb[5], crb[2]]]
    )
    d = crb[6:9] / crb[9]
    ref = about_origin - crb[9] * (float(d @ d) * np.eye(3) - np.outer(d, d))
    origin = data.subtree_com[model.body_rootid[model.body("slider").id]]
    com, tensor = ours.inertia_world["slider"]
    assert crb[9] == pytest.approx(ours.mass["slider"], rel=1e-12)
    assert np.abs(origin + d - com).max() <= 1e-12
    assert np.abs(tensor - ref).max() <= 1e-12 * np.abs(ref).max()
