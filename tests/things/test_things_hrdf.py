"""Things <-> HRDF: load, edit, attach a copied limb, save, generate MJCF/URDF."""

from __future__ import annotations

import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionError, ConversionWarning
from robotwright.generators import MJCFHumanoidGenerator, URDFHumanoidGenerator
from robotwright.hrdf import HRDF
from robotwright.things import Body, Box, General, Hinge, Motor, Plane, Sphere, World
from robotwright.things.hrdf_bridge import hrdf_to_body, hrdf_to_world, things_to_hrdf

from ._compare import assert_same_model

ROBOTS = Path(__file__).resolve().parents[2] / "src" / "robotwright" / "robots"


def _generated(robot: HRDF) -> mujoco.MjModel:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)  # peak velocities etc.
        return MJCFHumanoidGenerator.from_hrdf(robot).to_model(add_scene=False)


@pytest.mark.parametrize("name", ["arm6", "mini_humanoid"])
def test_bundled_robots_round_trip_through_things(name):
    robot = HRDF.from_dir(ROBOTS / name)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConversionWarning)  # HRDF-only columns ride along
        world = hrdf_to_world(robot)
        back = things_to_hrdf(world)
    reference = _generated(robot)
    assert_same_model(reference, world.model)  # same model as the MJCF generator's
    assert_same_model(reference, _generated(back))
    # HRDF-only columns come back exactly
    assert back.actuators == robot.actuators
    assert back.sensors == robot.sensors and back.meta == robot.meta
    assert sorted(back.joints, key=lambda j: str(j.name)) == sorted(
        robot.joints, key=lambda j: str(j.name)
    )

    # bodies are listed in tree order, so compare them with parents by name
    def by_name(r):
        return {b.name: (b, r.bodies[b.parent].name if b.parent >= 0 else None) for b in r.bodies}

    strip = {
        k: (b.__class__(**{**b.__dict__, "parent": 0}), p) for k, (b, p) in by_name(robot).items()
    }
    again = {
        k: (b.__class__(**{**b.__dict__, "parent": 0}), p) for k, (b, p) in by_name(back).items()
    }
    assert again == strip


@pytest.mark.hurodes
def test_hurodes_g1_edit_attach_copied_limb_save_and_generate(g1_hrdf_dir, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the fixture folder holds an extra export folder
        robot = HRDF.from_dir(g1_hrdf_dir)
    g1 = hrdf_to_body(robot)
    hand = g1.find("left_wrist_roll_link", Body)
    torso = g1.find("torso_link", Body)
    extra = hand.copy(pos=[0.1, 0.0, 0.3])
    torso.attach(extra)  # a third hand on the chest
    assert extra.name == "left_wrist_roll_link_1"
    assert [j.name for j in extra.all_joints()] == [
        "left_wrist_roll_joint_1",
        "left_wrist_pitch_joint_1",
        "left_wrist_yaw_joint_1",
    ]
    # the wrist motors came along with the copy, driving the copied joints
    motors = extra.find_all(Motor)
    assert [m.parent for m in motors] == extra.all_joints()
    g1.set_all("joint", armature=0.02)

    with warnings.catch_warnings():
        warnings.simplefilter("error", ConversionWarning)
        edited = things_to_hrdf(g1)
    folder = edited.save(tmp_path / "g1_three_hands")
    reread = HRDF.from_dir(folder)
    assert len(reread.bodies) == len(robot.bodies) + 3
    assert len(reread.actuators) == len(robot.actuators) + 3
    assert reread.total_mass == pytest.approx(
        robot.total_mass + sum(b.mass for b in robot.bodies[20:23])
    )
    model = _generated(reread)
    original = _generated(robot)
    assert model.nu == original.nu + 3 and model.njnt == original.njnt + 3
    assert np.all(model.dof_armature[6:] == 0.02)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    torso_id, new_id = model.body("torso_link").id, model.body("left_wrist_roll_link_1").id
    rot = data.xmat[torso_id].reshape(3, 3)
    np.testing.assert_allclose(
        data.xpos[new_id], data.xpos[torso_id] + rot @ [0.1, 0, 0.3], atol=1e-12
    )
    # and out through the URDF generator too
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        URDFHumanoidGenerator.from_hrdf(reread).export(tmp_path / "urdf" / "g1.urdf")
    text = (tmp_path / "urdf" / "g1.urdf").read_text()
    assert '<link name="left_wrist_yaw_link_1">' in text
    assert '<joint name="left_wrist_roll_joint_1" type="revolute">' in text


def test_python_built_robot_to_hrdf_uses_mujoco_inertia_and_reports_losses():
    base = Body("base")
    link = Body("link", pos=[0, 0, 0.2])
    hinge = Hinge("j", axis=[0, 1, 0], range=[-1, 1], margin=0.01)
    hinge.attach(Motor("m", ctrlrange=[-2, 2]), General("g"))
    link.attach(hinge, Box("box", size=[0.05, 0.05, 0.1], density=500))
    base.attach(Sphere("ball", radius=0.05), link)
    world = World("bot")
    world.attach(base, Plane("floor", size=[1, 1, 0.1]))
    with pytest.warns(ConversionWarning) as record:
        robot = things_to_hrdf(world)
    message = str(record[0].message)
    assert "'margin'" in message and "General 'g'" in message and "Plane 'floor'" in message
    model = world.model
    assert robot.body("link").mass == pytest.approx(model.body_mass[model.body("link").id])
    assert robot.body("link").mass == pytest.approx(500 * 0.1 * 0.1 * 0.2)
    assert [a.name for a in robot.actuators] == ["m"] and robot.actuators[0].ctrl_range == (-2, 2)
    with pytest.raises(ConversionError, match="margin"):
        things_to_hrdf(world, strict=True)
    two = World()
    two.attach(Body("a"), Body("b"))
    with pytest.raises(ConversionError, match="one top-level body"):
        things_to_hrdf(two)


def test_mjcf_extra_is_kept_by_world_and_reported_by_body():
    import dataclasses

    robot = dataclasses.replace(
        HRDF.from_dir(ROBOTS / "arm6"),
        mjcf_extra='<mujoco><contact><exclude body1="base_link" body2="shoulder_link"/></contact>'
        '<keyframe><key name="home" qpos="0 0.1 0.2 0 0 0"/></keyframe></mujoco>',
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConversionWarning)
        world = hrdf_to_world(robot)
        back = things_to_hrdf(world)
    assert world.model.nexclude == 1 and world.model.key_qpos[0][2] == pytest.approx(0.2)
    regenerated = _generated(back)
    assert regenerated.nexclude == 1 and regenerated.nkey == 1
    with pytest.raises(ConversionError, match="mjcf_extra"):
        hrdf_to_body(robot, strict=True)
