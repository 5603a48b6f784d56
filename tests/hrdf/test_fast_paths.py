"""The loader's fast paths give exactly what the general paths give, on good and bad input.

HRDF loading has fast paths (CSV split without the csv module where a table has no
quoting, per-row validation quick passes). Each test here
runs the fast and the general path on the same input, including malformed input, and
requires identical values, problems and messages.
"""

from __future__ import annotations

import dataclasses
import math
import os
import random
from pathlib import Path

import pytest

from robotwright.hrdf import HRDF, validate_common
from robotwright.hrdf import read_tables as hio
from robotwright.hrdf import validate as hval
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR
from robotwright.hrdf.tables import TABLES

#: The hurodes-written G1 that tools/fetch_test_data.py makes (as tests/conftest.py's
#: HURODES_FIXTURES; needed at collection time, before fixtures exist).
G1 = (
    Path(
        os.environ.get("ROBOTWRIGHT_HURODES_FIXTURES")
        or Path(__file__).resolve().parents[2] / ".testdata" / "hurodes-fixtures"
    )
    / "g1_29"
)


def _robot_dirs() -> list[Path]:
    dirs = sorted(p for p in BUNDLED_ROBOTS_DIR.iterdir() if (p / "meta.yaml").is_file())
    if G1.is_dir():
        dirs.append(G1)
    return dirs


# ----------------------------------------------------------------------------- CSV


def _read_both(path: Path, stem: str, monkeypatch: pytest.MonkeyPatch, hurodes: bool):
    fast_problems: list = []
    fast = hio._read_table(path, TABLES[stem], fast_problems, hurodes_format=hurodes)
    with monkeypatch.context() as m:
        m.setattr(hio, "_split_plain", lambda text: None)
        slow_problems: list = []
        slow = hio._read_table(path, TABLES[stem], slow_problems, hurodes_format=hurodes)
    return (fast, fast_problems), (slow, slow_problems)


def _same_tables(a, b) -> None:
    (ta, pa), (tb, pb) = a, b
    assert pa == pb
    if ta is None or tb is None:
        assert ta is tb
        return
    assert ta.extra_columns == tb.extra_columns
    rows_a = [None if r is None else dict(zip(ta.fields, r, strict=True)) for r in ta.rows]
    rows_b = [None if r is None else dict(zip(tb.fields, r, strict=True)) for r in tb.rows]
    assert rows_a == rows_b


BODY_CSV = (
    "diag_inertia0,diag_inertia1,diag_inertia2,mass,inertial_pos0,inertial_pos1,"
    "inertial_pos2,inertial_quat0,inertial_quat1,inertial_quat2,inertial_quat3,pos0,pos1,"
    "pos2,quat0,quat1,quat2,quat3,name,id\n"
    "0.1,0.1,0.1,2.5,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,0.0,1.0,1.0,0.0,0.0,0.0,base,0\n"
    "0.01,0.02,0.02,0.5,0.0,0.0,0.1,1.0,0.0,0.0,0.0,0.0,0.0,0.2,1.0,0.0,0.0,0.0,arm,1\n"
)
_GOOD_LINE = "0.01,0.02,0.02,0.5,0.0,0.0,0.1,1.0,0.0,0.0,0.0,0.0,0.0,0.2,1.0,0.0,0.0,0.0,arm,1"


@pytest.mark.parametrize(
    "text",
    [
        BODY_CSV,
        BODY_CSV.rstrip("\n"),  # no final newline
        BODY_CSV + "\n\n",  # trailing empty lines
        BODY_CSV.replace("\n0.01", "\n\n0.01"),  # empty line between rows
        BODY_CSV.replace("\n0.01", "\n   \n0.01"),  # blank line between rows
        BODY_CSV.replace("\n", "\r\n"),  # CRLF (csv module path)
        BODY_CSV.replace(",arm,", ',"arm",'),  # quoted cell (csv module path)
        BODY_CSV.replace(",arm,", ',"a,rm",'),  # quoted comma
        BODY_CSV.replace(",arm,", ", arm,"),  # padded name
        BODY_CSV.replace(",2.5,", ", 2.5,"),  # padded number
        BODY_CSV.replace(",2.5,", ",,"),  # empty mass
        BODY_CSV.replace(",2.5,", ",abc,"),  # non-numeric
        BODY_CSV.replace(",2.5,", ",inf,"),  # non-finite
        BODY_CSV.replace(",2.5,", ",nan,"),
        BODY_CSV.replace(",2.5,", ",1e400,"),
        BODY_CSV.replace(",arm,1", ",arm,1.5"),  # non-integer id
        BODY_CSV.replace(",arm,1", ",arm,1.0"),
        BODY_CSV.replace(",arm,1", ",arm,1,extra"),  # ragged row
        BODY_CSV.replace(",arm,1", ",arm"),  # short row
        BODY_CSV.replace(",base,0\n", ",base,0,\n"),  # trailing comma
        BODY_CSV + _GOOD_LINE + ",x\n" + _GOOD_LINE[:-6] + "\n",  # long + short rows
        BODY_CSV.replace("name,id", "name,id,colour"),  # unknown column, ragged
        BODY_CSV.replace("mass,", ""),  # missing column
        "\n" + BODY_CSV,  # empty first line
        "",  # empty file
        "\n",
        BODY_CSV.splitlines()[0] + "\n",  # header only
        BODY_CSV.replace("name", " name "),  # padded header
        BODY_CSV.replace("\n0.01", "\n0.01\x00"),  # NUL (csv module path)
        BODY_CSV.replace(",arm,", ",ärm,"),  # non-ASCII name
    ],
)
def test_csv_fast_split_matches_csv_module(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, text: str
) -> None:
    path = tmp_path / "body.csv"
    path.write_text(text, encoding="utf-8", newline="")
    fast, slow = _read_both(path, "body", monkeypatch, hurodes=True)
    if "\x00" in text:
        # the csv module refuses NUL characters; the fast path must leave it that way
        return
    _same_tables(fast, slow)


