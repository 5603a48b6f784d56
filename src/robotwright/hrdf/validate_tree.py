"""The HRDF checks of the kinematic tree: one root and no loops, bodies (masses and
inertias MuJoCo accepts), joints and actuators."""

from __future__ import annotations

import math

from robotwright.errors import Problem
from robotwright.hrdf import validate_common
from robotwright.hrdf.model import (
    ACTUATOR_TYPES,
    HRDF,
    JOINT_TYPES,
)
from robotwright.hrdf.validate_common import (
    AXIS_NORM_MIN,
    INERTIA_TRIANGLE_RTOL,
    MJ_MINVAL,
    QUAT_NORM_TOL,
    _duplicates,
    _quat_problem,
    _reversed_range,
)


def _check_tree(hrdf: HRDF) -> list[Problem]:
    out: list[Problem] = []
    n = len(hrdf.bodies)
    if n == 0:
        return [Problem("body.csv", "no bodies: expected at least one (the root)")]
    roots = [i for i, b in enumerate(hrdf.bodies) if b.parent == -1]
    if not roots:
        out.append(
            Problem(
                "meta.yaml", "no root body: expected at least one entry -1", column="body_parent_id"
            )
        )
    bad_parent = False
    for i, b in enumerate(hrdf.bodies):
        if b.parent != -1 and not (0 <= b.parent < n):
            out.append(
                Problem(
                    "meta.yaml",
                    f"body '{b.name}' (id {i}) has parent id {b.parent}: expected -1 or 0..{n - 1}",
                    column="body_parent_id",
                )
            )
            bad_parent = True
        elif b.parent == i:
            out.append(
                Problem(
                    "meta.yaml",
                    f"body '{b.name}' (id {i}) is its own parent",
                    column="body_parent_id",
                )
            )
            bad_parent = True
    if bad_parent:
        return out
    reported: set[int] = set()
    parents = [b.parent for b in hrdf.bodies]
    # Bodies already known to reach the root: a walk that meets one stops there, so a
    # valid tree costs O(n) instead of O(n * depth). Walks into a cycle never add to it.
    rooted: set[int] = set()
    for start in range(n):
        seen: list[int] = []
        i = start
        while i != -1 and i not in rooted and i not in seen:
            seen.append(i)
            i = parents[i]
        if i == -1 or i in rooted:
            rooted.update(seen)
        else:
            cycle = seen[seen.index(i) :]
            if not reported.intersection(cycle):
                reported.update(cycle)
                names = [hrdf.bodies[k].name for k in cycle]
                out.append(
                    Problem(
                        "meta.yaml",
                        f"bodies {names} form a cycle: the body tree must be a tree",
                        column="body_parent_id",
                    )
                )
    return out


