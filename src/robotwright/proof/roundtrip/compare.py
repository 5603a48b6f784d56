"""Two views of one robot compared row by row: masses and inertias, joints, forward
kinematics in random configurations, actuators, geoms and the other elements."""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.parsers import inertia as inr
from robotwright.parsers.reference import (
    RobotView,
)
from robotwright.proof.roundtrip.geoms import (
    _in_frame,
    compare_extras,
    compare_geoms,
    rotation_angles,
)
from robotwright.proof.roundtrip.report import FLOOR, TOL_EXACT, Row


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