def test_csv_fast_split_matches_on_every_robot_table(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    checked = 0
    for folder in _robot_dirs():
        hurodes = "format_version" not in (folder / "meta.yaml").read_text()
        for stem in TABLES:
            path = folder / f"{stem}.csv"
            if path.is_file():
                fast, slow = _read_both(path, stem, monkeypatch, hurodes)
                assert fast[0] is not None and fast[0].rows
                _same_tables(fast, slow)
                checked += 1
    assert checked >= 5


def test_csv_fast_split_matches_on_mutated_g1_tables(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    if not G1.is_dir():
        pytest.skip(f"hurodes G1 fixture not made: {G1} (run python tools/fetch_test_data.py)")
    rng = random.Random(7)
    alphabet = ',\n\r" .-e0123456789xa\t'
    for stem in ("body", "joint", "actuator", "mesh", "simple_geom"):
        original = (G1 / f"{stem}.csv").read_text()
        for _ in range(40):
            chars = list(original)
            for _ in range(rng.randint(1, 3)):
                at = rng.randrange(len(chars))
                op = rng.random()
                if op < 0.4:
                    del chars[at]
                elif op < 0.8:
                    chars.insert(at, rng.choice(alphabet))
                else:
                    chars[at] = rng.choice(alphabet)
            path = tmp_path / f"{stem}.csv"
            path.write_text("".join(chars), encoding="utf-8", newline="")
            fast, slow = _read_both(path, stem, monkeypatch, hurodes=True)
            _same_tables(fast, slow)


# ---------------------------------------------------------------------- validation


def _problems_both(hrdf: HRDF, monkeypatch: pytest.MonkeyPatch) -> tuple[list, list]:
    quick = hval.check_model(hrdf, check_files=True)
    with monkeypatch.context() as m:
        m.setattr(validate_common, "QUICK_PASS", False)
        full = hval.check_model(hrdf, check_files=True)
    return quick, full


_ODD = [0.0, -0.0, -1.0, 1e-12, 1.00005, 1.0002, math.nan, math.inf, -math.inf, 2.0]


def _variants(rec, rng: random.Random, n: int) -> list:
    """Copies of ``rec`` with one numeric field (or one vector entry) set to an odd value."""
    out = []
    numeric = [
        f.name
        for f in dataclasses.fields(rec)
        if isinstance(getattr(rec, f.name), (int, float, tuple))
        and not isinstance(getattr(rec, f.name), bool)
        and getattr(rec, f.name) != ()  # no user data to change
    ]
    for _ in range(n):
        name = rng.choice(numeric)
        value = getattr(rec, name)
        odd = rng.choice(_ODD)
        if isinstance(value, tuple):
            i = rng.randrange(len(value))
            value = (*value[:i], odd, *value[i + 1 :])
        elif isinstance(value, int):
            value = rng.choice([0, -1, 2, 5, 7])
        else:
            value = odd
        out.append(dataclasses.replace(rec, **{name: value}))
    return out


@pytest.mark.parametrize("folder", _robot_dirs(), ids=lambda p: p.name)
def test_validation_quick_pass_reports_exactly_the_full_checks(
    folder: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    hrdf = HRDF.from_dir(folder)
    quick, full = _problems_both(hrdf, monkeypatch)
    assert quick == full == [p for p in full if p.severity == "warning"]
    rng = random.Random(folder.name)
    tables = ("bodies", "joints", "actuators", "meshes", "simple_geoms")
    broken = 0
    for table in tables:
        rows = getattr(hrdf, table)
        for _ in range(min(len(rows), 12)):
            i = rng.randrange(len(rows))
            for bad in _variants(rows[i], rng, 3):
                model = dataclasses.replace(hrdf, **{table: [*rows[:i], bad, *rows[i + 1 :]]})
                quick, full = _problems_both(model, monkeypatch)
                assert quick == full, (table, i, bad)
                broken += bool(full)
    # names, references and types as well
    for table, field, value in (
        ("bodies", "name", ""),
        ("joints", "name", ""),
        ("joints", "body", "nowhere"),
        ("joints", "type", "screw"),
        ("actuators", "joint", "nowhere"),
        ("actuators", "type", "position"),
        ("actuators", "type", "velocity"),
        ("meshes", "body", "nowhere"),
        ("meshes", "name", "missing_mesh"),
        ("meshes", "file", "../outside.stl"),
        ("simple_geoms", "type", "cone"),
    ):
        rows = getattr(hrdf, table)
        if not rows:
            continue
        bad = dataclasses.replace(rows[-1], **{field: value})
        model = dataclasses.replace(hrdf, **{table: [*rows[:-1], bad]})
        quick, full = _problems_both(model, monkeypatch)
        assert quick == full, (table, field, value)
        broken += bool(full)
    assert broken > 20


def _tree_problems_reference(parents: list[int]) -> list[list[int]]:
    """Cycles as the plain walk from every body finds them (the definition)."""
    cycles: list[list[int]] = []
    reported: set[int] = set()
    for start in range(len(parents)):
        seen: list[int] = []
        i = start
        while i != -1 and i not in seen:
            seen.append(i)
            i = parents[i]
        if i != -1:
            cycle = seen[seen.index(i) :]
            if not reported.intersection(cycle):
                reported.update(cycle)
                cycles.append(cycle)
    return cycles


def test_tree_check_finds_the_same_cycles_as_the_plain_walk() -> None:
    rng = random.Random(3)
    base = HRDF.from_dir(_robot_dirs()[0])
    body = base.bodies[0]
    for _ in range(300):
        n = rng.randint(2, 12)
        parents = [-1] + [rng.randrange(n) for _ in range(n - 1)]
        parents = [p if p != i else -1 for i, p in enumerate(parents)]
        rng.shuffle(parents)
        parents = [p if p != i else (i + 1) % n for i, p in enumerate(parents)]
        bodies = [dataclasses.replace(body, name=f"b{i}", parent=p) for i, p in enumerate(parents)]
        got = [
            p.message
            for p in hval._check_tree(dataclasses.replace(base, bodies=bodies))
            if "cycle" in p.message
        ]
        want = [
            f"bodies {[f'b{k}' for k in c]} form a cycle: the body tree must be a tree"
            for c in _tree_problems_reference(parents)
        ]
        assert got == want, parents


# ------------------------------------------------------------------ remembered work


def _table(tmp_path: Path, header: str, rows: list[str]) -> Path:
    path = tmp_path / "joint.csv"
    path.write_text("\n".join([header, *rows]) + "\n", encoding="utf-8")
    return path


def test_remembered_cell_numbers_are_exact_and_bad_cells_still_refused() -> None:
    """Cell numbers are remembered by text: a number read again is the same float, and a
    cell that is not a number is refused on every read (never remembered)."""
    rng = random.Random(3)
    texts = [repr(rng.uniform(-1e3, 1e3)) for _ in range(200)] + ["1e-320", "-0.0", "7"]
    remembered = hio._float_of_cell.__self__
    for t in texts:
        first = hio._float_of_cell(t)
        again = hio._float_of_cell(t)
        assert first == float(t) and math.copysign(1, first) == math.copysign(1, float(t))
        assert again is first  # the remembered value
    for _ in range(2):
        with pytest.raises(ValueError):
            hio._float_of_cell("1.0.0")
        assert "1.0.0" not in remembered
    # bounded: a full memory starts again rather than growing
    small = hio._FloatOfCell()
    small.update({str(i): float(i) for i in range(1 << 16)})
    assert small["0.5"] == 0.5 and len(small) == 1


def test_a_remembered_header_layout_reports_unknown_columns_on_every_read(
    tmp_path: Path,
) -> None:
    """The header layout is worked out once per header; the warnings about unknown
    columns and the errors about missing ones still come on every read."""
    required = [h for c in TABLES["joint"] if c.required for h in c.headers]
    header = ",".join([*required, "extra_col"])
    row = ",".join("b1" if h == "body_name" else "j1" if h == "name" else "0.5" for h in required)
    good = _table(tmp_path, header, [f"{row},5"])
    for _ in range(2):
        problems: list = []
        table = hio._read_table(good, TABLES["joint"], problems, hurodes_format=False)
        assert table is not None and table.extra_columns == ["extra_col"]
        assert [(p.column, p.severity) for p in problems] == [("extra_col", "warning")]
        table.extra_columns.append("changed")  # the caller's list, not the remembered one
    for _ in range(2):
        problems = []
        without_name = [h for h in required if h != "name"]
        bad = _table(
            tmp_path, ",".join([*without_name, "extra_col"]), [",".join(["0.5"] * len(required))]
        )
        assert hio._read_table(bad, TABLES["joint"], problems, hurodes_format=False) is None
        assert ("name", "error") in [(p.column, p.severity) for p in problems]
        assert ("extra_col", "warning") in [(p.column, p.severity) for p in problems]
