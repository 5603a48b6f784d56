"""Where a robot with a free base stands: its initial state on the floor (z = 0), the
standing form of an HRDF for MJCF export, and which of its bodies say that it walks.

A free base read from a URDF sits at the world origin, so a legged robot's legs reach
below the floor: :func:`stand_on_floor` raises the base until its lowest collision geom
touches z = 0 and adds a ``home`` keyframe, the pose a simulator resets to. Only the
MJCF export writes it so: the robot itself (its HRDF) is not changed.
"""

from __future__ import annotations

import dataclasses
import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from fnmatch import fnmatchcase

import mujoco

from robotwright._names import shown
from robotwright._notes import name_list
from robotwright.errors import GeneratorError
from robotwright.hrdf.model import HRDF

__all__ = ["HOME_KEY", "fixed_walker", "initial_state", "stand_on_floor", "walking_bodies"]

#: The keyframe :func:`stand_on_floor` adds: the robot standing in its initial pose.
HOME_KEY = "home"

#: Body names that say a robot walks (its feet and the links above them).
_LEGGED = re.compile(r"(foot|feet|toe|ankle|calf|shin|sole)", re.IGNORECASE)


def walking_bodies(hrdf: HRDF) -> list[str]:
    """The bodies whose names say the robot walks (feet, ankles, calves, ...); empty
    unless there are at least two of them (one ``toe`` is a gripper's part)."""
    feet = [b.name for b in hrdf.bodies if _LEGGED.search(b.name)]
    return feet if len(feet) >= 2 else []


def fixed_walker(robot: str, feet: Sequence[str]) -> str:
    """The warning for a walking robot (``feet``: :func:`walking_bodies`) whose base is
    fixed: it hangs from its root's frame, in a picture or a scan its legs go through
    the floor, and in training it never walks."""
    return (
        f"robot {shown(robot)} has a fixed base but its bodies say it walks "
        f"({name_list(list(feet), 4)}): its base is held where its root's frame is, legs "
        "through the floor at z = 0; give --floating-base for a free base standing on it"
    )


def initial_state(
    model: mujoco.MjModel, joint_pos: Sequence[tuple[str, float]] = ()
) -> tuple[tuple[float, float, float], dict[str, float], list[str]]:
    """Root position [m] and joint positions, with a line per clamped joint.

    A joint's position is the value of the first ``(pattern, value)`` of ``joint_pos``
    whose fnmatch pattern matches its name (a user's standing pose, rad or m), else the
    MJCF's reference pose clamped into the joint's range (Isaac Lab checks ranges). A
    free base is raised so that its collision geometry, in that pose, stands on z = 0
    (in the USD of :func:`~robotwright.generators.isaaclab_cfg.write_articulation_cfg`
    the root body sits at its prim's origin, so this position is where the base spawns
    and where a reset puts it).

    Raises:
        GeneratorError: a pattern matches no joint, or a value lies outside the range of
            a joint it sets.
    """
    pos = (0.0, 0.0, 0.0)
    positions: dict[str, float] = {}
    clamped = []
    used = [False] * len(joint_pos)
    problems = []
    for j in range(model.njnt):
        adr = int(model.jnt_qposadr[j])
        kind = int(model.jnt_type[j])
        if kind == int(mujoco.mjtJoint.mjJNT_FREE):
            pos = tuple(float(v) for v in model.qpos0[adr : adr + 3])  # type: ignore[assignment]
            continue
        if kind not in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
            continue
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        lo, hi = (float(v) for v in model.jnt_range[j])
        limited = bool(model.jnt_limited[j])
        given = next((k for k, (pat, _) in enumerate(joint_pos) if fnmatchcase(name, pat)), None)
        if given is not None:
            used[given] = True
            q = float(joint_pos[given][1])
            if limited and not lo <= q <= hi:
                problems.append(
                    f"--joint-pos {shown(joint_pos[given][0])}={q:g}: joint {shown(name)} "
                    f"moves in [{lo:g}, {hi:g}]"
                )
            positions[name] = q
            continue
        q = float(model.qpos0[adr])
        if limited and not lo <= q <= hi:
            new = min(max(q, lo), hi)
            clamped.append(
                f"{name}: reference position {q:g} outside [{lo:g}, {hi:g}], written as {new:g}"
            )
            q = new
        positions[name] = q
    problems += [
        f"--joint-pos {shown(pat)}: matches no hinge or slide joint"
        for (pat, _), hit in zip(joint_pos, used, strict=True)
        if not hit
    ]
    if problems:
        raise GeneratorError("; ".join(problems))
    if not model.njnt or int(model.jnt_type[0]) != int(mujoco.mjtJoint.mjJNT_FREE):
        pos = tuple(float(v) for v in model.body_pos[1])  # type: ignore[assignment]
    else:
        pos = (pos[0], pos[1], pos[2] + _floor_clearance(model, positions))
    return pos, positions, clamped


