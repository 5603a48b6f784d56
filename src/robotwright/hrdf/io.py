"""Reading and writing HRDF folders (hurodes 0.1.9 folders and robotwright's extension).

Reading collects every problem of every file before raising one
:class:`~robotwright.errors.HRDFError`; writing goes to a temporary folder that is
renamed into place, so a failed save leaves nothing behind.
"""

from __future__ import annotations

import csv
import io
import math
import os
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from itertools import repeat
from pathlib import Path
from typing import Any

import yaml

from robotwright._atomic import atomic_dir, copy_mesh_file
from robotwright._inputs import (
    MAX_TABLE_BYTES,
    MAX_XML_BYTES,
    MAX_YAML_BYTES,
    load_yaml,
    read_text,
)
from robotwright._paths import resolve_inside, trusted_roots
from robotwright._progress import steps
from robotwright.errors import (
    HRDFError,
    InputFileError,
    OutputExistsError,
    Problem,
    UnsafePathError,
)
from robotwright.hrdf.model import (
    FORMAT_VERSION,
    GROUND_TYPES,
    HRDF,
    INTEGRATORS,
    Actuator,
    Body,
    BodyNameConfig,
    GroundConfig,
    ImuConfig,
    Joint,
    MeshGeom,
    Meta,
    Sensor,
    SimpleGeom,
    SimulatorConfig,
    Site,
)
from robotwright.hrdf.tables import (
    HURODES_TABLES,
    NO_DEFAULT,
    TABLES,
    CellError,
    Column,
    format_cell,
    parse_cell,
)

_RECORD_TYPES: dict[str, type] = {
    "body": Body,
    "joint": Joint,
    "actuator": Actuator,
    "mesh": MeshGeom,
    "simple_geom": SimpleGeom,
    "site": Site,
    "sensor": Sensor,
}

#: meta.yaml keys hurodes defines.
HURODES_META_KEYS: tuple[str, ...] = (
    "body_parent_id",
    "mesh_file_type",
    "simulator_config",
    "body_name_config",
    "imu_config_list",
    "motor_config_list",
)
#: meta.yaml keys robotwright adds.
EXTENSION_META_KEYS: tuple[str, ...] = (
    "format_version",
    "floating_base",
    "base_joint_name",
    "base_joint",
    "mjcf_size",
)
#: ``joint.csv`` columns that the root's free joint keeps in ``meta.yaml``'s
#: ``base_joint`` mapping (its dof and constraint properties; a free joint has no
#: anchor, axis, range or spring reference of its own).
BASE_JOINT_FIELDS: tuple[str, ...] = (
    "armature",
    "static_friction",
    "dynamic_friction",
    "viscous_friction",
    "stiffness",
    "margin",
    "actuatorgravcomp",
    "solreflimit",
    "solimplimit",
    "solreffriction",
    "solimpfriction",
    "user",
)
EXTRA_MJCF_FILE = "extra.xml"
JOINT_MAPPING_FILE = "joint_mapping.yaml"
#: Where hurodes' generators export a robot by default (``<folder>/exported/robot.xml``):
#: its own output, not robot data, so it is ignored without a warning.
HURODES_EXPORT_DIR = "exported"
_KNOWN_FILES = frozenset(
    {f"{stem}.csv" for stem in TABLES}
    | {"meta.yaml", "meshes", EXTRA_MJCF_FILE, JOINT_MAPPING_FILE, HURODES_EXPORT_DIR}
)


class HRDFWarning(UserWarning):
    """Something in an HRDF folder was not understood and is ignored (named in the message)."""


@dataclass
class _Table:
    """Rows of one CSV file after conversion.

    ``rows[i]`` holds the values of ``fields`` (in that order) or is ``None`` for a row
    with a problem (already reported).
    """

    fields: list[str]
    rows: list[tuple[Any, ...] | None]
    extra_columns: list[str]


def _split_plain(text: str) -> list[str] | None:
    """The lines of ``text`` when ``str.split`` cuts it into the cells ``csv.reader`` reads.

    Without quotes, carriage returns or NUL characters, ``csv.reader`` (excel dialect)
    splits exactly at every comma and newline, so splitting the text ourselves (several
    times faster) gives the same cells. Anything else, or an empty first line (csv reads
    it as ``[]``), returns ``None`` and the csv module reads the file.
    """
    if '"' in text or "\r" in text or "\0" in text:
        return None
    lines = text.split("\n")
    if not lines[0]:
        return None
    if not lines[-1]:
        lines.pop()  # the final newline
    return lines


def _flat_columns(lines: list[str], width: int) -> list[list[str]] | None:
    """Columns of data ``lines`` that all have ``width`` cells (else ``None``).

    When every line has the same number of commas, the cells of the joined text are
    row-major, so column ``j`` is every ``width``-th cell from ``j``: no per-row lists.
    """
    if width < 2 or not set(map(str.count, lines, repeat(","))) <= {width - 1}:
        return None
    flat = ",".join(lines).split(",") if lines else []
    return [flat[j::width] for j in range(width)]


