"""Round-trip fidelity: source -> HRDF -> our MJCF (and our URDF), compared with the
source compiled by MuJoCo, or with an independent URDF library when MuJoCo refuses it.

Used by ``robotwright roundtrip SOURCE`` and by the real-robot tests. Tolerances:

- MJCF path: masses and inertia tensors relative 1e-9, centres of mass 1e-9 m, joint
  axes and ranges 1e-9, forward kinematics of every body and site 1e-9 (m and rad) at
  ``configs`` random configurations (uniform inside joint ranges, [-pi, pi] for
  unlimited hinges, [-1, 1] m for unlimited slides, uniform rotations for ball/free).
- URDF path (our URDF loaded by MuJoCo): total mass and FK 1e-6.

Mimic joints are set from the joint they follow (``offset + multiplier * q``) in both
models, since forward kinematics does not apply equality constraints.
"""

from __future__ import annotations

import functools
import os
import tempfile
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from robotwright._paths import trusted_asset_roots
from robotwright.errors import ConversionError, InputFileError, Problem
from robotwright.hrdf.model import HRDF
from robotwright.parsers import inertia as inr
from robotwright.parsers.reference import (
    JointInfo,
    RobotView,
    body_name,
    compile_urdf,
    mimic_map,
    urdf_for_mujoco,
    urdf_yourdfpy_view,
    view_from_model,
)
from robotwright.parsers.report import ParseResult
from robotwright.parsers.xacro import is_xacro, xacro_as_urdf

TOL_EXACT = 1e-9
TOL_URDF = 1e-6
#: A body's mass or inertia below FLOOR times the robot's largest is compared relative to
#: that instead of to itself (the absolute floor of the relative tolerances).
FLOOR = 1e-6


@dataclass
class Row:
    """One line of the fidelity table."""

    check: str
    value: str
    ok: bool
    note: str = ""
    #: How many items the row compared (None: a measurement, always applicable). A row
    #: that compared nothing (0 of 0 sensors) is shown as "n/a", not counted as passed.
    compared: int | None = None

    @property
    def applicable(self) -> bool:
        return self.compared != 0


@dataclass
class RoundTripReport:
    """The fidelity table of one robot."""

    source: str
    reference: str
    rows: list[Row] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    error: str | None = None
    #: The parser's refusal of the input itself (a missing mesh, a bad value, a lost one
    #: under ``strict``), also summed up in ``error``: the command line reports it as bad
    #: input (exit 2), as ``convert`` does.
    input_error: ConversionError | None = field(default=None, repr=False)
    #: The parse of the source the table is about (None when it failed): a caller that
    #: needs the robot too reads it here instead of parsing the file again. Meshes the
    #: parse staged stay only when ``roundtrip`` was given a ``work_dir``.
    parse: ParseResult | None = field(default=None, repr=False)
    #: MuJoCo's compile of our MJCF of that robot (None when not written or refused).
    mjcf_model: mujoco.MjModel | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        return self.error is None and all(r.ok for r in self.rows)

    def failures(self) -> list[Row]:
        return [r for r in self.rows if not r.ok]

    def passed(self) -> list[Row]:
        """Rows that compared something and agree (``n/a`` rows are not passed checks)."""
        return [r for r in self.rows if r.ok and r.applicable]

    def table(self) -> str:
        lines = [f"source:    {self.source}", f"reference: {self.reference}"]
        if self.error:
            lines.append(f"ERROR: {self.error}")
        width = max((len(r.check) for r in self.rows), default=10)
        for r in self.rows:
            mark = "FAIL" if not r.ok else ("ok  " if r.applicable else "n/a ")
            note = f"  ({r.note})" if r.note else ""
            lines.append(f"  {mark} {r.check:<{width}}  {r.value}{note}")
        lines.append(f"warnings:  {len(self.warnings)}")
        lines.append("result:    " + ("PASS" if self.ok else "FAIL"))
        return "\n".join(lines)


