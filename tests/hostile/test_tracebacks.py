"""Hostile inputs that used to end in a traceback or in output MuJoCo refuses (issue 19,
"Tracebacks and silent bad output"). Each is now bad input: a one-line ``error:`` (or
the usual problem list) with exit code 2 and nothing written, or correct output.

Families: a NUL character in a mesh path; a CSV cell over the csv module's field limit;
a robot name that looks like a path; a mesh MuJoCo cannot read given to ``render``,
``view``, ``convert`` and ``export``; ``MUJOCO_GL`` naming an OpenGL platform that
cannot start; malformed ``FilePatternCfg`` files; a height field too large to draw
whole; HRDF tables whose model MuJoCo refuses (targeted and seeded random variants).
"""

from __future__ import annotations

import csv
import os
import random
import shutil
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from robotwright._paths import resolve_inside
from robotwright.cli import main
from robotwright.errors import HRDFError, RobotwrightError, SensorError, UnsafePathError
from robotwright.generators.compiles import validate_dir
from robotwright.hrdf import HRDF
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR

MESH_HEADER = (
    "contact_type,contact_affinity,static_friction,dynamic_friction,restitution,"
    "pos0,pos1,pos2,quat0,quat1,quat2,quat3,rgba0,rgba1,rgba2,rgba3,body_name,name"
)
MESH_ROW = "1,1,1.0,1.0,,0,0,0,1,0,0,0,0.5,0.5,0.5,1,base_link,{name}"


def _stl(path: Path, size: float = 0.05) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=(size, size, size)).export(str(path), file_type="stl")


def _robot(tmp_path: Path, name: str = "robot") -> Path:
    """The bundled arm with one mesh row (``meshes/part.stl``); valid."""
    dest = tmp_path / name
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", dest)
    (dest / "mesh.csv").write_text(MESH_HEADER + "\n" + MESH_ROW.format(name="part") + "\n")
    _stl(dest / "meshes" / "part.stl")
    return dest


def _errors(folder: Path) -> list:
    return [p for p in validate_dir(folder) if p.severity == "error"]


def _refused(argv: list[str], capsys: pytest.CaptureFixture[str], *absent: Path) -> str:
    """Run the CLI: exit 2, an ``error:`` first line, no traceback, no output written."""
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith("error: "), err
    assert "Traceback" not in err
    for path in absent:
        assert not path.exists(), path
    return err


def _set_cells(path: Path, row: int, changes: dict[str, str]) -> None:
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    for column, value in changes.items():
        if column not in rows[0]:
            rows[0].append(column)
            for r in rows[1:]:
                r.append("")
        rows[row + 1][rows[0].index(column)] = value
    with path.open("w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)


# --------------------------------------------------------------------- NUL in a path

NUL_PAYLOADS = ["\0", "part\0", "\0part", "pa\0rt", "../\0etc/passwd", "x\0/../../../etc"]


@pytest.mark.parametrize("payload", NUL_PAYLOADS)
@pytest.mark.parametrize("column", ["file", "name"])
def test_nul_in_mesh_path_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], column: str, payload: str
) -> None:
    folder = _robot(tmp_path)
    value = f"meshes/{payload}.stl" if column == "file" else payload
    _set_cells(folder / "mesh.csv", 0, {column: value})
    errors = _errors(folder)
    assert any(
        p.file == "mesh.csv" and p.row == 0 and p.column == column and "NUL" in p.message
        for p in errors
    ), errors
    with pytest.raises(HRDFError):
        HRDF.from_dir(folder)
    out = tmp_path / "out.xml"
    err = _refused(["convert", str(folder), "-o", str(out)], capsys, out)
    assert "mesh.csv" in err and "NUL" in err


@pytest.mark.parametrize("position", [0, 1, 5, -1])
def test_resolve_inside_refuses_nul(tmp_path: Path, position: int) -> None:
    name = list("meshes/part.stl")
    name.insert(position if position >= 0 else len(name), "\0")
    with pytest.raises(UnsafePathError, match="NUL"):
        resolve_inside("".join(name), base=tmp_path, root=tmp_path)


# ---------------------------------------------------------------- CSV field limit