def _csv_rows(text: str, fname: str, problems: list[Problem]) -> list[list[str]] | None:
    """The rows ``csv.reader`` reads from ``text``, or ``None`` after reporting (naming
    the file and line) what the csv module refuses: a cell longer than its field limit
    (131,072 characters)."""
    reader = csv.reader(io.StringIO(text))
    try:
        return list(reader)
    except csv.Error as exc:
        problems.append(Problem(fname, f"line {reader.line_num}: cannot read the CSV table: {exc}"))
        return None


def _folder_read(path: Path, read: Callable[[Path], Any], problems: list[Problem]) -> Any:
    """``read(path)`` for a file of the robot folder (``path.parent``), or ``None`` after
    reporting why it cannot be read: a symbolic link leading out of the folder, not a
    regular file (FIFO, device), over its size limit, not UTF-8 (see
    :mod:`robotwright._inputs`), not parseable YAML."""
    try:
        if os.path.islink(path):
            resolve_inside(path.name, base=path.parent, root=path.parent, trusted=())
        return read(path)
    except UnsafePathError as exc:
        problems.append(Problem(path.name, f"the file is a link out of the robot folder: {exc}"))
    except InputFileError as exc:
        problems.append(Problem(path.name, f"cannot read file: it {exc.reason}"))
    except OSError as exc:
        problems.append(Problem(path.name, f"cannot read file: {exc.strerror or exc}"))
    except yaml.YAMLError as exc:
        problems.append(Problem(path.name, f"cannot parse YAML: {exc}"))
    return None


def _folder_text(path: Path, limit: int, problems: list[Problem]) -> str | None:
    """The text of a file of the robot folder, at most ``limit`` bytes (see :func:`_folder_read`)."""
    return _folder_read(path, lambda p: read_text(p, limit), problems)


def _read_table(
    path: Path, schema: list[Column], problems: list[Problem], *, hurodes_format: bool
) -> _Table | None:
    fname = path.name
    text = _folder_text(path, MAX_TABLE_BYTES, problems)
    if text is None:
        return None
    lines = _split_plain(text)
    columns: list[list[str]] | None = None
    if lines is not None:
        header = lines[0].split(",")
        columns = _flat_columns(lines[1:], len(header))
        body_rows: Any = (line.split(",") for line in lines[1:])
    else:
        parsed = _csv_rows(text, fname, problems)
        if parsed is None:
            return None
        if not parsed:
            problems.append(Problem(fname, "file is empty: expected a header row"))
            return None
        header, body_rows = parsed[0], parsed[1:]
    header = [h.strip() for h in header]
    index = {h: i for i, h in enumerate(header)}
    known: set[str] = set()
    missing = False
    for col in schema:
        known.update(col.headers)
        present = [h in index for h in col.headers]
        if col.required and not all(present):
            for h in col.headers:
                if h not in index:
                    problems.append(Problem(fname, "required column is missing", column=h))
            missing = True
        elif any(present) and not all(present):
            absent = [h for h in col.headers if h not in index]
            problems.append(
                Problem(fname, f"vector columns incomplete: missing {absent}", column=col.csv)
            )
            missing = True
    extra = [h for h in header if h not in known]
    for h in extra:
        problems.append(Problem(fname, "unknown column, ignored", column=h, severity="warning"))
    if missing:
        return None

    def empty_ok_here(col: Column) -> bool:
        return col.empty_ok and not (hurodes_format and col.csv == "range")

    plan = [(col, [index[h] for h in col.headers]) for col in schema if col.headers[0] in index]
    absent = {col.field: col.default for col in schema if col.headers[0] not in index}
    if columns is not None:
        fast = _convert_table_fast(columns, plan, absent, empty_ok_here)
        if fast is not None:
            return _Table(fields=fast[0], rows=fast[1], extra_columns=extra)
    # Empty lines are skipped (an empty line is [] for csv, [""] for str.split).
    data = [cells for cells in body_rows if cells and (len(cells) > 1 or cells[0].strip())]
    if columns is None and data and all(len(cells) == len(header) for cells in data):
        fast = _convert_table_fast(
            [list(col) for col in zip(*data, strict=True)], plan, absent, empty_ok_here
        )
        if fast is not None:
            return _Table(fields=fast[0], rows=fast[1], extra_columns=extra)
    fields = [col.field for col in schema]
    rows: list[tuple[Any, ...] | None] = []
    for row_no, cells in enumerate(data):
        if len(cells) != len(header):
            problems.append(
                Problem(
                    fname,
                    f"row has {len(cells)} cells, header has {len(header)}",
                    row=row_no,
                )
            )
            rows.append(None)
            continue
        record: dict[str, Any] = {}
        ok = True
        for col in schema:
            if col.headers[0] not in index:
                record[col.field] = col.default
                continue
            texts = [cells[index[h]].strip() for h in col.headers]
            if all(t == "" for t in texts):
                if empty_ok_here(col):
                    record[col.field] = col.default
                    continue
                if col.default is NO_DEFAULT or col.required:
                    why = "empty cell: this column has no default"
                    if hurodes_format and col.csv == "range":
                        why = (
                            "empty joint range in a hurodes folder (hurodes would invent "
                            "+-3.14); give the range, or add format_version to meta.yaml "
                            "where empty means unlimited"
                        )
                    problems.append(Problem(fname, why, row=row_no, column=col.headers[0]))
                    ok = False
                    continue
                record[col.field] = col.default
                continue
            values = []
            for h, t in zip(col.headers, texts, strict=True):
                if t == "":
                    problems.append(
                        Problem(fname, "empty cell inside a vector", row=row_no, column=h)
                    )
                    ok = False
                    break
                try:
                    values.append(parse_cell(t, col.kind))
                except CellError as exc:
                    problems.append(Problem(fname, str(exc), row=row_no, column=h))
                    ok = False
                    break
            else:
                record[col.field] = values[0] if col.size == 0 else tuple(values)
        rows.append(tuple([record[f] for f in fields]) if ok else None)
    return _Table(fields=fields, rows=rows, extra_columns=extra)


