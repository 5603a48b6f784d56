"""Quaternion and rotation helpers shared by the subpackages, built on MuJoCo's own
functions. Quaternions are (w, x, y, z); angles in radians; positions in metres."""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np

Quat = tuple[float, float, float, float]

__all__ = [
    "compose_pose",
    "mat_to_quat",
    "mul_quat",
    "quat_angle",
    "quat_angles",
    "quat_to_mat",
    "rpy_to_quat",
]


def quat_to_mat(quat: Sequence[float]) -> np.ndarray:
    """3x3 rotation matrix of a (w, x, y, z) quaternion (normalised first)."""
    q = np.asarray(quat, dtype=float)
    q = q / np.linalg.norm(q)
    out = np.zeros(9)
    mujoco.mju_quat2Mat(out, q)
    return out.reshape(3, 3)


def mat_to_quat(mat: np.ndarray) -> Quat:
    """(w, x, y, z) quaternion of a proper 3x3 rotation matrix, with w >= 0 (one sign
    convention, so equal rotations give equal quaternions)."""
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(mat, dtype=float).reshape(9))
    if q[0] < 0:
        q = -q
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def rpy_to_quat(rpy: Sequence[float]) -> Quat:
    """Quaternion of URDF roll-pitch-yaw (rad): R = Rz(yaw) Ry(pitch) Rx(roll)."""
    q = np.zeros(4)
    mujoco.mju_euler2Quat(q, np.asarray(rpy, dtype=float), "XYZ")
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def mul_quat(a: Sequence[float], b: Sequence[float]) -> Quat:
    """Quaternion product ``a * b`` (rotation b then a, in a's frame)."""
    out = np.zeros(4)
    mujoco.mju_mulQuat(out, np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    return (float(out[0]), float(out[1]), float(out[2]), float(out[3]))


def compose_pose(
    pos_a: Sequence[float], quat_a: Sequence[float], pos_b: Sequence[float], quat_b: Sequence[float]
) -> tuple[np.ndarray, np.ndarray]:
    """Pose a then pose b (b given in a's frame): ``(pos_a + R(a) pos_b, quat_a * quat_b)``.

    ``quat_a`` must be a unit quaternion; the result quaternion is not renormalised.
    """
    pos = np.zeros(3)
    quat = np.zeros(4)
    mujoco.mju_mulPose(
        pos,
        quat,
        np.asarray(pos_a, dtype=float),
        np.asarray(quat_a, dtype=float),
        np.asarray(pos_b, dtype=float),
        np.asarray(quat_b, dtype=float),
    )
    return pos, quat


def quat_angle(a: Sequence[float], b: Sequence[float]) -> float:
    """Angle [rad] of the rotation between two unit quaternions (w, x, y, z): atan2, not
    acos, so that it is exact near zero, where float32 poses live."""
    return float(quat_angles(np.asarray(a)[None], np.asarray(b)[None])[0])


def quat_angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:func:`quat_angle` of each row pair of two ``(n, 4)`` arrays of unit quaternions
    (w, x, y, z) [rad], at once."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    # conj(a) * b: its real part is the dot product, its vector part aw bv - bw av - av x bv
    real = np.einsum("ni,ni->n", a, b)
    vec = a[:, :1] * b[:, 1:] - b[:, :1] * a[:, 1:] - np.cross(a[:, 1:], b[:, 1:])
    return 2.0 * np.arctan2(np.linalg.norm(vec, axis=1), np.abs(real))