def random_configs(
    view: RobotView, n: int, seed: int = 0, mimic: dict | None = None
) -> list[dict[str, Any]]:
    """``n`` random joint configurations of ``view`` (see the module docstring)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q: dict[str, Any] = {}
        for j in view.joints:
            if j.type in ("hinge", "slide"):
                if j.range is not None:
                    q[j.name] = float(rng.uniform(j.range[0], j.range[1]))
                else:
                    lim = np.pi if j.type == "hinge" else 1.0
                    q[j.name] = float(rng.uniform(-lim, lim))
            else:
                quat = rng.normal(size=4)
                quat /= np.linalg.norm(quat)
                q[j.name] = (
                    quat if j.type == "ball" else np.concatenate([rng.uniform(-1, 1, 3), quat])
                )
        for name, (src, mult, off) in (mimic or {}).items():
            if src in q and name in q:
                q[name] = off + mult * q[src]
        out.append(q)
    return out


def _rel(a: float, b: float, floor: float = 0.0) -> float:
    """Relative difference, relative to ``floor`` at least (the absolute floor)."""
    scale = max(abs(a), abs(b), floor)
    return 0.0 if scale == 0 else abs(a - b) / scale


def _compare_inertials(ref: RobotView, ours: RobotView, tol: float, label: str) -> list[Row]:
    """Rows for the mass, inertia and centre of mass of every body of ``ref`` (bodies
    merged into one of ours are combined first)."""
    rows: list[Row] = []
    # Inertials are compared in the frame of the body that holds them, each model at
    # its own zero configuration: the two may differ where a joint has a reference
    # position (our URDF has none), while body frames agree (the FK row checks them).
    ref_frames, our_frames0 = ref.fk({}), ours.fk({})
    # Group reference bodies by the body that holds them in ours (merged links).
    groups: dict[str, list[str]] = {}
    for b in ref.bodies:
        owner = b if b in ours.mass else ours.site_body.get(b)
        groups.setdefault(owner, []).append(b)
    worst_m = worst_i = worst_c = 0.0
    worst_i_body = ""
    # Absolute floors: a value below FLOOR of the robot's largest is compared to that
    # (a zero inertia that compiles to 6e-36 is zero; see the module docstring).
    m_floor = FLOOR * max((abs(v) for v in ref.mass.values()), default=0.0)
    i_floor = FLOOR * max(
        (float(np.abs(v[1]).max()) for v in ref.inertia_world.values()), default=0.0
    )
    for owner, members in groups.items():
        # Every part with mass or inertia: a massless link may carry inertia (MuJoCo
        # keeps it), and dropping it must show here.
        parts = [
            (ref.mass[m], ref.inertia_world[m][0], ref.inertia_world[m][1])
            for m in members
            if ref.mass[m] > 0 or np.any(ref.inertia_world[m][1])
        ]
        m_ref, c_ref, i_ref = inr.combine(parts) if parts else (0.0, np.zeros(3), np.zeros((3, 3)))
        m_o = ours.mass[owner]
        c_o, i_o = ours.inertia_world[owner]
        if owner in ref_frames and owner in our_frames0:
            c_ref, i_ref = _in_frame(ref_frames[owner], c_ref, i_ref)
            c_o, i_o = _in_frame(our_frames0[owner], c_o, i_o)
        worst_m = max(worst_m, _rel(m_ref, m_o, m_floor))
        if m_ref > 0:
            worst_c = max(worst_c, float(np.abs(c_ref - c_o).max()))
        scale = max(np.abs(i_ref).max(), np.abs(i_o).max(), i_floor)
        if scale > 0:
            err = float(np.abs(i_ref - i_o).max() / scale)
            if err > worst_i:
                worst_i, worst_i_body = err, owner
    rows.append(Row("body masses max rel.err" + label, f"{worst_m:.1e}", worst_m <= tol))
    rows.append(
        Row(
            "inertia tensors max rel.err" + label,
            f"{worst_i:.1e}",
            worst_i <= tol,
            f"worst: {worst_i_body}" if worst_i > tol else "",
        )
    )
    rows.append(Row("centres of mass max err (m)" + label, f"{worst_c:.1e}", worst_c <= tol))
    return rows


def compare_views(
    ref: RobotView,
    ours: RobotView,
    *,
    tol: float = TOL_EXACT,
    configs: int = 50,
    mimic: dict | None = None,
    full: bool = True,
    collision_only: bool = False,
    inertials_ref: RobotView | None = None,
    source_has_actuators: bool = True,
) -> list[Row]:
    """Rows comparing ``ours`` with ``ref``. ``full=False`` checks masses, inertias and
    centres of mass of every body and FK only (what a URDF can carry of an MJCF robot).
    ``source_has_actuators=False`` (a URDF): our actuators, if any, were made by the
    parser's ``actuators`` option, and are checked to drive joints of the source."""
    rows: list[Row] = []
    # Sets for membership: lists made these checks quadratic in bodies.
    our_bodies, our_sites = set(ours.bodies), set(ours.sites)
    ref_bodies, ref_sites = set(ref.bodies), set(ref.sites)
    our_frames = our_bodies | our_sites
    missing = [b for b in ref.bodies if b not in our_frames]
    as_sites = [b for b in ref.bodies if b not in our_bodies and b in our_sites]
    # URDF has no sites: our URDF carries each site as a massless link.
    extra = [b for b in ours.bodies if b not in ref_bodies and b not in ref_sites]
    site_links = [b for b in ours.bodies if b not in ref_bodies and b in ref_sites]
    note = f"{len(as_sites)} as sites" if as_sites else ""
    if site_links:
        # URDF has no sites: ours carries each as a massless link, so ours has more.
        note = f"{len(site_links)} site(s) as massless links: {site_links[:5]}"
    if missing or extra:
        note = f"missing {missing[:5]} extra {extra[:5]}"
    rows.append(
        Row(
            "bodies (ref/ours)",
            f"{len(ref.bodies)}/{len(ours.bodies)}",
            not missing and not extra,
            note,
        )
    )
    tm_ref, tm_ours = sum(ref.mass.values()), sum(ours.mass.values())
    # Links our URDF adds (dummy links, 1e-9 kg each) are in its total, not in its bodies:
    # their mass is the allowance (0.88 g robot, a few dummies: over 1e-6 relative).
    added = sum(v for k, v in ours.mass.items() if k not in our_bodies)
    tm_err = max(0.0, abs(tm_ref - tm_ours) - added) / max(abs(tm_ref), abs(tm_ours), 1e-300)
    rows.append(
        Row(
            "total mass (kg)",
            f"{tm_ref:.6g} rel.err {tm_err:.1e}",
            tm_err <= tol,
            f"{added:.1e} kg of links the URDF form adds allowed" if added else "",
        )
    )

    # The URDF leg compares inertials with our MJCF of the same HRDF (``inertials_ref``):
    # its links merged by fixed joints keep their own (massless) link, which the
    # source's bodies cannot be matched to one by one; the MJCF leg compares with the source.
    iref = inertials_ref if inertials_ref is not None else ref
    if all(b in our_frames for b in iref.bodies):
        label = "" if inertials_ref is None else " (vs our MJCF)"
        rows += _compare_inertials(iref, ours, tol, label)

    if full and not missing:
        ours_j = {j.name: j for j in ours.joints}
        bad_type, miss_j, worst_axis, worst_rng, bad_lim = [], [], 0.0, 0.0, []
        for j in ref.joints:
            o = ours_j.get(j.name)
            if o is None:
                miss_j.append(j.name)
                continue
            if o.type != j.type:
                bad_type.append(j.name)
                continue
            if j.type in ("hinge", "slide"):
                a1 = j.axis / np.linalg.norm(j.axis)
                a2 = o.axis / np.linalg.norm(o.axis)
                worst_axis = max(worst_axis, float(np.abs(a1 - a2).max()))
            if (j.range is None) != (o.range is None):
                bad_lim.append(j.name)
            elif j.range is not None:
                worst_rng = max(worst_rng, float(np.abs(np.subtract(j.range, o.range)).max()))
        rows.append(
            Row(
                "joints (ref/ours)",
                f"{len(ref.joints)}/{len(ours.joints)}",
                not miss_j and len(ref.joints) == len(ours.joints),
                f"missing {miss_j[:5]}" if miss_j else "",
            )
        )
        rows.append(
            Row("joint types equal", "yes" if not bad_type else f"no: {bad_type[:5]}", not bad_type)
        )
        rows.append(Row("joint axes max err", f"{worst_axis:.1e}", worst_axis <= tol))
        worst_dyn, no_dyn = 0.0, []
        for j in ref.joints:
            o = ours_j.get(j.name)
            if o is None or j.dynamics is None:
                continue
            if o.dynamics is None:
                no_dyn.append(j.name)
                continue
            scale = np.maximum(np.abs(j.dynamics), 1.0)
            worst_dyn = max(worst_dyn, float((np.abs(j.dynamics - o.dynamics) / scale).max()))
        if ref.kind == "mujoco":
            rows.append(
                Row(
                    "joint dynamics max err (armature, damping, frictionloss, stiffness, "
                    "springref, qpos0)",
                    f"{worst_dyn:.1e}",
                    worst_dyn <= tol and not no_dyn,
                )
            )
        rows.append(
            Row(
                "joint ranges max err",
                f"{worst_rng:.1e}" + (f", limited differs: {bad_lim[:5]}" if bad_lim else ""),
                worst_rng <= tol and not bad_lim,
            )
        )
        if ref.kind == "mujoco":
            if source_has_actuators or ref.actuators:
                rows.append(_compare_actuators(ref, ours, tol))
            else:
                rows.append(_made_actuators_row(ref, ours))
            missing_sites = [s for s in ref.sites if s not in our_sites]
            rows.append(
                Row(
                    "sites kept",
                    f"{len(ref.sites) - len(missing_sites)}/{len(ref.sites)}",
                    not missing_sites,
                    f"missing {missing_sites[:5]}" if missing_sites else "",
                    compared=len(ref.sites),
                )
            )
            same = ref.sensors == ours.sensors
            rows.append(
                Row(
                    "sensors equal (name, type, object)",
                    f"{len(ref.sensors)}/{len(ours.sensors)}",
                    same,
                    compared=max(len(ref.sensors), len(ours.sensors)),
                )
            )
            if ours.model is not None and ref.model is not None:
                rows.append(compare_geoms(ref, ours, tol, collision_only))
                rows.append(compare_extras(ref, ours, tol))

    # Forward kinematics.
    names = [b for b in ref.bodies if b in our_frames] + [s for s in ref.sites if s in our_frames]
    worst_p = worst_r = 0.0
    our_joints = {o.name for o in ours.joints}
    unknown = [j.name for j in ref.joints if j.name not in our_joints]
    for q in random_configs(ref, configs, mimic=mimic):
        a, b = ref.fk(q), ours.fk({k: v for k, v in q.items() if k not in unknown})
        present = [n for n in names if n in a]
        if not present:
            continue
        # One array operation per configuration (not one per frame): large robots.
        pa = np.array([a[n][0] for n in present])
        pb = np.array([b[n][0] for n in present])
        ra = np.array([a[n][1] for n in present])
        rb = np.array([b[n][1] for n in present])
        worst_p = max(worst_p, float(np.abs(pa - pb).max()))
        worst_r = max(worst_r, float(rotation_angles(ra, rb).max()))
    rows.append(
        Row(
            f"FK {len(names)} frames x {configs} configs (m / rad)",
            f"{worst_p:.1e} / {worst_r:.1e}",
            worst_p <= tol and worst_r <= tol and not unknown,
            f"joints unknown to ours: {unknown[:5]}" if unknown else "",
        )
    )
    return rows


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