@pytest.mark.parametrize("length", [131_073, 200_000, 1_000_000])
@pytest.mark.parametrize(
    ("table", "column"), [("body.csv", "name"), ("joint.csv", "name"), ("mesh.csv", "name")]
)
def test_csv_cell_over_field_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], table: str, column: str, length: int
) -> None:
    folder = _robot(tmp_path)
    _set_cells(folder / table, 0, {column: "n" * length})
    path = folder / table
    # csv quotes nothing here; a quoted cell takes the csv module's path (with its limit)
    text = path.read_text()
    path.write_text(text.replace("n" * length, '"' + "n" * length + '"'))
    errors = _errors(folder)
    assert any(p.file == table and "line 2" in p.message for p in errors), errors
    out = tmp_path / "out.xml"
    err = _refused(["convert", str(folder), "-o", str(out)], capsys, out)
    assert table in err


# --------------------------------------------------------- robot names that are paths

ROBOT_NAMES = [
    "../../x",
    "..",
    ".",
    "/tmp/abs",
    "a/b/c",
    "a\\b",
    "~",
    "x" * 300,
    "名前",
    " ",
    "-rf",
    "../" * 40 + "etc",
]


@pytest.mark.parametrize("suffix", [".xml", ".urdf"])
@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_robot_name_makes_no_path(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, suffix: str
) -> None:
    from xml.sax.saxutils import quoteattr

    src = tmp_path / "src"
    _stl(src / "m.stl")
    (src / "r.urdf").write_text(
        f"<robot name={quoteattr(name)}><link name='a'><inertial><mass value='1'/>"
        "<inertia ixx='0.01' iyy='0.01' izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial>"
        "<collision><geometry><mesh filename='m.stl'/></geometry></collision></link></robot>"
    )
    out_dir = tmp_path / "out" / "deep"
    out_dir.mkdir(parents=True)
    out = out_dir / f"robot{suffix}"
    before = {p for p in tmp_path.rglob("*") if p.is_file()}
    assert main(["convert", str(src / "r.urdf"), "-o", str(out)]) == 0, capsys.readouterr().err
    written = {p for p in tmp_path.rglob("*") if p.is_file()} - before
    assert written and all(p.is_relative_to(out_dir) for p in written), written
    copies = [p for p in written if p.suffix == ".stl"]
    assert len(copies) == 1 and copies[0].parent.parent == out_dir / "meshes"
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nmesh == 1


# ---------------------------------------------- a mesh MuJoCo refuses: render, view, ...


def _bad_meshes() -> dict[str, bytes]:
    rng = random.Random(19)
    header = b"\0" * 80
    nan_tri = np.zeros(12, "<f4")
    nan_tri[3] = np.nan
    binary_nan = header + (1).to_bytes(4, "little") + nan_tri.tobytes() + b"\0\0"
    cases = {
        "empty": b"",
        "ascii-empty": b"solid x\nendsolid x\n",
        "truncated": header + (1000).to_bytes(4, "little") + b"\0" * 10,
        "nan-vertex": binary_nan,
    }
    for seed in range(3):
        cases[f"random{seed}"] = bytes(rng.randrange(256) for _ in range(300 + 97 * seed))
    return cases


BAD_MESHES = _bad_meshes()


@pytest.mark.parametrize("kind", sorted(BAD_MESHES))
def test_mesh_mujoco_refuses_is_bad_input_everywhere(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str
) -> None:
    from robotwright.scene.load import load_source

    folder = _robot(tmp_path)
    (folder / "meshes" / "part.stl").write_bytes(BAD_MESHES[kind])
    assert any(p.file == "mesh.csv" and p.row == 0 for p in _errors(folder))
    picture = tmp_path / "p.png"
    err = _refused(
        ["render", str(folder), "-o", str(picture), "--backend", "software"], capsys, picture
    )
    assert "part.stl" in err
    with pytest.raises(RobotwrightError, match="part.stl"):
        load_source(str(folder))
    for argv in (["convert", str(folder)], ["export", str(folder)]):
        for suffix in (".xml", ".urdf", ""):
            if argv[0] == "export" and not suffix:
                continue
            out = tmp_path / f"out_{argv[0]}{suffix}"
            err = _refused([*argv, "-o", str(out)], capsys, out)
            assert "part.stl" in err


