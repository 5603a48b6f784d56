"""Helpers on a compiled ``mujoco.MjModel``: counts that differ between MuJoCo releases,
and where a floating robot's collision geometry reaches down to."""

from __future__ import annotations

import math
from typing import Any


def actuator_count(model: Any) -> int:
    """Number of actuators of ``model``.

    MuJoCo 4 counts actuators (``nactuator``) apart from controls (``nu``): an ``so3``
    actuator on a ball joint takes three controls. MuJoCo 3.11 has one control per
    actuator and no ``nactuator``.
    """
    return int(getattr(model, "nactuator", model.nu))


def lowest_collision_point(model: Any, data: Any) -> float:
    """The lowest world z [m] of the robot's collision geoms (``contype`` or
    ``conaffinity`` set, on a body: the world's geoms are scene) at ``data``'s pose
    (forward kinematics done): the lowest corner of each geom's bounding box
    (``geom_aabb``, in the geom's frame); ``inf`` without collision geoms."""
    import numpy as np

    lowest = math.inf
    signs = np.array([(sx, sy, sz) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    for g in range(model.ngeom):
        if not (model.geom_contype[g] or model.geom_conaffinity[g]) or model.geom_bodyid[g] == 0:
            continue
        center, half = model.geom_aabb[g][:3], model.geom_aabb[g][3:]
        rot = data.geom_xmat[g].reshape(3, 3)
        corners = data.geom_xpos[g] + (center + half * signs) @ rot.T
        lowest = min(lowest, float(corners[:, 2].min()))
    return lowest


def stand_on_floor(model: Any) -> float | None:
    """Raise (or lower) a robot whose root body floats (a free joint on a child of the
    world) so that, in its reference pose and in each keyframe, its lowest collision geom
    touches z = 0; returns the shift of the reference pose [m], ``None`` when the root
    does not float or has no collision geom. Changes ``model.qpos0`` and ``key_qpos``."""
    import mujoco

    free = [
        j
        for j in range(model.njnt)
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE
        and model.body_parentid[model.jnt_bodyid[j]] == 0
    ]
    if len(free) != 1:
        return None
    z = int(model.jnt_qposadr[free[0]]) + 2
    data = mujoco.MjData(model)
    shift = None
    for k in range(-1, model.nkey):
        data.qpos[:] = model.qpos0 if k < 0 else model.key_qpos[k]
        mujoco.mj_kinematics(model, data)
        lowest = lowest_collision_point(model, data)
        if not math.isfinite(lowest):
            return None
        if k < 0:
            model.qpos0[z] -= lowest
            shift = -lowest
        else:
            model.key_qpos[k, z] -= lowest
    return shift
