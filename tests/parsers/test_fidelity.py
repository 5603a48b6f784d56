"""No silent change of meaning (issue 13, section 2): each case on the real file that
showed it, plus the synthetic cases that pin the rule down.

Real files come from tools/fetch_test_data.py (robosuite-models, robosuite, pybullet
data) and the ``test`` extra (example-robot-data); tests skip with a reason when absent.
"""

from __future__ import annotations

import sysconfig
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from robotwright._xmlsafe import parse_xml
from robotwright.errors import ConversionError
from robotwright.generators import MJCFHumanoidGenerator, URDFHumanoidGenerator
from robotwright.hrdf.model import HRDF, Body, Joint
from robotwright.hrdf.validate import check_model as validate
from robotwright.parsers.api import mjcf_to_hrdf_with_warnings, urdf_to_hrdf_with_warnings
from robotwright.parsers.reference import compile_urdf, urdf_for_mujoco, view_from_model
from robotwright.proof.roundtrip.run import compare_extras, our_mjcf_model, roundtrip

pytestmark = pytest.mark.usefixtures("quiet_parsers")

TESTDATA = Path(__file__).resolve().parents[2] / ".testdata"
RSM = TESTDATA / "robosuite-models" / "robosuite_models" / "assets"
RS = TESTDATA / "robosuite" / "robosuite" / "models" / "assets"
PB = TESTDATA / "pybullet" / "pybullet_data"
ERD = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"


def _need(path: Path) -> Path:
    if not path.is_file():
        pytest.skip(f"test data absent (python tools/fetch_test_data.py): {path}")
    return path


def _warnings(result) -> list[str]:
    return [str(w) for w in result.warnings]


# -- 1. every inertial configuration MuJoCo compiles ---------------------------------------
@pytest.mark.realdata
def test_massless_moving_body_with_massive_welded_child_robosuite_g1() -> None:
    """robosuite-models g1: the free-floating root body has mass 0; the body welded to it
    carries the mass. MuJoCo compiles it, and so do we, exactly."""
    path = _need(RSM / "robots" / "g1" / "robot.xml")
    hrdf = mjcf_to_hrdf_with_warnings(path).hrdf
    root = hrdf.bodies[hrdf.root_index]
    assert root.mass == 0.0 and any(j.body == root.name for j in hrdf.joints)
    assert validate(hrdf) == [] or all(p.severity != "error" for p in validate(hrdf))
    report = roundtrip(path, configs=20)
    assert report.ok, report.table()


@pytest.mark.realdata
def test_welded_point_mass_link_example_robot_data_quadruped() -> None:
    """A contact link on a fixed joint with mass and zero inertia (FL_contact) stays a
    body (fixed_joints='keep') and the robot round-trips exactly."""
    path = _need(ERD / "quadruped_description" / "urdf" / "quadruped.urdf")
    hrdf = urdf_to_hrdf_with_warnings(path, fixed_joints="keep").hrdf
    contact = hrdf.body("FL_contact")
    assert contact.mass > 0 and contact.diag_inertia == (0.0, 0.0, 0.0)
    report = roundtrip(path, configs=10, fixed_joints="keep")
    assert report.ok, report.table()


def _body(name, parent, mass, diag, pos=(0.0, 0.0, 0.0), inertial_quat=(1.0, 0.0, 0.0, 0.0)):
    return Body(
        name=name,
        parent=parent,
        pos=pos,
        quat=(1.0, 0.0, 0.0, 0.0),
        mass=mass,
        inertial_pos=(0.0, 0.0, 0.0),
        inertial_quat=inertial_quat,
        diag_inertia=diag,
    )


def _chain(child_mass: float, child_inertia: tuple, child_joint: bool) -> HRDF:
    """A hinge body of mass 0 whose child (welded or on a hinge) has the given inertia."""
    bodies = [
        _body("base", -1, 1.0, (0.1, 0.1, 0.1)),
        _body("arm", 0, 0.0, (0.0, 0.0, 0.0)),
        _body("tip", 1, child_mass, child_inertia, pos=(0.5, 0.0, 0.0)),
    ]
    joints = [Joint(name="j1", body="arm", axis=(0, 0, 1))]
    if child_joint:
        joints.append(Joint(name="j2", body="tip", axis=(0, 1, 0)))
    return HRDF(name="chain", bodies=bodies, joints=joints)