def _floats_or_none(cells: list[str]) -> list[float | None]:
    return [None if t == "" else float(t) for t in cells]


def _convert_table_fast(
    columns: list[list[str]],
    plan: list[tuple[Column, list[int]]],
    absent: dict[str, Any],
    empty_ok_here: Any,
) -> tuple[list[str], list[tuple[Any, ...]]] | None:
    """Convert the cell columns of a rectangular table into (fields, row tuples).

    ``None`` sends the table to the checking path: any unusual cell (empty where not
    allowed, non-numeric, non-finite, padded) is reported precisely there.
    """
    n = len(columns[0]) if columns else 0
    fields_: list[str] = []
    values: list[list[Any]] = []
    isfinite = math.isfinite
    try:
        for col, idx in plan:
            if col.kind == "float":
                parts = []
                had_empty = False
                for i in idx:
                    cells = columns[i]
                    if col.empty_ok and "" in cells:
                        if not empty_ok_here(col):
                            return None
                        had_empty = True
                        part = _floats_or_none(cells)
                        if not all(isfinite(v) for v in part if v is not None):
                            return None
                    else:
                        part = list(map(float, cells))
                        # inf/nan propagate through a sum: one C-level check per column
                        # (a finite sum that overflows only sends us to the slow path).
                        if not isfinite(sum(part)):
                            return None
                    parts.append(part)
                if col.size == 0:
                    vals = parts[0]
                elif not had_empty:
                    vals = list(zip(*parts, strict=True))
                else:
                    vals = []
                    for vec in zip(*parts, strict=True):
                        if None in vec:
                            if any(v is not None for v in vec):
                                return None
                            vals.append(col.default)
                        else:
                            vals.append(vec)
            elif col.kind == "int":
                vals = list(map(int, columns[idx[0]]))
            elif col.kind == "floats":
                vals = []
                for text in columns[idx[0]]:
                    vec = tuple(map(float, text.split()))
                    if not isfinite(sum(vec)):
                        return None
                    vals.append(vec)
            else:
                cells = columns[idx[0]]
                if cells != list(map(str.strip, cells)):
                    return None
                if "" in cells:
                    if not col.empty_ok:
                        return None
                    vals = [col.default if t == "" else t for t in cells]
                else:
                    vals = cells  # type: ignore[assignment]
            fields_.append(col.field)
            values.append(vals)
    except ValueError:
        return None
    for name, default in absent.items():
        fields_.append(name)
        values.append([default] * n)
    return fields_, list(zip(*values))


def _records(cls: type, fields: list[str], rows: list[tuple[Any, ...] | None]) -> list[Any]:
    """Frozen records of ``cls`` from complete, already converted rows (``None`` stays).

    The schema covers every field (tested), so the dataclass ``__init__`` adds nothing
    but ~2 us per record of frozen-attribute overhead, a quarter of the load time.
    """
    new = object.__new__
    out: list[Any] = []
    for row in rows:
        if row is None:
            out.append(None)
            continue
        obj = new(cls)
        obj.__dict__.update(zip(fields, row))
        out.append(obj)
    return out


def _load_yaml(path: Path, problems: list[Problem]) -> Any:
    return _folder_read(path, lambda p: load_yaml(p, MAX_YAML_BYTES), problems)


def _float_list(value: Any, size: int, key: str, problems: list[Problem]) -> tuple | None:
    if value is None:
        return None
    if (
        not isinstance(value, list)
        or len(value) != size
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    ):
        problems.append(Problem("meta.yaml", f"expected a list of {size} numbers", column=key))
        return None
    return tuple(float(v) for v in value)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _checked(value: Any, ok: bool, key: str, expected: str, problems: list[Problem]) -> Any:
    """``value`` when ``ok`` (or ``None``); else ``None`` after reporting it at ``key``."""
    if value is None or ok:
        return value
    problems.append(Problem("meta.yaml", f"{value!r}: expected {expected}", column=key))
    return None


