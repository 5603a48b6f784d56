"""Shared rotation helpers against independent matrix arithmetic."""

from __future__ import annotations

import mujoco
import numpy as np

from robotwright._rotations import (
    compose_pose,
    mat_to_quat,
    mul_quat,
    quat_angle,
    quat_angles,
    quat_to_mat,
)


def _random_unit_quat(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def test_compose_pose_matches_homogeneous_transforms() -> None:
    rng = np.random.default_rng(3)
    for _ in range(50):
        qa, qb = _random_unit_quat(rng), _random_unit_quat(rng)
        pa, pb = rng.normal(size=3), rng.normal(size=3)
        pos, quat = compose_pose(pa, qa, pb, qb)
        ta, tb = np.eye(4), np.eye(4)
        ta[:3, :3], ta[:3, 3] = quat_to_mat(qa), pa
        tb[:3, :3], tb[:3, 3] = quat_to_mat(qb), pb
        expected = ta @ tb
        assert np.abs(pos - expected[:3, 3]).max() < 1e-12
        assert np.abs(quat_to_mat(quat) - expected[:3, :3]).max() < 1e-12
        assert np.abs(quat_to_mat(mul_quat(qa, qb)) - expected[:3, :3]).max() < 1e-12


def test_mat_to_quat_picks_nonnegative_w_and_round_trips() -> None:
    rng = np.random.default_rng(4)
    for _ in range(50):
        q = _random_unit_quat(rng)
        back = np.array(mat_to_quat(quat_to_mat(q)))
        assert back[0] >= 0.0
        assert np.abs(back - np.sign(q[0]) * q).max() < 1e-12


def _angle_by_mujoco(a: np.ndarray, b: np.ndarray) -> float:
    """The angle of conj(a) * b, from MuJoCo's own quaternion functions."""
    inv, rel = np.empty(4), np.empty(4)
    mujoco.mju_negQuat(inv, a)
    mujoco.mju_mulQuat(rel, inv, b)
    return 2.0 * float(np.arctan2(np.linalg.norm(rel[1:]), abs(rel[0])))


def test_quat_angles_is_quat_angle_row_by_row() -> None:
    rng = np.random.default_rng(5)
    a = np.array([_random_unit_quat(rng) for _ in range(40)])
    b = np.array([_random_unit_quat(rng) for _ in range(40)])
    b[:10] = a[:10]  # no rotation between them
    b[10:20] = -a[10:20]  # the same rotation, the other sign
    b[20:25] = [mul_quat(q, (np.cos(1e-7), np.sin(1e-7), 0.0, 0.0)) for q in a[20:25]]
    got = quat_angles(a, b)
    want = np.array([_angle_by_mujoco(x, y) for x, y in zip(a, b, strict=True)])
    assert np.abs(got - want).max() < 1e-12
    one_by_one = np.array([quat_angle(x, y) for x, y in zip(a, b, strict=True)])
    assert np.abs(one_by_one - want).max() < 1e-12
    assert got[:20].max() < 1e-12
    assert np.abs(got[20:25] - 2e-7).max() < 1e-15
