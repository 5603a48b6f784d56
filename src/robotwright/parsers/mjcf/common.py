"""What every part of the MJCF reader shares: its options (:class:`MJCFOptions`), MuJoCo's
defaults for telling a value that was set, and how numbers are written into the HRDF's
text cells."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from robotwright._names import shown
from robotwright.parsers import inertia as inr


@dataclass(frozen=True)
class MJCFOptions:
    """How an MJCF is turned into HRDF.

    Attributes:
        root_body: name of the top-level body that is the robot, when the world holds
            several top-level bodies (the others are dropped with a warning). ``None``:
            the only top-level body.
        work_dir: folder where meshes are staged (default: a new temp folder).
        massless_frames: ``"keep"`` (default) or ``"site"``: a massless leaf body without
            joints that nothing else names (a camera or tool frame) becomes a site on its
            parent named after it, its sites and (massless) geoms moved to the parent.
            HRDF checks require mass > 0 on every body, so ``"keep"`` leaves such a robot
            invalid (reported).
        join_obj_objects: convert an OBJ mesh split into several objects (``o``/``g``
            lines), of which MuJoCo reads the first only, into one mesh holding every
            object's triangles unchanged (each such mesh is reported; the robot then
            differs from the source as MuJoCo compiles it). Without it the loss is
            reported.
        asset_roots: folders outside the MJCF's folder that its files (meshes,
            textures, includes) may point into. By default every file must lie inside
            the MJCF's folder (see :mod:`robotwright._paths`).
    """

    root_body: str | None = None
    work_dir: Path | None = None
    massless_frames: str = "keep"
    join_obj_objects: bool = False
    asset_roots: tuple[str | os.PathLike, ...] = ()

    def __post_init__(self) -> None:
        if self.massless_frames not in ("keep", "site"):
            raise ValueError(
                f"massless_frames={shown(self.massless_frames)}: expected 'keep' or 'site'"
            )


_DEFAULT_MODEL = mujoco.MjModel.from_xml_string(
    '<mujoco><asset><material name="m"/></asset>'
    '<worldbody><body><joint/><geom size="1"/></body></worldbody></mujoco>'
)


def _differs(model: mujoco.MjModel, attr: str, i: int, j: int = 0) -> bool:
    if not hasattr(model, attr):  # fields of other MuJoCo versions
        return False
    return bool(np.any(getattr(model, attr)[i] != getattr(_DEFAULT_MODEL, attr)[j]))


def _user(values) -> tuple[float, ...]:
    """MuJoCo ``user`` data without its trailing zeros (``<size nuser_*>`` pads them)."""
    vals = [float(v) for v in values]
    while vals and vals[-1] == 0.0:
        vals.pop()
    return tuple(vals)


def _pair(v) -> tuple[float, float]:
    return (float(v[0]), float(v[1]))


def _five(v) -> tuple[float, float, float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]), float(v[3]), float(v[4]))


def _t3(v) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _t4(v) -> tuple[float, float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]), float(v[3]))


def _fmt(values) -> str:
    return " ".join(repr(float(v)) for v in np.atleast_1d(values))


def _reparent(
    model: mujoco.MjModel, b: int, pos, quat, frames: set[int]
) -> tuple[int, tuple[float, float, float], tuple[float, float, float, float]]:
    """(body id, pos, quat) of a pose on body ``b``, moved to its parent when ``b`` is a
    frame turned into a site."""
    if b not in frames:
        return b, _t3(pos), _t4(quat)
    rot = inr.quat_to_mat(model.body_quat[b])
    new_pos = model.body_pos[b] + rot @ np.asarray(pos, dtype=float)
    return int(model.body_parentid[b]), _t3(new_pos), inr.mul_quat(model.body_quat[b], quat)