def _made_actuators_row(ref: RobotView, ours: RobotView) -> Row:
    """The actuators of a robot whose source format has none (URDF): made by the parser's
    ``actuators`` option, so there is nothing to compare them with; each must drive a
    moving joint of the source, one actuator per joint."""
    moving = {j.name for j in ref.joints if j.type in ("hinge", "slide")}
    joints = [a["joint"] for a in ours.actuators]
    stray = [j or a["name"] for j, a in zip(joints, ours.actuators, strict=True) if j not in moving]
    twice = sorted({j for j in joints if j is not None and joints.count(j) > 1})
    note = "the source has none: made by --actuators" if joints else "the source has none"
    if stray:
        note += f"; not on a moving joint of the source: {stray[:5]}"
    if twice:
        note += f"; joints driven twice: {twice[:5]}"
    return Row(
        "actuators (made, each on a moving joint of the source)",
        f"0/{len(ours.actuators)}",
        not stray and not twice,
        note,
        compared=len(ours.actuators),
    )


def _compare_actuators(ref: RobotView, ours: RobotView, tol: float) -> Row:
    if len(ref.actuators) != len(ours.actuators):
        return Row(
            "actuators (order, type, transmission, dyn/gain/bias, ranges)",
            f"{len(ref.actuators)}/{len(ours.actuators)}",
            False,
            compared=max(len(ref.actuators), len(ours.actuators)),
        )
    bad = []
    for a, b in zip(ref.actuators, ours.actuators, strict=True):
        same = (
            a["name"] == b["name"]
            and a["type"] == b["type"]
            and a["joint"] == b["joint"]
            and a["kinds"] == b["kinds"]
        )
        for key in (
            "gear", "gainprm", "biasprm", "dynprm", "ctrlrange", "forcerange", "actrange",
        ):  # fmt: skip
            x, y = a[key], b[key]
            if (x is None) != (y is None):
                same = False
            elif x is not None:
                x, y = np.atleast_1d(x), np.atleast_1d(y)
                scale = max(float(np.abs(x).max()), 1e-300)
                same = same and float(np.abs(x - y).max()) <= tol * max(scale, 1.0)
        if not same:
            bad.append(a["name"] or a["joint"])
    return Row(
        "actuators (order, type, transmission, dyn/gain/bias, ranges)",
        f"{len(ref.actuators)}/{len(ours.actuators)}",
        not bad,
        f"differ: {bad[:5]}" if bad else "",
        compared=len(ref.actuators),
    )


