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

import defusedxml
import defusedxml.ElementTree as SafeET

from robotwright._limits import keyframes_problem
from robotwright._names import name_problem, shown
from robotwright.errors import Problem
from robotwright.hrdf.model import (
    EXTRA_MAX_DEPTH,
    EXTRA_SECTIONS,
    HRDF,
)
from robotwright.hrdf.validate_common import (  # noqa: F401
    AXIS_NORM_MIN,
    INERTIA_TRIANGLE_RTOL,
    MJ_MINVAL,
    QUAT_NORM_TOL,
    _quat_problem,
    _reversed_range,
)
from robotwright.hrdf.validate_geoms import _check_geoms, _check_sites_sensors
from robotwright.hrdf.validate_tree import (
    _check_actuators,
    _check_bodies,
    _check_joints,
    _check_tree,
    moving_bodies_without_mass,  # noqa: F401
)


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
                        message = f"expected a finite number, got '{shown(v)}'"
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
                        Problem(
                            f"{stem}.csv", f"name {shown(value)} {problem}", row=row, column=field
                        )
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
                    f"actuatorgravcomp {shown(j.actuatorgravcomp)}: expected 0 or 1",
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
