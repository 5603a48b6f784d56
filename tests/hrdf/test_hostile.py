"""Hostile HRDF folders (issue 11): mesh paths that leave the robot folder, files that
are links out of it, FIFOs, oversized and non-UTF-8 files. Each is refused with an error
naming the file, row and column, and no command writes any output."""

from __future__ import annotations

import csv
import dataclasses
import os
import shutil
import threading
from pathlib import Path

import pytest
import trimesh
import yaml

from robotwright._inputs import MAX_TABLE_BYTES
from robotwright._paths import trusted_asset_roots
from robotwright.cli import main
from robotwright.errors import (
    ConversionWarning,
    GeneratorError,
    HRDFError,
    Problem,
    UnsafePathError,
)
from robotwright.generators import MJCFHumanoidGenerator
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


@pytest.fixture
def outside(tmp_path: Path) -> Path:
    """A folder next to the robot holding a file an attacker wants copied."""
    folder = tmp_path / "outside"
    _stl(folder / "secret.stl", size=0.3)
    return folder


@pytest.fixture
def robot(tmp_path: Path) -> Path:
    """The bundled arm with one mesh row (``meshes/part.stl``); valid."""
    dest = tmp_path / "robot"
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", dest)
    (dest / "mesh.csv").write_text(MESH_HEADER + "\n" + MESH_ROW.format(name="part") + "\n")
    _stl(dest / "meshes" / "part.stl")
    assert [p for p in validate_dir(dest) if p.severity == "error"] == []
    return dest


def _set_mesh(folder: Path, *, name: str | None = None, file: str | None = None) -> None:
    path = folder / "mesh.csv"
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    if name is not None:
        rows[1][rows[0].index("name")] = name
    if file is not None:
        rows[0].append("file")
        rows[1].append(file)
    with path.open("w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)


def _errors(folder: Path) -> list[Problem]:
    problems = [p for p in validate_dir(folder) if p.severity == "error"]
    with pytest.raises(HRDFError):
        HRDF.from_dir(folder)
    return problems


def _escape(problems: list[Problem], column: str) -> Problem:
    hits = [
        p
        for p in problems
        if p.file == "mesh.csv" and p.row == 0 and p.column == column and "escapes" in p.message
    ]
    assert len(hits) == 1, problems
    return hits[0]


def _no_output_from_commands(folder: Path, tmp_path: Path, capsys) -> str:
    """convert (to MJCF, URDF, HRDF) and export --copy-meshes all exit 2, write nothing."""
    outs = tmp_path / "outs"
    outs.mkdir()
    runs = [
        ["validate", str(folder)],
        ["convert", str(folder), "-o", str(outs / "r.xml")],
        ["convert", str(folder), "-o", str(outs / "r.urdf")],
        ["convert", str(folder), "-o", str(outs / "copy")],
        ["export", str(folder), "--copy-meshes", "-o", str(outs / "e.xml")],
        ["export", str(folder), "--format", "urdf", "--copy-meshes", "-o", str(outs / "e.urdf")],
        ["things", str(folder), str(outs / "t.xml")],
    ]
    err = ""
    for argv in runs:
        code = main(argv)
        captured = capsys.readouterr()
        assert code == (1 if argv[0] == "validate" else 2), (argv, captured)
        err += captured.out + captured.err
    assert list(outs.iterdir()) == []
    return err


def test_absolute_file_cell_is_refused_everywhere(robot, outside, tmp_path, capsys) -> None:
    secret = outside / "secret.stl"
    _set_mesh(robot, file=str(secret))
    p = _escape(_errors(robot), "file")
    assert str(secret) in p.message and str(robot) in p.message
    text = _no_output_from_commands(robot, tmp_path, capsys)
    assert "mesh.csv: row 0: column 'file'" in text


def test_dotdot_in_name_column_is_refused(robot, outside, tmp_path, capsys) -> None:
    _set_mesh(robot, name="../../outside/secret")
    p = _escape(_errors(robot), "name")
    assert str(outside / "secret.stl") in p.message
    _no_output_from_commands(robot, tmp_path, capsys)


def test_relative_file_cell_climbing_out_is_refused(robot, outside) -> None:
    _set_mesh(robot, file="../outside/secret.stl")
    _escape(_errors(robot), "file")


def test_symlink_inside_meshes_pointing_out_is_refused(robot, outside, tmp_path, capsys):
    (robot / "meshes" / "part.stl").unlink()
    (robot / "meshes" / "part.stl").symlink_to(outside / "secret.stl")
    p = _escape(_errors(robot), "name")
    assert "through a symbolic link" in p.message
    _no_output_from_commands(robot, tmp_path, capsys)


def test_meshes_folder_that_is_a_symlink_out_is_refused(robot, outside, tmp_path, capsys):
    shutil.rmtree(robot / "meshes")
    shutil.copy(outside / "secret.stl", outside / "part.stl")
    (robot / "meshes").symlink_to(outside, target_is_directory=True)
    p = _escape(_errors(robot), "name")
    assert "through a symbolic link" in p.message
    _no_output_from_commands(robot, tmp_path, capsys)


def test_symlink_that_stays_inside_the_folder_is_fine(robot) -> None:
    (robot / "assets").mkdir()
    os.replace(robot / "meshes" / "part.stl", robot / "assets" / "part.stl")
    (robot / "meshes" / "part.stl").symlink_to(Path("..") / "assets" / "part.stl")
    assert [p for p in validate_dir(robot) if p.severity == "error"] == []


def test_save_of_a_model_pointing_out_writes_nothing(robot, outside, tmp_path) -> None:
    hrdf = HRDF.from_dir(robot)
    bad = dataclasses.replace(hrdf.meshes[0], file=str(outside / "secret.stl"))
    model = dataclasses.replace(hrdf, meshes=[bad])
    with pytest.raises(HRDFError) as exc:
        model.save(tmp_path / "saved")
    assert any(p.column == "file" and "escapes" in p.message for p in exc.value.problems)
    assert not (tmp_path / "saved").exists()
    # The generators check the same path before they reference or copy it.
    with pytest.raises(HRDFError, match="escapes the robot folder"):
        MJCFHumanoidGenerator.from_hrdf(model)


def test_generator_copier_rechecks_the_path(robot, outside, tmp_path) -> None:
    """A robot whose mesh became a link out after loading (a race) is not copied."""
    gen = MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(robot))
    (robot / "meshes" / "part.stl").unlink()
    (robot / "meshes" / "part.stl").symlink_to(outside / "secret.stl")
    with pytest.raises(UnsafePathError, match="mesh 'part'"):
        gen.export(tmp_path / "out" / "r.xml", copy_meshes=True)
    assert not (tmp_path / "out").exists()


