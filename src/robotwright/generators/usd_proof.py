"""The proof of a USD export: Newton's USD importer reads the file back, and every body
and joint is compared with MuJoCo's compile of our MJCF of the same robot.

Compared, by the names the robot gave its bodies and joints (a prim's ``displayName``
where the converter renamed the prim; each axis of a D6 joint Newton merged from
several prims is the joint of that prim): body masses, centres of mass and inertia
tensors (body frame, about the centre of mass), joint types and ranges, each hinge and
slide's drive against MuJoCo's compiled actuators (mode, stiffness, damping, max force;
the rated velocity against the HRDF's ``peak_velocity``; a joint without an actuator has
no drive), and forward kinematics: the world pose of every body at random joint
positions (within the joint ranges) and, for a free base, a random base pose. Each
difference is one line naming the body, joint or actuator, the field and both values.

Newton reads no shape the comparison does not need: no visual shape, no collision mesh's
hull, and no collision shape of a body whose mass, centre of mass and inertia the file
gives on the body (:func:`_leave_out_shapes_that_change_nothing`); so a change to a
shape is not seen here.

Needs Newton (Isaac Lab's environment).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from robotwright._rotations import quat_angles, quat_to_mat
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


# MuJoCo's enums as plain ints: a numpy integer read from a model is not ``in`` a tuple
# of enum members under every numpy and MuJoCo pairing we support.
_HINGE_SLIDE = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
_FREE = int(mujoco.mjtJoint.mjJNT_FREE)


def _rel(a: float, b: float) -> float:
    return abs(a - b) / max(1.0, abs(a), abs(b))


def _mj_inertia(model: mujoco.MjModel, b: int) -> np.ndarray:
    """Body ``b``'s inertia tensor about its centre of mass, in the body frame."""
    r = quat_to_mat(model.body_iquat[b])
    return r @ np.diag(model.body_inertia[b]) @ r.T


def _joint_dofs(model, found: dict, stage, names: dict[str, str]) -> dict[str, tuple[int, int]]:
    """Joint name -> (Newton joint, degree of freedom within it): a joint prim of its
    own, or one axis of a D6 joint Newton merged from several prims."""
    from robotwright._usd_names import joint_dof_prims, name_of

    where: dict[str, tuple[int, int]] = {}
    for i, prims in joint_dof_prims(found.get("path_joint_map", {}), stage).items():
        for k, path in enumerate(prims):
            where.setdefault(name_of(names, path), (i, k))
    for i, label in enumerate(model.joint_label):  # a floating base has no joint prim
        where.setdefault(name_of(names, label), (i, 0))
    return where


def _axis_in_child(model_axes, x_c, qd: int, k: int, i: int) -> np.ndarray:
    """Axis ``k`` of Newton joint ``i`` in its child body's frame."""
    x, y, z, w = (float(v) for v in x_c[i][3:])
    out = np.empty(3)
    mujoco.mju_rotVecQuat(out, model_axes[qd + k].astype(np.float64), np.array([w, x, y, z]))
    return out


def _by_axis(mj: mujoco.MjModel, model, where: dict[str, tuple[int, int]]) -> list[str]:
    """Match the joints Newton merged into one D6 joint to its axes by direction, in
    place: each MuJoCo joint gets the axis (of its kind) nearest its own, both in the
    child body's frame. Returns a line for each body whose hinges Newton turns in
    another order than MuJoCo (rotations do not commute: the body's pose differs)."""
    axes, x_c = model.joint_axis.numpy(), model.joint_X_c.numpy()
    dof_dim, qd_start = model.joint_dof_dim.numpy(), model.joint_qd_start.numpy()
    merged: dict[int, list[int]] = {}
    for j in range(mj.njnt):
        at = where.get(mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, j) or "")
        if at is not None and int(dof_dim[at[0]].sum()) > 1 and int(mj.jnt_type[j]) in _HINGE_SLIDE:
            merged.setdefault(at[0], []).append(j)
    out = []
    for i, joints in merged.items():
        lin = int(dof_dim[i][0])
        pools = {True: set(range(lin)), False: set(range(lin, int(dof_dim[i].sum())))}
        turns: list[tuple[int, str]] = []  # (Newton's axis, joint) of the hinges
        for j in joints:
            name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, j)
            slide = int(mj.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_SLIDE)
            pool = pools[slide]
            if not pool:
                continue
            own = np.asarray(mj.jnt_axis[j], dtype=np.float64)
            k = max(
                sorted(pool),
                key=lambda k: abs(float(_axis_in_child(axes, x_c, qd_start[i], k, i) @ own)),
            )
            pool.discard(k)
            where[name] = (i, k)
            if not slide:
                turns.append((k, name))
        if [n for _, n in sorted(turns)] != [n for _, n in turns]:
            body = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_BODY, int(mj.jnt_bodyid[joints[0]]))
            out.append(
                f"body {body!r}: Newton reads its hinges {', '.join(repr(n) for _, n in turns)} "
                f"as one D6 joint turning them in the order "
                f"{', '.join(repr(n) for _, n in sorted(turns))}; MuJoCo turns them in the "
                "order written, so the body's pose differs wherever two of them are not zero"
            )
    return out


