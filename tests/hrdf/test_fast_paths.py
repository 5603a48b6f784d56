"""The loader's fast paths give exactly what the general paths give, on good and bad input.

HRDF loading has fast paths (CSV split without the csv module, plain YAML documents built
without PyYAML's generic constructor, per-row validation quick passes). Each test here
runs the fast and the general path on the same input, including malformed input, and
requires identical values, problems and messages.
"""

from __future__ import annotations

import dataclasses
import math
import random
from pathlib import Path

import pytest
import yaml

from robotwright.hrdf import HRDF
from robotwright.hrdf import io as hio
from robotwright.hrdf import validate as hval
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR
from robotwright.hrdf.tables import TABLES

G1 = Path(__file__).resolve().parents[3] / "shared" / "fixtures" / "hurodes" / "g1_29"


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
        pytest.skip("shared fixtures absent (../shared/fixtures/hurodes/g1_29)")
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


# ---------------------------------------------------------------------------- YAML


def _pyyaml(text: str):
    try:
        return ("ok", yaml.load(text, Loader=hio._YAML_LOADER))
    except (yaml.YAMLError, ValueError) as exc:  # PyYAML lets int("²") through
        return ("error", type(exc))


def _ours(text: str):
    try:
        return ("ok", hio._parse_yaml(text))
    except (yaml.YAMLError, ValueError) as exc:
        return ("error", type(exc))