def _number(value: Any, key: str, problems: list[Problem], *, minimum: float = -math.inf) -> Any:
    ok = _is_number(value) and value >= minimum
    low = "" if minimum == -math.inf else f" >= {minimum:g}"
    return _checked(value, ok, key, f"a finite number{low}", problems)


def _bitmask(value: Any, key: str, problems: list[Problem]) -> Any:
    ok = isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 2**31
    return _checked(value, ok, key, "an integer bitmask in [0, 2^31)", problems)


def _text(value: Any, key: str, problems: list[Problem]) -> Any:
    return _checked(value, isinstance(value, str) and value != "", key, "a name", problems)


def _option_and_flag(sim: dict, problems: list[Problem]) -> tuple[dict[str, Any], dict[str, str]]:
    """``simulator_config.option`` and ``.flag``: every name and value checked against
    :mod:`robotwright.hrdf.options` (they are written into MJCF as attributes)."""
    from robotwright.hrdf.options import flag_problem, option_problem

    out: list[dict[str, Any]] = []
    for key, check in (("option", option_problem), ("flag", flag_problem)):
        raw = sim.get(key)
        kept: dict[str, Any] = {}
        if raw is not None and not isinstance(raw, dict):
            problems.append(
                Problem("meta.yaml", "expected a mapping", column=f"simulator_config.{key}")
            )
        for name, value in (raw or {}).items() if isinstance(raw, dict) else ():
            why = check(str(name), value)
            if why is not None:
                problems.append(Problem("meta.yaml", why, column=f"simulator_config.{key}.{name}"))
            else:
                kept[str(name)] = list(value) if isinstance(value, list) else value
        out.append(kept)
    return out[0], out[1]


def _base_joint(raw: Any, problems: list[Problem]) -> dict[str, Any]:
    """``base_joint``: the root free joint's properties, each checked like its
    ``joint.csv`` column (see :data:`BASE_JOINT_FIELDS`)."""
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        problems.append(Problem("meta.yaml", "expected a mapping", column="base_joint"))
        return {}
    columns = {c.csv: c for c in TABLES["joint"] if c.field in BASE_JOINT_FIELDS}
    out: dict[str, Any] = {}
    for name, value in raw.items():
        key = f"base_joint.{name}"
        col = columns.get(name)
        if col is None:
            problems.append(Problem("meta.yaml", f"expected one of {sorted(columns)}", column=key))
            continue
        if col.kind == "floats" or col.size:
            size = len(value) if col.kind == "floats" and isinstance(value, list) else col.size
            got = _float_list(value, size, key, problems)
            if got is not None and not all(map(math.isfinite, got)):
                problems.append(Problem("meta.yaml", "expected finite numbers", column=key))
                got = None
            if got is not None:
                out[col.field] = got
        elif col.kind == "int":
            if value in (0, 1) and not isinstance(value, float):
                out[col.field] = bool(value)
            else:
                problems.append(Problem("meta.yaml", f"{value!r}: expected 0 or 1", column=key))
        else:
            got = _number(value, key, problems)
            if got is not None:
                out[col.field] = float(got)
    return out


def _mjcf_size(raw: Any, problems: list[Problem]) -> dict[str, int]:
    """``mjcf_size``: MJCF ``<size>`` ``nuser_*`` values (integers >= 0)."""
    from robotwright.hrdf.model import NUSER_KEYS

    if raw is None:
        return {}
    if not isinstance(raw, dict):
        problems.append(Problem("meta.yaml", "expected a mapping", column="mjcf_size"))
        return {}
    out: dict[str, int] = {}
    for name, value in raw.items():
        key = f"mjcf_size.{name}"
        if name not in NUSER_KEYS:
            problems.append(Problem("meta.yaml", f"expected one of {list(NUSER_KEYS)}", column=key))
        elif isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 2**31:
            out[name] = value
        else:
            problems.append(
                Problem("meta.yaml", f"{value!r}: expected an integer >= 0", column=key)
            )
    return out