def test_trusted_asset_root_is_an_explicit_opt_in(robot, outside, tmp_path, capsys) -> None:
    _set_mesh(robot, file=str(outside / "secret.stl"))
    hrdf = HRDF.from_dir(robot, asset_roots=[outside])
    assert hrdf.mesh_source(hrdf.meshes[0]) == (outside / "secret.stl").resolve()
    # save copies the trusted file *into* the new folder, under meshes/.
    saved = hrdf.save(tmp_path / "saved")
    assert (saved / "meshes" / "secret.stl").read_bytes() == (outside / "secret.stl").read_bytes()
    assert HRDF.from_dir(saved).meshes[0].file == "meshes/secret.stl"
    with trusted_asset_roots([outside]):
        assert HRDF.from_dir(robot).meshes[0].file == str(outside / "secret.stl")
    from robotwright.proof.convert import convert

    convert(robot, tmp_path / "api.xml", asset_roots=[outside])
    assert (tmp_path / "meshes").is_dir()
    with pytest.raises(HRDFError):
        convert(robot, tmp_path / "api2.xml")
    out = tmp_path / "r.xml"
    assert main(["convert", str(robot), "-o", str(out), "--asset-root", str(outside)]) == 0
    assert main(["validate", str(robot), "--asset-root", str(outside)]) == 0
    capsys.readouterr()
    assert main(["validate", str(robot), "--asset-root", str(tmp_path / "nope")]) == 2
    assert "trusted asset root is not a folder" in capsys.readouterr().err


def test_two_trusted_files_with_one_name_are_both_kept(robot, outside, tmp_path) -> None:
    _stl(outside / "b" / "secret.stl", size=0.1)
    hrdf = HRDF.from_dir(robot, asset_roots=[outside])
    first = dataclasses.replace(hrdf.meshes[0], name="a", file=str(outside / "secret.stl"))
    second = dataclasses.replace(hrdf.meshes[0], name="b", file=str(outside / "b/secret.stl"))
    saved = dataclasses.replace(hrdf, meshes=[first, second]).save(tmp_path / "saved")
    back = HRDF.from_dir(saved)
    assert [m.file for m in back.meshes] == ["meshes/secret.stl", "meshes/secret_1.stl"]
    assert (saved / "meshes/secret_1.stl").read_bytes() == (outside / "b/secret.stl").read_bytes()


