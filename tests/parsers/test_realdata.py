"""Round-trip fidelity on real robots (data installed from PyPI; skipped when absent).

Every example-robot-data URDF is parsed with ``fixed_joints="merge"`` (HRDF needs
mass > 0 on every body, and URDFs mark frames with massless fixed links; merged links
stay as sites and their FK is compared), written as our MJCF and URDF and compared with
MuJoCo's import of the source (or yourdfpy where MuJoCo refuses it). Robots that cannot
round-trip exactly are strict expected failures with the reason (docs/parsers.md).
"""

from __future__ import annotations

import sysconfig
from pathlib import Path

import pytest

from robotwright.proof.roundtrip.run import roundtrip

pytestmark = [pytest.mark.realdata, pytest.mark.usefixtures("quiet_parsers")]


ERD = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"
PURELIB = Path(sysconfig.get_paths()["purelib"])
TESTDATA = Path(__file__).resolve().parents[2] / ".testdata/mjlab/mjlab/asset_zoo/robots"
# Mesh-heavy corpus: 10 configurations per robot keeps the corpus near a minute on
# 2 cores; tolerances are the same as for 50.
CORPUS_CONFIGS = 10

MASSLESS = (
    "moving link without mass or inertia, itself or in a link welded to it: MuJoCo refuses "
    "it (passes with bound_mass/bound_inertia, see test_repaired_robots_match_yourdfpy)"
)
EXPECTED_FAILURES: dict[str, str] = {
    "alex_description/urdf/alex_nub_hands.urdf": "nub.obj holds 4 objects and MuJoCo reads the first only, an open 29-face shell whose volume it refuses, in the source and in our MJCF (passes with join_obj_objects, see test_split_obj_robot_passes_with_join_obj_objects)",
    "alex_description/urdf/alex_psyonic_hands.urdf": "non-physical inertias (A + B < C on four links) that HRDF refuses: the round trip is refused as bad input; its mimic joints also name a joint ('index_q1') that does not exist (dropped with a note; yourdfpy still couples them)",
    "human_description/robots/human.urdf": MASSLESS,
    "icub_description/robots/icub.urdf": MASSLESS,
    "icub_description/robots/icub_reduced.urdf": MASSLESS,
    "romeo_description/urdf/romeo.urdf": MASSLESS,
    "romeo_description/urdf/romeo_small.urdf": "non-physical inertia (A + B < C) that HRDF refuses (passes with balance_inertia, see test_repaired_robots_match_yourdfpy)",
    "romeo_description/urdf/romeo_laas_small.urdf": "meshes point to file:///usr/Romeo/..., absent",
    "ur_description/urdf/ur3.urdf": "the file holds an empty <robot>",
}


def _corpus() -> list:
    if not ERD.is_dir():
        return [
            pytest.param(None, marks=pytest.mark.skip(reason=f"example-robot-data absent: {ERD}"))
        ]
    params = []
    for path in sorted(ERD.rglob("*.urdf")):
        rel = path.relative_to(ERD).as_posix()
        marks = []
        if rel in EXPECTED_FAILURES:
            marks.append(pytest.mark.xfail(reason=EXPECTED_FAILURES[rel], strict=True))
        params.append(pytest.param(rel, marks=marks, id=rel))
    return params


@pytest.mark.corpus
@pytest.mark.parametrize("rel", _corpus())
def test_example_robot_data_roundtrip(rel: str) -> None:
    report = roundtrip(ERD / rel, configs=CORPUS_CONFIGS, fixed_joints="merge")
    assert report.ok, report.table()


def test_expected_failures_exist() -> None:
    if not ERD.is_dir():
        pytest.skip(f"example-robot-data absent: {ERD}")
    missing = [k for k in EXPECTED_FAILURES if not (ERD / k).is_file()]
    assert not missing


REPAIRED = [
    "human_description/robots/human.urdf",
    "icub_description/robots/icub.urdf",
    "icub_description/robots/icub_reduced.urdf",
    "romeo_description/urdf/romeo.urdf",
    "romeo_description/urdf/romeo_small.urdf",
]


@pytest.mark.parametrize("rel", REPAIRED)
def test_repaired_robots_match_yourdfpy(rel: str) -> None:
    """The robots HRDF refuses as they are import with MuJoCo's repairs, given as options
    (each repair is a warning), and match yourdfpy with the same repairs applied."""
    if not (ERD / rel).is_file():
        pytest.skip(f"example-robot-data absent: {ERD / rel}")
    report = roundtrip(
        ERD / rel,
        configs=CORPUS_CONFIGS,
        reference="yourdfpy",
        fixed_joints="keep",
        bound_mass=1e-4,
        bound_inertia=1e-8,
        balance_inertia=True,
    )
    assert report.ok, report.table()
    assert any("raised to bound" in w or "balanced" in w for w in report.warnings)


def test_split_obj_robot_passes_with_join_obj_objects() -> None:
    """alex_nub_hands' nub.obj is split into 4 objects; joined (every triangle kept) the
    mesh compiles, and the robot matches yourdfpy (MuJoCo refuses the source)."""
    rel = "alex_description/urdf/alex_nub_hands.urdf"
    if not (ERD / rel).is_file():
        pytest.skip(f"example-robot-data absent: {ERD / rel}")
    report = roundtrip(
        ERD / rel, configs=CORPUS_CONFIGS, fixed_joints="merge", join_obj_objects=True
    )
    assert report.ok, report.table()
    assert report.reference.startswith("yourdfpy")
    nub = [w for w in report.warnings if "nub.obj" in w]
    assert nub and "4 objects (faces [29, 58, 75, 1242])" in nub[0] and "joined" in nub[0]


