"""Build a two-finger gripper on a 2-link arm with Things, simulate it, export MJCF.

One finger is built once, copied and attached twice (the copy mirrored); the second
finger's elements get enumerated names (``finger_1``, ``finger_joint_1``, ...).

Run: ``python examples/gripper_on_arm.py [output_dir]`` (default ``./gripper_on_arm``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from robotwright.things import (
    Body,
    Box,
    Camera,
    Capsule,
    Cylinder,
    Hinge,
    JointPos,
    Light,
    Plane,
    Position,
    Site,
    Slide,
    Touch,
    World,
)


def build_finger() -> Body:
    """A finger on a slide joint (m) closing along its body +y, with a touch pad."""
    finger = Body("finger", pos=[0, 0.04, -0.05])
    joint = Slide("finger_joint", axis=[0, -1, 0], range=[0, 0.035], damping=[5])
    joint.attach(Position("finger_servo", kp=300, ctrlrange=[0, 0.035]), JointPos("finger_pos"))
    pad = Site("pad", type="box", size=[0.01, 0.004, 0.02], pos=[0, -0.006, -0.02])
    pad.attach(Touch("pad_touch"))
    finger.attach(
        joint, Box("finger_geom", size=[0.01, 0.005, 0.03], pos=[0, 0, -0.02], mass=0.05), pad
    )
    return finger


def build_world() -> World:
    world = World("gripper_on_arm", timestep=0.002)
    world.attach(
        Plane("floor", size=[1, 1, 0.05]),
        Light("sun", pos=[0, 0, 2], dir=[0, 0, -1], type="directional"),
        Camera("overview", pos=[0, -1.2, 0.5]).rotate([1, 0, 0], np.pi / 2),
    )
    base = Body("base", pos=[0, 0, 0.05])
    base.attach(Cylinder("pedestal", radius=0.06, half_length=0.05))
    upper = Body("upper_arm", pos=[0, 0, 0.05])
    shoulder = Hinge("shoulder", axis=[0, 1, 0], range=[-1.5, 1.5], damping=[2])
    shoulder.attach(Position("shoulder_servo", kp=200, ctrlrange=[-1.5, 1.5]))
    upper.attach(shoulder, Capsule("upper_geom", radius=0.03, half_length=0.15, pos=[0, 0, 0.15]))
    fore = Body("forearm", pos=[0, 0, 0.3])
    elbow = Hinge("elbow", axis=[0, 1, 0], range=[-2.0, 2.0], damping=[1])
    elbow.attach(Position("elbow_servo", kp=100, ctrlrange=[-2.0, 2.0]))
    fore.attach(elbow, Capsule("fore_geom", radius=0.025, half_length=0.12, pos=[0, 0, 0.12]))
    palm = Body("palm", pos=[0, 0, 0.27])
    palm.rotate([1, 0, 0], np.pi)  # fingers point along the forearm
    palm.attach(Box("palm_geom", size=[0.02, 0.05, 0.01], mass=0.2))

    finger = build_finger()
    # The same limb twice: a copy as is, a copy mirrored by a half turn about z.
    palm.attach(finger.copy(), finger.copy(pos=[0, -0.04, -0.05]).rotate([0, 0, 1], np.pi))
    fore.attach(palm)
    upper.attach(fore)
    base.attach(upper)
    world.attach(base)
    return world


def main(out_dir: str = "gripper_on_arm") -> None:
    world = build_world()
    left, right = world.find("palm").bodies
    print(f"fingers: {left.name}, {right.name}; joints: {[j.name for j in world.all_joints()]}")
    # Close both fingers and bend the arm for one simulated second.
    for servo in world.find_all(Position):
        servo.ctrl = {"shoulder_servo": 0.3, "elbow_servo": -0.4}.get(servo.name, 0.03)
    world.step(500)
    fingers = [j for j in world.all_joints() if j.name.startswith("finger_joint")]
    print("finger openings after 1 s (m):", [round(float(j.qpos[0]), 4) for j in fingers])
    print("palm position (m):", np.round(world.find("palm").xpos, 3))
    path = world.export(Path(out_dir) / "gripper_on_arm.xml")
    print(
        f"wrote {path} ({world.model.nbody} bodies, {world.model.nu} actuators, {world.model.nsensor} sensors)"
    )


if __name__ == "__main__":
    main(*sys.argv[1:])