# -- whole round trips ----------------------------------------------------------------------
def source_kind(path: Path) -> str:
    ext = path.suffix.lower()
    if ext in (".urdf", ".xacro"):
        return "urdf"
    if ext == ".xml" or ext == ".mjcf":
        return "mjcf"
    raise ValueError(f"{path}: expected a .urdf, .xacro or .xml (MJCF) file")


def parse_source(path: Path, strict: bool = False, **options: Any):
    """ParseResult of an MJCF or URDF file (by extension)."""
    from robotwright.parsers.api import mjcf_to_hrdf_with_warnings, urdf_to_hrdf_with_warnings

    if source_kind(path) == "urdf":
        return urdf_to_hrdf_with_warnings(path, strict=strict, **options)
    return mjcf_to_hrdf_with_warnings(path, strict=strict, **options)


def our_mjcf_text(hrdf: HRDF) -> str:
    """Our MJCF of ``hrdf`` as a string (no scene, mesh paths absolute)."""
    import warnings

    from robotwright.generators import MJCFHumanoidGenerator

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gen = MJCFHumanoidGenerator.from_hrdf(hrdf)
        return gen.export(None, relative_mesh_path=False, add_scene=False)


def our_mjcf_model(hrdf: HRDF) -> mujoco.MjModel:
    """Our MJCF of ``hrdf`` compiled by MuJoCo (no scene)."""
    return mujoco.MjSpec.from_string(our_mjcf_text(hrdf)).compile()