@pytest.mark.parametrize("name", ["meta.yaml", "body.csv", "extra.xml", "joint_mapping.yaml"])
def test_folder_file_that_links_out_is_refused(robot, tmp_path, name) -> None:
    """extra.xml or joint_mapping.yaml linked to a file elsewhere would be copied on save."""
    target = tmp_path / "elsewhere" / name
    target.parent.mkdir()
    if (robot / name).exists():
        shutil.copy(robot / name, target)
        (robot / name).unlink()
    else:
        target.write_text("<mujoco/>\n" if name.endswith(".xml") else "a: 1\n")
    (robot / name).symlink_to(target)
    problems = validate_dir(robot)
    assert any(p.file == name and "link out of the robot folder" in p.message for p in problems)


def _in_thread(fn, timeout: float = 20.0):
    result: dict = {}

    def run() -> None:
        result["value"] = fn()

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(timeout)
    assert not thread.is_alive(), "hung"
    return result["value"]


@pytest.mark.parametrize("name", ["body.csv", "meta.yaml", "extra.xml"])
def test_fifo_in_place_of_a_file_does_not_hang(robot, name) -> None:
    (robot / name).unlink(missing_ok=True)
    os.mkfifo(robot / name)
    problems = _in_thread(lambda: validate_dir(robot))
    assert any(p.file == name and "FIFO" in p.message for p in problems), problems


def test_fifo_as_mesh_file_is_not_copied(robot, tmp_path) -> None:
    (robot / "meshes" / "part.stl").unlink()
    os.mkfifo(robot / "meshes" / "part.stl")
    problems = _in_thread(lambda: validate_dir(robot))
    assert any(p.file == "mesh.csv" and "not a regular file" in p.message for p in problems)


def test_oversized_table_is_refused_before_reading(robot) -> None:
    with (robot / "joint.csv").open("r+b") as f:
        f.truncate(MAX_TABLE_BYTES + 1)  # sparse: costs no disk
    problems = validate_dir(robot)
    assert any(p.file == "joint.csv" and "limit" in p.message for p in problems), problems


@pytest.mark.parametrize("name", ["meta.yaml", "extra.xml", "joint_mapping.yaml", "body.csv"])
def test_non_utf8_file_is_a_located_error(robot, name) -> None:
    (robot / name).write_bytes(b"\xff\xfe<mujoco/>\n")
    problems = [p for p in validate_dir(robot) if p.file == name]
    assert any("not UTF-8" in p.message and "offset 0" in p.message for p in problems), problems


def test_deeply_nested_meta_yaml_is_refused(robot) -> None:
    meta = yaml.safe_load((robot / "meta.yaml").read_text())
    text = yaml.safe_dump(meta) + "deep: " + "[" * 50_000 + "]" * 50_000 + "\n"
    (robot / "meta.yaml").write_text(text)
    problems = validate_dir(robot)
    # Our depth check or PyYAML's own (6.0.4 and later) may refuse it first: either way
    # a problem located at meta.yaml, never a RecursionError.
    assert [p.file for p in problems] == ["meta.yaml"], problems


# ------------------------------------------------------------------ XML injection

INJECTED = 'gyro site="tool0"/><body name="INJECTED"><geom size="1"/></body><gyro site="tool0"'


def _edit_sensor(folder: Path, column: str, value: str) -> None:
    path = folder / "sensor.csv"
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    rows[1][rows[0].index(column)] = value
    with path.open("w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)


@pytest.mark.parametrize("column", ["type", "objtype"])
def test_sensor_cells_written_as_xml_names_are_vocabulary(robot, tmp_path, capsys, column):
    """sensor.csv 'type' becomes an element name and (for non-frame sensors) 'objtype'
    an attribute name: markup in them used to reach the MJCF (<body name="INJECTED">
    compiled)."""
    if column == "objtype":
        _edit_sensor(robot, "type", "gyro")
    _edit_sensor(robot, column, INJECTED)
    problems = _errors(robot)
    assert any(
        p.file == "sensor.csv" and p.row == 0 and p.column == column and "expected" in p.message
        for p in problems
    ), problems
    out = tmp_path / "out.xml"
    assert main(["export", str(robot), "-o", str(out)]) == 2
    assert "sensor.csv: row 0: column" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")
def test_xml_writer_refuses_a_name_that_is_not_an_xml_name(robot) -> None:
    """Second line of defence: a model that skipped validation still cannot inject."""
    hrdf = HRDF.from_dir(robot)
    bad = dataclasses.replace(hrdf.sensors[0], type=INJECTED)
    gen = MJCFHumanoidGenerator().load(dataclasses.replace(hrdf, sensors=[bad]), validate=False)
    with pytest.raises(GeneratorError, match="cannot write .* as an XML element or attribute"):
        gen.export()


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ('<mujoco><asset><mesh name="x" file="/etc/passwd"/></asset></mujoco>', "<asset>"),
        ('<mujoco><tendon><include file="/etc/passwd"/></tendon></mujoco>', "names a file"),
        ("<mujoco><worldbody><body/></worldbody></mujoco>", "section not allowed"),
        ('<!DOCTYPE m [<!ENTITY e "x">]><mujoco><tendon/></mujoco>', "not safe"),
        ("<mujoco>" + "<tendon>" * 5000 + "</tendon>" * 5000 + "</mujoco>", "nested deeper"),
    ],
    ids=["asset", "include", "worldbody", "entity", "deep"],
)
def test_extra_xml_holds_only_its_sections(robot, tmp_path, capsys, extra, message) -> None:
    (robot / "extra.xml").write_text(extra)
    problems = _errors(robot)
    assert any(p.file == "extra.xml" and message in str(p) for p in problems), problems
    out = tmp_path / "out.xml"
    assert main(["export", str(robot), "-o", str(out)]) == 2
    capsys.readouterr()
    assert not out.exists()