def _check_bodies(hrdf: HRDF) -> list[Problem]:
    out: list[Problem] = []
    for name in sorted(_duplicates(b.name for b in hrdf.bodies)):
        out.append(Problem("body.csv", f"duplicate body name '{name}'", column="name"))
    hypot = math.hypot
    k = 1.0 - INERTIA_TRIANGLE_RTOL
    moving = {j.body for j in hrdf.joints}
    for i, b in enumerate(hrdf.bodies):
        # Quick pass: exactly the negation of every check below, so the per-row messages
        # are built only for rows that have a problem (most loads have none).
        d = b.diag_inertia
        if (
            validate_common.QUICK_PASS
            and b.name
            and MJ_MINVAL <= b.mass < math.inf
            and not abs(hypot(*b.quat) - 1.0) > QUAT_NORM_TOL
            and not abs(hypot(*b.inertial_quat) - 1.0) > QUAT_NORM_TOL
            and len(d) == 3
            and MJ_MINVAL <= d[0] < math.inf
            and MJ_MINVAL <= d[1] < math.inf
            and MJ_MINVAL <= d[2] < math.inf
            and not d[0] + d[1] < d[2] * k
            and not d[1] + d[2] < d[0] * k
            and not d[2] + d[0] < d[1] * k
        ):
            continue
        if not b.name:
            out.append(Problem("body.csv", "empty body name", row=i, column="name"))
        if not 0 <= b.mass < math.inf:
            out.append(
                Problem(
                    "body.csv",
                    f"mass {b.mass} kg: expected a finite number >= 0",
                    row=i,
                    column="mass",
                )
            )
        for col, q in (("quat", b.quat), ("inertial_quat", b.inertial_quat)):
            msg = _quat_problem(q)
            if msg:
                out.append(Problem("body.csv", msg, row=i, column=col))
        d = b.diag_inertia
        if len(d) != 3 or any(not 0 <= v < math.inf for v in d):
            out.append(
                Problem(
                    "body.csv",
                    f"diag_inertia {d}: expected finite numbers, all >= 0",
                    row=i,
                    column="diag_inertia",
                )
            )
            continue
        for a, bb, c in ((d[0], d[1], d[2]), (d[1], d[2], d[0]), (d[2], d[0], d[1])):
            if a + bb < c * (1.0 - INERTIA_TRIANGLE_RTOL):
                out.append(
                    Problem(
                        "body.csv",
                        f"diag_inertia {d} violates the triangle inequality "
                        f"({a} + {bb} < {c}): not a physical rigid body",
                        row=i,
                        column="diag_inertia",
                    )
                )
                break
        if 0 <= b.mass < math.inf and b.name in moving and not _carries_mass(hrdf, i, moving):
            out.append(
                Problem(
                    "body.csv",
                    f"mass {b.mass} kg, diag_inertia {d}: a body with joints needs mass and "
                    f"every principal inertia >= {MJ_MINVAL}, or a child without joints "
                    "(welded to it) that has them, as MuJoCo requires",
                    row=i,
                    column="mass",
                )
            )
    return out


def _massive(b) -> bool:
    d = b.diag_inertia
    return b.mass >= MJ_MINVAL and len(d) == 3 and all(v >= MJ_MINVAL for v in d)


def moving_bodies_without_mass(hrdf: HRDF) -> list[str]:
    """Names of the bodies with joints that MuJoCo refuses: neither they nor a body
    welded to them has mass and principal inertias >= ``MJ_MINVAL``."""
    moving = {j.body for j in hrdf.joints}
    return [
        b.name
        for i, b in enumerate(hrdf.bodies)
        if b.name in moving and not _carries_mass(hrdf, i, moving)
    ]


def _carries_mass(hrdf: HRDF, index: int, moving: set[str]) -> bool:
    """MuJoCo's rule for a body with joints: it has mass and inertia itself, or one of
    the bodies welded to it (descendants reached without crossing a joint) has."""
    stack = [index]
    while stack:
        i = stack.pop()
        b = hrdf.bodies[i]
        if _massive(b):
            return True
        stack.extend(k for k, c in enumerate(hrdf.bodies) if c.parent == i and c.name not in moving)
    return False


