"""A walking robot exported with ``--floating-base`` stands on the floor (its free base
raised, a ``home`` keyframe that holds its pose); one read with its base fixed is said to
hang with its legs through the floor; a robot name nobody provides says which package
would (issue 43, item 3)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robotwright._mjmodel import lowest_collision_point
from robotwright.catalog import find_entry
from robotwright.cli import main
from robotwright.errors import RobotSetupWarning

needs_go2 = pytest.mark.skipif(
    find_entry("go2") is None, reason="go2 comes from example-robot-data (not installed)"
)
DRIVEN = ["--floating-base", "--actuators", "position", "--actuator-gain", "*=50,1"]
POSE = ["--joint-pos", "*thigh_joint=0.8", "--joint-pos", "*calf_joint=-1.5"]


def _lowest(model: mujoco.MjModel, qpos: np.ndarray) -> float:
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    return lowest_collision_point(model, data)


@needs_go2
def test_a_free_go2_is_written_standing_with_a_home_keyframe(tmp_path, capsys) -> None:
    out = tmp_path / "go2.xml"
    assert main(["export", "go2", "--floating-base", "-o", str(out)]) == 0
    captured = capsys.readouterr()
    assert "free base, 0 actuators" in captured.out
    assert "has no actuators" in captured.err and "raised from z = 0" in captured.err
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.qpos0[2] > 0.3  # the base is raised: no longer at z = 0
    assert [model.key(i).name for i in range(model.nkey)] == ["home"]
    # The reference pose has its calves outside their ranges: it is stood on clamped.
    assert model.key_qpos[0, 2] == pytest.approx(model.qpos0[2])
    assert _lowest(model, model.key_qpos[0]) == pytest.approx(0.0, abs=1e-9)
    for j in range(1, model.njnt):  # joint positions inside their ranges
        q = model.key_qpos[0, model.jnt_qposadr[j]]
        assert model.jnt_range[j, 0] - 1e-12 <= q <= model.jnt_range[j, 1] + 1e-12


@needs_go2
def test_a_driven_go2_stands_a_second_from_its_home_keyframe(tmp_path, capsys) -> None:
    out = tmp_path / "go2.xml"
    assert main(["export", "go2", *DRIVEN, *POSE, "-o", str(out)]) == 0
    assert "has no actuators" not in capsys.readouterr().err
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    assert data.joint("FL_calf_joint").qpos[0] == -1.5
    assert data.joint("RR_thigh_joint").qpos[0] == 0.8
    assert np.allclose(data.ctrl, data.qpos[7:])  # the servos hold the pose
    start = float(data.qpos[2])
    assert _lowest(model, data.qpos) == pytest.approx(0.0, abs=1e-9)
    rise = []
    for _ in range(int(1.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
        rise.append(float(data.qvel[2]))
    # It settles onto its servos; a robot started in the floor is thrown up at once.
    assert max(rise[:50]) < 0.02  # [m/s]
    assert 0.7 * start < data.qpos[2] < 1.05 * start  # still standing after 1 s
    up = np.array([0.0, 0.0, 1.0])
    assert data.xmat[model.body("base").id].reshape(3, 3)[:, 2] @ up > 0.9  # upright within 25 deg


@needs_go2
def test_a_fixed_walker_is_said_to_hang_through_the_floor(tmp_path, capsys) -> None:
    from robotwright.scene.load import load_source

    with pytest.warns(RobotSetupWarning, match="fixed base but its bodies say it walks"):
        load_source("go2")  # what render, view and lidar draw and scan
    assert main(["export", "go2", "-o", str(tmp_path / "go2.xml")]) == 0
    err = capsys.readouterr().err
    assert "give --floating-base" in err


def test_an_arm_is_written_as_it_is(tmp_path, capsys) -> None:
    from robotwright.generators.standing import stand_on_floor
    from robotwright.tasks import load_robot

    arm = load_robot("arm6")
    assert stand_on_floor(arm) == (arm, [])
    assert main(["export", "arm6", "-o", str(tmp_path / "arm.xml")]) == 0
    err = capsys.readouterr().err
    assert "walks" not in err
    assert mujoco.MjModel.from_xml_path(str(tmp_path / "arm.xml")).nkey == 0


def test_an_arm_gets_a_home_keyframe_in_a_given_pose(tmp_path) -> None:
    out = tmp_path / "arm.xml"
    assert main(["export", "arm6", "--joint-pos", "elbow_joint=1.25", "-o", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nkey == 1
    assert model.key_qpos[0, model.joint("elbow_joint").qposadr[0]] == 1.25


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["arm6", "--joint-pos", "elbow_joint=1", "-o", "a.urdf"], "home keyframe of MJCF"),
        (["arm6", "--joint-pos", "nothing=1", "-o", "a.xml"], "matches no hinge or slide"),
        (["arm6", "--joint-pos", "elbow_joint=9", "-o", "a.xml"], "moves in"),
    ],
)
def test_bad_joint_positions_on_export(tmp_path, monkeypatch, capsys, argv, says) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["export", *argv]) == 2
    err = capsys.readouterr().err
    assert says in err and "Traceback" not in err
    assert not list(tmp_path.iterdir())  # nothing written


def test_an_unknown_name_says_which_package_brings_more_robots(monkeypatch, capsys) -> None:
    import robotwright.catalog as catalog

    bundled = [e for e in catalog.list_robots() if e.source == "bundled"]
    monkeypatch.setattr(catalog, "list_robots", lambda: bundled)
    assert main(["info", "go2"]) == 2
    err = capsys.readouterr().err
    assert "no robot named 'go2'" in err
    assert "pip install example-robot-data" in err
    assert "robotwright[menagerie]" in err


def test_a_floating_robot_already_standing_is_written_as_it_is(tmp_path, capsys) -> None:
    from robotwright.generators.standing import stand_on_floor
    from robotwright.tasks import load_robot

    humanoid = load_robot("mini_humanoid")  # a free base set above the floor by its file
    assert humanoid.floating_base
    assert stand_on_floor(humanoid) == (humanoid, [])
    out = tmp_path / "mini.xml"
    assert main(["export", "mini_humanoid", "-o", str(out)]) == 0
    assert "keyframe" not in capsys.readouterr().err
    assert mujoco.MjModel.from_xml_path(str(out)).nkey == 0
