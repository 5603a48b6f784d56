"""What the page draws with: class colours, slider ranges of unlimited joints, which
bodies are robots, world boxes of geoms, and names made safe for Markdown."""

from __future__ import annotations

from typing import TYPE_CHECKING

import mujoco
import numpy as np

from robotwright.sensors.plot import CLASS_COLORS

if TYPE_CHECKING:
    pass


#: Slider range of a joint without limits: a full turn for a hinge [rad], +-1 m for a
#: slide. Only the slider's range; the model is not changed.
UNLIMITED_HINGE = (-np.pi, np.pi)

UNLIMITED_SLIDE = (-1.0, 1.0)

#: Joint types that get a slider (one coordinate each).
_SLIDER_JOINTS = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))


def class_color(class_id: int) -> tuple[int, int, int]:
    """RGB (0-255) of a semantic class id (the palette repeats after 9 classes)."""
    h = CLASS_COLORS[class_id % len(CLASS_COLORS)].lstrip("#")
    return (int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16))


def robot_bodies(model: mujoco.MjModel, *, roots_only: bool = False) -> np.ndarray:
    """Ids of the bodies of the robots: the subtrees hanging from the world whose
    joints are more than one free joint (an articulated robot, fixed or floating),
    not walls and furniture (no joint) nor loose props (one free joint).
    ``roots_only``: the subtrees' root bodies only."""
    free = int(mujoco.mjtJoint.mjJNT_FREE)
    root_of = np.asarray(model.body_rootid)
    roots = []
    for r in np.flatnonzero((np.arange(model.nbody) > 0) & (root_of == np.arange(model.nbody))):
        joints = np.flatnonzero(root_of[model.jnt_bodyid] == r)
        if len(joints) > 1 or (len(joints) == 1 and int(model.jnt_type[joints[0]]) != free):
            roots.append(r)
    roots_arr = np.array(roots, dtype=np.int64)
    if roots_only:
        return roots_arr
    return np.flatnonzero(np.isin(root_of, roots_arr))


def geom_box(
    model: mujoco.MjModel, data: mujoco.MjData, geoms: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World bounding box ``(lo, hi)`` [m] of ``geoms`` (their MuJoCo boxes ``geom_aabb``
    placed at their world poses; kinematics must be current)."""
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    points = []
    for g in geoms:
        centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
        rot = data.geom_xmat[g].reshape(3, 3)
        points.append((centre + signs * half) @ rot.T + data.geom_xpos[g])
    every = np.concatenate(points)
    return every.min(axis=0), every.max(axis=0)


def _md(text: str) -> str:
    """Escape Markdown's special characters in a name."""
    return "".join("\\" + c if c in "\\`*_{}[]()#+-.!|<>" else c for c in text)
