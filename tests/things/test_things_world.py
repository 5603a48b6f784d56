"""World: lazy build, rebuild on change, runtime access, helpers."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robotwright.things import (
    Accelerometer,
    Body,
    Box,
    Capsule,
    FramePos,
    Free,
    Gyro,
    Hinge,
    JointPos,
    Motor,
    Site,
    Slide,
    Sphere,
    ThingAttributeError,
    World,
)


def _pendulum() -> tuple[World, Body, Hinge]:
    world = World("pendulum")
    arm = Body("arm", pos=[0, 0, 1])
    hinge = Hinge("pivot", axis=[0, 1, 0])
    hinge.attach(Motor("torque", gear=[1]), JointPos("angle"))
    arm.attach(hinge, Capsule("rod", radius=0.02, half_length=0.25, pos=[0, 0, -0.25]))
    tip = Body("tip", pos=[0, 0, -0.5])
    tip.attach(Sphere("bob", radius=0.05, mass=1.0), Site("tip_site"))
    arm.attach(tip)
    world.attach(arm)
    return world, arm, hinge


def test_builds_lazily_and_rebuilds_only_after_changes():
    world, arm, hinge = _pendulum()
    assert world._built is None  # nothing compiled yet
    model = world.model
    assert world.model is model  # no change, no rebuild
    hinge.damping = [0.3]
    assert world.model is not model and world.model.dof_damping[0] == pytest.approx(0.3)
    model = world.model
    arm.attach(Box("plate", size=[0.1, 0.1, 0.01]))
    assert world.model is not model and world.model.ngeom == 3
    model = world.model
    world.find("plate").detach()
    assert world.model.ngeom == 2
    world.find("bob").name = "weight"  # renaming changes the model too
    assert world.model.geom("weight").id == 1


def test_runtime_state_is_readable_from_things_after_stepping():
    world, arm, hinge = _pendulum()
    hinge.qpos = [0.5]
    world.forward()
    tip = world.find("tip")
    # +0.5 rad about +y swings the tip (below the pivot) towards -x
    np.testing.assert_allclose(tip.xpos, [-0.5 * np.sin(0.5), 0, 1 - 0.5 * np.cos(0.5)], atol=1e-12)
    world.step(200)
    assert hinge.qpos[0] < 0.5  # it swung back under gravity
    world.forward()  # sensors are evaluated at the start of a step; refresh them
    assert world.find("angle").data[0] == pytest.approx(hinge.qpos[0])
    np.testing.assert_allclose(world.find("tip_site").xpos, tip.xpos, atol=1e-12)
    np.testing.assert_allclose(arm.xquat, world.data.xquat[1])
    motor = world.find("torque")
    motor.ctrl = 2.0
    world.step()
    assert motor.force == pytest.approx(2.0)


def test_thing_ids_map_to_the_right_model_elements():
    world = World()
    base = Body("base")
    base.attach(Free("free"), Site("s0"), Box("g0", size=[0.1, 0.1, 0.1]))
    for i in range(3):
        child = Body(f"b{i}", pos=[0.2 * i, 0, 0])
        joint = Slide(f"j{i}", axis=[1, 0, 0]) if i % 2 else Hinge(f"j{i}")
        site = Site(f"s{i + 1}")
        site.attach(Gyro(f"gyro{i}"), FramePos(f"fp{i}"))
        joint.attach(Motor(f"m{i}"))
        child.attach(
            Sphere(f"g{i + 1}", radius=0.05), joint, site, Capsule(radius=0.01, half_length=0.05)
        )
        base.attach(child)
    world.attach(base, Sphere("ground_ball", radius=0.1, pos=[2, 0, 0]))
    base.sites[0].attach(Accelerometer("acc"))
    model = world.model
    _, _, index = world._ensure_built()
    kinds = {
        "body": mujoco.mjtObj.mjOBJ_BODY,
        "joint": mujoco.mjtObj.mjOBJ_JOINT,
        "geom": mujoco.mjtObj.mjOBJ_GEOM,
        "site": mujoco.mjtObj.mjOBJ_SITE,
        "actuator": mujoco.mjtObj.mjOBJ_ACTUATOR,
        "sensor": mujoco.mjtObj.mjOBJ_SENSOR,
    }
    checked = 0
    for thing in world.walk():
        if thing._NAMESPACE in kinds and thing.name:
            assert index[thing.ID] == mujoco.mj_name2id(
                model, kinds[thing._NAMESPACE], thing.name
            ), thing
            checked += 1
    assert checked > 20


def test_runtime_access_outside_a_world_is_a_clear_error():
    with pytest.raises(ThingAttributeError, match="not inside a World"):
        _ = Body("loose").xpos


def test_move_rotate_and_bulk_edits():
    world, arm, hinge = _pendulum()
    arm.move(0.1, 0, 0).rotate([0, 0, 1], np.pi / 2)
    np.testing.assert_allclose(arm.pos, [0.1, 0, 1])
    world.forward()
    np.testing.assert_allclose(arm.xmat @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    tip = world.find("tip")
    tip.set_euler([0, 0, np.pi / 2])
    np.testing.assert_allclose(tip.quat, [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)], atol=1e-12)
    assert arm.set_all("geom", rgba=[0, 0, 1, 1], condim=4) == 2
    assert all(g.condim == 4 for g in arm.all_geoms())
    assert np.all(world.model.geom_condim == 4)
    assert world.set_all("joint", damping=[0.2], armature=0.01) == 1
    assert world.model.dof_armature[0] == pytest.approx(0.01)
    with pytest.raises(AttributeError, match="no MuJoCo attribute 'dampin'"):
        arm.set_all("joint", dampin=1.0)
    with pytest.raises(ThingAttributeError, match="damping"):
        arm.set_all("joint", damping=-1.0)


def test_world_copy_is_independent():
    world, arm, hinge = _pendulum()
    clone = world.copy(timestep=0.005)
    assert clone.timestep == 0.005 and world.timestep == 0.002
    clone.find("pivot").range = [-1, 1]
    assert world.model.jnt_limited[0] == 0 and clone.model.jnt_limited[0] == 1


def test_changing_a_shared_asset_rebuilds_and_shape_helpers_validate():
    from robotwright.things import Material

    red = Material("paint", rgba=[1, 0, 0, 1])
    rod = Capsule("rod", radius=0.02, half_length=0.1, material=red)
    world = World()
    world.attach(Body("b").attach(rod, rod.copy()))
    assert world.model.nmat == 1  # copies share the asset object
    model = world.model
    red.rgba = [0, 1, 0, 1]
    assert world.model is not model
    np.testing.assert_allclose(world.model.mat_rgba[0], [0, 1, 0, 1])
    rod.half_length = 0.3
    assert world.model.geom_size[0][1] == pytest.approx(0.3)
    with pytest.raises(ThingAttributeError, match=r"Capsule 'rod' .*\.size"):
        rod.radius = -1.0