def _parse_meta(raw: Any, problems: list[Problem]) -> tuple[Meta, list[Any] | None, dict]:
    """Returns (meta, body_parent_id, robotwright keys)."""
    meta = Meta(format_version=None, imu_config_list=None)
    if not isinstance(raw, dict):
        problems.append(Problem("meta.yaml", "expected a mapping of keys"))
        return meta, None, {}
    parent_ids = raw.get("body_parent_id")
    if parent_ids is None:
        problems.append(Problem("meta.yaml", "required key is missing", column="body_parent_id"))
    elif not isinstance(parent_ids, list) or not all(
        isinstance(p, int) and not isinstance(p, bool) for p in parent_ids
    ):
        problems.append(
            Problem("meta.yaml", "expected a list of integers", column="body_parent_id")
        )
        parent_ids = None

    mft = raw.get("mesh_file_type")
    if mft is not None:
        if mft not in ("stl", "obj"):
            problems.append(
                Problem(
                    "meta.yaml", f"expected 'stl' or 'obj', got {mft!r}", column="mesh_file_type"
                )
            )
        else:
            meta.mesh_file_type = mft

    sim = raw.get("simulator_config")
    if sim is None:
        meta.simulator_config = None
    elif isinstance(sim, dict):
        ground_raw = sim.get("ground")
        ground = None
        if isinstance(ground_raw, dict):
            key = "simulator_config.ground."
            gtype = ground_raw.get("type")
            ground = GroundConfig(
                type=_checked(
                    gtype, gtype in GROUND_TYPES, key + "type", repr(GROUND_TYPES[0]), problems
                ),
                contact_type=_bitmask(
                    ground_raw.get("contact_type"), key + "contact_type", problems
                ),
                contact_affinity=_bitmask(
                    ground_raw.get("contact_affinity"), key + "contact_affinity", problems
                ),
                friction=_number(ground_raw.get("friction"), key + "friction", problems, minimum=0),
            )
        elif ground_raw is not None:
            problems.append(
                Problem("meta.yaml", "expected a mapping", column="simulator_config.ground")
            )
        integrator = sim.get("integrator")
        option, flag = _option_and_flag(sim, problems)
        meta.simulator_config = SimulatorConfig(
            timestep=_number(sim.get("timestep"), "simulator_config.timestep", problems),
            gravity=_float_list(sim.get("gravity"), 3, "simulator_config.gravity", problems),
            ground=ground,
            integrator=_checked(
                integrator,
                integrator in INTEGRATORS,
                "simulator_config.integrator",
                f"one of {list(INTEGRATORS)}",
                problems,
            ),
            option=option,
            flag=flag,
        )
        for key in sim:
            if key not in ("timestep", "gravity", "ground", "integrator", "option", "flag"):
                problems.append(
                    Problem(
                        "meta.yaml",
                        "unknown key, ignored",
                        column=f"simulator_config.{key}",
                        severity="warning",
                    )
                )
    else:
        problems.append(Problem("meta.yaml", "expected a mapping", column="simulator_config"))

    bnc = raw.get("body_name_config")
    if bnc is None:
        meta.body_name_config = None
    elif isinstance(bnc, dict):
        meta.body_name_config = BodyNameConfig(
            torso_name=bnc.get("torso_name"),
            hip_names=bnc.get("hip_names"),
            knee_names=bnc.get("knee_names"),
            foot_names=bnc.get("foot_names"),
        )
    else:
        problems.append(Problem("meta.yaml", "expected a mapping", column="body_name_config"))

    imus = raw.get("imu_config_list")
    if imus is not None:
        if not isinstance(imus, list):
            problems.append(Problem("meta.yaml", "expected a list", column="imu_config_list"))
        else:
            meta.imu_config_list = []
            for i, imu in enumerate(imus):
                key = f"imu_config_list[{i}]"
                if not isinstance(imu, dict) or not isinstance(imu.get("body_name"), str):
                    problems.append(
                        Problem("meta.yaml", "expected a mapping with body_name", column=key)
                    )
                    continue
                pos = _float_list(
                    imu.get("position", [0.0, 0.0, 0.0]), 3, key + ".position", problems
                )
                ori = _float_list(
                    imu.get("orientation", [1.0, 0.0, 0.0, 0.0]), 4, key + ".orientation", problems
                )
                value = imu.get("value") or []
                if not isinstance(value, list):
                    problems.append(
                        Problem(
                            "meta.yaml",
                            f"{value!r}: expected a list of linacc, angvel, quat",
                            column=key + ".value",
                        )
                    )
                    value = []
                bad = [v for v in value if v not in ("linacc", "angvel", "quat")]
                if bad:
                    problems.append(
                        Problem(
                            "meta.yaml",
                            f"unknown IMU values {bad}: expected linacc, angvel, quat",
                            column=key + ".value",
                        )
                    )
                meta.imu_config_list.append(
                    ImuConfig(
                        body_name=imu["body_name"],
                        position=pos or (0.0, 0.0, 0.0),
                        orientation=ori or (1.0, 0.0, 0.0, 0.0),
                        value=list(value),
                        device_type=imu.get("device_type"),
                        device_config_name=imu.get("device_config_name"),
                    )
                )
    meta.motor_config_list = raw.get("motor_config_list")
    meta.format_version = raw.get("format_version")
    ext = {k: raw[k] for k in ("floating_base", "base_joint_name") if k in raw}
    if "base_joint_name" in ext:
        ext["base_joint_name"] = _text(ext["base_joint_name"], "base_joint_name", problems)
    ext["base_joint"] = _base_joint(raw.get("base_joint"), problems)
    meta.mjcf_size = _mjcf_size(raw.get("mjcf_size"), problems)
    meta.extra = {k: v for k, v in raw.items() if k not in HURODES_META_KEYS + EXTENSION_META_KEYS}
    for key in meta.extra:
        problems.append(
            Problem("meta.yaml", "unknown key, kept verbatim", column=key, severity="warning")
        )
    return meta, parent_ids, ext


