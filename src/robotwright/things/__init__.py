"""Things: build MuJoCo models in Python.

A Thing is a Python object for one MJCF element (body, geom, joint, site, camera,
light, actuator, sensor). Things form a tree, copy deeply, resolve name clashes
deterministically, write compact MJCF and compile through ``mujoco.MjSpec``::

    from robotwright.things import World, Body, Capsule, Hinge, Motor

    world = World()
    arm = Body("arm", pos=[0, 0, 1])
    hinge = Hinge("shoulder", axis=[0, 1, 0], range=[-1.5, 1.5])
    hinge.attach(Motor(gear=[50]))
    arm.attach(hinge, Capsule(radius=0.04, half_length=0.2, pos=[0, 0, -0.2]))
    world.attach(arm)
    world.step(100)
    print(hinge.qpos, arm.xpos)
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.things.actuators import Actuator, General, Motor, Position, Velocity
    from robotwright.things.assets import Material, MeshAsset, Texture
    from robotwright.things.attrs import ThingAttributeError
    from robotwright.things.base import BaseThing, ThingType
    from robotwright.things.body import Body
    from robotwright.things.cameras import Camera
    from robotwright.things.geoms import (
        Box,
        Capsule,
        Cylinder,
        Ellipsoid,
        Geom,
        HField,
        Mesh,
        Plane,
        Sphere,
    )
    from robotwright.things.hrdf_bridge import hrdf_to_body, hrdf_to_world, things_to_hrdf
    from robotwright.things.joints import Ball, Free, Hinge, Joint, Slide
    from robotwright.things.lights import Light
    from robotwright.things.registry import REGISTRY
    from robotwright.things.sensors import (
        Accelerometer,
        ActuatorFrc,
        ActuatorPos,
        ActuatorVel,
        BallAngVel,
        BallQuat,
        Force,
        FrameAngAcc,
        FrameAngVel,
        FrameLinAcc,
        FrameLinVel,
        FramePos,
        FrameQuat,
        FrameSensor,
        FrameXAxis,
        FrameYAxis,
        FrameZAxis,
        Gyro,
        JointActuatorFrc,
        JointPos,
        JointVel,
        Magnetometer,
        Rangefinder,
        Sensor,
        SubtreeAngMom,
        SubtreeCom,
        SubtreeLinVel,
        Torque,
        Touch,
        Velocimeter,
    )
    from robotwright.things.sites import Site
    from robotwright.things.world import World

__all__ = [
    "REGISTRY",
    "Accelerometer",
    "Actuator",
    "ActuatorFrc",
    "ActuatorPos",
    "ActuatorVel",
    "Ball",
    "BallAngVel",
    "BallQuat",
    "BaseThing",
    "Body",
    "Box",
    "Camera",
    "Capsule",
    "Cylinder",
    "Ellipsoid",
    "Force",
    "FrameAngAcc",
    "FrameAngVel",
    "FrameLinAcc",
    "FrameLinVel",
    "FramePos",
    "FrameQuat",
    "FrameSensor",
    "FrameXAxis",
    "FrameYAxis",
    "FrameZAxis",
    "Free",
    "General",
    "Geom",
    "Gyro",
    "HField",
    "Hinge",
    "Joint",
    "JointActuatorFrc",
    "JointPos",
    "JointVel",
    "Light",
    "Magnetometer",
    "Material",
    "Mesh",
    "MeshAsset",
    "Motor",
    "Plane",
    "Position",
    "Rangefinder",
    "Sensor",
    "Site",
    "Slide",
    "Sphere",
    "SubtreeAngMom",
    "SubtreeCom",
    "SubtreeLinVel",
    "Texture",
    "ThingAttributeError",
    "ThingType",
    "Torque",
    "Touch",
    "Velocimeter",
    "Velocity",
    "World",
    "hrdf_to_body",
    "hrdf_to_world",
    "things_to_hrdf",
]

attach(__name__, __file__)