@pytest.mark.parametrize(
    "robot", ["unitree_g1/xmls/g1.xml", "unitree_go1/xmls/go1.xml", "i2rt_yam/xmls/yam.xml"]
)
def test_mjlab_mjcf_roundtrip(robot: str) -> None:
    path = TESTDATA / robot
    if not path.is_file():
        pytest.skip(f"mjlab data not fetched (python tools/fetch_test_data.py): {path}")
    # The YAM arm has a massless camera-frame body, which HRDF keeps as a site.
    report = roundtrip(path, configs=50, massless_frames="site")
    assert report.ok, report.table()
    assert "MJCF: sensors equal (name, type, object)" in report.table()


DM = PURELIB / "dm_control" / "suite"
# The URDF leg of these fails because the MJCF leg does: the robot refers to objects
# outside it (the table leaves out the links our URDF adds: dummy links splitting a
# multi-joint body or an anchor off the body origin, and `<site>_site` links).
DM_EXPECTED = {
    "ball_in_cup.xml": "a tendon ties the cup to the ball, which is not part of the robot "
    "(dropped)",
    "finger.xml": "sensors read the spinner/target outside the robot (dropped)",
    "swimmer.xml": "a sensor reads a site outside the robot (dropped)",
}
DM_ROOT = {
    "ball_in_cup.xml": "cup",
    "dog.xml": "torso",
    "finger.xml": "proximal",
    "manipulator.xml": "upper_arm",
    "quadruped.xml": "torso",
    "stacker.xml": "upper_arm",
}


DM_MJCF_EXPECTED = {
    "ball_in_cup.xml": "a tendon ties the cup to the ball, which is not part of the robot",
    "finger.xml": "sensors read the spinner/target outside the robot (dropped)",
    "swimmer.xml": "a sensor reads a site outside the robot (dropped)",
}


def _dm(expected: dict[str, str]) -> list:
    if not DM.is_dir():
        return [pytest.param(None, marks=pytest.mark.skip(reason=f"dm_control absent: {DM}"))]
    out = []
    for p in sorted(DM.glob("*.xml")):
        if p.name == "lqr.xml":  # generated at run time, the file holds no body
            continue
        marks = (
            [pytest.mark.xfail(reason=expected[p.name], strict=True)] if p.name in expected else []
        )
        out.append(pytest.param(p.name, marks=marks, id=p.name))
    return out


@pytest.mark.parametrize("name", _dm(DM_MJCF_EXPECTED))
def test_dm_control_suite_mjcf_roundtrip(name: str) -> None:
    """Source -> HRDF -> our MJCF, every row of the table exact."""
    opts = {"root_body": DM_ROOT[name]} if name in DM_ROOT else {}
    report = roundtrip(DM / name, configs=20, urdf=False, **opts)
    assert report.ok, report.table()


@pytest.mark.parametrize("name", _dm(DM_EXPECTED))
def test_dm_control_suite_full_roundtrip(name: str) -> None:
    """Both paths: our MJCF exact and our URDF (mass, FK to 1e-6)."""
    opts = {"root_body": DM_ROOT[name]} if name in DM_ROOT else {}
    report = roundtrip(DM / name, configs=20, **opts)
    assert report.ok, report.table()


def test_jvrc_dae_meshes_roundtrip() -> None:
    path = PURELIB / "jvrc_description" / "urdf" / "jvrc1.urdf"
    if not path.is_file():
        pytest.skip(f"jvrc-description absent: {path}")
    report = roundtrip(path, configs=20, fixed_joints="merge")
    assert report.ok, report.table()
    assert any("converted to STL" in w for w in report.warnings)


def test_g1_full_circle_mjcf_urdf_mjcf(tmp_path: Path) -> None:
    """G1 MJCF -> HRDF -> our URDF -> parsed again -> our MJCF: the same robot as the
    source (body masses, inertias, FK; the URDF carries sites as links, merged back)."""
    import mujoco

    from robotwright.parsers.reference import view_from_model
    from robotwright.proof.convert import convert
    from robotwright.proof.roundtrip.run import compare_views

    path = TESTDATA / "unitree_g1/xmls/g1.xml"
    if not path.is_file():
        pytest.skip(f"mjlab data not fetched (python tools/fetch_test_data.py): {path}")
    convert(path, tmp_path / "g1.urdf")
    convert(tmp_path / "g1.urdf", tmp_path / "g1_again.xml", fixed_joints="merge")
    source = view_from_model(mujoco.MjModel.from_xml_path(str(path)))
    again = view_from_model(mujoco.MjModel.from_xml_path(str(tmp_path / "g1_again.xml")))
    rows = {r.check: r for r in compare_views(source, again, configs=20, full=True)}
    for key in (
        "bodies (ref/ours)",
        "body masses max rel.err",
        "inertia tensors max rel.err",
        "joint axes max err",
        "joint ranges max err",
    ):
        assert rows[key].ok, rows[key]
    fk = next(r for k, r in rows.items() if k.startswith("FK"))
    assert fk.ok, fk