@pytest.mark.parametrize(
    ("mass", "inertia", "joint", "accepted"),
    [
        (1.0, (0.01, 0.01, 0.01), False, True),  # welded child carries the mass
        (1.0, (0.0, 0.0, 0.0), False, False),  # welded point mass: no inertia
        (1.0, (0.01, 0.01, 0.01), True, False),  # the child moves on its own joint
    ],
)
def test_hrdf_accepts_what_mujoco_compiles(
    mass: float, inertia: tuple, joint: bool, accepted: bool
) -> None:
    """The HRDF check and MuJoCo agree on a massless moving body (MuJoCo is the judge:
    the same robot written by hand as MJCF)."""
    hrdf = _chain(mass, inertia, joint)
    errors = [p for p in validate(hrdf) if p.severity == "error"]
    tip_joint = '<joint axis="0 1 0"/>' if joint else ""
    xml = f"""<mujoco><worldbody><body name="base">
      <inertial pos="0 0 0" mass="1" diaginertia=".1 .1 .1"/>
      <body name="arm"><joint axis="0 0 1"/><inertial pos="0 0 0" mass="0" diaginertia="0 0 0"/>
        <body name="tip" pos=".5 0 0">{tip_joint}<inertial pos="0 0 0" mass="{mass}"
          diaginertia="{" ".join(map(str, inertia))}"/></body></body></body></worldbody></mujoco>"""
    try:
        mujoco.MjModel.from_xml_string(xml)
        mujoco_ok = True
    except ValueError:
        mujoco_ok = False
    assert mujoco_ok is accepted
    assert (not errors) is accepted, errors
    if accepted:
        model = MJCFHumanoidGenerator.from_hrdf(hrdf).to_model(add_scene=False)
        assert model.body("arm").mass[0] == 0.0 and model.body("tip").mass[0] == mass


# -- 2. a massless URDF link keeps its inertia -----------------------------------------------
@pytest.mark.realdata
def test_massless_link_keeps_its_inertia_pybullet_panda() -> None:
    """pybullet franka_panda: panda_link8 has mass 0 and a non-zero inertia; MuJoCo keeps
    the inertia, so do we (it used to be zeroed without a word)."""
    path = _need(PB / "franka_panda" / "panda.urdf")
    src = ET.parse(path).getroot()
    link8 = next(x for x in src.iter("link") if x.get("name") == "panda_link8")
    ixx = float(link8.find("inertial/inertia").get("ixx"))
    assert float(link8.find("inertial/mass").get("value")) == 0.0 and ixx > 0
    hrdf = urdf_to_hrdf_with_warnings(path).hrdf
    ref = view_from_model(compile_urdf(urdf_for_mujoco(path)))
    ours = view_from_model(our_mjcf_model(hrdf))
    i_ref, i_ours = ref.inertia_world["panda_link8"][1], ours.inertia_world["panda_link8"][1]
    assert np.abs(i_ref).max() > 0
    np.testing.assert_allclose(i_ours, i_ref, rtol=0, atol=1e-12 * np.abs(i_ref).max())


# -- 3 and 7. visual geoms MuJoCo cannot build ---------------------------------------------
@pytest.mark.realdata
def test_zero_size_visual_spheres_dropped_with_warning_pybullet_laikago() -> None:
    path = _need(PB / "laikago" / "laikago_toes_zup.urdf")
    result = urdf_to_hrdf_with_warnings(path)
    dropped = [w for w in _warnings(result) if "visual sphere of size (0.0,)" in w]
    assert len(dropped) == 4 and all("dropped" in w for w in dropped)
    report = roundtrip(path, configs=10, reference="mujoco")
    assert report.ok, report.table()


