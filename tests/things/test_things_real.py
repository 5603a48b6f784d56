"""Real robots: dm-control suite models and the mjlab Unitree G1/Go1 MJCFs.

For each file: read it into Things, write MJCF again, and check that the model compiled
from the original file and the one compiled from our output are equal in masses,
inertia tensors, joint ranges, actuators, sensors and forward kinematics; the second
round trip must give the same text.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import mujoco
import pytest

from robotwright.errors import ConversionError, ConversionWarning
from robotwright.things import World

from ._compare import assert_same_model

pytestmark = pytest.mark.realdata

TESTDATA = Path(__file__).resolve().parents[2] / ".testdata"


def _suite_dir() -> Path:
    dm_control = pytest.importorskip("dm_control", reason="dm-control (test extra) not installed")
    return Path(dm_control.__file__).parent / "suite"


SUITE = [
    "acrobot",
    "ball_in_cup",
    "cartpole",
    "cheetah",
    "finger",
    "fish",
    "hopper",
    "humanoid",
    "humanoid_CMU",
    "lqr",
    "manipulator",
    "pendulum",
    "point_mass",
    "quadruped",
    "reacher",
    "stacker",
    "swimmer",
    "walker",
]


def _round_trip(path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConversionWarning)  # nothing may be dropped
        world = World.from_xml_path(path)
    original = mujoco.MjModel.from_xml_path(str(path))
    assert_same_model(original, world.model)
    xml = world.to_xml_string()
    assert World.from_xml_string(xml).to_xml_string() == xml


@pytest.mark.filterwarnings("ignore:compiler attribute 'settotalmass' is deprecated")
@pytest.mark.parametrize("name", SUITE)
def test_dm_control_suite_round_trip(name):
    _round_trip(_suite_dir() / f"{name}.xml")


def test_dm_control_unsupported_parts_are_named():
    suite = _suite_dir()
    with pytest.warns(ConversionWarning, match='<skin name="skin">'):
        world = World.from_xml_path(suite / "dog.xml")
    assert world.model.nskin == 0
    with pytest.raises(ConversionError, match="skin"):
        World.from_xml_path(suite / "dog.xml", strict=True)


def _mjlab(robot: str, file: str) -> Path:
    path = TESTDATA / "mjlab" / "mjlab" / "asset_zoo" / "robots" / robot / "xmls" / file
    if not path.is_file():
        pytest.skip(f"mjlab test data not fetched (run python tools/fetch_test_data.py): {path}")
    return path


@pytest.mark.parametrize(("robot", "file"), [("unitree_g1", "g1.xml"), ("unitree_go1", "go1.xml")])
def test_mjlab_robot_round_trip(robot, file):
    _round_trip(_mjlab(robot, file))


def test_g1_export_is_self_contained_and_editable(tmp_path):
    world = World.from_xml_path(_mjlab("unitree_g1", "g1.xml"))
    # edit in Python: stiffer knees, then export with meshes next to the file
    knees = [j for j in world.all_joints() if "knee" in j.name]
    assert len(knees) == 2
    for knee in knees:
        knee.armature = 0.05
    out = world.export(tmp_path / "g1" / "g1.xml")
    exported = mujoco.MjModel.from_xml_path(str(out))
    assert_same_model(world.model, exported)
    assert {
        exported.dof_armature[exported.jnt_dofadr[exported.joint(k.name).id]] for k in knees
    } == {0.05}
    assert exported.nmesh == len(list((tmp_path / "g1" / "assets").iterdir()))
