"""Modified Denavit-Hartenberg kinematics (Craig's convention).

Frame ``i`` follows frame ``i-1`` by

    T(i-1 -> i) = RotX(alpha_{i-1}) . TransX(a_{i-1}) . RotZ(theta_i) . TransZ(d_i)

Joint ``i`` moves along/about the z axis of frame ``i``: a hinge adds ``q_i`` to
``theta_i``, a slide adds ``q_i`` to ``d_i``. Lengths in metres, angles in radians.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np


@dataclass(frozen=True)
class DHRow:
    """One row of a modified DH table (one joint, one DoF).

    Attributes:
        a: a_{i-1}, distance from z_{i-1} to z_i along x_{i-1} (m).
        alpha: alpha_{i-1}, angle from z_{i-1} to z_i about x_{i-1} (rad).
        d: d_i, distance from x_{i-1} to x_i along z_i (m); the slide offset.
        theta: theta_i, angle from x_{i-1} to x_i about z_i (rad); the hinge offset.
        type: ``"hinge"`` (q adds to theta) or ``"slide"`` (q adds to d).
        name: joint name, for display.
    """

    a: float
    alpha: float
    d: float
    theta: float = 0.0
    type: Literal["hinge", "slide"] = "hinge"
    name: str = ""

    def __post_init__(self) -> None:
        if self.type not in ("hinge", "slide"):
            raise ValueError(
                f"DHRow {self.name!r}: type must be 'hinge' or 'slide', got {self.type!r}"
            )
        for f in ("a", "alpha", "d", "theta"):
            if not math.isfinite(getattr(self, f)):
                raise ValueError(f"DHRow {self.name!r}: {f} must be finite")


def rot_x(angle: np.ndarray | float) -> np.ndarray:
    """Homogeneous rotation(s) about x, shape ``angle.shape + (4, 4)``."""
    a = np.asarray(angle, dtype=float)
    T = np.zeros(a.shape + (4, 4))
    c, s = np.cos(a), np.sin(a)
    T[..., 0, 0] = 1.0
    T[..., 1, 1], T[..., 1, 2], T[..., 2, 1], T[..., 2, 2] = c, -s, s, c
    T[..., 3, 3] = 1.0
    return T


def link_transform(
    a: float, alpha: float, d: np.ndarray | float, theta: np.ndarray | float
) -> np.ndarray:
    """``RotX(alpha) TransX(a) RotZ(theta) TransZ(d)``; ``d``/``theta`` may be arrays."""
    d = np.asarray(d, dtype=float)
    theta = np.asarray(theta, dtype=float)
    shape = np.broadcast(d, theta).shape
    ca, sa = np.cos(alpha), np.sin(alpha)
    ct, st = np.cos(theta), np.sin(theta)
    T = np.zeros(shape + (4, 4))
    T[..., 0, 0], T[..., 0, 1], T[..., 0, 2], T[..., 0, 3] = ct, -st, 0.0, a
    T[..., 1, 0], T[..., 1, 1], T[..., 1, 2], T[..., 1, 3] = st * ca, ct * ca, -sa, -sa * d
    T[..., 2, 0], T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = st * sa, ct * sa, ca, ca * d
    T[..., 3, 3] = 1.0
    return T


def fk_frames(rows: Sequence[DHRow], q: np.ndarray | Sequence[float]) -> np.ndarray:
    """Transforms of every frame 1..n in frame 0.

    Args:
        rows: the DH table, n rows.
        q: joint values, shape ``(n,)`` or batched ``(..., n)`` (rad or m).

    Returns:
        Array of shape ``(..., n, 4, 4)``.
    """
    q = np.asarray(q, dtype=float)
    n = len(rows)
    if q.shape[-1:] != (n,):
        raise ValueError(f"q has shape {q.shape}; expected (..., {n}) for {n} DH rows")
    batch = q.shape[:-1]
    if not batch:
        return _fk_frames_one(rows, q)
    out = np.empty(batch + (n, 4, 4))
    T = np.broadcast_to(np.eye(4), batch + (4, 4))
    for i, row in enumerate(rows):
        qi = q[..., i]
        if row.type == "hinge":
            A = link_transform(row.a, row.alpha, np.full(batch, row.d), row.theta + qi)
        else:
            A = link_transform(row.a, row.alpha, row.d + qi, np.full(batch, row.theta))
        T = T @ A
        out[..., i, :, :] = T
    return out


def _fk_frames_one(rows: Sequence[DHRow], q: np.ndarray) -> np.ndarray:
    """:func:`fk_frames` of one pose, row by row on Python floats: a design's build asks
    for one pose at a time, where the batched arrays' set-up costs more than the work."""
    out = np.empty((len(rows), 4, 4))
    T = np.eye(4)
    for i, row in enumerate(rows):
        qi = float(q[i])
        d, theta = (row.d, row.theta + qi) if row.type == "hinge" else (row.d + qi, row.theta)
        ca, sa = math.cos(row.alpha), math.sin(row.alpha)
        ct, st = math.cos(theta), math.sin(theta)
        A = np.array(
            [
                [ct, -st, 0.0, row.a],
                [st * ca, ct * ca, -sa, -sa * d],
                [st * sa, ct * sa, ca, ca * d],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
        T = T @ A
        out[i] = T
    return out


def fk(
    rows: Sequence[DHRow],
    q: np.ndarray | Sequence[float],
    tool: np.ndarray | None = None,
) -> np.ndarray:
    """Transform of the last frame (times ``tool`` when given) in frame 0.

    Args:
        rows: the DH table.
        q: joint values, ``(n,)`` or batched ``(..., n)``.
        tool: optional 4x4 transform from the last frame to a tool frame.

    Returns:
        ``(4, 4)``, or ``(..., 4, 4)`` for batched ``q``. With no rows, the identity
        (times ``tool``).
    """
    q = np.asarray(q, dtype=float)
    if len(rows) == 0:
        T = np.broadcast_to(np.eye(4), q.shape[:-1] + (4, 4)).copy()
    else:
        T = fk_frames(rows, q)[..., -1, :, :]
    if tool is not None:
        T = T @ np.asarray(tool, dtype=float)
    return T