@pytest.mark.realdata
def test_flat_visual_mesh_kept_as_shell_pybullet_plane() -> None:
    path = _need(PB / "plane.urdf")
    result = urdf_to_hrdf_with_warnings(path)
    (mesh,) = result.hrdf.meshes
    assert mesh.inertia == "shell"
    assert any("kept with inertia='shell'" in w for w in _warnings(result))
    model = our_mjcf_model(result.hrdf)
    assert model.nmesh == 1 and model.ngeom == 2  # the visual plane and its collision box


@pytest.mark.realdata
def test_unreadable_visual_mesh_rewritten_pybullet_table_square() -> None:
    """table.obj has out-of-range normal indices: MuJoCo 4 cannot decode it (its URDF
    import discards visuals; MuJoCo 3.11 reads it); ours keeps the geometry, rewritten by
    trimesh where MuJoCo refuses it (reported), and the robot compiles with it."""
    from robotwright.parsers.urdf.visuals import _mesh_error

    path = _need(PB / "table_square" / "table_square.urdf")
    result = urdf_to_hrdf_with_warnings(path)
    rewritten = any("table.obj" in w and "rewritten with trimesh" in w for w in _warnings(result))
    assert rewritten == bool(_mesh_error(path.parent / "table.obj", (1.0, 1.0, 1.0), None))
    (visual,) = [m for m in result.hrdf.meshes if not m.contact_type]
    assert visual.file.endswith("table_rewritten.stl" if rewritten else "table.obj")
    src_faces = len(trimesh.load(path.parent / "table.obj", force="mesh", process=False).faces)
    model = our_mjcf_model(result.hrdf)
    assert model.nmesh == 1 and int(model.mesh_facenum[0]) == src_faces
    report = roundtrip(path, configs=5, reference="mujoco")
    assert report.ok, report.table()


# -- 4. a link named world -----------------------------------------------------------------
@pytest.mark.realdata
@pytest.mark.parametrize("name", ["pendulum5.urdf", "cube_rotate.urdf"])
def test_world_root_link_with_moving_joint_pybullet(name: str) -> None:
    path = _need(PB / name)
    result = urdf_to_hrdf_with_warnings(path)
    assert "world" not in [b.name for b in result.hrdf.bodies]
    assert any("'world' is MuJoCo's world" in w for w in _warnings(result))
    report = roundtrip(path, configs=20, reference="mujoco")
    assert report.ok, report.table()