def collect_hrdf_dir(
    path: str | Path, *, asset_roots: Iterable[str | os.PathLike[str]] | None = None
) -> tuple[HRDF | None, list[Problem]]:
    """Read an HRDF folder, returning the model (``None`` if unreadable) and all problems.

    The model is returned even when some rows had problems (those rows are left out), so
    that semantic checks can still run; callers raise when any problem is an error.
    ``asset_roots``: folders outside the robot folder that mesh paths may point into.
    """
    from robotwright.hrdf.validate import check_model

    root = Path(path)
    problems: list[Problem] = []
    try:
        # One listing answers every "is this file there" question below.
        present = {e.name for e in os.scandir(root)}
    except (FileNotFoundError, NotADirectoryError):
        return None, [Problem(str(root), "not a folder: expected an HRDF folder")]
    meta_path = root / "meta.yaml"
    if "meta.yaml" not in present:
        return None, [Problem(str(meta_path), "meta.yaml is missing")]
    raw_meta = _load_yaml(meta_path, problems)
    if problems:  # not a readable YAML file (a folder, a FIFO, a link out, ...)
        return None, problems
    meta, parent_ids, ext = _parse_meta(raw_meta, problems)
    hurodes_format = meta.format_version is None
    if meta.format_version is not None and meta.format_version != FORMAT_VERSION:
        problems.append(
            Problem(
                "meta.yaml",
                f"unsupported format_version {meta.format_version!r}: expected {FORMAT_VERSION!r}",
                column="format_version",
            )
        )

    tables: dict[str, _Table | None] = {}
    for stem, schema in TABLES.items():
        if f"{stem}.csv" not in present:
            if stem == "body":
                problems.append(Problem("body.csv", "required file is missing"))
            tables[stem] = None
            continue
        csv_path = root / f"{stem}.csv"
        if stem not in HURODES_TABLES and hurodes_format:
            problems.append(
                Problem(
                    csv_path.name,
                    "robotwright table in a folder without format_version; read anyway",
                    severity="warning",
                )
            )
        tables[stem] = _read_table(csv_path, schema, problems, hurodes_format=hurodes_format)

    for child_name in sorted(present - _KNOWN_FILES):
        if not child_name.startswith("."):
            problems.append(Problem(child_name, "unknown file, ignored", severity="warning"))

    if tables.get("body") is None:
        return None, problems

    records: dict[str, list] = {}
    for stem, table in tables.items():
        if stem != "body":
            records[stem] = (
                [] if table is None else _records(_RECORD_TYPES[stem], table.fields, table.rows)
            )

    # Body ids must match row order: hurodes silently uses row order, we refuse to guess.
    body_table = tables["body"]
    id_at = body_table.fields.index("id")
    for i, row in enumerate(body_table.rows):
        if row is not None and row[id_at] != i:
            problems.append(
                Problem(
                    "body.csv",
                    f"id {row[id_at]} does not match the row position {i}: rows must be in id order",
                    row=i,
                    column="id",
                )
            )
    n_bodies = len(body_table.rows)
    if parent_ids is not None and len(parent_ids) != n_bodies:
        problems.append(
            Problem(
                "meta.yaml",
                f"body_parent_id has {len(parent_ids)} entries, body.csv has {n_bodies} rows",
                column="body_parent_id",
            )
        )
        parent_ids = None
    # "id" was checked above; the "parent" field comes from meta.yaml (-1 when unusable).
    body_fields = ["parent" if f == "id" else f for f in body_table.fields]
    parents = parent_ids if parent_ids is not None else [-1] * n_bodies
    bodies: list[Body] = _records(
        Body,
        body_fields,
        [
            None if row is None else (*row[:id_at], parent, *row[id_at + 1 :])
            for row, parent in zip(body_table.rows, parents, strict=True)
        ],
    )

    joints: list[Joint] = [j for j in records["joint"] if j is not None]
    floating = ext.get("floating_base", True if hurodes_format else None)
    if floating is None:
        floating = False
    if not isinstance(floating, bool):
        problems.append(Problem("meta.yaml", "expected true or false", column="floating_base"))
        floating = False
    root_name = None
    roots = [b for b in bodies if b is not None and b.parent == -1]
    if len(roots) == 1:
        root_name = roots[0].name
    if floating and root_name is not None:
        joints.insert(
            0,
            Joint(
                name=ext.get("base_joint_name"),
                body=root_name,
                type="free",
                **ext.get("base_joint", {}),
            ),
        )
    elif ext.get("base_joint"):
        problems.append(
            Problem("meta.yaml", "base_joint given but the base is fixed", column="base_joint")
        )

    joint_mapping = None
    if JOINT_MAPPING_FILE in present:
        joint_mapping = _load_yaml(root / JOINT_MAPPING_FILE, problems)
    meta.joint_mapping = joint_mapping
    mjcf_extra = None
    if EXTRA_MJCF_FILE in present:
        mjcf_extra = _folder_text(root / EXTRA_MJCF_FILE, MAX_XML_BYTES, problems)

    resolved = root.resolve()
    hrdf = HRDF(
        name=resolved.name,
        bodies=[b for b in bodies if b is not None]
        if all(b is not None for b in bodies)
        else bodies,  # type: ignore[misc]
        joints=joints,
        actuators=[a for a in records["actuator"] if a is not None],
        meshes=[m for m in records["mesh"] if m is not None],
        simple_geoms=[g for g in records["simple_geom"] if g is not None],
        sites=[s for s in records["site"] if s is not None],
        sensors=[s for s in records["sensor"] if s is not None],
        meta=meta,
        mjcf_extra=mjcf_extra,
        root_dir=resolved,
        asset_roots=trusted_roots(asset_roots),
    )
    if any(b is None for b in hrdf.bodies):
        return None, problems
    # Every cell was checked finite as it was read.
    problems.extend(check_model(hrdf, check_files=True, finite=False))
    return hrdf, problems