def _floor_clearance(model: mujoco.MjModel, joint_pos: dict[str, float]) -> float:
    """How far [m] to raise a free-base robot (at its initial joint positions) so that
    the lowest corner of its collision geoms' bounding boxes is on z = 0."""
    from robotwright._mjmodel import lowest_collision_point

    data = mujoco.MjData(model)
    for name, q in joint_pos.items():
        data.joint(name).qpos[0] = q
    mujoco.mj_kinematics(model, data)
    lowest = lowest_collision_point(model, data)
    return 0.0 if not math.isfinite(lowest) else -lowest


def _holding_ctrl(model: mujoco.MjModel, qpos) -> list[float]:
    """Controls that hold ``qpos``: a position servo's (``kp * (ctrl - q)``) target is its
    joint's position (clamped into its control range), every other control 0."""
    ctrl = [0.0] * model.nu
    for i in range(model.nu):
        kp = float(model.actuator_gainprm[i, 0])
        servo = (
            int(model.actuator_trntype[i]) == int(mujoco.mjtTrn.mjTRN_JOINT)
            and kp > 0
            and float(model.actuator_biasprm[i, 1]) == -kp
        )
        if servo:
            j = int(model.actuator_trnid[i, 0])
            q = float(qpos[int(model.jnt_qposadr[j])])
            if model.actuator_ctrllimited[i]:
                lo, hi = (float(v) for v in model.actuator_ctrlrange[i])
                q = min(max(q, lo), hi)
            ctrl[i] = q
    return ctrl


def stand_on_floor(
    hrdf: HRDF, joint_pos: Sequence[tuple[str, float]] = ()
) -> tuple[HRDF, list[str]]:
    """The robot standing on the floor, for an MJCF file: a free base whose collision
    geometry reaches below z = 0 in its reference pose is raised until it touches it,
    and then, or when ``joint_pos`` is given, a robot without keyframes gets a ``home``
    keyframe that holds the base at its standing height [m] in the joint positions of
    ``joint_pos`` (see :func:`initial_state`; the reference pose, clamped into the
    ranges, without it) and the controls that hold it (a position servo's target is its
    joint's position). A fixed base gets the keyframe only with ``joint_pos``. Returns
    the robot and a line for each change made.

    Raises:
        GeneratorError: as :func:`initial_state`.
    """
    from robotwright.generators.mjcf import MJCFHumanoidGenerator, parse_mjcf_extra

    if not hrdf.floating_base and not joint_pos:
        return hrdf, []
    model = MJCFHumanoidGenerator.from_hrdf(hrdf).to_model()
    changes = []
    root = hrdf.root_body
    pos = initial_state(model)[0]
    # Only raised: a base its file sets above the floor stays there.
    if hrdf.floating_base and pos[2] > root.pos[2] + 1e-9:
        changes.append(
            f"robot {shown(hrdf.name)}: free base {shown(root.name)} raised from z = "
            f"{root.pos[2]:.4g} to {pos[2]:.4g} m, its lowest collision geom on the floor"
        )
        bodies = [dataclasses.replace(b, pos=pos) if b is root else b for b in hrdf.bodies]
        hrdf = dataclasses.replace(hrdf, bodies=bodies)
        model = MJCFHumanoidGenerator.from_hrdf(hrdf).to_model()
    if model.nkey:
        if joint_pos:
            raise GeneratorError(
                f"robot {shown(hrdf.name)} has keyframes of its own: --joint-pos would "
                "add a home keyframe beside them"
            )
        return hrdf, changes
    if not changes and not joint_pos:  # standing already, as its file says: kept as is
        return hrdf, changes
    home, joints, clamped = initial_state(model, joint_pos)
    qpos = model.qpos0.copy()
    if hrdf.floating_base:
        qpos[int(model.jnt_qposadr[0]) : int(model.jnt_qposadr[0]) + 3] = home
    for name, q in joints.items():
        qpos[int(model.joint(name).qposadr[0])] = q
    extra = parse_mjcf_extra(hrdf)
    if extra is None:
        extra = ET.Element("mujoco")
    section = extra.find("keyframe")
    if section is None:
        section = ET.SubElement(extra, "keyframe")
    key = {"name": HOME_KEY, "qpos": " ".join(repr(float(v)) for v in qpos)}
    if model.nu:
        key["ctrl"] = " ".join(repr(float(v)) for v in _holding_ctrl(model, qpos))
    ET.SubElement(section, "key", key)
    hrdf = dataclasses.replace(hrdf, mjcf_extra=ET.tostring(extra, encoding="unicode"))
    base = f"the base at z = {home[2]:.4g} m " if hrdf.floating_base else ""
    pose = "the --joint-pos pose" if joint_pos else "the reference pose"
    changes.append(f"robot {shown(hrdf.name)}: keyframe {HOME_KEY!r} added: {base}in {pose}")
    changes += [f"keyframe {HOME_KEY!r}: {c}" for c in clamped]
    return hrdf, changes
