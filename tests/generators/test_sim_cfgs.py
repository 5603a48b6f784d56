"""``isaaclab-cfg`` and ``mjlab-cfg``: the options that make a legged robot trainable
from one command (issue 39, item 1), checked without Isaac Lab or mjlab (the modules are
read as Python source, and the MJCF compiled by MuJoCo)."""

from __future__ import annotations

import ast

import mujoco
import numpy as np
import pytest

from robotwright._mjmodel import lowest_collision_point
from robotwright.catalog import find_entry
from robotwright.cli import main

needs_go2 = pytest.mark.skipif(
    find_entry("go2") is None, reason="go2 comes from example-robot-data (not installed)"
)
STAND = ["--floating-base", "--actuators", "position", "--actuator-gain", "*=50,1"]
STAND += ["--joint-pos", "F?_thigh_joint=0.8", "--joint-pos", "R?_thigh_joint=1.0"]
STAND += ["--joint-pos", "*calf_joint=-1.5"]


def _assigned(module_text: str, name: str) -> ast.Call:
    tree = ast.parse(module_text)
    for node in tree.body:
        if isinstance(node, ast.Assign) and node.targets[0].id == name:  # type: ignore[attr-defined]
            return node.value  # type: ignore[return-value]
    raise AssertionError(f"{name} not assigned")


def _init_state(module_text: str) -> tuple[tuple[float, ...], dict[str, float]]:
    call = _assigned(module_text, "ROBOT_CFG")
    init = next(k.value for k in call.keywords if k.arg == "init_state")
    kw = {k.arg: ast.literal_eval(k.value) for k in init.keywords}  # type: ignore[attr-defined]
    return kw["pos"], kw["joint_pos"]


@needs_go2
def test_mjlab_cfg_stands_the_go2_on_the_ground(tmp_path, capsys) -> None:
    out = tmp_path / "go2_entity.py"
    assert main(["mjlab-cfg", "go2", *STAND, "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning: robot" not in err  # driven, damped, floating: nothing to say
    xml = tmp_path / "go2_entity.xml"
    assert xml.is_file() and (tmp_path / "meshes").is_dir()
    pos, joint_pos = _init_state(out.read_text())
    model = mujoco.MjModel.from_xml_path(str(xml))
    assert model.nu == 12 and np.allclose(model.actuator_gainprm[:, 0], 50.0)
    assert np.allclose(model.actuator_biasprm[:, 2], -1.0)  # kv = 1
    data = mujoco.MjData(model)
    data.qpos[:3] = pos
    for pattern, value in joint_pos.items():
        name = pattern.replace("\\", "")  # the escaped exact name
        data.joint(name).qpos[0] = value
        if name.endswith("calf_joint"):
            assert value == -1.5
        elif name.endswith("thigh_joint"):
            assert value == (0.8 if name.startswith("F") else 1.0)
    mujoco.mj_kinematics(model, data)
    assert lowest_collision_point(model, data) == pytest.approx(0.0, abs=1e-9)  # feet on z = 0
    assert len(joint_pos) == 12


@needs_go2
def test_setup_warnings_name_what_to_give(tmp_path, capsys) -> None:
    assert main(["mjlab-cfg", "go2", "-o", str(tmp_path / "a.py")]) == 0
    err = capsys.readouterr().err
    assert "has no actuators" in err and "--actuators position" in err
    assert "fixed base" in err and "--floating-base" in err and "FL_foot" in err
    args = ["--floating-base", "--actuators", "position", "--actuator-gain", "*=25"]
    assert main(["mjlab-cfg", "go2", *args, "-o", str(tmp_path / "b.py")]) == 0
    err = capsys.readouterr().err
    assert "kv = 0" in err and "FL_hip_joint" in err
    assert "no actuators" not in err and "fixed base" not in err


@needs_go2
@pytest.mark.parametrize(
    ("joint_pos", "says"),
    [
        ("nothing_*=0.1", "matches no hinge or slide joint"),
        ("*calf_joint=1.5", "moves in"),
        ("*calf_joint=1e400", "PATTERN=VALUE"),
        ("*calf_joint", "PATTERN=VALUE"),
    ],
)
def test_bad_joint_positions_are_one_line(tmp_path, capsys, joint_pos, says) -> None:
    out = tmp_path / "a.py"
    try:  # a malformed option is argparse's: exit 2 with its usage line
        code = main(
            ["mjlab-cfg", "go2", "--floating-base", "--joint-pos", joint_pos, "-o", str(out)]
        )
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2 and says in err and "Traceback" not in err
    assert not out.exists() and not out.with_suffix(".xml").exists()


def test_isaaclab_cfg_source_takes_the_same_pose() -> None:
    """The Isaac Lab module's initial state is the mjlab one's (one function)."""
    from robotwright.generators.isaaclab_cfg import articulation_cfg_source
    from robotwright.generators.mjlab_cfg import entity_cfg_source
    from robotwright.sources import load_robot

    hrdf = load_robot("mini_humanoid")
    from robotwright.generators import MJCFHumanoidGenerator

    model = MJCFHumanoidGenerator.from_hrdf(hrdf).to_model(add_scene=False)
    knees = [("*knee*", 0.3)]
    lab, _ = articulation_cfg_source(hrdf, model, "r.usd", knees)
    mj = entity_cfg_source(hrdf, model, "r.xml", knees)
    assert _init_state(lab) == _init_state(mj)
    pos, joints = _init_state(mj)
    assert any("knee" in k and v == 0.3 for k, v in joints.items())
    assert pos[2] > 0.1  # a free base raised to stand


def test_a_free_base_sits_at_its_prims_origin_only_for_a_config(tmp_path) -> None:
    """isaaclab-cfg's USD puts the free base at its prim's origin (its config's
    init_state then gives the height: spawn and reset agree); a plain export keeps the
    robot's reference position (the USD reads back as the robot)."""
    from robotwright.generators.isaaclab_cfg import initial_state
    from robotwright.generators.usd import _robot_mjcf
    from robotwright.sources import load_robot

    hrdf = load_robot("mini_humanoid")
    assert hrdf.floating_base and hrdf.root_body.pos[2] > 0.5
    kept, _ = _robot_mjcf(hrdf, tmp_path / "kept")
    moved, _ = _robot_mjcf(hrdf, tmp_path / "moved", root_at_origin=True)
    kept_model = mujoco.MjModel.from_xml_path(str(kept))
    moved_model = mujoco.MjModel.from_xml_path(str(moved))
    assert kept_model.body_pos[1][2] == pytest.approx(hrdf.root_body.pos[2])
    assert np.allclose(moved_model.body_pos[1], 0.0)
    pos, _, _ = initial_state(moved_model)
    data = mujoco.MjData(moved_model)
    data.qpos[:3] = pos
    mujoco.mj_kinematics(moved_model, data)
    assert lowest_collision_point(moved_model, data) == pytest.approx(0.0, abs=1e-9)
    assert initial_state(kept_model)[0] == pytest.approx(pos)  # the same standing pose