def read_hrdf_dir(
    path: str | Path, *, asset_roots: Iterable[str | os.PathLike[str]] | None = None
) -> HRDF:
    """Load an HRDF folder; raise :class:`HRDFError` listing all errors, warn for the rest.

    ``asset_roots``: folders outside the robot folder that mesh paths may point into.
    """
    hrdf, problems = collect_hrdf_dir(path, asset_roots=asset_roots)
    errors = [p for p in problems if p.severity == "error"]
    if errors or hrdf is None:
        raise HRDFError(errors or problems, summary=f"invalid HRDF folder {path}")
    for p in problems:
        warnings.warn(f"{Path(path).name}/{p}", HRDFWarning, stacklevel=3)
    return hrdf


# --------------------------------------------------------------------------------- write


def table_rows(hrdf: HRDF, stem: str) -> list[Any]:
    """The records of table ``stem`` in CSV row order (``joint``: the free joint is in
    ``meta.yaml``, not a row)."""
    if stem == "body":
        return list(hrdf.bodies)
    if stem == "joint":
        return [j for j in hrdf.joints if j.type != "free"]
    return list(
        {
            "actuator": hrdf.actuators,
            "mesh": hrdf.meshes,
            "simple_geom": hrdf.simple_geoms,
            "site": hrdf.sites,
            "sensor": hrdf.sensors,
        }[stem]
    )


def _column_needed(col: Column, rows: list[Any]) -> bool:
    """hurodes columns always; extension columns only when some row differs from default."""
    if col.required:
        return True
    return any(getattr(r, col.field) != col.default for r in rows)


def table_csv(hrdf: HRDF, stem: str) -> str | None:
    """The CSV text of one table, or ``None`` when the table has no rows."""
    rows = table_rows(hrdf, stem)
    if not rows:
        return None
    schema = TABLES[stem]
    cols = [c for c in schema if _column_needed(c, rows)]
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow([h for c in cols for h in c.headers])
    for i, rec in enumerate(rows):
        line: list[str] = []
        for c in cols:
            value = i if c.field == "id" else getattr(rec, c.field)
            if c.size == 0:
                line.append(format_cell(value))
            elif value is None:
                line.extend([""] * c.size)
            else:
                line.extend(format_cell(float(v) if c.kind == "float" else v) for v in value)
        writer.writerow(line)
    return out.getvalue()


def _yaml_value(value: Any) -> Any:
    """A plain YAML value: tuples and numpy numbers become lists and Python numbers."""
    if isinstance(value, (tuple, list)):
        return [_yaml_value(v) for v in value]
    if isinstance(value, bool):
        return int(value)
    if hasattr(value, "item"):
        return value.item()
    return value


def meta_dict(hrdf: HRDF) -> dict[str, Any]:
    """The ``meta.yaml`` mapping (hurodes keys, then robotwright's)."""
    meta = hrdf.meta
    sim = meta.simulator_config
    out: dict[str, Any] = {
        "body_parent_id": hrdf.body_parent_id,
        "mesh_file_type": meta.mesh_file_type,
        "simulator_config": None,
        "body_name_config": None,
        "imu_config_list": None,
        "motor_config_list": meta.motor_config_list,
    }
    if sim is not None:
        sim_d: dict[str, Any] = {
            "timestep": sim.timestep,
            "gravity": list(sim.gravity) if sim.gravity is not None else None,
            "ground": None,
        }
        if sim.ground is not None:
            sim_d["ground"] = {
                "type": sim.ground.type,
                "contact_type": sim.ground.contact_type,
                "contact_affinity": sim.ground.contact_affinity,
                "friction": sim.ground.friction,
            }
        if sim.integrator is not None:
            sim_d["integrator"] = sim.integrator
        if sim.option:
            sim_d["option"] = {k: _yaml_value(v) for k, v in sim.option.items()}
        if sim.flag:
            sim_d["flag"] = dict(sim.flag)
        out["simulator_config"] = sim_d
    if meta.body_name_config is not None:
        b = meta.body_name_config
        out["body_name_config"] = {
            "torso_name": b.torso_name,
            "hip_names": b.hip_names,
            "knee_names": b.knee_names,
            "foot_names": b.foot_names,
        }
    if meta.imu_config_list is not None:
        out["imu_config_list"] = [
            {
                "body_name": imu.body_name,
                "device_config_name": imu.device_config_name,
                "device_type": imu.device_type,
                "orientation": list(imu.orientation),
                "position": list(imu.position),
                "value": list(imu.value),
            }
            for imu in meta.imu_config_list
        ]
    out["format_version"] = FORMAT_VERSION
    out["floating_base"] = hrdf.floating_base
    free = [j for j in hrdf.joints if j.type == "free"]
    if free and free[0].name is not None:
        out["base_joint_name"] = free[0].name
    if free:
        base = {
            c.csv: _yaml_value(getattr(free[0], c.field))
            for c in TABLES["joint"]
            if c.field in BASE_JOINT_FIELDS
            and getattr(free[0], c.field) != (0.0 if c.default is NO_DEFAULT else c.default)
        }
        if base:
            out["base_joint"] = base
    if meta.mjcf_size:
        out["mjcf_size"] = dict(meta.mjcf_size)
    out.update(meta.extra)
    return out


