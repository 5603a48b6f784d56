"""Robots built in memory for generator tests (every HRDF feature, no downloaded data)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import trimesh

from robotwright.hrdf.model import (
    HRDF,
    Actuator,
    Body,
    GroundConfig,
    ImuConfig,
    Joint,
    MeshGeom,
    Meta,
    Sensor,
    SimpleGeom,
    SimulatorConfig,
    Site,
)

BUNDLED = Path(__file__).resolve().parents[2] / "src" / "robotwright" / "robots"


def _q(angle: float, axis: tuple[float, float, float]) -> tuple[float, float, float, float]:
    s = math.sin(angle / 2)
    return (math.cos(angle / 2), axis[0] * s, axis[1] * s, axis[2] * s)


def make_robot(root_dir: Path, *, ball: bool = True, floating: bool = True) -> HRDF:
    """A 5-body robot using every HRDF feature; ``ball=False`` leaves out what URDF cannot
    express exactly (ball joint, ellipsoid, restitution)."""
    meshes = root_dir / "meshes"
    meshes.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=(0.1, 0.08, 0.06)).export(meshes / "box.stl")
    inertia = (0.01, 0.02, 0.015)
    bodies = [
        Body("base", -1, (0.0, 0.0, 1.0), _q(0.3, (0, 0, 1)), 2.0, (0.01, 0, 0), _q(0.2, (1, 0, 0)), inertia),
        Body("link1", 0, (0.1, 0.0, 0.0), _q(0.5, (0, 1, 0)), 1.0, (0, 0.02, 0), (1, 0, 0, 0), inertia),
        Body("link2", 1, (0.0, 0.0, 0.2), (1, 0, 0, 0), 0.5, (0, 0, 0.05), _q(0.1, (0, 0, 1)), inertia),
        Body("link3", 2, (0.0, 0.1, 0.0), (1, 0, 0, 0), 0.4, (0, 0, 0), (1, 0, 0, 0), inertia),
        Body("tool", 3, (0.0, 0.0, 0.1), _q(0.7, (1, 0, 0)), 0.2, (0, 0, 0.01), (1, 0, 0, 0), inertia),
    ]  # fmt: skip
    joints = []
    if floating:
        joints.append(Joint(name="root", body="base", type="free"))
    joints += [
        Joint("j1a", "link1", "hinge", (0, 0, 0.05), (0, 0, 1), (-1.0, 1.0), armature=0.02,
              static_friction=0.1, dynamic_friction=0.1, viscous_friction=0.3, stiffness=2.0,
              springref=0.1),
        Joint("j1b", "link1", "hinge", (0.02, 0, 0), (1, 0, 0), None),
        Joint("j2", "link2", "slide", (0, 0, 0), (1, 0, 0), (-0.1, 0.2), viscous_friction=1.0),
    ]  # fmt: skip
    if ball:
        joints.append(Joint("j3", "link3", "ball", (0, 0, 0.01), range=(0.0, 0.5)))
    else:
        joints.append(Joint("j3", "link3", "hinge", (0, 0, 0.01), (0, 1, 0), (-2.0, 2.0)))
    mesh_geoms = [
        MeshGeom(body="base", name="box", scale=(1.0, 2.0, 1.0), contact_type=0, contact_affinity=0),
        MeshGeom(body="link1", name="box", geom_name="link1_shell"),
    ]  # fmt: skip
    simple = [
        SimpleGeom(body="link1", name="link1_cyl", type="cylinder", size=(0.03, 0.05, 0)),
        SimpleGeom(body="link2", name="link2_caps", type="capsule", size=(0.02, 0.08, 0),
                   pos=(0, 0, 0.05), quat=_q(0.4, (1, 0, 0)), contact_type=2,
                   contact_affinity=3, group=2, condim=4, static_friction=0.8,
                   dynamic_friction=0.8, torsional_friction=0.01, rolling_friction=0.001,
                   rgba=(0.9, 0.1, 0.1, 1.0)),
        SimpleGeom(body="link3", name="link3_ball", type="sphere", size=(0.03, 0, 0)),
        SimpleGeom(body="tool", name="tool_box", type="box", size=(0.02, 0.03, 0.04),
                   restitution=0.5 if ball else None),
    ]  # fmt: skip
    if ball:
        simple.append(
            SimpleGeom(body="tool", name="tool_egg", type="ellipsoid", size=(0.01, 0.02, 0.03))
        )
    sites = [Site("tool_tip", "tool", (0, 0, 0.1), _q(0.2, (0, 0, 1)), rgba=(0, 1, 0, 1))]
    sensors = [
        Sensor("tip_pos", "framepos", "site", "tool_tip"),
        Sensor("j1a_pos", "jointpos", "joint", "j1a", noise=0.01),
        Sensor("tip_touch", "touch", "site", "tool_tip"),
    ]
    actuators = [
        Actuator("j1a", name="j1a_motor", type="motor", peak_torque=5.0, gear=2.0),
        Actuator("j1b", name="j1b_servo", type="position", p_gain=50.0, d_gain=2.0,
                 ctrl_range=(-1.0, 1.0), force_range=(-3.0, 3.0)),
        Actuator("j2", name="j2_vel", type="velocity", d_gain=4.0),
    ]  # fmt: skip
    meta = Meta(
        simulator_config=SimulatorConfig(
            timestep=0.001,
            gravity=(0.0, 0.0, -9.8),
            ground=GroundConfig(friction=0.7),
            integrator="implicitfast",
        ),
        imu_config_list=[ImuConfig("base", position=(0, 0, 0.02), orientation=_q(0.1, (0, 1, 0)))],
    )
    extra = None
    if ball:
        extra = (
            "<mujoco>"
            '<tendon><fixed name="couple"><joint joint="j1a" coef="1"/>'
            '<joint joint="j1b" coef="-1"/></fixed></tendon>'
            '<equality><joint name="lock" joint1="j1a" joint2="j1b" active="false"/></equality>'
            '<contact><exclude body1="base" body2="link1"/></contact>'
            "</mujoco>"
        )
    return HRDF(
        name="synth",
        bodies=bodies,
        joints=joints,
        actuators=actuators,
        meshes=mesh_geoms,
        simple_geoms=simple,
        sites=sites,
        sensors=sensors,
        meta=meta,
        mjcf_extra=extra,
        root_dir=root_dir,
    )


@pytest.fixture
def synth(tmp_path: Path) -> HRDF:
    """Every feature, including the ones URDF cannot hold."""
    return make_robot(tmp_path / "synth")


@pytest.fixture
def synth_urdf_safe(tmp_path: Path) -> HRDF:
    """Every feature URDF can express exactly (no ball joint, ellipsoid, restitution)."""
    return make_robot(tmp_path / "synth_safe", ball=False)


@pytest.fixture
def synth_fixed(tmp_path: Path) -> HRDF:
    """As ``synth_urdf_safe`` but with a fixed base."""
    return make_robot(tmp_path / "synth_fixed", ball=False, floating=False)
