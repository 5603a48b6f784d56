"""The round trip's comparison of geoms (each matched to its counterpart by pose, size and
type, in the body's frame) and of the other elements: equalities, tendons, sensors,
keyframes and options."""

from __future__ import annotations

import mujoco
import numpy as np

from robotwright.parsers.reference import (
    RobotView,
    body_name,
)
from robotwright.proof.roundtrip.report import Row


def _in_frame(
    frame: tuple[np.ndarray, np.ndarray], com: np.ndarray, inertia: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A centre of mass and an inertia tensor (world) in the frame ``(pos, rot)``."""
    pos, rot = frame
    return rot.T @ (com - pos), rot.T @ inertia @ rot


def _geom_records(model: mujoco.MjModel, bodies: set[str], collision_only: bool) -> list:
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    names = [model.body(i).name or f"body_{i}" for i in range(model.nbody)]
    out = []
    for g in range(model.ngeom):
        b = names[int(model.geom_bodyid[g])]
        if b not in bodies:
            continue
        if collision_only and model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0:
            continue
        t = int(model.geom_type[g])
        verts = int(model.mesh_vertnum[model.geom_dataid[g]]) if t == 7 else 0
        # Only the size values the type uses (MuJoCo keeps unused ones as written).
        used = {2: 1, 3: 2, 5: 2, 7: 0}.get(t, 3)
        out.append(
            (
                t,
                verts,
                model.geom_size[g][:used].copy(),
                data.geom_xpos[g].copy(),
                data.geom_xmat[g].reshape(3, 3).copy(),
                model.geom(g).name,
                b,
            )
        )
    return out


def rotation_angles(r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """Rotation angle (rad) between each pair of rotation matrices (``(n, 3, 3)`` arrays);
    :func:`~robotwright.parsers.reference.quat_angle` for many pairs at once."""
    rel = np.einsum("nji,njk->nik", r1, r2)
    c = (np.trace(rel, axis1=1, axis2=2) - 1.0) / 2.0
    # acos loses precision near 1; the skew part keeps small angles exact
    skew = np.stack(
        [rel[:, 2, 1] - rel[:, 1, 2], rel[:, 0, 2] - rel[:, 2, 0], rel[:, 1, 0] - rel[:, 0, 1]],
        axis=1,
    )
    return np.arctan2(np.linalg.norm(skew, axis=1) / 2.0, c)


def _errors(rec: tuple, cands: list[tuple]) -> np.ndarray:
    """Size, position and orientation error of ``rec`` against each candidate record of
    the same type and vertex count (a sphere has no orientation to compare)."""
    size = np.abs(np.array([c[2] for c in cands]) - rec[2])
    err = np.maximum(
        size.max(axis=1, initial=0.0),
        np.abs(np.array([c[3] for c in cands]) - rec[3]).max(axis=1),
    )
    if rec[0] != 2:
        rots = np.array([c[4] for c in cands])
        err = np.maximum(err, rotation_angles(np.broadcast_to(rec[4], rots.shape), rots))
    return err


def compare_geoms(ref: RobotView, ours: RobotView, tol: float, collision_only: bool) -> Row:
    """Each reference geom matched to the closest of ours with the same type (and mesh
    vertex count): worst size, world position and orientation error at the zero pose.

    Matching looks first at a geom of the same name, then among ours on the same body,
    then among all of ours of that shape, so a robot of many links costs about linear
    time (geoms of one body are few)."""
    a = _geom_records(ref.model, set(ref.bodies), collision_only)
    b = _geom_records(ours.model, set(ours.bodies), collision_only)
    worst, unmatched = 0.0, 0
    taken = [False] * len(b)
    by_name = {rec[5]: k for k, rec in enumerate(b) if rec[5]}
    by_body: dict[tuple, list[int]] = {}
    by_shape: dict[tuple, list[int]] = {}
    for k, rec in enumerate(b):
        by_body.setdefault((rec[0], rec[1], rec[6]), []).append(k)
        by_shape.setdefault((rec[0], rec[1]), []).append(k)

    for rec in a:
        shape = (rec[0], rec[1])
        k = by_name.get(rec[5]) if rec[5] else None
        best_k = None
        if k is not None and not taken[k] and (b[k][0], b[k][1]) == shape:
            best_k = k
        else:
            # The same body's geoms first; all of that shape only when none there fits.
            best = np.inf
            for pool in (by_body.get((*shape, rec[6]), []), by_shape.get(shape, [])):
                free = [k for k in pool if not taken[k]]
                if free:
                    errs = _errors(rec, [b[k] for k in free])
                    i = int(np.argmin(errs))
                    if errs[i] < best:
                        best_k, best = free[i], float(errs[i])
                if best <= tol:
                    break
        if best_k is None:
            unmatched += 1
            continue
        taken[best_k] = True
        worst = max(worst, float(_errors(rec, [b[best_k]])[0]))
    kind = "collision geoms" if collision_only else "geoms"
    return Row(
        f"{kind} (type, size, pose at q0)",
        f"{len(a)}/{len(b)} max err {worst:.1e}"
        + (f", {unmatched} unmatched" if unmatched else ""),
        worst <= tol and unmatched == 0 and len(a) == len(b),
        compared=max(len(a), len(b)),
    )


def _equalities_in(view: RobotView) -> list[int]:
    """Indices of the view's model's equality constraints whose bodies, joints and sites
    are all on the robot's bodies (or the world); a tendon coupling counts as on it."""
    m = view.model
    keep = set(view.bodies)
    body_of = {
        mujoco.mjtObj.mjOBJ_BODY: lambda i: i,
        mujoco.mjtObj.mjOBJ_XBODY: lambda i: i,
        mujoco.mjtObj.mjOBJ_JOINT: lambda i: int(m.jnt_bodyid[i]),
        mujoco.mjtObj.mjOBJ_SITE: lambda i: int(m.site_bodyid[i]),
    }
    rows = []
    for i in range(m.neq):
        ot = int(m.eq_objtype[i])
        if ot == 0:  # MuJoCo leaves it unset for joint/tendon couplings
            ot = {2: mujoco.mjtObj.mjOBJ_JOINT, 3: mujoco.mjtObj.mjOBJ_TENDON}.get(
                int(m.eq_type[i]), mujoco.mjtObj.mjOBJ_BODY
            )
        to_body = body_of.get(ot)
        ids = [int(m.eq_obj1id[i]), int(m.eq_obj2id[i])]
        bodies = [] if to_body is None else [to_body(k) for k in ids if k >= 0]
        if all(b == 0 or body_name(m, b) in keep for b in bodies):
            rows.append(i)
    return rows


def compare_extras(ref: RobotView, ours: RobotView, tol: float) -> Row:
    """Equality constraints, tendons, contact excludes/pairs and keyframes of the compiled
    models: counts, equality data, tendon lengths at the zero pose, keyframe vectors."""
    m1, m2 = ref.model, ours.model
    problems = []
    # A robot taken out of a larger world (root_body) keeps only its own equalities: the
    # parsers drop the others with a note naming them.
    ref_eqs = _equalities_in(ref)
    counts1 = {"neq": len(ref_eqs)}
    for attr in ("neq", "ntendon", "nexclude", "npair", "nkey"):
        n1 = counts1.get(attr, getattr(m1, attr))
        if n1 != getattr(m2, attr):
            problems.append(f"{attr} {n1}/{getattr(m2, attr)}")
    if not problems:
        if ref_eqs:
            # Matched by (type, object names): importers order equalities differently.
            def eqs(m: mujoco.MjModel, rows: list[int]) -> dict:
                out = {}
                for i in rows:
                    ot = int(m.eq_objtype[i])
                    if ot == 0:  # MuJoCo leaves it unset for joint/tendon couplings
                        ot = {2: mujoco.mjtObj.mjOBJ_JOINT, 3: mujoco.mjtObj.mjOBJ_TENDON}.get(
                            int(m.eq_type[i]), mujoco.mjtObj.mjOBJ_BODY
                        )
                    key = (
                        int(m.eq_type[i]),
                        mujoco.mj_id2name(m, ot, int(m.eq_obj1id[i])),
                        mujoco.mj_id2name(m, ot, int(m.eq_obj2id[i])),
                    )
                    out[key] = m.eq_data[i]
                return out

            e1, e2 = eqs(m1, ref_eqs), eqs(m2, list(range(m2.neq)))
            if set(e1) != set(e2) or any(
                np.abs(e1[k] - e2[k]).max() > tol * max(1.0, np.abs(e1[k]).max()) for k in e1
            ):
                problems.append("equality constraints differ")
        if m1.ntendon:
            d1, d2 = mujoco.MjData(m1), mujoco.MjData(m2)
            mujoco.mj_fwdPosition(m1, d1)
            mujoco.mj_fwdPosition(m2, d2)
            if np.abs(d1.ten_length - d2.ten_length).max() > tol:
                problems.append("tendon lengths differ")
        if m1.ntendon:
            for field_name in sorted(dir(m1)):
                if not (field_name.startswith(("tendon_", "wrap_"))) or field_name.endswith(
                    ("adr", "num", "id", "treeid", "treenum", "objid")
                ):
                    continue
                x, y = getattr(m1, field_name), getattr(m2, field_name)
                if not (isinstance(x, np.ndarray) and x.size):
                    continue
                x, y = x.astype(float), np.asarray(y, dtype=float)
                if field_name == "tendon_range" and x.shape == y.shape:
                    # MuJoCo ignores the range of an unlimited tendon (the parser notes it).
                    x, y = x[m1.tendon_limited == 1], y[m1.tendon_limited == 1]
                    if not x.size:
                        continue
                if field_name in ("tendon_rgba", "tendon_width") and x.shape == y.shape:
                    # Drawing fields: MJCF has no such attribute on a fixed tendon.
                    spatial = m1.wrap_type[m1.tendon_adr] != mujoco.mjtWrap.mjWRAP_JOINT
                    x, y = x[spatial], y[spatial]
                    if not x.size:
                        continue
                scale = max(1.0, float(np.abs(x).max()))
                if x.shape != y.shape or np.abs(x - y).max() > tol * scale:
                    problems.append(f"{field_name} differs")
        if m1.npair:
            for field_name in ("pair_dim", "pair_friction", "pair_solref", "pair_solimp",
                               "pair_solreffriction", "pair_margin", "pair_gap"):  # fmt: skip
                x, y = getattr(m1, field_name), getattr(m2, field_name)
                if x.shape != y.shape or np.abs(x - y).max() > tol:
                    problems.append(f"{field_name} differs")
        if m1.nkey:
            # Per joint name: a robot taken out of a larger world has fewer qpos entries.
            def key_slices(m: mujoco.MjModel) -> dict[str, np.ndarray]:
                out = {}
                for j in range(m.njnt):
                    a = int(m.jnt_qposadr[j])
                    n = {0: 7, 1: 4}.get(int(m.jnt_type[j]), 1)
                    out[m.joint(j).name or f"joint_{j}"] = m.key_qpos[:, a : a + n]
                return out

            k1, k2 = key_slices(m1), key_slices(m2)
            if any(name not in k1 or np.abs(k1[name] - k2[name]).max() > tol for name in k2):
                problems.append("keyframe qpos differ")
        sig = lambda m: sorted(  # noqa: E731 - a tiny key function
            tuple(sorted((int(s) >> 16, int(s) & 0xFFFF))) for s in m.exclude_signature
        )
        names = lambda m, pairs: [(m.body(x).name, m.body(y).name) for x, y in pairs]  # noqa: E731
        if sorted(names(m1, sig(m1))) != sorted(names(m2, sig(m2))):
            problems.append("contact excludes differ")
    summary = f"eq {len(ref_eqs)}, tendons {m1.ntendon}, excludes {m1.nexclude}, pairs {m1.npair}, keys {m1.nkey}"
    counts = (len(ref_eqs), m1.ntendon, m1.nexclude, m1.npair, m1.nkey)
    return Row(
        "equality/tendon/contact/keyframe",
        summary,
        not problems,
        "; ".join(problems),
        compared=sum(counts) + len(problems),
    )