@dataclass
class OurURDF:
    """Our URDF of a robot, ready for MuJoCo's import (:func:`urdf_for_mujoco`), with the
    links the URDF form adds: dummy links (link -> the body it splits) and frame links
    (site -> its link)."""

    text: str
    dummy_links: dict[str, str]
    frame_links: dict[str, str]
    #: ball joint -> the x, y, z revolute joints our URDF writes for it.
    split_joints: dict[str, tuple[str, str, str]] = field(default_factory=dict)

    def view(self, model: mujoco.MjModel) -> RobotView:
        """View of ``model`` (this URDF compiled) without the links the URDF form adds:
        dummy links (their 1e-9 kg each stays in the total mass) and site links renamed
        because a body has the site's name (the reference's FK of that name is the body).
        A ball joint is one joint of the view again: its FK takes the ball's quaternion
        and sets the three revolute joints that stand for it to the same rotation."""
        view = view_from_model(model)
        drop = set(self.dummy_links)
        drop |= {link for site, link in self.frame_links.items() if link != site}
        view.bodies = [b for b in view.bodies if b not in drop]
        view.inertia_world = {k: v for k, v in view.inertia_world.items() if k not in drop}
        view.mass = {k: v for k, v in view.mass.items() if k not in drop or k in self.dummy_links}
        if self.split_joints:
            _join_split_balls(view, self.split_joints)
        return view


def xyz_angles(quat: np.ndarray) -> tuple[float, float, float]:
    """Angles ``(a, b, c)`` (rad) with ``Rx(a) Ry(b) Rz(c)`` the rotation of the unit
    quaternion ``quat`` (w, x, y, z): a rotation about x, then about the new y, then
    about the newest z, as the revolute joints standing for a ball joint turn."""
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, np.asarray(quat, dtype=float))
    r = mat.reshape(3, 3)
    b = float(np.arctan2(r[0, 2], np.hypot(r[0, 0], r[0, 1])))
    a = float(np.arctan2(-r[1, 2], r[2, 2]))
    c = float(np.arctan2(-r[0, 1], r[0, 0]))
    return a, b, c