def _same_kind(mj_type: int, newton_type: int, k: int, dof_dim: tuple[int, int], JT) -> bool:
    """Whether MuJoCo joint type ``mj_type`` is degree of freedom ``k`` of a Newton
    joint of ``newton_type`` (a D6's linear axes come first, then its angular ones)."""
    hinge, slide = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)
    if newton_type == int(JT.D6):
        return (mj_type == slide and k < dof_dim[0]) or (mj_type == hinge and k >= dof_dim[0])
    single = {
        hinge: int(JT.REVOLUTE),
        slide: int(JT.PRISMATIC),
        int(mujoco.mjtJoint.mjJNT_FREE): int(JT.FREE),
        int(mujoco.mjtJoint.mjJNT_BALL): int(JT.BALL),
    }
    return k == 0 and single.get(mj_type) == newton_type


def _mass_is_authored(prim) -> bool:
    """Whether USD's rules take the body's mass, centre of mass and inertia from its own
    ``MassAPI`` alone, its colliders adding nothing: a positive mass, a diagonal inertia
    that is not all zero, and a finite centre of mass (a fallback value of the schema
    means "not given", authored or not)."""
    from pxr import UsdPhysics

    api = UsdPhysics.MassAPI(prim)
    if not api:
        return False
    mass = api.GetMassAttr().Get()
    diag = api.GetDiagonalInertiaAttr().Get()
    com = api.GetCenterOfMassAttr().Get()
    if mass is None or diag is None or com is None:
        return False
    # As arrays: iterating a Gf vector is ten times slower (it ends on an IndexError).
    diag, com = np.array(diag, dtype=np.float64), np.array(com, dtype=np.float64)
    return bool(
        math.isfinite(mass)
        and mass > 0.0
        and diag.any()
        and np.isfinite(diag).all()
        and (diag >= 0.0).all()
        and np.isfinite(com).all()
    )


