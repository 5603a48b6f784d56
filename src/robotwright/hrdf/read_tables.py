"""Reading an HRDF folder's CSV tables (untrusted): each file read within the folder with
its size capped, every cell converted to its column's type, each bad cell a
:class:`~robotwright.errors.Problem` naming file, row and column. Plain tables take a
fast path; the ``csv`` module reads the rest."""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from itertools import repeat
from pathlib import Path
from typing import Any

import yaml

from robotwright._inputs import (
    MAX_TABLE_BYTES,
    read_text,
)
from robotwright._paths import resolve_inside
from robotwright.errors import (
    InputFileError,
    Problem,
    UnsafePathError,
)
from robotwright.hrdf.tables import (
    NO_DEFAULT,
    CellError,
    Column,
    parse_cell,
)


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


_Layout = tuple[dict[str, int], list[tuple[Column, list[int]]], dict[str, Any], list[str]]
#: Header layouts already worked out, by (schema identity, header): a robot's tables
#: keep their headers from load to load. The schema is kept in the value so that its
#: identity cannot be reused by another list.
_LAYOUTS: dict[tuple[int, tuple[str, ...]], tuple[list[Column], _Layout]] = {}


def _header_layout(
    schema: list[Column], header: list[str], fname: str, problems: list[Problem]
) -> _Layout | None:
    """(column index by header, conversion plan, defaults of absent fields, unknown
    headers) of a table, or ``None`` after reporting missing or incomplete columns."""
    key = (id(schema), tuple(header))
    cached = _LAYOUTS.get(key)
    if cached is not None and cached[0] is schema:
        return cached[1]
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
            gone = [h for h in col.headers if h not in index]
            problems.append(
                Problem(fname, f"vector columns incomplete: missing {gone}", column=col.csv)
            )
            missing = True
    extra = [h for h in header if h not in known]
    if missing:
        for h in extra:
            problems.append(Problem(fname, "unknown column, ignored", column=h, severity="warning"))
        return None
    plan = [(col, [index[h] for h in col.headers]) for col in schema if col.headers[0] in index]
    absent = {col.field: col.default for col in schema if col.headers[0] not in index}
    layout = (index, plan, absent, extra)
    if len(_LAYOUTS) < 256:  # a bound for a process that reads many odd headers
        _LAYOUTS[key] = (schema, layout)
    return layout


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
    layout = _header_layout(schema, header, fname, problems)
    if layout is None:
        return None
    index, plan, absent, extra = layout
    for h in extra:
        problems.append(Problem(fname, "unknown column, ignored", column=h, severity="warning"))

    def empty_ok_here(col: Column) -> bool:
        return col.empty_ok and not (hurodes_format and col.csv == "range")

    if columns is not None:
        fast = _convert_table_fast(columns, plan, absent, empty_ok_here)
        if fast is not None:
            return _Table(fields=fast[0], rows=fast[1], extra_columns=list(extra))
    # Empty lines are skipped (an empty line is [] for csv, [""] for str.split).
    data = [cells for cells in body_rows if cells and (len(cells) > 1 or cells[0].strip())]
    if columns is None and data and all(len(cells) == len(header) for cells in data):
        fast = _convert_table_fast(
            [list(col) for col in zip(*data, strict=True)], plan, absent, empty_ok_here
        )
        if fast is not None:
            return _Table(fields=fast[0], rows=fast[1], extra_columns=list(extra))
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
    return _Table(fields=fields, rows=rows, extra_columns=list(extra))


class _FloatOfCell(dict[str, float]):
    """``float(text)`` of table cells, remembered (bounded): a robot's tables repeat most
    numbers (the G1's five tables hold 2,352 numeric cells, 592 distinct), and parsing a
    17-digit number costs several dictionary lookups. Exact: the same text is the same
    float. A text ``float`` refuses raises ``ValueError`` and is not stored."""

    def __missing__(self, text: str) -> float:
        if len(self) >= 1 << 16:
            self.clear()
        value = self[text] = float(text)
        return value


_float_of_cell = _FloatOfCell().__getitem__


def _floats_or_none(cells: list[str]) -> list[float | None]:
    return [None if t == "" else _float_of_cell(t) for t in cells]


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
                        part = list(map(_float_of_cell, cells))
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