# ------------------------------------------------------------------ deep trees


def _chain(n: int) -> HRDF:
    hrdf = HRDF.from_dir(BUNDLED_ROBOTS_DIR / "arm6")
    body = hrdf.bodies[1]
    bodies = [hrdf.bodies[0]] + [
        dataclasses.replace(body, name=f"b{i}", parent=i - 1) for i in range(1, n)
    ]
    joint = hrdf.joints[0]
    joints = [dataclasses.replace(joint, name=f"j{i}", body=f"b{i}") for i in range(1, n)]
    return HRDF(name="chain", bodies=bodies, joints=joints, meta=hrdf.meta)


def test_chain_of_10000_bodies_saves_loads_and_exports_urdf(tmp_path) -> None:
    from robotwright.generators import URDFHumanoidGenerator

    folder = _chain(10_000).save(tmp_path / "chain")
    hrdf = HRDF.from_dir(folder)
    assert len(hrdf.bodies) == 10_000
    with pytest.warns(ConversionWarning, match="armature"):  # URDF has no armature
        text = URDFHumanoidGenerator.from_hrdf(hrdf).export(tmp_path / "chain.urdf")
    assert text.count("<link ") == 10_001  # and MuJoCo's "world"


def test_chain_deeper_than_mujoco_reads_is_refused_for_mjcf(tmp_path, capsys) -> None:
    folder = _chain(1_000).save(tmp_path / "chain")
    for argv in (
        ["export", str(folder), "-o", str(tmp_path / "c.xml")],
        ["convert", str(folder), "-o", str(tmp_path / "c.xml")],
        ["things", str(folder), str(tmp_path / "c.xml")],
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert "'b496'" in err and "nested 497 bodies deep" in err and "at most 496" in err
    assert not (tmp_path / "c.xml").exists()
    # 496 nested bodies are written, and MuJoCo reads them.
    model = MJCFHumanoidGenerator.from_hrdf(_chain(496)).to_model()
    assert model.nbody == 497


# ------------------------------------------------------------ wrong types in meta.yaml


@pytest.mark.parametrize(
    ("key", "value", "column"),
    [
        ("simulator_config.timestep", "abc", "simulator_config.timestep"),
        ("simulator_config.timestep", [1], "simulator_config.timestep"),
        ("simulator_config.integrator", "bogus", "simulator_config.integrator"),
        ("simulator_config.integrator", ["RK4"], "simulator_config.integrator"),
        ("simulator_config.ground.type", "box", "simulator_config.ground.type"),
        ("simulator_config.ground.friction", [1], "simulator_config.ground.friction"),
        ("simulator_config.ground.contact_type", 3.4e38, "simulator_config.ground.contact_type"),
        ("base_joint_name", ["a"], "base_joint_name"),
        ("imu_config_list", [{"body_name": ["base_link"]}], "imu_config_list[0]"),
        (
            "imu_config_list",
            [{"body_name": "base_link", "value": True}],
            "imu_config_list[0].value",
        ),
    ],
)
def test_wrong_type_in_meta_yaml_is_a_located_error(robot, capsys, key, value, column) -> None:
    meta = yaml.safe_load((robot / "meta.yaml").read_text())
    *parents, last = key.split(".")
    node = meta
    for part in parents:
        node = node[part]
    node[last] = value
    (robot / "meta.yaml").write_text(yaml.safe_dump(meta))
    problems = _errors(robot)
    assert any(p.file == "meta.yaml" and p.column == column for p in problems), problems
    assert main(["validate", str(robot)]) == 1
    assert f"meta.yaml: column '{column}'" in capsys.readouterr().out