def _check_joints(hrdf: HRDF, body_names: set[str]) -> list[Problem]:
    out: list[Problem] = []
    roots = {hrdf.bodies[i].name for i in hrdf.root_indices}
    for name in sorted(_duplicates(j.name for j in hrdf.joints)):
        out.append(Problem("joint.csv", f"duplicate joint name '{name}'", column="name"))
    row = -1
    for j in hrdf.joints:
        if j.type == "free":
            if j.body not in roots:
                out.append(
                    Problem(
                        "joint.csv",
                        f"free joint '{j.name}' on body '{j.body}': only a root body may float",
                        column="type",
                    )
                )
            continue
        row += 1
        # Quick pass: exactly the negation of every check below (see _check_bodies).
        ax, rng = j.axis, j.range
        if (
            validate_common.QUICK_PASS
            and j.name is not None
            and j.name != ""
            and j.type in JOINT_TYPES
            and j.body in body_names
            and (
                j.type not in ("hinge", "slide")
                or (
                    len(ax) == 3
                    and not math.sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]) < AXIS_NORM_MIN
                )
            )
            and (rng is None or not rng[0] > rng[1])
            and not j.armature < 0
            and not j.viscous_friction < 0
            and not j.static_friction < 0
            and not j.dynamic_friction < 0
            and not j.stiffness < 0
        ):
            continue
        if j.name is None or j.name == "":
            out.append(Problem("joint.csv", "empty joint name", row=row, column="name"))
        if j.type not in JOINT_TYPES:
            out.append(
                Problem(
                    "joint.csv",
                    f"joint type '{j.type}': expected one of {list(JOINT_TYPES)}",
                    row=row,
                    column="type",
                )
            )
        if j.body not in body_names:
            out.append(
                Problem("joint.csv", f"unknown body '{j.body}'", row=row, column="body_name")
            )
        elif j.body in roots and j.type != "free":
            pass  # a joint on the root is allowed (e.g. a slide rail base)
        if j.type in ("hinge", "slide"):
            norm = math.sqrt(sum(v * v for v in j.axis))
            if norm < AXIS_NORM_MIN:
                out.append(Problem("joint.csv", f"axis {j.axis} is zero", row=row, column="axis0"))
        out += _reversed_range("joint.csv", "range", j.range, row)
        for col in (
            "armature",
            "viscous_friction",
            "static_friction",
            "dynamic_friction",
            "stiffness",
        ):
            if getattr(j, col) < 0:
                out.append(
                    Problem(
                        "joint.csv", f"{col} {getattr(j, col)}: expected >= 0", row=row, column=col
                    )
                )
    return out


def _check_actuators(hrdf: HRDF) -> list[Problem]:
    out: list[Problem] = []
    joint_names = {j.name for j in hrdf.joints if j.name}
    for name in sorted(_duplicates(a.name for a in hrdf.actuators)):
        out.append(Problem("actuator.csv", f"duplicate actuator name '{name}'", column="name"))
    for i, a in enumerate(hrdf.actuators):
        # Quick pass: exactly the negation of every check below (see _check_bodies).
        cr, fr = a.ctrl_range, a.force_range
        if (
            validate_common.QUICK_PASS
            and a.joint in joint_names
            and a.type in ACTUATOR_TYPES
            and (a.peak_torque is None or not a.peak_torque <= 0)
            and (cr is None or not cr[0] > cr[1])
            and (fr is None or not fr[0] > fr[1])
            and not (a.type == "position" and a.p_gain is None)
            and not (a.type == "velocity" and a.d_gain is None)
        ):
            continue
        if a.joint not in joint_names:
            out.append(
                Problem("actuator.csv", f"unknown joint '{a.joint}'", row=i, column="joint_name")
            )
        if a.type not in ACTUATOR_TYPES:
            out.append(
                Problem(
                    "actuator.csv",
                    f"actuator type '{a.type}': expected one of {list(ACTUATOR_TYPES)}",
                    row=i,
                    column="type",
                )
            )
        if a.peak_torque is not None and a.peak_torque <= 0:
            out.append(
                Problem(
                    "actuator.csv",
                    f"peak_torque {a.peak_torque}: expected > 0",
                    row=i,
                    column="peak_torque",
                )
            )
        for col in ("ctrl_range", "force_range"):
            out += _reversed_range("actuator.csv", col, getattr(a, col), i)
        if a.type == "position" and a.p_gain is None:
            out.append(
                Problem(
                    "actuator.csv", "position actuator needs p_gain (kp)", row=i, column="p_gain"
                )
            )
        if a.type == "velocity" and a.d_gain is None:
            out.append(
                Problem(
                    "actuator.csv", "velocity actuator needs d_gain (kv)", row=i, column="d_gain"
                )
            )
    return out
