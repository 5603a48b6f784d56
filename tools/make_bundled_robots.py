#!/usr/bin/env python
"""Regenerate the robots bundled with robotwright (``src/robotwright/robots/``).

Each robot is described below with primitive geoms and per-geom masses; MuJoCo computes
the body masses, centres of mass and principal inertias from those geoms
(``inertiafromgeom``), and the result is saved as an HRDF folder. Run from the repo root:

    python tools/make_bundled_robots.py
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from robotwright._outputs import MARKER
from robotwright.hrdf import (
    HRDF,
    Actuator,
    Body,
    BodyNameConfig,
    ImuConfig,
    Joint,
    Meta,
    Sensor,
    SimpleGeom,
    SimulatorConfig,
    Site,
)

OUT = Path(__file__).resolve().parents[1] / "src" / "robotwright" / "robots"


@dataclass
class G:
    """A primitive geom: type, MuJoCo half-sizes (m), pose in the body, mass (kg)."""

    type: str
    size: tuple[float, float, float]
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mass: float = 0.1
    collide: bool = True
    rgba: tuple[float, float, float, float] = (0.7, 0.7, 0.75, 1.0)


@dataclass
class B:
    name: str
    parent: str | None
    pos: tuple[float, float, float]
    joint: tuple[str, str, tuple[float, float, float], tuple[float, float]] | None
    geoms: list[G]
    #: (name, pos) or (name, pos, quat) in the body frame.
    sites: list[tuple] = field(default_factory=list)


def _mjcf(bodies: list[B]) -> str:
    """An MJCF used only to let MuJoCo compute inertial properties from the geoms."""
    children: dict[str | None, list[B]] = {}
    for b in bodies:
        children.setdefault(b.parent, []).append(b)

    def emit(b: B, depth: int) -> str:
        pad = "  " * depth
        out = [f'{pad}<body name="{b.name}" pos="{" ".join(map(str, b.pos))}">']
        for g in b.geoms:
            out.append(
                f'{pad}  <geom type="{g.type}" size="{" ".join(map(str, g.size))}" '
                f'pos="{" ".join(map(str, g.pos))}" mass="{g.mass}"/>'
            )
        for c in children.get(b.name, []):
            out.append(emit(c, depth + 1))
        out.append(f"{pad}</body>")
        return "\n".join(out)

    body = "\n".join(emit(b, 1) for b in children[None])
    return f'<mujoco><compiler angle="radian" inertiafromgeom="true"/><worldbody>\n{body}\n</worldbody></mujoco>'


def _round(v: float) -> float:
    # 12 significant digits: exact enough for physics, short and stable in the CSV.
    return float(f"{v:.12g}")


def build(
    name: str,
    bodies: list[B],
    *,
    floating: bool,
    actuators: list[Actuator],
    sensors: list[Sensor],
    imu_body: str | None,
    body_names: BodyNameConfig,
) -> HRDF:
    model = mujoco.MjModel.from_xml_string(_mjcf(bodies))
    index = {b.name: i for i, b in enumerate(bodies)}
    hb: list[Body] = []
    joints: list[Joint] = []
    geoms: list[SimpleGeom] = []
    sites: list[Site] = []
    for b in bodies:
        mid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b.name)
        iq = model.body_iquat[mid]
        iq = iq / np.linalg.norm(iq)
        hb.append(
            Body(
                name=b.name,
                parent=-1 if b.parent is None else index[b.parent],
                pos=tuple(_round(v) for v in b.pos),
                quat=(1.0, 0.0, 0.0, 0.0),
                mass=_round(model.body_mass[mid]),
                inertial_pos=tuple(_round(v) for v in model.body_ipos[mid]),
                inertial_quat=tuple(_round(v) for v in iq),
                diag_inertia=tuple(_round(v) for v in model.body_inertia[mid]),
            )
        )
        if b.joint is not None:
            jname, jtype, axis, rng = b.joint
            joints.append(
                Joint(
                    name=jname,
                    body=b.name,
                    type=jtype,
                    axis=axis,
                    range=rng,
                    armature=0.01,
                    static_friction=0.1,
                    dynamic_friction=0.1,
                    viscous_friction=0.5,
                )
            )
        for k, g in enumerate(b.geoms):
            geoms.append(
                SimpleGeom(
                    body=b.name,
                    name=f"{b.name}_geom{k}",
                    type=g.type,
                    size=g.size,
                    pos=g.pos,
                    rgba=g.rgba,
                    contact_type=1 if g.collide else 0,
                    contact_affinity=1 if g.collide else 0,
                )
            )
        for sname, spos, *squat in b.sites:
            quat = squat[0] if squat else (1.0, 0.0, 0.0, 0.0)
            sites.append(Site(name=sname, body=b.name, pos=spos, quat=quat, size=(0.01, 0.0, 0.0)))
    if floating:
        joints.insert(0, Joint(name=None, body=bodies[0].name, type="free"))
    meta = Meta(
        mesh_file_type="stl",
        simulator_config=SimulatorConfig(),
        body_name_config=body_names,
        imu_config_list=[ImuConfig(body_name=imu_body)] if imu_body else None,
    )
    return HRDF(
        name=name,
        bodies=hb,
        joints=joints,
        actuators=actuators,
        simple_geoms=geoms,
        sites=sites,
        sensors=sensors,
        meta=meta,
    )


GREY = (0.7, 0.7, 0.75, 1.0)
DARK = (0.25, 0.25, 0.3, 1.0)
ORANGE = (0.95, 0.55, 0.15, 1.0)


def humanoid() -> HRDF:
    """A 1 m, ~28 kg humanoid: 2 x 6-DoF legs, 2 x 3-DoF arms, waist and neck (19 DoF)."""
    pi = math.pi
    bodies = [
        B(
            "pelvis",
            None,
            (0.0, 0.0, 0.672),
            None,
            [G("box", (0.05, 0.08, 0.04), mass=3.0)],
            [("imu", (0.0, 0.0, 0.0))],
        ),
        B(
            "torso",
            "pelvis",
            (0.0, 0.0, 0.1),
            ("waist_yaw_joint", "hinge", (0.0, 0.0, 1.0), (-1.5, 1.5)),
            [G("box", (0.07, 0.1, 0.12), (0.0, 0.0, 0.12), 6.0, rgba=ORANGE)],
            [("back_mount", (-0.07, 0.0, 0.15)), ("chest", (0.07, 0.0, 0.15))],
        ),
        B(
            "head",
            "torso",
            (0.0, 0.0, 0.28),
            ("neck_pitch_joint", "hinge", (0.0, 1.0, 0.0), (-0.6, 0.6)),
            [G("sphere", (0.08, 0.0, 0.0), (0.0, 0.0, 0.08), 1.2, rgba=DARK)],
            # Mounted upside down (as on Unitree's G1): a Mid-360's -7..52 deg field of
            # view then looks at the floor and obstacles around the robot, not the sky.
            [("head_lidar", (0.0, 0.0, 0.17), (0.0, 1.0, 0.0, 0.0))],
        ),
    ]
    for side, s in (("left", 1.0), ("right", -1.0)):
        bodies += [
            B(
                f"{side}_shoulder_pitch_link",
                "torso",
                (0.0, 0.13 * s, 0.2),
                (f"{side}_shoulder_pitch_joint", "hinge", (0.0, 1.0, 0.0), (-pi, 1.0)),
                [G("sphere", (0.04, 0.0, 0.0), mass=0.5, collide=False, rgba=DARK)],
            ),
            B(
                f"{side}_shoulder_roll_link",
                f"{side}_shoulder_pitch_link",
                (0.0, 0.03 * s, 0.0),
                (
                    f"{side}_shoulder_roll_joint",
                    "hinge",
                    (1.0, 0.0, 0.0),
                    (-0.3, 2.5) if s > 0 else (-2.5, 0.3),
                ),
                [G("capsule", (0.03, 0.08, 0.0), (0.0, 0.0, -0.1), 1.0)],
            ),
            B(
                f"{side}_elbow_link",
                f"{side}_shoulder_roll_link",
                (0.0, 0.0, -0.2),
                (f"{side}_elbow_joint", "hinge", (0.0, 1.0, 0.0), (-2.5, 0.0)),
                [G("capsule", (0.025, 0.08, 0.0), (0.0, 0.0, -0.1), 0.7)],
                [(f"{side}_hand", (0.0, 0.0, -0.22))],
            ),
            B(
                f"{side}_hip_yaw_link",
                "pelvis",
                (0.0, 0.08 * s, -0.05),
                (f"{side}_hip_yaw_joint", "hinge", (0.0, 0.0, 1.0), (-0.8, 0.8)),
                [G("sphere", (0.04, 0.0, 0.0), mass=0.8, collide=False, rgba=DARK)],
            ),
            B(
                f"{side}_hip_roll_link",
                f"{side}_hip_yaw_link",
                (0.0, 0.0, -0.04),
                (
                    f"{side}_hip_roll_joint",
                    "hinge",
                    (1.0, 0.0, 0.0),
                    (-0.4, 0.8) if s > 0 else (-0.8, 0.4),
                ),
                [G("box", (0.03, 0.03, 0.02), mass=1.0, collide=False, rgba=DARK)],
            ),
            B(
                f"{side}_thigh",
                f"{side}_hip_roll_link",
                (0.0, 0.0, -0.02),
                (f"{side}_hip_pitch_joint", "hinge", (0.0, 1.0, 0.0), (-2.0, 0.8)),
                [G("capsule", (0.045, 0.1, 0.0), (0.0, 0.0, -0.125), 2.5)],
            ),
            B(
                f"{side}_shin",
                f"{side}_thigh",
                (0.0, 0.0, -0.25),
                (f"{side}_knee_joint", "hinge", (0.0, 1.0, 0.0), (0.0, 2.4)),
                [G("capsule", (0.04, 0.1, 0.0), (0.0, 0.0, -0.125), 1.6)],
            ),
            B(
                f"{side}_ankle_pitch_link",
                f"{side}_shin",
                (0.0, 0.0, -0.25),
                (f"{side}_ankle_pitch_joint", "hinge", (0.0, 1.0, 0.0), (-0.9, 0.6)),
                [G("sphere", (0.03, 0.0, 0.0), mass=0.3, collide=False, rgba=DARK)],
            ),
            B(
                f"{side}_foot",
                f"{side}_ankle_pitch_link",
                (0.0, 0.0, -0.02),
                (f"{side}_ankle_roll_joint", "hinge", (1.0, 0.0, 0.0), (-0.4, 0.4)),
                [G("box", (0.09, 0.045, 0.02), (0.02, 0.0, -0.02), 0.6, rgba=DARK)],
                [(f"{side}_sole", (0.02, 0.0, -0.04))],
            ),
        ]
    torque = {
        "waist_yaw": 40.0,
        "neck_pitch": 5.0,
        "shoulder_pitch": 20.0,
        "shoulder_roll": 20.0,
        "elbow": 15.0,
        "hip_yaw": 40.0,
        "hip_roll": 60.0,
        "hip_pitch": 60.0,
        "knee": 80.0,
        "ankle_pitch": 30.0,
        "ankle_roll": 30.0,
    }
    actuators = []
    for b in bodies:
        if b.joint is None:
            continue
        jname = b.joint[0]
        key = jname.removeprefix("left_").removeprefix("right_").removesuffix("_joint")
        actuators.append(Actuator(joint=jname, peak_torque=torque[key], peak_velocity=20.0))
    sensors = [
        Sensor(name=f"{side}_foot_touch", type="touch", objtype="site", objname=f"{side}_sole")
        for side in ("left", "right")
    ]
    return build(
        "mini_humanoid",
        bodies,
        floating=True,
        actuators=actuators,
        sensors=sensors,
        imu_body="pelvis",
        body_names=BodyNameConfig(
            torso_name="torso",
            hip_names=["left_hip_yaw_link", "right_hip_yaw_link"],
            knee_names=["left_shin", "right_shin"],
            foot_names=["left_foot", "right_foot"],
        ),
    )


def arm() -> HRDF:
    """A fixed-base 6-DoF arm (0.9 m reach, ~8 kg) with position servos and a tool0 site."""
    z, y = (0.0, 0.0, 1.0), (0.0, 1.0, 0.0)
    bodies = [
        B(
            "base_link",
            None,
            (0.0, 0.0, 0.0),
            None,
            [G("cylinder", (0.06, 0.04, 0.0), (0.0, 0.0, 0.04), 2.0, rgba=DARK)],
        ),
        B(
            "shoulder_link",
            "base_link",
            (0.0, 0.0, 0.08),
            ("shoulder_pan_joint", "hinge", z, (-2.9, 2.9)),
            [G("cylinder", (0.05, 0.04, 0.0), (0.0, 0.0, 0.04), 1.5)],
        ),
        B(
            "upper_arm_link",
            "shoulder_link",
            (0.0, 0.0, 0.08),
            ("shoulder_lift_joint", "hinge", y, (-2.0, 2.0)),
            [G("capsule", (0.04, 0.12, 0.0), (0.0, 0.0, 0.15), 2.0, rgba=ORANGE)],
        ),
        B(
            "forearm_link",
            "upper_arm_link",
            (0.0, 0.0, 0.3),
            ("elbow_joint", "hinge", y, (-2.6, 2.6)),
            [G("capsule", (0.03, 0.1, 0.0), (0.0, 0.0, 0.125), 1.2, rgba=ORANGE)],
        ),
        B(
            "wrist_1_link",
            "forearm_link",
            (0.0, 0.0, 0.25),
            ("wrist_1_joint", "hinge", y, (-2.9, 2.9)),
            [G("cylinder", (0.03, 0.025, 0.0), (0.0, 0.0, 0.025), 0.4, rgba=DARK)],
        ),
        B(
            "wrist_2_link",
            "wrist_1_link",
            (0.0, 0.0, 0.05),
            ("wrist_2_joint", "hinge", z, (-2.9, 2.9)),
            [G("cylinder", (0.03, 0.025, 0.0), (0.0, 0.0, 0.025), 0.4)],
        ),
        B(
            "wrist_3_link",
            "wrist_2_link",
            (0.0, 0.0, 0.05),
            ("wrist_3_joint", "hinge", y, (-2.9, 2.9)),
            [G("cylinder", (0.025, 0.015, 0.0), (0.0, 0.0, 0.015), 0.2, rgba=DARK)],
            [("tool0", (0.0, 0.0, 0.04))],
        ),
    ]
    peak = {
        "shoulder_pan_joint": 60.0,
        "shoulder_lift_joint": 60.0,
        "elbow_joint": 30.0,
        "wrist_1_joint": 10.0,
        "wrist_2_joint": 10.0,
        "wrist_3_joint": 10.0,
    }
    actuators = [
        Actuator(
            joint=b.joint[0],
            name=b.joint[0].removesuffix("_joint") + "_servo",
            type="position",
            peak_torque=peak[b.joint[0]],
            peak_velocity=3.0,
            p_gain=200.0 if peak[b.joint[0]] > 20 else 50.0,
            d_gain=20.0 if peak[b.joint[0]] > 20 else 5.0,
            ctrl_range=b.joint[3],
            force_range=(-peak[b.joint[0]], peak[b.joint[0]]),
        )
        for b in bodies
        if b.joint is not None
    ]
    sensors = [
        Sensor(name="tool0_pos", type="framepos", objtype="site", objname="tool0"),
        Sensor(name="tool0_quat", type="framequat", objtype="site", objname="tool0"),
    ]
    return build(
        "arm6",
        bodies,
        floating=False,
        actuators=actuators,
        sensors=sensors,
        imu_body=None,
        body_names=BodyNameConfig(),
    )


def main() -> None:
    for robot in (humanoid(), arm()):
        path = robot.save(OUT / robot.name, overwrite=True)
        # The mark every saved output folder gets is for a user's outputs; the bundled
        # robots are part of the package, so nothing is left in the checkout beside them.
        (path / MARKER).unlink(missing_ok=True)
        print(f"wrote {path}: {robot.summary()}")


if __name__ == "__main__":
    main()
