"""The proof of a USD export: Newton's USD importer reads the file back, and every body
and joint is compared with MuJoCo's compile of our MJCF of the same robot.

Compared, by body and joint name (the last element of Newton's prim-path labels): body
masses, centres of mass and inertia tensors (body frame, about the centre of mass), joint
types and ranges, drives (stiffness, damping, max force, velocity limit against the HRDF
actuators), and forward kinematics: the world pose of every body at random joint
positions (within the joint ranges) and, for a free base, a random base pose. Each
difference is one line naming the body or joint, the field and both values.

Needs Newton (Isaac Lab's environment).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from robotwright._rotations import quat_to_mat
from robotwright._usd_format import prim_name
from robotwright.hrdf.model import HRDF

__all__ = ["UsdProof", "prove_usd"]


@dataclass
class UsdProof:
    """The outcome of :func:`prove_usd`.

    Attributes:
        differences: one line per difference (empty: the USD is the robot).
        bodies: bodies compared.
        joints: joints compared.
        drives: drives compared.
        poses: random poses at which forward kinematics were compared.
        max_pose_error: the largest body position difference over those poses [m].
    """

    differences: list[str] = field(default_factory=list)
    bodies: int = 0
    joints: int = 0
    drives: int = 0
    poses: int = 0
    max_pose_error: float = 0.0


def _rel(a: float, b: float) -> float:
    return abs(a - b) / max(1.0, abs(a), abs(b))


def _mj_inertia(model: mujoco.MjModel, b: int) -> np.ndarray:
    """Body ``b``'s inertia tensor about its centre of mass, in the body frame."""
    r = quat_to_mat(model.body_iquat[b])
    return r @ np.diag(model.body_inertia[b]) @ r.T


def _quat_angle(wxyz_a: np.ndarray, wxyz_b: np.ndarray) -> float:
    """Angle [rad] of the rotation between two unit quaternions (atan2, not acos: exact
    near zero, where float32 poses live)."""
    inv, rel = np.empty(4), np.empty(4)
    mujoco.mju_negQuat(inv, np.asarray(wxyz_a, dtype=np.float64))
    mujoco.mju_mulQuat(rel, inv, np.asarray(wxyz_b, dtype=np.float64))
    return 2.0 * math.atan2(float(np.linalg.norm(rel[1:])), abs(float(rel[0])))


