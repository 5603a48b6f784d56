"""Semantic checks of an HRDF model: tree shape, references, physics, files.

Each check yields :class:`~robotwright.errors.Problem` records naming the table file, the
row (0-based data row, as in the CSV), the column and what was expected. Nothing stops at
the first problem: callers get all of them.

Tolerances (documented in ``docs/hrdf.md``):
- quaternion norm: ``abs(|q| - 1) <= QUAT_NORM_TOL``;
- inertia triangle inequality: ``a + b >= c * (1 - INERTIA_TRIANGLE_RTOL)`` for every
  ordering of the principal moments.
"""

from __future__ import annotations

import math
import os
from collections import Counter
from collections.abc import Iterable, Sequence
from pathlib import Path

import defusedxml
import defusedxml.ElementTree as SafeET

from robotwright._assets import check_asset_file
from robotwright._limits import keyframes_problem
from robotwright._names import name_problem
from robotwright.errors import InputFileError, Problem, UnsafePathError
from robotwright.hrdf.model import (
    ACTUATOR_TYPES,
    EXTRA_MAX_DEPTH,
    EXTRA_SECTIONS,
    FRAME_OBJTYPES,
    HRDF,
    JOINT_TYPES,
    MESH_INERTIA_MODES,
    SENSOR_OBJTYPES,
    SIMPLE_GEOM_TYPES,
    SITE_TYPES,
    WORLD,
    MeshGeom,
)

QUAT_NORM_TOL = 1e-4
INERTIA_TRIANGLE_RTOL = 1e-9
AXIS_NORM_MIN = 1e-9
#: MuJoCo's smallest mass or principal inertia of a moving body (``mjMINVAL``).
MJ_MINVAL = 1e-15
#: The per-row checks below start with a quick pass over the row, written as exactly the
#: negation of every check that follows it, so that messages are built only for rows
#: with a problem. Tests turn it off to compare both ways on broken rows.
_QUICK_PASS = True
#: size values a simple geom type uses (the others are ignored); 3 for the rest.
_SIZE_USED = {"sphere": 1, "capsule": 2, "cylinder": 2}


def _quat_problem(q: Sequence[float]) -> str | None:
    norm = math.hypot(*q)
    if abs(norm - 1.0) > QUAT_NORM_TOL:
        return f"quaternion {tuple(q)} has norm {norm:.6g}: expected 1 (tolerance {QUAT_NORM_TOL})"
    return None


def _duplicates(names: Iterable[str | None]) -> set[str]:
    counts = Counter(n for n in names if n is not None)
    return {n for n, c in counts.items() if c > 1}


def _reversed_range(
    table: str, column: str, bounds: Sequence[float] | None, row: int
) -> list[Problem]:
    """The problem of a ``column`` range whose lower bound is above its upper one
    (MuJoCo refuses it), on its ``<column>0`` cell; none for a sound or absent range."""
    if bounds is not None and bounds[0] > bounds[1]:
        message = f"{column} lower {bounds[0]} > upper {bounds[1]}"
        return [Problem(table, message, row=row, column=f"{column}0")]
    return []