def _join_split_balls(view: RobotView, split: dict[str, tuple[str, str, str]]) -> None:
    """Turn the revolute joints standing for each ball joint back into that ball joint
    of ``view`` (joints and FK)."""
    joints = {j.name: j for j in view.joints}
    parts = {n for names in split.values() for n in names}
    balls = {ball: names for ball, names in split.items() if all(n in joints for n in names)}
    kept = []
    for j in view.joints:
        ball = next((b for b, names in balls.items() if j.name == names[0]), None)
        if ball is not None:
            last = joints[balls[ball][2]]
            kept.append(JointInfo(ball, "ball", last.body, np.zeros(3), None))
        elif j.name not in parts:
            kept.append(j)
    view.joints = kept
    inner = view.fk

    def fk(q: dict[str, Any]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        q = dict(q)
        for ball, names in balls.items():
            if ball in q:
                q.update(zip(names, xyz_angles(q.pop(ball)), strict=True))
        return inner(q)  # type: ignore[operator]

    view.fk = fk


def our_urdf(hrdf: HRDF) -> OurURDF:
    """Our URDF of ``hrdf``, with mesh paths absolute (files of the robot, or of the
    parser's staging folder: keep the robot until MuJoCo has loaded the text)."""
    import warnings

    from robotwright.generators import URDFHumanoidGenerator

    gen = URDFHumanoidGenerator.from_hrdf(hrdf)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        root = gen.generate(relative_mesh_path=False)
    # The generated tree as is: the same document export writes, less its indentation.
    text = urdf_for_mujoco(Path(f"{hrdf.name}.urdf"), root=root)
    return OurURDF(text, dict(gen.dummy_links), dict(gen.frame_links), dict(gen.split_joints))


def our_urdf_model(hrdf: HRDF) -> mujoco.MjModel:
    """Our URDF of ``hrdf`` loaded by MuJoCo (every link kept, inertia from <inertial>)."""
    return compile_urdf(our_urdf(hrdf).text)


def our_urdf_view(hrdf: HRDF) -> RobotView:
    """View of our URDF in MuJoCo without the links the URDF form adds (see
    :meth:`OurURDF.view`)."""
    ours = our_urdf(hrdf)
    return ours.view(compile_urdf(ours.text))


def _check_reference(reference: str) -> None:
    if reference not in ("auto", "mujoco", "yourdfpy"):
        raise ValueError(f"reference={reference!r}: expected 'auto', 'mujoco' or 'yourdfpy'")


@dataclass
class ReferenceLoader:
    """The reference of a round trip, in steps: the text MuJoCo will import is prepared
    on construction (see :func:`reference_loader`); :meth:`load` does the import
    (MuJoCo's work, which may run on another thread: MuJoCo releases the interpreter
    while it parses and compiles) and raises ValueError when MuJoCo refuses the source;
    :meth:`instead` is the view to use then."""

    load: Callable[[], RobotView]
    #: For a URDF MuJoCo refuses, with ``reference="auto"``: yourdfpy's view (None: the
    #: refusal is the answer).
    fallback: Callable[[ValueError], RobotView] | None = None
    #: Starts the import in a confined reader now and returns the wait for its view
    #: (see :func:`robotwright._confine.start_confined`); None: :attr:`load` it is.
    start: Callable[[], Callable[[], RobotView]] | None = None

    def started(self) -> Callable[[], RobotView]:
        """The import, started now (before other threads run MuJoCo)."""
        return self.start() if self.start is not None else self.load

    def instead(self, exc: ValueError) -> RobotView:
        if self.fallback is None:
            raise exc
        return self.fallback(exc)

    def __call__(self) -> RobotView:
        try:
            return self.load()
        except ValueError as exc:
            return self.instead(exc)


def _yourdfpy_instead(path: Path, compiler: dict[str, Any], exc: ValueError) -> RobotView:
    view = urdf_yourdfpy_view(path, **compiler)
    view.kind = f"yourdfpy (MuJoCo refuses the source: {str(exc).splitlines()[0][:120]})"
    return view


def reference_loader(path: Path, reference: str = "auto", **options: Any) -> ReferenceLoader:
    """The reference of ``path`` (see :func:`reference_view`), prepared to be loaded."""
    _check_reference(reference)
    from robotwright._confine import start_confined
    from robotwright.parsers.packages import source_read_roots

    roots = source_read_roots(path, source_kind(path), options)
    if source_kind(path) == "mjcf":
        root = options.get("root_body")

        def start_mjcf() -> Callable[[], RobotView]:
            call = start_confined(_model_from_path, str(path), roots=roots, what=str(path))
            return lambda: view_from_model(call(), root=root)

        return ReferenceLoader(lambda: start_mjcf()(), start=start_mjcf)
    compiler = {
        k: options[k] for k in ("balance_inertia", "bound_mass", "bound_inertia") if k in options
    }
    if reference == "yourdfpy":
        return ReferenceLoader(lambda: urdf_yourdfpy_view(path, **compiler))
    fallback = (
        None if reference == "mujoco" else functools.partial(_yourdfpy_instead, path, compiler)
    )
    try:
        # The source's mesh paths under the parsers' containment rule (trusted folders:
        # the caller's asset_roots and those of an enclosing --asset-root).
        with trusted_asset_roots(options.get("asset_roots") or ()):
            text = urdf_for_mujoco(
                path,
                options.get("package_map"),
                inertia_from_geoms=options.get("inertia_from_geoms", "auto"),
                **compiler,
            )
    except ValueError as exc:
        if fallback is None:
            raise
        return ReferenceLoader(functools.partial(fallback, exc))  # yourdfpy's from the start
    density = options.get("density")  # of links without <inertial>, as the parser's

    def start_urdf() -> Callable[[], RobotView]:
        call = start_confined(compile_urdf, text, density, roots=roots, what=str(path))
        return lambda: view_from_model(call(), "mujoco")

    return ReferenceLoader(lambda: start_urdf()(), fallback, start=start_urdf)


def _model_from_path(path: str) -> mujoco.MjModel:
    """MuJoCo's compile of the MJCF file ``path`` (run confined)."""
    return mujoco.MjModel.from_xml_path(path)


def reference_view(path: Path, reference: str = "auto", **options: Any) -> RobotView:
    """The source as MuJoCo compiles it; for a URDF MuJoCo refuses (or with
    ``reference="yourdfpy"``), yourdfpy's view."""
    return reference_loader(path, reference, **options)()


def roundtrip(
    source: str | os.PathLike,
    *,
    configs: int = 50,
    urdf: bool = True,
    reference: str = "auto",
    **options: Any,
) -> RoundTripReport:
    """The fidelity table of one MJCF or URDF file (see the module docstring).

    ``reference``: ``"auto"`` (MuJoCo's import; yourdfpy for a URDF MuJoCo refuses),
    ``"mujoco"`` or ``"yourdfpy"`` (URDF only). ``options`` go to the parser. Staged
    meshes live in a temporary folder removed at the end (unless ``work_dir`` is given).

    Raises:
        ConversionError: the input itself is unusable (no such file, not a .urdf/.xml
            file, not well-formed or unsafe XML, ``configs`` < 1); later failures
            (parser, reference, compile) are reported in the table instead.
    """
    _check_input(Path(source), configs)
    if "work_dir" in options:
        return _roundtrip(Path(source), configs, urdf, reference, options)
    with tempfile.TemporaryDirectory(prefix="robotwright-rt-") as tmp:
        return _roundtrip(Path(source), configs, urdf, reference, {**options, "work_dir": tmp})


def _check_input(path: Path, configs: int) -> None:
    from robotwright._xmlsafe import parse_xml

    if configs < 1:
        raise ConversionError(
            [Problem(str(path), f"configs: expected at least 1 configuration, got {configs}")]
        )
    if path.suffix.lower() not in (".urdf", ".xml", ".mjcf", ".xacro"):
        raise ConversionError([Problem(str(path), "expected a .urdf, .xacro or .xml (MJCF) file")])
    if not path.is_file():
        what = (
            "is a folder"
            if path.is_dir()
            else "not a regular file"
            if path.exists()
            else "file not found"
        )
        raise ConversionError([Problem(str(path), f"{what}: expected a .urdf or .xml file")])
    parse_xml(path)  # not well-formed or unsafe XML: an input error, named with its line


def _roundtrip(
    path: Path, configs: int, urdf: bool, reference: str, options: dict[str, Any]
) -> RoundTripReport:
    # The three MuJoCo imports (the source, our MJCF, our URDF) run on threads as soon as
    # each text is ready, beside the Python work that writes the next one: on a large
    # robot they are most of the time, and MuJoCo releases the interpreter while it works.
    with ThreadPoolExecutor(max_workers=3) as pool:
        return _roundtrip_on(pool, path, configs, urdf, reference, options)


def _roundtrip_on(
    pool: ThreadPoolExecutor,
    path: Path,
    configs: int,
    urdf: bool,
    reference: str,
    options: dict[str, Any],
) -> RoundTripReport:
    report = RoundTripReport(str(path), "")
    try:
        # The parse reads the xacro itself (its messages name it); the references read
        # a URDF file: the expansion, written into work_dir.
        result = parse_source(path, **options)
        if is_xacro(path):
            path, options = xacro_as_urdf(path, options)
    except Exception as exc:  # the table reports any failure with its reason
        report.error = f"parse failed: {type(exc).__name__}: {exc}"
        if isinstance(exc, ConversionError):
            report.input_error = exc
        elif isinstance(exc, InputFileError):  # a file refused unread (over a size cap)
            report.input_error = ConversionError([Problem(exc.path, exc.reason)])
        return report
    report.warnings = [str(w) for w in result.warnings]
    report.parse = result
    mimic = mimic_map(path)
    try:
        mjcf_text = our_mjcf_text(result.hrdf)
    except Exception as exc:
        # Known before MuJoCo's import of the source starts: for a robot our MJCF cannot
        # hold (a chain deeper than MJCF allows) that import can take far longer than
        # this answer (MuJoCo 4.0 spends 20 s refusing a chain of 2,000 links).
        report.error = f"our MJCF is not written: {type(exc).__name__}: {exc}"
        from robotwright.errors import HRDFError

        if isinstance(exc, HRDFError):
            # The robot's own values are refused (non-physical inertias): bad input, exit
            # 2, as convert refuses it.
            report.input_error = ConversionError(
                exc.problems, summary=f"{path}: the robot is not a valid HRDF"
            )
        return report
    try:
        loader = reference_loader(
            path, reference, **{k: v for k, v in options.items() if k != "work_dir"}
        )
    except Exception as exc:
        report.error = f"no reference: {type(exc).__name__}: {exc}"
        return report
    # MuJoCo's import, started in its confined reader before the pool's threads run
    # MuJoCo; a fallback runs only if needed.
    ref_job = pool.submit(loader.started())
    mjcf_job = pool.submit(lambda: mujoco.MjSpec.from_string(mjcf_text).compile())
    ours_urdf: OurURDF | Exception | None = None
    urdf_job = None
    if urdf:
        try:
            ours_urdf = our_urdf(result.hrdf)
        except Exception as exc:  # reported in the URDF rows
            ours_urdf = exc
        else:
            urdf_job = pool.submit(compile_urdf, ours_urdf.text)
    try:
        try:
            ref = ref_job.result()
        except ValueError as exc:
            ref = loader.instead(exc)
    except Exception as exc:
        report.error = f"no reference: {type(exc).__name__}: {exc}"
        return report
    report.reference = ref.kind
    try:
        report.mjcf_model = mjcf_job.result()
        ours = view_from_model(report.mjcf_model)
    except Exception as exc:
        report.error = f"our MJCF does not compile: {type(exc).__name__}: {exc}"
        if ref.kind.startswith("yourdfpy (MuJoCo refuses"):
            # MuJoCo refuses the source too (non-physical inertias): bad input, exit 2.
            report.input_error = ConversionError(
                [Problem(str(path), f"MuJoCo refuses it: {str(exc).splitlines()[0]}")]
            )
        if "mass" in str(exc) and source_kind(path) == "urdf":
            report.error += (
                "\nhint: massless links; try --fixed-joints merge, or --bound-mass/--bound-inertia"
            )
        return report
    collision_only = source_kind(path) == "urdf"  # MuJoCo's URDF import drops visuals
    rows = compare_views(
        ref,
        ours,
        configs=configs,
        mimic=mimic,
        collision_only=collision_only,
        source_has_actuators=source_kind(path) != "urdf",
    )
    for r in rows:
        r.check = "MJCF: " + r.check
        report.rows.append(r)
    if not urdf:
        return report
    if isinstance(ours_urdf, ImportError):
        report.rows.append(Row("URDF: generator", "not available", False))
        return report
    try:
        if isinstance(ours_urdf, Exception):
            raise ours_urdf
        assert isinstance(ours_urdf, OurURDF) and urdf_job is not None
        ours_u = ours_urdf.view(urdf_job.result())
    except Exception as exc:
        # MuJoCo refusing our URDF for the reason it refuses the source (a non-physical
        # inertia the parser noted and kept) is the source's fault: nothing to compare.
        first = str(exc).splitlines()[0] if str(exc) else ""
        as_source = (
            bool(first) and ref.kind.startswith("yourdfpy (MuJoCo refuses") and (first in ref.kind)
        )
        report.rows.append(
            Row(
                "URDF: our URDF loads in MuJoCo",
                f"no: {type(exc).__name__}: {str(exc)[:200]}",
                as_source,
                "MuJoCo refuses the source for the same reason" if as_source else "",
                compared=0 if as_source else None,
            )
        )
        return report
    urdf_rows = compare_views(
        ref, ours_u, tol=TOL_URDF, configs=configs, mimic=mimic, full=False, inertials_ref=ours
    )
    for r in urdf_rows:
        r.check = "URDF: " + r.check
        report.rows.append(r)
    return report
