"""Rigid-body inertia: exact diagonalisation, frame changes and combination.

Frames: a full inertia tensor ``I`` (kg m^2, about the centre of mass) is expressed in
some frame ``F``; :func:`diagonalize` returns the principal moments and the orientation
of the principal frame in ``F`` as a quaternion (w, x, y, z) of a proper rotation, so
that ``R(q) @ diag(d) @ R(q).T == I`` to rounding.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

# mul_quat and rpy_to_quat are re-exported: the parsers call them as ``inertia.<name>``.
from robotwright._rotations import mat_to_quat, mul_quat, quat_to_mat, rpy_to_quat  # noqa: F401
from robotwright.hrdf.model import Quat, Vec3


def full_inertia(diag: Sequence[float], quat: Sequence[float]) -> np.ndarray:
    """Full tensor ``R diag R^T`` in the frame the principal frame ``quat`` is given in."""
    rot = quat_to_mat(quat)
    return rot @ np.diag(np.asarray(diag, dtype=float)) @ rot.T


def diagonalize(tensor: np.ndarray) -> tuple[Vec3, Quat]:
    """Principal moments and principal-frame orientation of a symmetric 3x3 tensor.

    The eigenvector matrix is made a proper rotation (determinant +1) so that it maps to
    a quaternion. Eigenvalues are returned as computed, except round-off around zero
    (below 16 eps times the largest) which is zero: a non-physical tensor (negative
    moment, triangle inequality violated) is not altered here; callers decide.
    """
    sym = 0.5 * (np.asarray(tensor, dtype=float) + np.asarray(tensor, dtype=float).T)
    # An already-diagonal tensor keeps identity orientation and its own order, so that
    # a round trip of a diagonal URDF inertia is bit-exact.
    off = np.abs(sym - np.diag(np.diag(sym))).max()
    if off == 0.0:
        d = np.diag(sym)
        return (float(d[0]), float(d[1]), float(d[2])), (1.0, 0.0, 0.0, 0.0)
    values, vectors = np.linalg.eigh(sym)
    # A zero moment (a rod, a point) comes out of eigh as +-1e-22 or so: round-off of the
    # size eps * |I|, which would read as a negative moment; it is zero.
    values[np.abs(values) <= 16 * np.finfo(float).eps * np.abs(values).max()] = 0.0
    if np.linalg.det(vectors) < 0:
        vectors[:, 2] = -vectors[:, 2]
    return (float(values[0]), float(values[1]), float(values[2])), mat_to_quat(vectors)


def is_physical(diag: Sequence[float], rtol: float = 1e-9) -> bool:
    """True when all moments are > 0 and satisfy the triangle inequality (A + B >= C)."""
    a, b, c = (float(v) for v in diag)
    if min(a, b, c) <= 0:
        return False
    return all(x + y >= z * (1.0 - rtol) for x, y, z in ((a, b, c), (b, c, a), (c, a, b)))


def balance(diag: Sequence[float]) -> Vec3:
    """MuJoCo's ``balanceinertia`` repair: when A + B < C for some ordering, all moments
    become their mean. Other tensors are returned unchanged."""
    a, b, c = (float(v) for v in diag)
    if all(x + y >= z for x, y, z in ((a, b, c), (b, c, a), (c, a, b))):
        return (a, b, c)
    mean = (a + b + c) / 3.0
    return (mean, mean, mean)


def combine(
    parts: Sequence[tuple[float, np.ndarray, np.ndarray]],
) -> tuple[float, np.ndarray, np.ndarray]:
    """Combine rigid parts given in one common frame.

    Each part is ``(mass, com, tensor)`` with ``com`` (m) and ``tensor`` (kg m^2, about
    that part's own centre of mass) expressed in the common frame. Returns the total
    mass, the combined centre of mass and the combined tensor about it (parallel-axis
    theorem), all in the common frame.
    """
    total = float(sum(m for m, _, _ in parts))
    if total <= 0:
        # Massless parts may still carry inertia (MuJoCo keeps it): no parallel-axis
        # term without mass, so the tensors add; the first part's centre is the centre.
        if not parts:
            return 0.0, np.zeros(3), np.zeros((3, 3))
        tensor = sum(np.asarray(t, dtype=float) for _, _, t in parts)
        return 0.0, np.asarray(parts[0][1], dtype=float), tensor
    com = sum(m * np.asarray(c, dtype=float) for m, c, _ in parts) / total
    tensor = np.zeros((3, 3))
    for m, c, t in parts:
        d = np.asarray(c, dtype=float) - com
        tensor += np.asarray(t, dtype=float) + m * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return total, com, tensor
