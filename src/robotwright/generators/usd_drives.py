"""The joint drive a USD file should hold for each actuated joint, from MuJoCo's compile
of the robot: what the USD export authors and what its proof expects Newton to read.

A USD joint drive (``UsdPhysics.DriveAPI``) is a PD law on one degree of freedom,
``force = stiffness * (target - q) + damping * (target_velocity - qdot)``, clipped at a
max force. MuJoCo's actuators map onto it as follows, with gear ``g`` (joint units: N m
and rad for a hinge, N and m for a slide):

* ``position`` (``kp``, ``kv``): stiffness ``kp g^2``, damping ``kv g^2``;
* ``velocity`` (``kv``): damping ``kv g^2``;
* ``motor`` (gain ``k``): an effort drive (stiffness and damping 0; the force comes from
  the user's effort target);
* several of these on one joint add up (a position and a velocity actuator give one
  drive with both gains);
* max force: the tightest of each actuator's ``forcerange`` times ``|g|``, a motor's
  ``ctrlrange`` times ``|k g|``, and the joint's ``actuatorfrcrange``; infinite when
  nothing bounds it.

What no drive can hold is named, one note per actuator: an actuator on a tendon, site
or body, on a ball or free joint, with activation dynamics (a filter, an integrator, a
muscle), with a plugin, or with a gain or bias that is not one of the forms above.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco

__all__ = ["JointDrive", "joint_drives"]

_JOINT_TRN = (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))
_DRIVEN_JOINTS = {int(mujoco.mjtJoint.mjJNT_HINGE): "angular", int(mujoco.mjtJoint.mjJNT_SLIDE): "linear"}  # fmt: skip


@dataclass
class JointDrive:
    """The drive of one joint, in joint units (N m/rad, N m s/rad, N m for a hinge; N/m,
    N s/m, N for a slide).

    Attributes:
        joint: the joint's name.
        axis: ``"angular"`` (hinge) or ``"linear"`` (slide).
        actuators: the names of the actuators it holds.
        kinds: their kinds (``position``, ``velocity``, ``motor``), in actuator order.
        stiffness, damping: the PD gains.
        max_force: the largest force or torque (``inf``: unbounded).
    """

    joint: str
    axis: str
    actuators: list[str] = field(default_factory=list)
    kinds: list[str] = field(default_factory=list)
    stiffness: float = 0.0
    damping: float = 0.0
    max_force: float = 0.0


def _name(model: mujoco.MjModel, obj: mujoco.mjtObj, i: int, fallback: str) -> str:
    return mujoco.mj_id2name(model, obj, i) or f"{fallback}#{i}"


def _kind(model: mujoco.MjModel, a: int) -> tuple[str, float, float] | str:
    """(kind, stiffness, damping) before gear, or the reason no drive holds actuator
    ``a``."""
    if int(model.actuator_dyntype[a]) != int(mujoco.mjtDyn.mjDYN_NONE):
        dyn = mujoco.mjtDyn(int(model.actuator_dyntype[a])).name.removeprefix("mjDYN_").lower()
        return f"its activation dynamics ({dyn}) have no USD drive form"
    if int(model.actuator_plugin[a]) >= 0:
        return "it is computed by a plugin"
    gain, bias = model.actuator_gainprm[a], model.actuator_biasprm[a]
    if int(model.actuator_gaintype[a]) != int(mujoco.mjtGain.mjGAIN_FIXED) or gain[1:].any():
        return "its gain is not a constant"
    k = float(gain[0])
    biastype = int(model.actuator_biastype[a])
    if biastype == int(mujoco.mjtBias.mjBIAS_NONE):
        return ("motor", 0.0, 0.0)
    if biastype == int(mujoco.mjtBias.mjBIAS_AFFINE) and not bias[3:].any() and bias[0] == 0:
        b1, b2 = float(bias[1]), float(bias[2])
        if k != 0 and b1 == -k:
            return ("position", k, -b2)
        if k != 0 and b1 == 0 and b2 == -k:
            return ("velocity", 0.0, k)
    return "its gain and bias are not a position, velocity or motor law"


def _force_bound(model: mujoco.MjModel, a: int, kind: str) -> float:
    """The largest joint force actuator ``a`` gives [N m or N]."""
    g = abs(float(model.actuator_gear[a, 0]))
    bounds = [math.inf]
    if model.actuator_forcelimited[a]:
        bounds.append(float(abs(model.actuator_forcerange[a]).max()) * g)
    if kind == "motor" and model.actuator_ctrllimited[a]:
        bounds.append(float(abs(model.actuator_ctrlrange[a]).max()) * abs(model.actuator_gainprm[a, 0]) * g)  # fmt: skip
    return min(bounds)


def joint_drives(model: mujoco.MjModel) -> tuple[dict[str, JointDrive], list[str]]:
    """The drive of every actuated hinge and slide joint of ``model`` (by joint name, in
    actuator order), and one note per actuator no drive holds."""
    drives: dict[str, JointDrive] = {}
    notes: list[str] = []
    for a in range(model.nu):
        act = _name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, a, "actuator")
        trn = int(model.actuator_trntype[a])
        if trn not in _JOINT_TRN:
            what = mujoco.mjtTrn(trn).name.removeprefix("mjTRN_").lower()
            notes.append(f"actuator {act!r} drives a {what}, not a joint: no USD joint drive carries it")  # fmt: skip
            continue
        j = int(model.actuator_trnid[a, 0])
        joint = _name(model, mujoco.mjtObj.mjOBJ_JOINT, j, "joint")
        axis = _DRIVEN_JOINTS.get(int(model.jnt_type[j]))
        if axis is None:
            jtype = mujoco.mjtJoint(int(model.jnt_type[j])).name.removeprefix("mjJNT_").lower()
            notes.append(f"actuator {act!r} drives {jtype} joint {joint!r}: USD drives are on hinge and slide joints only")  # fmt: skip
            continue
        kind = _kind(model, a)
        if isinstance(kind, str):
            notes.append(f"actuator {act!r} on joint {joint!r}: no USD drive, {kind}")
            continue
        name, kp, kv = kind
        g2 = float(model.actuator_gear[a, 0]) ** 2
        drive = drives.setdefault(joint, JointDrive(joint, axis))
        drive.actuators.append(act)
        drive.kinds.append(name)
        drive.stiffness += kp * g2
        drive.damping += kv * g2
        drive.max_force += _force_bound(model, a, name)
    for drive in drives.values():
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, drive.joint)
        if j >= 0 and model.jnt_actfrclimited[j]:
            drive.max_force = min(drive.max_force, float(abs(model.jnt_actfrcrange[j]).max()))
    return drives, notes
