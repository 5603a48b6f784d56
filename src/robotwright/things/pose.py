"""Pose helpers shared by Things placed in a parent frame (bodies, geoms, sites, ...)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np

from robotwright.things.attrs import Vector

POS = Vector(3)
QUAT = Vector(4, nonzero=True)


def axis_angle_quat(axis: Sequence[float], angle: float) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation by ``angle`` radians about ``axis``."""
    quat = np.zeros(4)
    mujoco.mju_axisAngle2Quat(quat, np.asarray(axis, dtype=float), float(angle))
    return quat


def euler_quat(euler: Sequence[float], seq: str = "xyz") -> np.ndarray:
    """Quaternion (w, x, y, z) of Euler angles in radians.

    ``seq`` follows MJCF ``eulerseq``: lower-case axes rotate with the frame (intrinsic),
    upper-case axes stay fixed (extrinsic).
    """
    quat = np.zeros(4)
    mujoco.mju_euler2Quat(quat, np.asarray(euler, dtype=float), seq)
    return quat


class PoseMixin:
    """``pos`` (m) and ``quat`` (w, x, y, z) in the parent frame, with move/rotate helpers."""

    pos: np.ndarray
    quat: np.ndarray

    def move(self, dx: float = 0.0, dy: float = 0.0, dz: float = 0.0) -> Any:
        """Translate by (dx, dy, dz) metres in the parent frame; returns self."""
        self.pos = self.pos + np.array([dx, dy, dz], dtype=float)
        return self

    def rotate(self, axis: Sequence[float], angle: float) -> Any:
        """Rotate by ``angle`` radians about ``axis`` given in the parent frame; returns self.

        Only the orientation changes; the position stays where it is.
        """
        out = np.zeros(4)
        mujoco.mju_mulQuat(out, axis_angle_quat(axis, angle), np.asarray(self.quat, dtype=float))
        mujoco.mju_normalize4(out)
        self.quat = out
        return self

    def set_euler(self, euler: Sequence[float], seq: str = "xyz") -> Any:
        """Set the orientation from Euler angles in radians (MJCF ``eulerseq`` rules)."""
        self.quat = euler_quat(euler, seq)
        return self