def prove_usd(
    usd: str | Path,
    mjcf_model: mujoco.MjModel,
    hrdf: HRDF | None = None,
    *,
    poses: int = 20,
    tol: float = 1e-6,
    seed: int = 0,
) -> UsdProof:
    """Compare the USD file ``usd`` (read by Newton) with ``mjcf_model``.

    Args:
        usd: the exported file.
        mjcf_model: MuJoCo's compile of our MJCF of the robot (no scene).
        hrdf: the robot, for the drives (``None``: drives are not compared).
        poses: random joint configurations compared by forward kinematics.
        tol: relative tolerance of masses/inertias, absolute of positions [m], angles [rad].
        seed: seed of the random poses.
    """
    from robotwright._warp import quiet_warp

    wp = quiet_warp()  # before Newton initialises warp
    import newton

    builder = newton.ModelBuilder()
    builder.add_usd(str(usd))
    model = builder.finalize(device="cpu")
    proof = UsdProof()
    diff = proof.differences
    mj = mjcf_model

    # -- bodies ---------------------------------------------------------------------
    nb = {prim_name(lb): i for i, lb in enumerate(model.body_label)}
    mass = model.body_mass.numpy()
    com = model.body_com.numpy()
    inertia = model.body_inertia.numpy()
    for b in range(1, mj.nbody):
        name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_BODY, b)
        i = nb.get(name)
        if i is None:
            diff.append(f"body {name!r}: not in the USD")
            continue
        proof.bodies += 1
        if _rel(float(mj.body_mass[b]), float(mass[i])) > tol:
            diff.append(f"body {name!r}: mass {mj.body_mass[b]:.9g} in MJCF, {mass[i]:.9g} in USD")
        if np.abs(mj.body_ipos[b] - com[i]).max() > tol:
            diff.append(f"body {name!r}: centre of mass {mj.body_ipos[b]} in MJCF, {com[i]} in USD")
        want = _mj_inertia(mj, b)
        scale = max(1.0, float(np.abs(want).max()))
        if np.abs(want - inertia[i]).max() / scale > tol:
            diff.append(
                f"body {name!r}: inertia tensor {want.round(9).tolist()} in MJCF, "
                f"{np.asarray(inertia[i]).round(9).tolist()} in USD"
            )
    extra = sorted(
        set(nb) - {mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(mj.nbody)}
    )
    for name in extra:
        diff.append(f"body {name!r}: in the USD, not in the MJCF")

    # -- joints ---------------------------------------------------------------------
    nj = {prim_name(lb): i for i, lb in enumerate(model.joint_label)}
    q_start = model.joint_q_start.numpy()
    qd_start = model.joint_qd_start.numpy()
    jtype = model.joint_type.numpy()
    lower = model.joint_limit_lower.numpy()
    upper = model.joint_limit_upper.numpy()
    kinds = {
        int(mujoco.mjtJoint.mjJNT_HINGE): int(newton.JointType.REVOLUTE),
        int(mujoco.mjtJoint.mjJNT_SLIDE): int(newton.JointType.PRISMATIC),
        int(mujoco.mjtJoint.mjJNT_FREE): int(newton.JointType.FREE),
        int(mujoco.mjtJoint.mjJNT_BALL): int(newton.JointType.BALL),
    }
    matched: dict[int, int] = {}
    for j in range(mj.njnt):
        name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}"
        i = nj.get(name)
        if i is None and mj.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            free = [k for k in range(model.joint_count) if jtype[k] == int(newton.JointType.FREE)]
            i = free[0] if len(free) == 1 else None
        if i is None:
            diff.append(f"joint {name!r}: not in the USD")
            continue
        proof.joints += 1
        matched[j] = i
        if kinds.get(int(mj.jnt_type[j])) != int(jtype[i]):
            diff.append(
                f"joint {name!r}: type {mj.jnt_type[j]} in MJCF, Newton type {jtype[i]} in USD"
            )
            continue
        if mj.jnt_type[j] in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            d = qd_start[i]
            if mj.jnt_limited[j]:
                lo, hi = mj.jnt_range[j]
                if abs(lo - lower[d]) > tol or abs(hi - upper[d]) > tol:
                    diff.append(
                        f"joint {name!r}: range [{lo:.9g}, {hi:.9g}] in MJCF, "
                        f"[{lower[d]:.9g}, {upper[d]:.9g}] in USD"
                    )

    # -- drives ---------------------------------------------------------------------
    if hrdf is not None:
        ke, kd = model.joint_target_ke.numpy(), model.joint_target_kd.numpy()
        effort, vel = model.joint_effort_limit.numpy(), model.joint_velocity_limit.numpy()
        for act in hrdf.actuators:
            i = nj.get(act.joint)
            if i is None:
                continue
            d = qd_start[i]
            proof.drives += 1
            want = {
                "stiffness": act.p_gain or 0.0,
                "damping": act.d_gain or 0.0,
                "max force": act.peak_torque
                if act.peak_torque is not None
                else (max(abs(v) for v in act.force_range) if act.force_range else math.inf),
                "velocity limit": act.peak_velocity,
            }
            got = {
                "stiffness": ke[d],
                "damping": kd[d],
                "max force": effort[d],
                "velocity limit": vel[d],
            }
            for key, w in want.items():
                if w is None or (math.isinf(w) and math.isinf(got[key])):
                    continue
                if _rel(float(w), float(got[key])) > max(tol, 1e-6):
                    diff.append(
                        f"joint {act.joint!r}: drive {key} {w:.9g} in HRDF, {got[key]:.9g} in USD"
                    )

    # -- forward kinematics at random poses -----------------------------------------
    rng = np.random.default_rng(seed)
    data = mujoco.MjData(mj)
    state = model.state()
    for _ in range(poses):
        qpos = mj.qpos0.copy()
        joint_q = model.joint_q.numpy().copy()
        for j, i in matched.items():
            a, s = mj.jnt_qposadr[j], q_start[i]
            t = mj.jnt_type[j]
            if t == mujoco.mjtJoint.mjJNT_FREE:
                pos = rng.uniform(-1.0, 1.0, 3)
                quat = rng.normal(size=4)
                quat /= np.linalg.norm(quat)  # w, x, y, z
                qpos[a : a + 7] = [*pos, *quat]
                joint_q[s : s + 7] = [*pos, quat[1], quat[2], quat[3], quat[0]]
            elif t in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
                lo, hi = mj.jnt_range[j] if mj.jnt_limited[j] else (-math.pi, math.pi)
                v = rng.uniform(lo, hi)
                qpos[a] = v
                joint_q[s] = v
        data.qpos[:] = qpos
        mujoco.mj_kinematics(mj, data)
        newton.eval_fk(
            model,
            wp.array(joint_q, dtype=wp.float32, device="cpu"),
            model.joint_qd,
            state,
        )
        body_q = state.body_q.numpy()
        proof.poses += 1
        for b in range(1, mj.nbody):
            name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_BODY, b)
            i = nb.get(name)
            if i is None:
                continue
            err = float(np.abs(data.xpos[b] - body_q[i][:3]).max())
            proof.max_pose_error = max(proof.max_pose_error, err)
            x, y, z, w = body_q[i][3:]
            ang = _quat_angle(data.xquat[b], np.array([w, x, y, z]))
            if err > max(tol, 2e-6) or ang > max(tol, 2e-6):
                diff.append(
                    f"body {name!r}: world pose differs by {err:.3g} m, {ang:.3g} rad at a "
                    "random configuration"
                )
                break
    return proof