def test_link_named_world_inside_the_tree_is_renamed(tmp_path: Path) -> None:
    urdf = tmp_path / "r.urdf"
    urdf.write_text(
        """<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx=".1" iyy=".1" izz=".1"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="world"><inertial><mass value="1"/><inertia ixx=".1" iyy=".1" izz=".1"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="world"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""
    )
    result = urdf_to_hrdf_with_warnings(urdf)
    names = [b.name for b in result.hrdf.bodies]
    assert names == ["base", "world_link"] and result.hrdf.joints[0].body == "world_link"
    assert any("renamed 'world_link'" in w for w in _warnings(result))
    assert our_mjcf_model(result.hrdf).body("world_link").mass[0] == 1.0


# -- 5. negative mesh scale ----------------------------------------------------------------
@pytest.mark.realdata
def test_negative_mesh_scale_kept_robosuite_tiago() -> None:
    """tiago's arms use their meshes at negative scales (``"-1 -1 -1"``, ``"1 -1 -1"``...): the rows keep
    the negative scale and the file itself (no copy, no note), and the round trip,
    hulls included, is exact."""
    path = _need(RS / "robots" / "tiago" / "robot.xml")
    result = mjcf_to_hrdf_with_warnings(path)
    mirrored = [m for m in result.hrdf.meshes if min(m.scale) < 0]
    assert mirrored, "tiago's mirrored arm meshes"
    assert {m.file for m in mirrored} >= {"meshes/arm_1.stl", "meshes/arm_6-wrist-2017.stl"}
    assert {m.scale for m in mirrored} >= {(1.0, -1.0, -1.0), (-1.0, -1.0, -1.0)}
    assert not any("negative scale" in w or "mirrored" in w for w in _warnings(result))
    report = roundtrip(path, configs=20)
    assert report.ok, report.table()


# -- 6. triangle inequality kept through the URDF writer -----------------------------------
def test_urdf_inertia_on_the_triangle_edge_compiles(tmp_path: Path) -> None:
    """Principal moments with A + B == C in a rotated frame: 40 random rotations and
    scales, each URDF loads in MuJoCo with moments equal to 1e-9 (MuJoCo 3.11's
    diagonalisation is good to ~4e-12)."""
    rng = np.random.default_rng(3)
    for _ in range(40):
        a, b = rng.uniform(0.1, 1.0, 2) * 10 ** rng.uniform(-6, 1)
        diag = tuple(float(v) for v in rng.permutation([a, b, a + b]))
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        hrdf = HRDF(
            name="rod",
            bodies=[
                _body("base", -1, 1.0, (0.1, 0.1, 0.1)),
                _body("link", 0, 1.0, diag, inertial_quat=tuple(float(v) for v in q)),
            ],
            joints=[Joint(name="j", body="link", axis=(0, 0, 1), range=(-1.0, 1.0))],
        )
        out = tmp_path / "rod.urdf"
        URDFHumanoidGenerator.from_hrdf(hrdf).export(out)
        model = mujoco.MjModel.from_xml_path(str(out))
        got = np.sort(model.body("link").inertia)
        np.testing.assert_allclose(got, np.sort(diag), rtol=1e-9)


# -- 8. mesh inertia mode ------------------------------------------------------------------
@pytest.mark.realdata
@pytest.mark.parametrize("robot", ["baxter", "sawyer"])
def test_shell_mesh_inertia_carried_robosuite(robot: str) -> None:
    path = _need(RS / "robots" / robot / "robot.xml")
    hrdf = mjcf_to_hrdf_with_warnings(path).hrdf
    assert any(m.inertia == "shell" for m in hrdf.meshes)
    report = roundtrip(path, configs=20, urdf=False)
    assert report.ok, report.table()


def test_mesh_inertia_mode_survives_the_hrdf_folder(arm_mjcf: Path, tmp_path: Path) -> None:
    from dataclasses import replace

    from robotwright.hrdf.model import MeshGeom

    hrdf = mjcf_to_hrdf_with_warnings(arm_mjcf).hrdf
    import trimesh

    (tmp_path / "meshes").mkdir()
    trimesh.creation.box().export(str(tmp_path / "meshes" / "tet.stl"))
    mesh = MeshGeom(body="link2", name="tet", file="meshes/tet.stl", inertia="shell")
    hrdf = replace(hrdf, meshes=[mesh], root_dir=tmp_path)
    folder = hrdf.save(tmp_path / "out")
    again = HRDF.from_dir(folder)
    assert again.meshes[0].inertia == "shell"
    bad = replace(again, meshes=[replace(mesh, inertia="hollow")])
    assert any(p.column == "inertia" for p in validate(bad))


# -- 11. what MuJoCo's XML reader accepts --------------------------------------------------
@pytest.mark.realdata
@pytest.mark.parametrize(
    "name",
    [
        "humanoid/humanoid.urdf",  # ends with a NUL byte
        "biped/biped2d_pybullet.urdf",  # blank lines before the XML declaration
    ],
)
def test_files_mujoco_reads_are_read_pybullet(name: str) -> None:
    """Our strict reader refused these as not well-formed XML; MuJoCo's reads them.
    humanoid.urdf then converts exactly (its 'spherical' joints, pybullet's and MuJoCo's
    extension, are ball joints); biped2d holds a fault further in (a limit '-1.57.'),
    which the parse now reaches and names."""
    path = _need(PB / name)
    assert len(list(parse_xml(path).iter("link"))) > 3
    if name.startswith("biped"):
        with pytest.raises(ConversionError, match="expected a finite number"):
            urdf_to_hrdf_with_warnings(path)
        return
    hrdf = urdf_to_hrdf_with_warnings(path).hrdf
    assert sum(j.type == "ball" for j in hrdf.joints) == 8
    report = roundtrip(path, configs=20, reference="mujoco", urdf=False)
    assert report.ok, report.table()


def test_attributes_without_space_accepted_entities_still_refused(tmp_path: Path) -> None:
    glued = tmp_path / "glued.urdf"
    glued.write_text(
        '<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx=".1"'
        'iyy=".1" izz=".1" ixy="0"ixz="0" iyz="0"/></inertial></link></robot>'
    )
    inertia = parse_xml(glued).find("link/inertial/inertia")
    assert inertia.get("iyy") == ".1" and inertia.get("ixz") == "0"
    evil = tmp_path / "evil.urdf"
    evil.write_text(
        '<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n'
        '<robot name="r"a="1">&x;</robot>'
    )
    with pytest.raises(ConversionError, match="unsafe XML"):
        parse_xml(evil)


# -- the unnamed free joint ----------------------------------------------------------------
@pytest.mark.realdata
def test_unnamed_free_joint_named_alike_in_mjcf_and_urdf(tmp_path: Path) -> None:
    path = _need(RSM / "robots" / "g1" / "robot.xml")
    hrdf = mjcf_to_hrdf_with_warnings(path).hrdf
    (free,) = [j for j in hrdf.joints if j.type == "free"]
    mjcf_model = our_mjcf_model(hrdf)
    URDFHumanoidGenerator.from_hrdf(hrdf).export(tmp_path / "g1.urdf")
    urdf_root = ET.parse(tmp_path / "g1.urdf").getroot()
    floating = [j.get("name") for j in urdf_root.iter("joint") if j.get("type") == "floating"]
    assert mjcf_model.joint(0).name == free.name == floating[0] == "joint_0"


def test_urdf_floating_base_option_names_the_joint_alike(tmp_path: Path) -> None:
    urdf = tmp_path / "r.urdf"
    urdf.write_text(
        '<robot name="r"><link name="base"><inertial><mass value="1"/><inertia ixx=".1" '
        'iyy=".1" izz=".1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>'
    )
    hrdf = urdf_to_hrdf_with_warnings(urdf, floating_base=True).hrdf
    assert our_mjcf_model(hrdf).joint(0).name == "floating_base"
    URDFHumanoidGenerator.from_hrdf(hrdf).export(tmp_path / "out.urdf")
    out = ET.parse(tmp_path / "out.urdf").getroot()
    assert [j.get("name") for j in out.iter("joint")] == ["floating_base"]


# -- 10. tendons and actuators through sites of the world -----------------------------------
ARM_MUSCLES = """<mujoco model="arm26ish">
  <compiler angle="radian"/>
  <worldbody>
    <site name="origin_a" pos="0.01 0.02 0.9" quat="0.9 0.1 0.3 0.2"/>
    <site name="origin_b" pos="-0.02 0.01 1.1"/>
    <body name="thorax" pos="0 0 1" quat="0.8 0 0.6 0">
      <geom type="sphere" size=".05" mass="2"/>
      <body name="upper" pos="0 0 -.05"><joint name="shoulder" axis="0 1 0" range="-1 2"/>
        <geom type="capsule" fromto="0 0 0 0 0 -.3" size=".03"/>
        <site name="insert_a" pos="0.02 0 -.2"/>
        <body name="lower" pos="0 0 -.3"><joint name="elbow" axis="0 1 0" range="0 2"/>
          <geom type="capsule" fromto="0 0 0 0 0 -.25" size=".025"/>
          <site name="insert_b" pos="-0.02 0 -.1"/></body></body></body>
    <body name="target" pos="1 0 1"><geom type="sphere" size=".02" mass=".1"/></body>
  </worldbody>
  <tendon>
    <spatial name="flexor" width=".005"><site site="origin_a"/><site site="insert_a"/></spatial>
    <spatial name="biceps" width=".005"><site site="origin_b"/><site site="insert_b"/></spatial>
  </tendon>
  <actuator>
    <muscle name="flexor" tendon="flexor" lengthrange=".1 .5"/>
    <muscle name="biceps" tendon="biceps" lengthrange=".1 .5"/>
  </actuator>
</mujoco>
"""


def test_world_sites_of_muscles_kept_on_a_fixed_root(tmp_path: Path) -> None:
    """A musculoskeletal arm whose muscles start at sites of the world: with
    root_body='thorax' (the world also holds a target) every tendon and muscle is kept,
    and the round trip is exact (tendon lengths, muscle parameters, site FK)."""
    path = tmp_path / "arm.xml"
    path.write_text(ARM_MUSCLES)
    result = mjcf_to_hrdf_with_warnings(path, root_body="thorax")
    sites = {s.name: s.body for s in result.hrdf.sites}
    assert sites["origin_a"] == sites["origin_b"] == "thorax"
    assert sum("site of the world kept" in w for w in _warnings(result)) == 2
    report = roundtrip(path, configs=20, root_body="thorax", urdf=False)
    assert report.ok, report.table()
    assert "tendons 2" in report.table()


def test_world_sites_stay_world_sites_when_the_root_moves(tmp_path: Path) -> None:
    path = tmp_path / "arm.xml"
    path.write_text(ARM_MUSCLES.replace('quat="0.8 0 0.6 0">', 'quat="0.8 0 0.6 0"><freejoint/>'))
    result = mjcf_to_hrdf_with_warnings(path, root_body="thorax")
    world = [s for s in result.hrdf.sites if s.body == "world"]
    assert len(world) == 2  # the muscles' origins, where they were
    assert not any("site" in w.message and "dropped" in w.message for w in result.warnings)


WELDED_TO_THE_WORLD = """<mujoco model="welded">
  <worldbody>
    <body name="base" pos="0 0 1">
      <geom type="box" size=".1 .1 .1" mass="2"/>
      <body name="l1">
        <joint name="j1" axis="0 1 0" range="-1 1"/>
        <geom type="capsule" fromto="0 0 0 0 0 -.3" size=".03" mass=".5"/>
        <body name="l2" pos="0 0 -.3">
          <joint name="j2" axis="0 1 0" range="-1 1"/>
          <geom type="capsule" fromto="0 0 0 0 0 -.3" size=".03" mass=".5"/>
        </body>
      </body>
    </body>
    <body name="box" pos="1 0 .1">
      <freejoint/>
      <geom type="box" size=".05 .05 .05" mass=".2"/>
    </body>
  </worldbody>
  <equality>
    <weld body1="l2" body2="box"/>
    <joint joint1="j2" joint2="j1" polycoef="0.1 0.5 0 0 0"/>
  </equality>
</mujoco>
"""


def test_round_trip_of_a_robot_taken_out_of_a_world_compares_its_own_equalities(
    tmp_path: Path,
) -> None:
    """root_body='base': the weld to the box (outside the robot) is dropped with a note
    naming it, and the round trip compares the robot's own equality (the joint coupling),
    not the world's count."""
    path = tmp_path / "welded.xml"
    path.write_text(WELDED_TO_THE_WORLD)
    result = mjcf_to_hrdf_with_warnings(path, root_body="base")
    assert any("equality dropped" in w and "'box'" in w for w in _warnings(result))
    report = roundtrip(path, configs=5, root_body="base", urdf=False)
    assert report.ok, report.table()
    (row,) = [r for r in report.rows if r.check.endswith("equality/tendon/contact/keyframe")]
    assert row.value.startswith("eq 1,"), report.table()
    # What is compared is the coupling itself: a changed multiplier is a failed row.
    ref = view_from_model(mujoco.MjModel.from_xml_path(str(path)), root="base")
    ours = our_mjcf_model(result.hrdf)
    assert compare_extras(ref, view_from_model(ours), 1e-9).ok
    ours.eq_data[0, 1] = 0.7
    bad = compare_extras(ref, view_from_model(ours), 1e-9)
    assert not bad.ok and "equality constraints differ" in bad.note