def _leave_out_shapes_that_change_nothing(stage) -> int:
    """Deactivate, in the stage's session layer (the file is not changed), each geometry
    prim whose body's mass is authored whole (:func:`_mass_is_authored`). Nothing the
    proof compares lies in such a shape: the body's mass, centre of mass and inertia are
    its ``MassAPI``'s, and bodies, joints, drives and poses are other prims. A body
    whose mass USD computes from its colliders keeps them, so Newton reads it as a
    simulator would. Returns the prims left out."""
    from pxr import Sdf, Usd, UsdGeom, UsdPhysics

    out: list = []
    it = iter(Usd.PrimRange(stage.GetPseudoRoot()))
    owner: dict = {}  # body prim path -> its mass is authored whole
    for prim in it:
        if prim.HasAPI(UsdPhysics.RigidBodyAPI):
            owner[prim.GetPath()] = _mass_is_authored(prim)
            continue
        if not prim.IsA(UsdGeom.Gprim):
            continue
        path = prim.GetPath().GetParentPath()  # bodies come before what is under them
        while path not in owner and path != Sdf.Path.absoluteRootPath:
            path = path.GetParentPath()
        # A shape is left out with everything under it, so only where nothing under it
        # is a body or a joint.
        if owner.get(path, False) and not any(
            p.HasAPI(UsdPhysics.RigidBodyAPI) or p.IsA(UsdPhysics.Joint)
            for p in Usd.PrimRange(prim)
        ):
            out.append(prim.GetPath())
            it.PruneChildren()
    layer = stage.GetSessionLayer()
    with Sdf.ChangeBlock():  # one recomposition for all, not one a prim
        for path in out:
            Sdf.CreatePrimInLayer(layer, path).active = False
    return len(out)


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

    Bodies and joints are matched by the names the robot gave them (a prim's
    ``displayName`` where the converter had to rename the prim); MuJoCo's several
    hinges or slides on one body are matched to the axes of the D6 joint Newton makes of
    them. Each hinge and slide joint's drive is compared with the one MuJoCo's
    actuators define (:func:`~robotwright.generators.usd_drives.joint_drives`): a joint
    no actuator drives must have none.

    Args:
        usd: the exported file.
        mjcf_model: MuJoCo's compile of our MJCF of the robot (no scene).
        hrdf: the robot, for the rated joint velocities (``peak_velocity``), which MJCF
            cannot hold (``None``: not compared).
        poses: random joint configurations compared by forward kinematics.
        tol: relative tolerance of masses/inertias and drives, absolute of positions
            [m] and angles [rad].
        seed: seed of the random poses.
    """
    from pxr import Usd

    from robotwright._usd_names import display_names, name_of
    from robotwright._warp import quiet_warp
    from robotwright.generators.usd_drives import joint_drives

    wp = quiet_warp()  # before Newton initialises warp
    import newton

    stage = Usd.Stage.Open(str(usd))
    names = display_names(stage)
    _leave_out_shapes_that_change_nothing(stage)
    builder = newton.ModelBuilder()
    # Nothing compared lies in a visual shape or a collision mesh's hull: Newton skips
    # reading and hulling them, which was most of the read on meshed robots (the G1:
    # 1.8 of 2.3 s).
    found = builder.add_usd(stage, load_visual_shapes=False, skip_mesh_approximation=True) or {}
    model = builder.finalize(device="cpu")
    proof = UsdProof()
    diff = proof.differences
    mj = mjcf_model

    # -- bodies ---------------------------------------------------------------------
    nb = {name_of(names, lb): i for i, lb in enumerate(model.body_label)}
    mass = model.body_mass.numpy()
    com = model.body_com.numpy()
    inertia = model.body_inertia.numpy()
    body_names = [mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(mj.nbody)]
    for b in range(1, mj.nbody):
        name = body_names[b]
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
    extra = sorted(set(nb) - set(body_names))
    for name in extra:
        diff.append(f"body {name!r}: in the USD, not in the MJCF")

    # -- joints ---------------------------------------------------------------------
    JT = newton.JointType
    where = _joint_dofs(model, found, stage, names)
    diff += _by_axis(mj, model, where)
    q_start = model.joint_q_start.numpy()
    qd_start = model.joint_qd_start.numpy()
    jtype = model.joint_type.numpy()
    dof_dim = model.joint_dof_dim.numpy()
    lower = model.joint_limit_lower.numpy()
    upper = model.joint_limit_upper.numpy()
    matched: dict[int, tuple[int, int]] = {}  # MuJoCo joint -> (q index, dof index)
    for j in range(mj.njnt):
        name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}"
        at = where.get(name)
        if at is None and int(mj.jnt_type[j]) == _FREE:
            free = [k for k in range(model.joint_count) if jtype[k] == int(JT.FREE)]
            at = (free[0], 0) if len(free) == 1 else None
        if at is None:
            diff.append(f"joint {name!r}: not in the USD")
            continue
        i, k = at
        proof.joints += 1
        dims = (int(dof_dim[i][0]), int(dof_dim[i][1]))
        if not _same_kind(int(mj.jnt_type[j]), int(jtype[i]), k, dims, JT):
            diff.append(
                f"joint {name!r}: type {mujoco.mjtJoint(int(mj.jnt_type[j])).name} in MJCF, "
                f"Newton {JT(int(jtype[i])).name} (axis {k}) in USD"
            )
            continue
        matched[j] = (int(q_start[i]) + k, int(qd_start[i]) + k)
        if int(mj.jnt_type[j]) in _HINGE_SLIDE:
            d = matched[j][1]
            if mj.jnt_limited[j]:
                lo, hi = mj.jnt_range[j]
                if abs(lo - lower[d]) > tol or abs(hi - upper[d]) > tol:
                    diff.append(
                        f"joint {name!r}: range [{lo:.9g}, {hi:.9g}] in MJCF, "
                        f"[{lower[d]:.9g}, {upper[d]:.9g}] in USD"
                    )

    # -- drives: every hinge and slide, against MuJoCo's actuators --------------------
    drives, _ = joint_drives(mj)  # what no drive holds is a note of the export
    rated = {a.joint: a.peak_velocity for a in (hrdf.actuators if hrdf is not None else ())}
    ke, kd = model.joint_target_ke.numpy(), model.joint_target_kd.numpy()
    effort, vel = model.joint_effort_limit.numpy(), model.joint_velocity_limit.numpy()
    mode = model.joint_target_mode.numpy() if model.joint_target_mode is not None else None
    modes = newton.JointTargetMode
    for j, (_, d) in matched.items():
        if int(mj.jnt_type[j]) not in _HINGE_SLIDE:
            continue
        name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}"
        got_mode = modes(int(mode[d])) if mode is not None else None
        want = drives.get(name)
        if want is None:
            if ke[d] != 0 or kd[d] != 0 or got_mode not in (None, modes.NONE):
                diff.append(
                    f"joint {name!r}: no actuator in MJCF, a drive in USD (stiffness "
                    f"{ke[d]:.9g}, damping {kd[d]:.9g}, mode {got_mode.name if got_mode else '?'})"
                )
            continue
        proof.drives += 1
        who = f"joint {name!r} ({' + '.join(want.kinds)} actuator {', '.join(map(repr, want.actuators))})"  # fmt: skip
        if want.stiffness:
            kinds = (modes.POSITION, modes.POSITION_VELOCITY)
        elif want.damping:
            kinds = (modes.VELOCITY,)
        else:
            kinds = (modes.EFFORT,)
        if got_mode is not None and got_mode not in kinds:
            diff.append(f"{who}: drive mode {got_mode.name} in USD, expected {kinds[0].name}")
        checks = {
            "stiffness": (want.stiffness, float(ke[d])),
            "damping": (want.damping, float(kd[d])),
            "max force": (want.max_force, float(effort[d])),
        }
        if rated.get(name) is not None:
            checks["velocity limit"] = (float(rated[name]), float(vel[d]))
        for key, (w, g) in checks.items():
            if math.isinf(w) and math.isinf(g):
                continue
            if _rel(w, g) > max(tol, 1e-6):
                diff.append(f"{who}: drive {key} {w:.9g} in MJCF, {g:.9g} in USD")

    # -- forward kinematics at random poses -----------------------------------------
    # Each pose is set and evaluated in turn (one joint-position array, filled in
    # place); the body poses are compared for all of them at once afterwards.
    rng = np.random.default_rng(seed)
    data = mujoco.MjData(mj)
    state = model.state()
    pairs = [(b, nb[n]) for b, n in enumerate(body_names) if b and n in nb]
    ours = np.array([b for b, _ in pairs], dtype=int)
    theirs = np.array([i for _, i in pairs], dtype=int)
    joint_q0 = model.joint_q.numpy()
    joint_q_in = wp.array(joint_q0, dtype=wp.float32, device="cpu")
    mj_pos, mj_quat, newton_q = [], [], []  # per pose: (bodies, 3), (bodies, 4), (bodies, 7)
    for _ in range(poses):
        qpos = mj.qpos0.copy()
        joint_q = joint_q0.copy()
        for j, (s, _) in matched.items():
            a = mj.jnt_qposadr[j]
            t = int(mj.jnt_type[j])
            if t == _FREE:
                pos = rng.uniform(-1.0, 1.0, 3)
                quat = rng.normal(size=4)
                quat /= np.linalg.norm(quat)  # w, x, y, z
                qpos[a : a + 7] = [*pos, *quat]
                joint_q[s : s + 7] = [*pos, quat[1], quat[2], quat[3], quat[0]]
            elif t in _HINGE_SLIDE:
                lo, hi = mj.jnt_range[j] if mj.jnt_limited[j] else (-math.pi, math.pi)
                v = rng.uniform(lo, hi)
                qpos[a] = v
                joint_q[s] = v
        data.qpos[:] = qpos
        mujoco.mj_kinematics(mj, data)
        joint_q_in.assign(joint_q.astype(np.float32))
        newton.eval_fk(model, joint_q_in, model.joint_qd, state)
        proof.poses += 1
        mj_pos.append(data.xpos[ours])  # indexing with an array copies
        mj_quat.append(data.xquat[ours])
        newton_q.append(state.body_q.numpy()[theirs])
    worst: dict[str, tuple[float, float, int]] = {}  # body -> (metres, radians, poses)
    if pairs and poses:
        body_q = np.stack(newton_q)  # (poses, bodies, 7): x, y, z, qx, qy, qz, qw
        err = np.abs(np.stack(mj_pos) - body_q[..., :3]).max(axis=2)
        ang = quat_angles(
            np.stack(mj_quat).reshape(-1, 4), body_q[..., [6, 3, 4, 5]].reshape(-1, 4)
        ).reshape(err.shape)
        proof.max_pose_error = float(err.max())
        off = (err > max(tol, 2e-6)) | (ang > max(tol, 2e-6))
        for k in np.flatnonzero(off.any(axis=0)):
            hit = off[:, k]
            worst[body_names[ours[k]]] = (
                float(err[hit, k].max()),
                float(ang[hit, k].max()),
                int(hit.sum()),
            )
    for name, (m, r, n) in worst.items():
        diff.append(
            f"body {name!r}: world pose differs by up to {m:.3g} m, {r:.3g} rad (at {n} of "
            f"{proof.poses} random configurations)"
        )
    return proof