def _same_value(a, b) -> bool:
    """Equal, with equal types all the way down (1 vs 1.0 vs True differ), NaN == NaN."""
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        return (math.isnan(a) and math.isnan(b)) or a == b
    if isinstance(a, dict):
        return list(a) == list(b) and all(_same_value(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(_same_value(x, y) for x, y in zip(a, b, strict=True))
    return a == b


YAML_DOCS = [
    "a: 1\nb: -2\nc: 0\nd: -0\ne: 007\nf: 0x1F\ng: 1_000\nh: +5\ni: 1:30\nj: 0b101\nk: 010\nl: -010\n",
    "a: 1.5\nb: -0.0\nc: .inf\nd: -.inf\ne: .nan\nf: 1e3\ng: 6.02e+23\nh: 1_0.5\n",
    "a: true\nb: False\nc: yes\nd: off\ne: ~\nf: null\ng:\nh: ''\ni: 'x'\n",
    "a: !!str 12\nb: !!int '7'\nc: !!float 1\nd: 2001-12-14\ne: !!binary aGk=\n",
    "base: &b {x: 1, y: [1, 2]}\nother: *b\n",  # aliases share objects in PyYAML
    "base: &b {x: 1}\nmerged:\n  <<: *b\n  y: 2\n",  # merge key
    "=: value key\n",
    "? [1, 2]\n: complex key\n",
    "a: 1\na: 2\n",  # duplicate keys: the last wins in both
    "- 1\n- [2, 3]\n- {k: v}\n- - nested\n",
    "!!set {a, b}\n",
    "!!omap [a: 1]\n",
    "",
    "# only a comment\n",
    "plain string\n",
    "a: [1, 2\n",  # malformed
    "a: b: c\n",
    "a:\n - 1\n  - 2\n",
    "--- 1\n--- 2\n",  # two documents: an error in both
    "- ² \n- ١٢\n- '12'\n",  # non-ASCII digits are strings
    "a: !!int ²\n",  # an error in both
]


@pytest.mark.parametrize("text", YAML_DOCS)
def test_yaml_fast_build_matches_pyyaml(text: str) -> None:
    expected, got = _pyyaml(text), _ours(text)
    assert expected[0] == got[0]
    assert _same_value(expected[1], got[1]) if expected[0] == "ok" else expected == got


def test_yaml_fast_build_keeps_shared_objects_of_aliases() -> None:
    data = hio._parse_yaml("a: &x [1]\nb: *x\n")
    assert data["a"] is data["b"]


def test_yaml_fast_build_matches_on_robot_meta_and_mutations() -> None:
    rng = random.Random(11)
    texts = [(folder / "meta.yaml").read_text() for folder in _robot_dirs()]
    assert texts
    alphabet = ":-\n #&*!'\"{}[],0123456789.e_x~"
    for original in texts:
        assert _same_value(_pyyaml(original)[1], _ours(original)[1])
        for _ in range(150):
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
            text = "".join(chars)
            expected, got = _pyyaml(text), _ours(text)
            assert expected[0] == got[0], text
            if expected[0] == "ok":
                assert _same_value(expected[1], got[1]), text
            else:
                assert expected == got, text


def _random_data(rng: random.Random, depth: int = 0):
    """Nested data; mostly what the block parser's subset holds once dumped, sometimes not
    (bool words as strings get quoted, empty collections are written in flow style)."""
    words = ["a", "b_c", "y", "n", "_x", "x1", "robotwright-hrdf/1", "a.b", "x-y"]
    odd = ["on", "NO", "null", "", "1", "0.5", "a b", "-", [], {}]
    scalars = [
        lambda: rng.choice(words),
        lambda: rng.randint(-50, 50),
        lambda: rng.choice([0.0, -0.0, 1.0, -1.5, 1e-5, 2.5e20, 0.20000000298023224]),
        lambda: rng.uniform(-10, 10),
        lambda: None,
        lambda: rng.choice([True, False]),
    ]
    if rng.random() < 0.03:
        return rng.choice(odd)
    if depth > 0 and (depth >= 3 or rng.random() < 0.4):
        return rng.choice(scalars)()
    if rng.random() < 0.5:
        return [_random_data(rng, depth + 1) for _ in range(rng.randint(1, 4))]
    return {rng.choice(words[:6]): _random_data(rng, depth + 1) for _ in range(rng.randint(1, 4))}


def _check_block_parser(text: str) -> bool:
    """If the block parser accepts ``text``, PyYAML reads the same value; True if accepted."""
    try:
        value = hio._parse_block_yaml(text)
    except hio._NotBlockYAML:
        return False
    expected = _pyyaml(text)
    assert expected[0] == "ok", text
    assert _same_value(expected[1], value), text
    return True


def test_block_yaml_parser_matches_pyyaml_on_dumped_and_mutated_documents() -> None:
    rng = random.Random(5)
    accepted = 0
    alphabet = ":- \n_.0123456789abeyonNT/"
    for _ in range(1500):
        text = yaml.safe_dump(_random_data(rng), default_flow_style=False)
        accepted += _check_block_parser(text)
        for _ in range(3):
            chars = list(text)
            for _ in range(rng.randint(1, 2)):
                at = rng.randrange(len(chars) + 1)
                op = rng.random()
                if op < 0.4 and at < len(chars):
                    del chars[at]
                elif op < 0.8:
                    chars.insert(at, rng.choice(alphabet))
                elif at < len(chars):
                    chars[at] = rng.choice(alphabet)
            _check_block_parser("".join(chars))
    assert accepted > 500  # the subset covers what safe_dump writes for such data


@pytest.mark.parametrize(
    "text",
    [
        "on: yes\nOff: NO\nnull: Null\ny: n\nTRUE: false\nnull: 2\n",
        "a:\n- 1\n- -2\n- 0\n- -0\n- 1.50\n- -0.0\n- 1.0e-05\n- 1.0E+20\n",
        "a:\n  - x\n  - y\nb:\n- c: 1\n  d:\n  - 2\n  e: f\n- g\n",
        "a:\nb:\n  c:\nd: 1\n",
    ],
)
def test_block_yaml_parser_reads_its_subset_like_pyyaml(text: str) -> None:
    assert _check_block_parser(text)


@pytest.mark.parametrize(
    "text",
    [
        "a: 1\n  b: 2\n",  # continuation line
        "a: b\n  c\n",  # multi-line plain scalar
        "- a\n  - b\n",
        "a:\n    b: 1\n  c: 2\n",
        "  a: 1\n",  # indented document
        "a: 1\n\nb: 2\n",  # blank line
        "a: 1 \n",  # trailing space
        "a:  1\n",
        "a:1\n",
        "- - 1\n",
        "-\n  a: 1\n",
        "a: 1e5\n",  # a string for PyYAML's YAML 1.1 resolver
        "a: 0x10\n",
        "a: 007\n",
        "a: 1_000\n",
        "a: +1\n",
        "a: .5\n",
        "a: 12:30\n",
        "...\n",
        "a: b: c\n",
        "1: a\n",
    ],
)
def test_block_yaml_parser_leaves_everything_else_to_pyyaml(text: str) -> None:
    assert not _check_block_parser(text)
    assert _same_value(_pyyaml(text), _ours(text))


def test_block_yaml_parser_reads_every_robot_meta() -> None:
    for folder in _robot_dirs():
        assert _check_block_parser((folder / "meta.yaml").read_text()), folder


# ---------------------------------------------------------------------- validation


def _problems_both(hrdf: HRDF, monkeypatch: pytest.MonkeyPatch) -> tuple[list, list]:
    quick = hval.check_model(hrdf, check_files=True)
    with monkeypatch.context() as m:
        m.setattr(hval, "_QUICK_PASS", False)
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