def _with_folder_mesh_paths(hrdf: HRDF, sources: list[Path]) -> HRDF:
    """A view of ``hrdf`` whose mesh paths all lie inside the folder being written.

    A relative path without ``..`` is kept (the default ``meshes/<name>.<type>`` stays
    implicit). Any other (the absolute path of a robot built in memory, a path into a
    trusted folder outside the robot) becomes ``meshes/<file name>``, numbered when two
    different files would share a name.
    """
    from dataclasses import replace

    ext = hrdf.meta.mesh_file_type
    rels = [m.file if m.file is not None else f"meshes/{m.name}.{ext}" for m in hrdf.meshes]
    inside = [not Path(r).is_absolute() and ".." not in Path(r).parts for r in rels]
    taken = {r: src for r, src, ok in zip(rels, sources, inside, strict=True) if ok}
    meshes = []
    for mesh, rel, src, ok in zip(hrdf.meshes, rels, sources, inside, strict=True):
        if not ok:
            name = Path(rel)
            rel, k = f"meshes/{name.name}", 1
            while taken.setdefault(rel, src) != src:
                rel, k = f"meshes/{name.stem}_{k}{name.suffix}", k + 1
        file = None if rel == f"meshes/{mesh.name}.{ext}" else rel
        meshes.append(replace(mesh, file=file))
    return replace(hrdf, meshes=meshes)


def write_hrdf_dir(hrdf: HRDF, path: str | Path, *, overwrite: bool = False) -> Path:
    """Write ``hrdf`` as a folder at ``path``; validate first, write atomically.

    Mesh files are copied into ``meshes/`` (or to their ``file`` path inside the folder).

    Raises:
        HRDFError: the model is invalid (nothing is written).
        FileExistsError: ``path`` exists and ``overwrite`` is false.
    """
    from robotwright.hrdf.validate import check_model

    problems = [p for p in check_model(hrdf, check_files=True) if p.severity == "error"]
    if problems:
        raise HRDFError(problems, summary=f"cannot save robot '{hrdf.name}'")
    target = Path(path)
    # The copier checks again: every source inside the robot folder or a trusted one.
    sources = [hrdf.mesh_source(m) for m in hrdf.meshes]
    hrdf = _with_folder_mesh_paths(hrdf, sources)

    def fill(tmp: Path) -> None:
        meta_text = yaml.safe_dump(meta_dict(hrdf), default_flow_style=False, allow_unicode=True)
        (tmp / "meta.yaml").write_text(meta_text, encoding="utf-8")
        for stem in TABLES:
            text = table_csv(hrdf, stem)
            if text is not None:
                (tmp / f"{stem}.csv").write_text(text, encoding="utf-8")
        copied: set[str] = set()
        pairs = zip(hrdf.meshes, sources, strict=True)
        for mesh, source in steps(pairs, len(sources), "meshes copied"):
            rel = (
                mesh.file
                if mesh.file is not None
                else f"meshes/{mesh.name}.{hrdf.meta.mesh_file_type}"
            )
            if rel in copied:
                continue
            copied.add(rel)
            dest = tmp / rel
            if not dest.resolve().is_relative_to(tmp.resolve()):
                raise HRDFError(
                    [Problem("mesh.csv", f"mesh path '{rel}' would be written outside {path}")],
                    summary=f"cannot save robot '{hrdf.name}'",
                )
            dest.parent.mkdir(parents=True, exist_ok=True)
            copy_mesh_file(source, dest)  # regular files only, size-capped
        if hrdf.meta.joint_mapping is not None:
            (tmp / JOINT_MAPPING_FILE).write_text(
                yaml.safe_dump(
                    hrdf.meta.joint_mapping, default_flow_style=False, allow_unicode=True
                ),
                encoding="utf-8",
            )
        if hrdf.mjcf_extra:
            (tmp / EXTRA_MJCF_FILE).write_text(hrdf.mjcf_extra, encoding="utf-8")

    if target.exists() and not overwrite:
        raise OutputExistsError(
            f"{target} exists (replace it with overwrite=True, on the command line --overwrite)"
        )
    with atomic_dir(target, kind="hrdf") as tmp:  # replaces only an HRDF output
        fill(tmp)
    return target
