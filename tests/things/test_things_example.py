"""The gripper example builds, simulates and exports a valid, deterministic model."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import mujoco
import numpy as np

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "gripper_on_arm.py"


def _load():
    spec = importlib.util.spec_from_file_location("gripper_on_arm", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_gripper_example_closes_both_fingers_and_exports(tmp_path):
    example = _load()
    world = example.build_world()
    assert world.to_xml_string() == example.build_world().to_xml_string()  # deterministic
    left, right = world.find("palm").bodies
    assert (left.name, right.name) == ("finger", "finger_1")
    servos = {s.name: s for s in world.find_all(example.Position)}
    assert set(servos) == {"shoulder_servo", "elbow_servo", "finger_servo", "finger_servo_1"}
    servos["finger_servo"].ctrl = 0.03
    servos["finger_servo_1"].ctrl = 0.03
    world.step(500)
    openings = [world.find(n).qpos[0] for n in ("finger_joint", "finger_joint_1")]
    np.testing.assert_allclose(openings, [0.03, 0.03], atol=2e-3)
    # mirrored copy: the two pads face each other
    world.forward()
    pad0, pad1 = world.find("pad").xpos, world.find("pad_1").xpos
    assert abs(pad0[1] + pad1[1] - 2 * world.find("palm").xpos[1]) < 1e-9
    example.main(str(tmp_path))
    exported = mujoco.MjModel.from_xml_path(str(tmp_path / "gripper_on_arm.xml"))
    assert exported.nu == 4 and exported.nsensor == 4 and exported.nbody == world.model.nbody
