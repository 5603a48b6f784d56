"""Hostile values in the HRDF physics fields (geom/joint solver columns, ``user`` cells,
``simulator_config.option``/``flag``, ``base_joint``, ``mjcf_size``): each is refused by
the loader with an error naming the file and the column or key, never written into XML."""

from __future__ import annotations

import random
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from robotwright.errors import HRDFError
from robotwright.hrdf import HRDF

ROBOT = """<mujoco model="p">
  <option impratio="3"><flag energy="enable"/></option>
  <size nuser_body="2"/>
  <worldbody><body name="base" user="1 2">
    <joint name="root" type="free" damping="1"/>
    <geom name="g" type="box" size="0.1 0.1 0.1" solref="0.03 1" margin="0.01" priority="1" user="1"/>
    <body name="arm" pos="0.2 0 0">
      <joint name="j1" actuatorfrcrange="-1 1" actuatorgravcomp="true" solreflimit="0.03 1" user="1"/>
      <geom name="g1" type="sphere" size="0.05"/>
    </body>
  </body></worldbody>
</mujoco>"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from robotwright.parsers import mjcf_to_hrdf

    tmp = tmp_path_factory.mktemp("phys")
    (tmp / "p.xml").write_text(ROBOT)
    out = tmp / "robot"
    mjcf_to_hrdf(tmp / "p.xml").save(out)
    return out


def _copy(folder: Path, tmp_path: Path) -> Path:
    import shutil

    dest = tmp_path / "robot"
    shutil.copytree(folder, dest)
    return dest


def _refused(path: Path, file: str, column_prefix: str) -> None:
    with pytest.raises(HRDFError) as err:
        HRDF.from_dir(path)
    hits = [
        p
        for p in err.value.problems
        if p.file == file and (p.column or "").startswith(column_prefix)
    ]
    assert hits, [str(p) for p in err.value.problems]


_NAMES = ['a" onload="x', "<flag>", "impratio ", "x" * 2000, "solver\n", "__class__", ""]
_BAD_VALUES = ["abc", float("inf"), float("nan"), [1, 2, 3, 4, 5, 6], {"a": 1}, True, None]


def _option_cases() -> list[tuple[str, str, object]]:
    rng = random.Random(20)
    cases: list[tuple[str, str, object]] = []
    for name in _NAMES:
        cases.append(("option", name, 1.0))
        cases.append(("flag", name, "disable"))
    for name in ("impratio", "o_solref", "iterations", "cone", "solver", "wind"):
        for value in rng.sample(_BAD_VALUES, 4) + [-1 if name == "iterations" else "Newtonx"]:
            cases.append(("option", name, value))
    for value in ("on", 1, True, "", None, ["disable"]):
        cases.append(("flag", "contact", value))
    return cases


@pytest.mark.parametrize(("section", "name", "value"), _option_cases())
def test_bad_option_or_flag_is_refused(
    folder: Path, tmp_path: Path, section: str, name: str, value: object
) -> None:
    path = _copy(folder, tmp_path)
    meta = yaml.safe_load((path / "meta.yaml").read_text())
    meta["simulator_config"].setdefault(section, {})[name] = value
    (path / "meta.yaml").write_text(yaml.safe_dump(meta))
    _refused(path, "meta.yaml", f"simulator_config.{section}")


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("base_joint", {"armature": "x"}),
        ("base_joint", {"armature": float("inf")}),
        ("base_joint", {"damping": 1.0}),  # MJCF name, not the joint.csv column
        ("base_joint", {"solreflimit": [1.0]}),
        ("base_joint", {"user": ["a"]}),
        ("base_joint", {"actuatorgravcomp": 2}),
        ("base_joint", [1, 2]),
        ("mjcf_size", {"nuser_body": -1}),
        ("mjcf_size", {"nuser_body": 1.5}),
        ("mjcf_size", {"memory": "1G"}),
        ("mjcf_size", {"nuser_body": 1}),  # body.csv row 0 holds 2 values
        ("mjcf_size", "nuser_body"),
    ],
)
def test_bad_meta_physics_key_is_refused(
    folder: Path, tmp_path: Path, key: str, value: object
) -> None:
    path = _copy(folder, tmp_path)
    meta = yaml.safe_load((path / "meta.yaml").read_text())
    meta[key] = value
    (path / "meta.yaml").write_text(yaml.safe_dump(meta))
    if value == {"nuser_body": 1}:
        _refused(path, "body.csv", "user")
    else:
        _refused(path, "meta.yaml", key)


def _cell_cases() -> list[tuple[str, str, str]]:
    rng = random.Random(21)
    junk = ["abc", "inf", "nan", "1e400", "1,2", '"', "1 x", "0x10", "--1"]
    cases = []
    for table, column in (
        ("simple_geom", "solref0"),
        ("simple_geom", "margin"),
        ("simple_geom", "priority"),
        ("simple_geom", "user"),
        ("joint", "actuatorfrcrange1"),
        ("joint", "solreflimit1"),
        ("joint", "user"),
        ("joint", "actuatorgravcomp"),
        ("body", "user"),
    ):
        for text in rng.sample(junk, 4):
            cases.append((table, column, text))
    cases.append(("joint", "actuatorfrcrange0", "5"))  # lower 5 > upper 1
    cases.append(("joint", "actuatorgravcomp", "2"))
    cases.append(("simple_geom", "priority", "1.5"))
    return cases


@pytest.mark.parametrize(("table", "column", "text"), _cell_cases())
def test_bad_cell_is_refused(
    folder: Path, tmp_path: Path, table: str, column: str, text: str
) -> None:
    import csv
    import io

    path = _copy(folder, tmp_path)
    rows = list(csv.reader(io.StringIO((path / f"{table}.csv").read_text())))
    assert column in rows[0], rows[0]
    rows[1][rows[0].index(column)] = text
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows(rows)
    (path / f"{table}.csv").write_text(out.getvalue())
    base = column.rstrip("0123456789") if column != "user" else "user"
    _refused(path, f"{table}.csv", base)


def test_cli_refuses_with_one_line_and_no_traceback(folder: Path, tmp_path: Path) -> None:
    path = _copy(folder, tmp_path)
    meta = yaml.safe_load((path / "meta.yaml").read_text())
    meta["simulator_config"]["option"] = {'x" y="1': 1.0}
    (path / "meta.yaml").write_text(yaml.safe_dump(meta))
    out = tmp_path / "o.xml"
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", "export", str(path), "-o", str(out)],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 2
    assert "Traceback" not in run.stderr
    assert "simulator_config.option" in run.stderr
    assert not out.exists()