def _check_tree(hrdf: HRDF) -> list[Problem]:
    out: list[Problem] = []
    n = len(hrdf.bodies)
    if n == 0:
        return [Problem("body.csv", "no bodies: expected at least one (the root)")]
    roots = [i for i, b in enumerate(hrdf.bodies) if b.parent == -1]
    if not roots:
        out.append(
            Problem("meta.yaml", "no root body: expected one entry -1", column="body_parent_id")
        )
    elif len(roots) > 1:
        names = [hrdf.bodies[i].name for i in roots]
        out.append(
            Problem(
                "meta.yaml",
                f"several root bodies {names}: expected exactly one entry -1",
                column="body_parent_id",
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
            _QUICK_PASS
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
    root = hrdf.bodies[hrdf.root_index].name if any(b.parent == -1 for b in hrdf.bodies) else None
    for name in sorted(_duplicates(j.name for j in hrdf.joints)):
        out.append(Problem("joint.csv", f"duplicate joint name '{name}'", column="name"))
    row = -1
    for j in hrdf.joints:
        if j.type == "free":
            if j.body != root:
                out.append(
                    Problem(
                        "joint.csv",
                        f"free joint '{j.name}' on body '{j.body}': only the root body may float",
                        column="type",
                    )
                )
            continue
        row += 1
        # Quick pass: exactly the negation of every check below (see _check_bodies).
        ax, rng = j.axis, j.range
        if (
            _QUICK_PASS
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
        elif j.body == root and j.type != "free":
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
            _QUICK_PASS
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


def _mesh_file(hrdf: HRDF, mesh: MeshGeom) -> str:
    # Plain strings: this runs for every mesh row on every load.
    if mesh.file is None and hrdf.root_dir is not None:
        return f"{hrdf.root_dir}{os.sep}meshes{os.sep}{mesh.name}.{hrdf.meta.mesh_file_type}"
    return str(hrdf.mesh_path(mesh))


def _listing(folder: str, listings: dict[str, set[str]]) -> set[str]:
    """Names of the regular files in ``folder`` that are not symbolic links, listed once
    per check (meshes share a folder)."""
    names = listings.get(folder)
    if names is None:
        try:
            names = {e.name for e in os.scandir(folder) if e.is_file(follow_symlinks=False)}
        except OSError:
            names = set()
        listings[folder] = names
    return names


def _check_geoms(hrdf: HRDF, body_names: set[str], check_files: bool) -> list[Problem]:
    out: list[Problem] = []
    listings: dict[str, set[str]] = {}
    hypot = math.hypot
    for table, rows in (("mesh.csv", hrdf.meshes), ("simple_geom.csv", hrdf.simple_geoms)):
        for i, g in enumerate(rows):
            # Quick pass: exactly the negation of every check below (see _check_bodies).
            if (
                _QUICK_PASS
                and g.body in body_names
                and not abs(hypot(*g.quat) - 1.0) > QUAT_NORM_TOL
                and min(g.rgba) >= 0.0
                and max(g.rgba) <= 1.0
                and g.condim in (1, 3, 4, 6)
                and not g.static_friction < 0
            ):
                continue
            if g.body not in body_names:
                out.append(Problem(table, f"unknown body '{g.body}'", row=i, column="body_name"))
            msg = _quat_problem(g.quat)
            if msg:
                out.append(Problem(table, msg, row=i, column="quat"))
            if not (min(g.rgba) >= 0.0 and max(g.rgba) <= 1.0):
                out.append(
                    Problem(
                        table, f"rgba {g.rgba}: expected values in [0, 1]", row=i, column="rgba"
                    )
                )
            if g.condim not in (1, 3, 4, 6):
                out.append(
                    Problem(
                        table, f"condim {g.condim}: expected 1, 3, 4 or 6", row=i, column="condim"
                    )
                )
            if g.static_friction < 0:
                out.append(
                    Problem(
                        table, "static_friction: expected >= 0", row=i, column="static_friction"
                    )
                )
    for i, g in enumerate(hrdf.simple_geoms):
        if g.type not in SIMPLE_GEOM_TYPES:
            out.append(
                Problem(
                    "simple_geom.csv",
                    f"geom type '{g.type}': expected one of {list(SIMPLE_GEOM_TYPES)}",
                    row=i,
                    column="type",
                )
            )
            continue
        used = _SIZE_USED.get(g.type, 3)
        if any(not v > 0 for v in g.size[:used]):
            out.append(
                Problem(
                    "simple_geom.csv",
                    f"{g.type} size {g.size}: expected the first {used} value(s) > 0",
                    row=i,
                    column="size0",
                )
            )
    for name in sorted(_duplicates(g.name for g in hrdf.simple_geoms)):
        out.append(Problem("simple_geom.csv", f"duplicate geom name '{name}'", column="name"))
    unit = (1.0, 1.0, 1.0)
    ext = hrdf.meta.mesh_file_type
    root = hrdf.root_dir
    # The folder of meshes/<name>.<ext> paths, when it is a plain folder of the robot (not
    # a link): its plain files need no containment check, only a listing.
    default_dir = None
    if root is not None and os.sep not in str(ext):
        candidate = f"{root}{os.sep}meshes"
        if not os.path.islink(candidate):
            default_dir = candidate
    for i, m in enumerate(hrdf.meshes):
        if not m.name:
            out.append(Problem("mesh.csv", "empty mesh name", row=i, column="name"))
            continue
        if m.scale != unit and any(not s > 0 for s in m.scale):
            out.append(
                Problem("mesh.csv", f"scale {m.scale}: expected > 0", row=i, column="scale0")
            )
        if m.inertia is not None and m.inertia not in MESH_INERTIA_MODES:
            out.append(
                Problem(
                    "mesh.csv",
                    f"inertia {m.inertia!r}: expected one of {list(MESH_INERTIA_MODES)} or empty",
                    row=i,
                    column="inertia",
                )
            )
        # A plain file listed in the robot's own meshes/ folder is inside and exists.
        if (
            _QUICK_PASS
            and default_dir is not None
            and m.file is None
            and os.sep not in m.name
            and f"{m.name}.{ext}" in _listing(default_dir, listings)
        ):
            if check_files:
                out += _too_large(f"{default_dir}{os.sep}{m.name}.{ext}", i, "name")
            continue
        column = "file" if m.file is not None else "name"
        if root is not None:
            try:
                source = hrdf.mesh_source(m)
            except UnsafePathError as exc:
                # a NUL cannot escape anything: it is simply not a path
                written = m.file if m.file is not None else m.name
                refused = "refused" if "\0" in written else "escapes the robot folder"
                out.append(
                    Problem(
                        "mesh.csv",
                        f"mesh file {refused}: {exc.reason}",
                        row=i,
                        column=column,
                    )
                )
                continue
            if check_files and not os.path.isfile(source):
                out.append(_missing(source, i, column))
            elif check_files:
                out += _too_large(source, i, column)
        elif check_files:
            path = _mesh_file(hrdf, m)
            if not os.path.isfile(path):
                out.append(_missing(path, i, column))
            else:
                out += _too_large(path, i, column)
    return out


def _missing(path: str | Path, row: int, column: str) -> Problem:
    why = "is not a regular file" if os.path.exists(path) else "does not exist"
    return Problem("mesh.csv", f"mesh file '{path}' {why}", row=row, column=column)


def _too_large(path: str | Path, row: int, column: str) -> list[Problem]:
    """The mesh size cap (``--max-mesh-mb``), checked with ``stat`` before MuJoCo or a
    mesh reader opens the file (see :mod:`robotwright._assets`)."""
    try:
        check_asset_file(path)
    except InputFileError as exc:
        return [Problem("mesh.csv", f"mesh file {exc}", row=row, column=column)]
    return []


def _check_sites_sensors(hrdf: HRDF, body_names: set[str]) -> list[Problem]:
    out: list[Problem] = []
    for name in sorted(_duplicates(s.name for s in hrdf.sites)):
        out.append(Problem("site.csv", f"duplicate site name '{name}'", column="name"))
    for i, s in enumerate(hrdf.sites):
        if s.body not in body_names and s.body != WORLD:
            out.append(
                Problem(
                    "site.csv",
                    f"unknown body '{s.body}': expected a body of body.csv, or '{WORLD}' for "
                    "a site fixed in the world",
                    row=i,
                    column="body_name",
                )
            )
        if s.type not in SITE_TYPES:
            out.append(
                Problem(
                    "site.csv",
                    f"site type '{s.type}': expected one of {list(SITE_TYPES)}",
                    row=i,
                    column="type",
                )
            )
        msg = _quat_problem(s.quat)
        if msg:
            out.append(Problem("site.csv", msg, row=i, column="quat"))
        used = _SIZE_USED.get(s.type, 3)
        if s.type in SITE_TYPES and any(not v > 0 for v in s.size[:used]):
            out.append(
                Problem(
                    "site.csv",
                    f"{s.type} size {s.size}: expected the first {used} value(s) > 0",
                    row=i,
                    column="size0",
                )
            )
    for name in sorted(_duplicates(s.name for s in hrdf.sensors)):
        out.append(Problem("sensor.csv", f"duplicate sensor name '{name}'", column="name"))
    targets = {
        "site": {s.name for s in hrdf.sites},
        "body": body_names,
        "xbody": body_names,
        "joint": {j.name for j in hrdf.joints if j.name},
        "actuator": {a.name for a in hrdf.actuators if a.name},
    }
    for i, s in enumerate(hrdf.sensors):
        # Type and object types become XML element and attribute names: vocabulary only.
        allowed = SENSOR_OBJTYPES.get(s.type)
        if allowed is None:
            out.append(
                Problem(
                    "sensor.csv",
                    f"sensor type {s.type!r}: expected an MJCF sensor element that reads one "
                    f"object, one of {sorted(SENSOR_OBJTYPES)}",
                    row=i,
                    column="type",
                )
            )
            continue
        if s.objtype not in allowed:
            out.append(
                Problem(
                    "sensor.csv",
                    f"objtype {s.objtype!r}: expected one of {list(allowed)} for a {s.type} sensor",
                    row=i,
                    column="objtype",
                )
            )
            continue
        if s.reftype is not None and s.reftype not in FRAME_OBJTYPES:
            out.append(
                Problem(
                    "sensor.csv",
                    f"reftype {s.reftype!r}: expected one of {list(FRAME_OBJTYPES)}",
                    row=i,
                    column="reftype",
                )
            )
        known = targets.get(s.objtype)
        if known is not None and s.objname not in known:
            out.append(
                Problem(
                    "sensor.csv",
                    f"sensor '{s.name}' reads unknown {s.objtype} '{s.objname}'",
                    row=i,
                    column="objname",
                )
            )
    return out


def _check_meta(hrdf: HRDF, body_names: set[str]) -> list[Problem]:
    out: list[Problem] = []
    for i, imu in enumerate(hrdf.meta.imu_config_list or []):
        if imu.body_name not in body_names:
            out.append(
                Problem(
                    "meta.yaml",
                    f"IMU on unknown body '{imu.body_name}'",
                    column=f"imu_config_list[{i}].body_name",
                )
            )
        msg = _quat_problem(imu.orientation)
        if msg:
            out.append(Problem("meta.yaml", msg, column=f"imu_config_list[{i}].orientation"))
    sim = hrdf.meta.simulator_config
    if sim is not None and sim.timestep is not None and not sim.timestep > 0:
        out.append(
            Problem(
                "meta.yaml",
                f"timestep {sim.timestep}: expected > 0",
                column="simulator_config.timestep",
            )
        )
    return out


def check_extra(text: str | None) -> list[Problem]:
    """Problems of an ``extra.xml`` fragment: safe, well-formed XML (no DTD or entities),
    a ``<mujoco>`` root holding only :data:`EXTRA_SECTIONS`, nested at most
    :data:`EXTRA_MAX_DEPTH` levels, naming no file (no ``<include>``, no ``file``
    attribute). Its elements are copied into generated MJCF, so nothing else may pass."""
    if not text or not text.strip():
        return []
    file = "extra.xml"
    try:
        root = SafeET.fromstring(text)
    except (defusedxml.DefusedXmlException, SafeET.ParseError) as exc:
        return [Problem(file, f"not safe, well-formed XML ({type(exc).__name__}): {exc}")]
    if root.tag != "mujoco":
        return [Problem(file, f"root element <{root.tag}>: expected <mujoco>")]
    out: list[Problem] = []
    for section in root:
        if section.tag not in EXTRA_SECTIONS:
            out.append(
                Problem(
                    file,
                    f"section not allowed here: expected one of {list(EXTRA_SECTIONS)}",
                    element=f"<{section.tag}>",
                )
            )
    stack = [(root, 1)]
    while stack:
        el, depth = stack.pop()
        if depth > EXTRA_MAX_DEPTH:
            out.append(
                Problem(
                    file,
                    f"elements nested deeper than {EXTRA_MAX_DEPTH} levels; refused",
                    element=f"<{el.tag}>",
                )
            )
            break
        if el.tag == "include" or any(a.startswith("file") for a in el.attrib):
            out.append(
                Problem(file, "names a file: not allowed in extra.xml", element=f"<{el.tag}>")
            )
        stack.extend((child, depth + 1) for child in el)
    keys = sum(1 for section in root.iter("keyframe") for el in section if el.tag == "key")
    nkey = max((_int_or_zero(el.get("nkey")) for el in root.iter("size")), default=0)
    problem = keyframes_problem(max(keys, nkey))
    if problem is not None:
        out.append(Problem(file, problem, element="<keyframe>"))
    return out


def _int_or_zero(text: str | None) -> int:
    try:
        return int(text or 0)
    except ValueError:
        return 0  # MuJoCo refuses the value itself when it compiles the model


def _check_finite(hrdf: HRDF, reported: set[tuple[str, int | None, str]]) -> list[Problem]:
    """Every number a table holds is finite, as the CSV reader requires of a folder: a
    robot built in memory (by a parser, in Python) would otherwise be saved as a folder
    that does not load. Cells of a field ``reported`` already (table, row, field) are
    left out."""
    from robotwright.hrdf.tables import TABLES
    from robotwright.hrdf.write import table_rows

    out: list[Problem] = []
    for stem, schema in TABLES.items():
        table = f"{stem}.csv"
        columns = [c for c in schema if c.kind in ("float", "floats")]
        scalars = [c.field for c in columns if c.size == 0 and c.kind == "float"]
        vectors = [c.field for c in columns if c.size or c.kind == "floats"]
        for row, record in enumerate(table_rows(hrdf, stem)):
            # Fast pass: a sum is finite exactly when every term is (or it overflowed,
            # which the cell-by-cell pass below then clears).
            total = sum(v for f in scalars if (v := getattr(record, f)) is not None)
            total += sum(sum(v) for f in vectors if (v := getattr(record, f)) is not None)
            if math.isfinite(total):
                continue
            for col in columns:
                value = getattr(record, col.field)
                if value is None or (table, row, col.field) in reported:
                    continue
                values = (value,) if col.size == 0 and col.kind == "float" else value
                headers = [col.csv] * len(values) if col.kind == "floats" else col.headers
                for header, v in zip(headers, values, strict=False):
                    if not math.isfinite(v):
                        message = f"expected a finite number, got '{v!r}'"
                        out.append(Problem(table, message, row=row, column=header))
    return out


def _check_names(hrdf: HRDF) -> list[Problem]:
    """Every name a table defines is one XML, CSV and terminals can hold (see
    :mod:`robotwright._names`): a name with a control character would be written into
    an MJCF or URDF that no reader accepts."""
    from robotwright.hrdf.write import table_rows

    out: list[Problem] = []
    for stem in ("body", "joint", "actuator", "mesh", "simple_geom", "site", "sensor"):
        for row, record in enumerate(table_rows(hrdf, stem)):
            for field in ("name", "geom_name"):
                value = getattr(record, field, None)
                # Fast pass: most names are short ASCII words.
                if not value or (value.isascii() and value.isprintable() and len(value) < 64):
                    continue
                problem = name_problem(value)
                if problem is not None:
                    out.append(
                        Problem(f"{stem}.csv", f"name {value!r} {problem}", row=row, column=field)
                    )
    return out


#: ``user`` data per table -> the ``mjcf_size`` key bounding its length.
_NUSER_OF = {
    "body": "nuser_body",
    "joint": "nuser_jnt",
    "mesh": "nuser_geom",
    "simple_geom": "nuser_geom",
    "site": "nuser_site",
    "actuator": "nuser_actuator",
    "sensor": "nuser_sensor",
}


def _check_physics_fields(hrdf: HRDF) -> list[Problem]:
    """The MuJoCo fields MJCF refuses or we refuse as for ``range``: joint
    ``actuatorfrcrange`` lower > upper, ``actuatorgravcomp`` other than 0/1, ``user``
    data longer than ``mjcf_size``'s ``nuser_*`` (MuJoCo: "user has more values than
    nuser")."""
    from robotwright.hrdf.write import table_rows

    out: list[Problem] = []
    for row, j in enumerate(table_rows(hrdf, "joint")):
        out += _reversed_range("joint.csv", "actuatorfrcrange", j.actuatorfrcrange, row)
        if j.actuatorgravcomp not in (0, 1):
            out.append(
                Problem(
                    "joint.csv",
                    f"actuatorgravcomp {j.actuatorgravcomp!r}: expected 0 or 1",
                    row=row,
                    column="actuatorgravcomp",
                )
            )
    sizes = hrdf.meta.mjcf_size
    for stem, key in _NUSER_OF.items():
        limit = sizes.get(key)
        if limit is None:
            continue
        for row, record in enumerate(table_rows(hrdf, stem)):
            if len(record.user) > limit:
                out.append(
                    Problem(
                        f"{stem}.csv",
                        f"user has {len(record.user)} values, more than meta.yaml "
                        f"mjcf_size.{key} = {limit}",
                        row=row,
                        column="user",
                    )
                )
    return out


def check_model(hrdf: HRDF, *, check_files: bool = True, finite: bool = True) -> list[Problem]:
    """All problems of an in-memory model (empty list when it is valid). ``finite=False``
    skips the check that every table number is finite (for records read from CSV,
    whose cells the reader checked)."""
    problems = _check_tree(hrdf)
    problems += _check_bodies(hrdf)
    body_names = {b.name for b in hrdf.bodies}
    problems += _check_joints(hrdf, body_names)
    problems += _check_actuators(hrdf)
    problems += _check_geoms(hrdf, body_names, check_files)
    problems += _check_sites_sensors(hrdf, body_names)
    problems += _check_meta(hrdf, body_names)
    problems += _check_physics_fields(hrdf)
    problems += _check_names(hrdf)
    problems += check_extra(hrdf.mjcf_extra)
    if finite:
        reported = {(p.file, p.row, p.column) for p in problems if p.column is not None}
        problems += _check_finite(hrdf, reported)
    return problems