@pytest.mark.parametrize("kind", sorted(BAD_MESHES))
def test_urdf_with_mesh_mujoco_refuses_renders_no_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str
) -> None:
    """A URDF mesh without triangles is dropped with a note naming it (the picture is
    drawn without it); one MuJoCo refuses (a NaN vertex) is bad input."""
    (tmp_path / "m.stl").write_bytes(BAD_MESHES[kind])
    (tmp_path / "r.urdf").write_text(
        "<robot name='r'><link name='a'><inertial><mass value='1'/>"
        "<inertia ixx='0.01' iyy='0.01' izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial>"
        "<collision><geometry><mesh filename='m.stl'/></geometry></collision></link></robot>"
    )
    picture = tmp_path / "p.png"
    argv = ["render", str(tmp_path / "r.urdf"), "-o", str(picture), "--backend", "software"]
    if kind == "nan-vertex":
        err = _refused(argv, capsys, picture)
        assert "m.stl" in err and "not finite" in err
        return
    assert main([*argv, "-v"]) == 0
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert "collision dropped" in err and "m.stl" in err
    assert picture.read_bytes().startswith(b"\x89PNG")


# ------------------------------------------------------------------------- MUJOCO_GL


@pytest.mark.parametrize("platform", ["osmesa", "not-a-platform", "glx"])
def test_software_render_ignores_unusable_mujoco_gl(tmp_path: Path, platform: str) -> None:
    picture = tmp_path / "arm.png"
    env = {**os.environ, "MUJOCO_GL": platform}
    argv = ["render", "arm6", "-o", str(picture), "--backend", "software"]
    done = subprocess.run(
        [sys.executable, "-m", "robotwright", *argv],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
    assert picture.read_bytes().startswith(b"\x89PNG")


# ------------------------------------------------------------------ FilePatternCfg


def _pattern_files(folder: Path) -> dict[str, Path]:
    """Malformed pattern files, each written into ``folder``."""
    fmt_header = b"\x93NUMPY\x01\x00"
    declared = "{'descr': '<f8', 'fortran_order': False, 'shape': (1000000000000, 2), }"
    declared = declared.ljust(118) + "\n"
    raw: dict[str, bytes] = {
        "empty.npy": b"",
        "bomb.npy": fmt_header
        + len(declared).to_bytes(2, "little")
        + declared.encode()
        + b"\0" * 64,
        "latin1.csv": b"az,el\n\xff\xfe1,2\n",
        "garbage.npy": bytes(random.Random(7).randrange(256) for _ in range(200)),
    }
    for name, data in raw.items():
        (folder / name).write_bytes(data)
    np.save(folder / "objects.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True)
    np.save(folder / "strings.npy", np.array([["a", "b"]]))
    np.save(folder / "complex.npy", np.array([[1j, 0.2]]))
    np.save(folder / "records.npy", np.zeros(3, dtype=[("a", "f8"), ("b", "f8")]))
    np.save(folder / "bools.npy", np.ones((2, 2), bool))
    (folder / "truncated.npy").write_bytes((folder / "complex.npy").read_bytes()[:60])
    np.savez(folder / "archive.npz", a=np.zeros((2, 2)))
    (folder / "archive.npz").rename(folder / "archive.npy")
    os.mkfifo(folder / "fifo.csv")
    (folder / "folder.csv").mkdir()
    return {p.name: p for p in folder.iterdir()}


def test_pattern_file_errors_are_sensor_errors(tmp_path: Path) -> None:
    from robotwright.sensors.patterns import FilePatternCfg

    files = _pattern_files(tmp_path)
    assert len(files) == 13
    for name, path in sorted(files.items()):
        with pytest.raises(SensorError) as info:
            FilePatternCfg(path=path)
        assert name in str(info.value), name
    with pytest.raises(SensorError, match="not found"):
        FilePatternCfg(path=tmp_path / "missing.npy")


@pytest.mark.parametrize("dtype", [np.float64, np.float32, np.int32])
def test_pattern_file_real_arrays_still_load(tmp_path: Path, dtype: type) -> None:
    from robotwright.sensors.patterns import FilePatternCfg

    angles = np.array([[0, 0], [1, 1], [-1, 0]], dtype=dtype)
    np.save(tmp_path / "p.npy", angles)
    cfg = FilePatternCfg(path=tmp_path / "p.npy")
    assert np.array_equal(cfg._angles, angles.astype(np.float64))


# --------------------------------------------------------------------- height fields


@pytest.mark.parametrize(("nrow", "ncol"), [(2, 2), (7, 300), (1500, 1500), (3000, 40), (5, 9000)])
def test_hfield_drawn_within_cap(nrow: int, ncol: int) -> None:
    from robotwright.scene.geometry import MAX_HFIELD_DRAWN, hfield_surface

    xml = (
        f"<mujoco><asset><hfield name='h' nrow='{nrow}' ncol='{ncol}' size='1 2 0.5 0.1'/>"
        "</asset><worldbody><geom type='hfield' hfield='h'/></worldbody></mujoco>"
    )
    model = mujoco.MjModel.from_xml_string(xml)
    heights = np.random.default_rng(nrow * ncol).random(nrow * ncol)
    model.hfield_data[:] = heights
    vertices, faces = hfield_surface(model, 0)
    assert len(vertices) <= max(MAX_HFIELD_DRAWN, nrow * ncol if nrow * ncol <= 4 else 0)
    if nrow * ncol <= MAX_HFIELD_DRAWN:
        assert len(vertices) == nrow * ncol
    assert faces.min() >= 0 and faces.max() < len(vertices)
    # the whole extent is drawn, corners at their own heights
    assert np.isclose(vertices[:, 0].min(), -1) and np.isclose(vertices[:, 0].max(), 1)
    assert np.isclose(vertices[:, 1].min(), -2) and np.isclose(vertices[:, 1].max(), 2)
    grid = heights.reshape(nrow, ncol) * 0.5
    for corner_row, corner_col, x, y in ((0, 0, -1, -2), (-1, -1, 1, 2)):
        at = np.flatnonzero(np.isclose(vertices[:, 0], x) & np.isclose(vertices[:, 1], y))
        assert np.isclose(vertices[at[0], 2], grid[corner_row, corner_col], atol=1e-6)


# ------------------------------------------ tables MuJoCo refuses: export and validate

#: (table, row, changes): each passes the table checks and MuJoCo refuses the model.
MUJOCO_REFUSES = [
    ("joint.csv", 0, {"range0": "1", "range1": "1"}),
    ("joint.csv", 3, {"range0": "-0.5", "range1": "-0.5"}),
    ("actuator.csv", 0, {"d_gain": "-20"}),
    ("actuator.csv", 2, {"d_gain": "-1e-3"}),
    ("simple_geom.csv", 0, {"contact_type": "99999999999"}),
    ("simple_geom.csv", 1, {"contact_affinity": "99999999999"}),
]


@pytest.mark.parametrize("suffix", [".xml", ".urdf"])
@pytest.mark.parametrize("command", ["export", "convert"])
@pytest.mark.parametrize(("table", "row", "changes"), MUJOCO_REFUSES)
def test_export_refuses_model_mujoco_refuses(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    table: str,
    row: int,
    changes: dict[str, str],
    command: str,
    suffix: str,
) -> None:
    folder = tmp_path / "robot"
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", folder)
    _set_cells(folder / table, row, changes)
    errors = _errors(folder)
    assert errors, "validate must call it invalid"
    out = tmp_path / f"out{suffix}"
    err = _refused([command, str(folder), "-o", str(out)], capsys, out)
    assert "MuJoCo refuses" in err or table in err


FUZZ_VALUES = ["0", "-1", "-0.0", "1e-30", "1e30", "1e300", "-1e300", "0.5", "-100", "nan", "inf"]
FUZZ_TABLES = ["body.csv", "joint.csv", "simple_geom.csv", "actuator.csv", "site.csv"]


def _mutations(seed: int, count: int) -> list[tuple[str, int, str, str]]:
    rng = random.Random(seed)
    out = []
    for _ in range(count):
        table = rng.choice(FUZZ_TABLES)
        with (BUNDLED_ROBOTS_DIR / "arm6" / table).open(newline="") as f:
            rows = list(csv.reader(f))
        numeric = [h for h in rows[0] if h not in ("name", "body_name", "joint_name", "type", "id")]
        out.append(
            (table, rng.randrange(len(rows) - 1), rng.choice(numeric), rng.choice(FUZZ_VALUES))
        )
    return out


@pytest.mark.parametrize(("table", "row", "column", "value"), _mutations(19, 30))
def test_fuzzed_tables_validate_and_export_agree_with_mujoco(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    table: str,
    row: int,
    column: str,
    value: str,
) -> None:
    folder = tmp_path / "robot"
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", folder)
    _set_cells(folder / table, row, {column: value})
    valid = not _errors(folder)
    out = tmp_path / "out.xml"
    code = main(["export", str(folder), "-o", str(out)])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert code == (0 if valid else 2), err
    assert out.exists() == valid
    if valid:
        mujoco.MjModel.from_xml_path(str(out))
