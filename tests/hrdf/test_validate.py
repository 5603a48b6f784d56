"""Every bad input gets a clear error: one test per check, on a broken copy of a robot."""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
import yaml

from robotwright.errors import HRDFError, Problem
from robotwright.generators.compiles import validate_dir
from robotwright.hrdf import HRDF
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR


def edit_csv(path: Path, fn: Callable[[list[list[str]]], None]) -> None:
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    fn(rows)
    with path.open("w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)


def set_cell(path: Path, row: int, column: str, value: str) -> None:
    def fn(rows: list[list[str]]) -> None:
        rows[row + 1][rows[0].index(column)] = value

    edit_csv(path, fn)


def edit_meta(folder: Path, fn: Callable[[dict], None]) -> None:
    meta = yaml.safe_load((folder / "meta.yaml").read_text())
    fn(meta)
    (folder / "meta.yaml").write_text(yaml.safe_dump(meta))


@pytest.fixture
def arm(tmp_path: Path) -> Path:
    """A copy of the bundled arm (robotwright format, valid)."""
    dest = tmp_path / "arm6"
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", dest)
    assert [p for p in validate_dir(dest) if p.severity == "error"] == []
    return dest


@pytest.fixture
def synth(tmp_path: Path, synth_hrdf_dir: Path) -> Path:
    """A copy of the hurodes-written synthetic robot (hurodes format, one mesh)."""
    dest = tmp_path / "synth"
    shutil.copytree(synth_hrdf_dir, dest)
    return dest


def errors_of(folder: Path) -> list[Problem]:
    problems = [p for p in validate_dir(folder) if p.severity == "error"]
    with pytest.raises(HRDFError) as exc:
        HRDF.from_dir(folder)
    assert [str(p) for p in exc.value.problems] == [str(p) for p in problems]
    return problems


def has(
    problems: list[Problem], file: str, text: str, row: int | None = None, column: str | None = None
) -> bool:
    return any(
        p.file == file
        and text in p.message
        and (row is None or p.row == row)
        and (column is None or p.column == column)
        for p in problems
    )


def test_missing_meta(arm: Path) -> None:
    (arm / "meta.yaml").unlink()
    problems = errors_of(arm)
    assert "meta.yaml is missing" in problems[0].message


def test_missing_body_csv(arm: Path) -> None:
    (arm / "body.csv").unlink()
    assert has(errors_of(arm), "body.csv", "required file is missing")


def test_missing_required_column(arm: Path) -> None:
    def drop_axis1(rows: list[list[str]]) -> None:
        i = rows[0].index("axis1")
        for r in rows:
            del r[i]

    edit_csv(arm / "joint.csv", drop_axis1)
    assert has(errors_of(arm), "joint.csv", "required column is missing", column="axis1")


def test_non_numeric_cell(arm: Path) -> None:
    set_cell(arm / "body.csv", 3, "mass", "heavy")
    assert has(errors_of(arm), "body.csv", "expected a number, got 'heavy'", row=3, column="mass")


def test_non_integer_cell(arm: Path) -> None:
    set_cell(arm / "simple_geom.csv", 0, "contact_type", "1.5")
    assert has(
        errors_of(arm), "simple_geom.csv", "expected an integer", row=0, column="contact_type"
    )


def test_empty_cell_without_default(arm: Path) -> None:
    set_cell(arm / "body.csv", 2, "mass", "")
    assert has(errors_of(arm), "body.csv", "no default", row=2, column="mass")


def test_empty_range_is_error_in_hurodes_folder(synth: Path) -> None:
    set_cell(synth / "joint.csv", 0, "range0", "")
    set_cell(synth / "joint.csv", 0, "range1", "")
    assert has(errors_of(synth), "joint.csv", "hurodes would invent", row=0, column="range0")


def test_empty_range_means_unlimited_in_robotwright_folder(arm: Path) -> None:
    set_cell(arm / "joint.csv", 1, "range0", "")
    set_cell(arm / "joint.csv", 1, "range1", "")
    assert HRDF.from_dir(arm).joints[1].range is None


def test_no_root(arm: Path) -> None:
    edit_meta(arm, lambda m: m.update(body_parent_id=[1, 0, 1, 2, 3, 4, 5]))
    problems = errors_of(arm)
    assert has(problems, "meta.yaml", "no root body", column="body_parent_id")
    assert has(problems, "meta.yaml", "form a cycle")


def test_two_roots_are_a_scene_and_only_a_root_may_float(arm: Path) -> None:
    edit_meta(arm, lambda m: m.update(body_parent_id=[-1, 0, -1, 2, 3, 4, 5]))
    assert not [p for p in validate_dir(arm) if p.severity == "error"]
    assert HRDF.from_dir(arm).root_indices == [0, 2]
    import dataclasses

    from robotwright.hrdf.validate import check_model

    scene = HRDF.from_dir(arm)
    on_forearm = dataclasses.replace(scene.joints[2], type="free")  # not a root
    scene.joints[2] = on_forearm
    assert has(check_model(scene), "joint.csv", "only a root body may float")


def test_parent_out_of_range(arm: Path) -> None:
    edit_meta(arm, lambda m: m.update(body_parent_id=[-1, 0, 1, 2, 3, 4, 9]))
    assert has(errors_of(arm), "meta.yaml", "parent id 9: expected -1 or 0..6")


def test_cycle(arm: Path) -> None:
    edit_meta(arm, lambda m: m.update(body_parent_id=[-1, 0, 1, 4, 3, 4, 5]))
    problems = errors_of(arm)
    assert has(problems, "meta.yaml", "form a cycle") or has(
        problems, "meta.yaml", "its own parent"
    )


def test_parent_list_length(arm: Path) -> None:
    edit_meta(arm, lambda m: m.update(body_parent_id=[-1, 0, 1]))
    assert has(errors_of(arm), "meta.yaml", "body_parent_id has 3 entries, body.csv has 7 rows")


def test_id_inconsistent_with_row_order(arm: Path) -> None:
    set_cell(arm / "body.csv", 2, "id", "5")
    assert has(
        errors_of(arm), "body.csv", "id 5 does not match the row position 2", row=2, column="id"
    )


def test_duplicate_body_name(arm: Path) -> None:
    set_cell(arm / "body.csv", 2, "name", "shoulder_link")
    problems = errors_of(arm)
    assert has(problems, "body.csv", "duplicate body name 'shoulder_link'")


def test_duplicate_joint_name(arm: Path) -> None:
    set_cell(arm / "joint.csv", 2, "name", "shoulder_pan_joint")
    assert has(errors_of(arm), "joint.csv", "duplicate joint name 'shoulder_pan_joint'")


def test_joint_unknown_body(arm: Path) -> None:
    set_cell(arm / "joint.csv", 1, "body_name", "ghost")
    assert has(errors_of(arm), "joint.csv", "unknown body 'ghost'", row=1, column="body_name")


def test_actuator_unknown_joint(arm: Path) -> None:
    set_cell(arm / "actuator.csv", 4, "joint_name", "ghost_joint")
    assert has(
        errors_of(arm), "actuator.csv", "unknown joint 'ghost_joint'", row=4, column="joint_name"
    )


def test_geom_unknown_body(arm: Path) -> None:
    set_cell(arm / "simple_geom.csv", 3, "body_name", "ghost")
    assert has(errors_of(arm), "simple_geom.csv", "unknown body 'ghost'", row=3)


def test_mesh_unknown_body(synth: Path) -> None:
    set_cell(synth / "mesh.csv", 0, "body_name", "ghost")
    assert has(errors_of(synth), "mesh.csv", "unknown body 'ghost'", row=0)


def test_site_and_sensor_references(arm: Path) -> None:
    set_cell(arm / "sensor.csv", 0, "objname", "nowhere")
    assert has(errors_of(arm), "sensor.csv", "reads unknown site 'nowhere'", row=0)


def test_quaternion_not_normalized(arm: Path) -> None:
    set_cell(arm / "body.csv", 1, "quat0", "0.5")
    problems = errors_of(arm)
    assert has(problems, "body.csv", "has norm 0.5: expected 1", row=1, column="quat")


def test_quaternion_tolerance_accepts_rounding(arm: Path) -> None:
    set_cell(arm / "body.csv", 1, "quat0", "1.00001")
    assert [p for p in validate_dir(arm) if p.severity == "error"] == []


def test_moving_body_without_mass(arm: Path) -> None:
    # MuJoCo refuses a body with joints whose own (and welded) mass is zero.
    set_cell(arm / "body.csv", 4, "mass", "0.0")
    assert has(errors_of(arm), "body.csv", "a body with joints needs mass", row=4)


def test_inertia_not_positive(arm: Path) -> None:
    set_cell(arm / "body.csv", 4, "diag_inertia1", "-0.001")
    assert has(
        errors_of(arm),
        "body.csv",
        "expected finite numbers, all >= 0",
        row=4,
        column="diag_inertia",
    )


@pytest.mark.parametrize(
    ("column", "expected"),
    [
        ("mass", "mass inf kg: expected a finite"),
        ("diag_inertia", "expected finite numbers, all >= 0"),
    ],
)
def test_infinite_mass_or_inertia_of_a_robot_built_in_python(
    arm: Path, column: str, expected: str
) -> None:
    """Tables refuse 'inf' when read; a robot built in Python (or by a parser) is checked
    too: an infinite mass passed as ">= 0" and was written out."""
    import dataclasses
    import math

    from robotwright.hrdf.model import HRDF
    from robotwright.hrdf.validate import check_model

    robot = HRDF.from_dir(arm)
    body = robot.bodies[2]
    d = body.diag_inertia
    value = math.inf if column == "mass" else (d[0], math.inf, d[2])
    robot.bodies[2] = dataclasses.replace(body, **{column: value})
    problems = [p for p in check_model(robot) if p.severity == "error"]
    assert any(expected in p.message and p.row == 2 and p.column == column for p in problems)


def test_inertia_triangle_inequality(arm: Path) -> None:
    set_cell(arm / "body.csv", 4, "diag_inertia0", "0.001")
    set_cell(arm / "body.csv", 4, "diag_inertia1", "0.001")
    set_cell(arm / "body.csv", 4, "diag_inertia2", "0.01")
    assert has(errors_of(arm), "body.csv", "triangle inequality", row=4)


def test_joint_range_inverted(arm: Path) -> None:
    set_cell(arm / "joint.csv", 0, "range0", "3.0")
    assert has(errors_of(arm), "joint.csv", "range lower 3.0 > upper 2.9", row=0)


def test_mesh_file_missing(synth: Path) -> None:
    (synth / "meshes" / "box.stl").unlink()
    assert has(errors_of(synth), "mesh.csv", "does not exist", row=0)


def test_mesh_path_escaping_folder(synth: Path) -> None:
    edit_meta(synth, lambda m: m.update(format_version="robotwright-hrdf/1"))

    def add_file(rows: list[list[str]]) -> None:
        rows[0].append("file")
        rows[1].append("../../etc/passwd")

    edit_csv(synth / "mesh.csv", add_file)
    assert has(errors_of(synth), "mesh.csv", "escapes the robot folder", row=0, column="file")


def test_unknown_column_and_key_are_warnings(arm: Path) -> None:
    def add_col(rows: list[list[str]]) -> None:
        rows[0].append("colour_name")
        for r in rows[1:]:
            r.append("blue")

    edit_csv(arm / "body.csv", add_col)
    edit_meta(arm, lambda m: m.update(vendor="acme"))
    problems = validate_dir(arm)
    assert [p.severity for p in problems] == ["warning", "warning"]
    assert has(problems, "body.csv", "unknown column", column="colour_name")
    assert has(problems, "meta.yaml", "unknown key", column="vendor")
    with pytest.warns(UserWarning) as record:
        HRDF.from_dir(arm)
    messages = [str(w.message) for w in record]
    assert any("colour_name" in m for m in messages) and any("vendor" in m for m in messages)


def test_all_problems_reported_at_once(arm: Path) -> None:
    set_cell(arm / "body.csv", 1, "mass", "-2")
    set_cell(arm / "joint.csv", 2, "body_name", "ghost")
    set_cell(arm / "actuator.csv", 0, "joint_name", "nothing")
    problems = errors_of(arm)
    assert has(problems, "body.csv", "mass -2.0 kg")
    assert has(problems, "joint.csv", "unknown body 'ghost'")
    assert has(problems, "actuator.csv", "unknown joint 'nothing'")


def test_cli_validate_reports_and_fails(arm: Path) -> None:
    set_cell(arm / "body.csv", 1, "mass", "-2")
    set_cell(arm / "joint.csv", 0, "range0", "9")
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", "validate", str(arm)], capture_output=True, text=True
    )
    assert run.returncode == 1
    assert (
        "error: body.csv: row 1: column 'mass': mass -2.0 kg: expected a finite number >= 0"
        in run.stdout
    )
    assert "error: joint.csv: row 0: column 'range0'" in run.stdout
    assert "2 error(s)" in run.stdout


def test_cli_validate_ok(arm: Path) -> None:
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", "validate", str(arm)], capture_output=True, text=True
    )
    assert run.returncode == 0 and "valid" in run.stdout


def test_massless_body_without_joints_is_allowed(arm: Path) -> None:
    # A frame link (e.g. a URDF tool or sensor frame) welded to its parent: no joints.
    def add_body(rows: list[list[str]]) -> None:
        row = rows[-1][:]
        h = rows[0]
        for col in ("diag_inertia0", "diag_inertia1", "diag_inertia2", "mass"):
            row[h.index(col)] = "0.0"
        row[h.index("name")] = "tool_frame"
        row[h.index("id")] = str(len(rows) - 1)
        rows.append(row)

    edit_csv(arm / "body.csv", add_body)
    edit_meta(arm, lambda m: m.update(body_parent_id=[*m["body_parent_id"], 6]))
    assert HRDF.from_dir(arm).body("tool_frame").mass == 0.0


def test_moving_leaf_body_needs_mass_and_inertia(arm: Path) -> None:
    set_cell(arm / "body.csv", 6, "mass", "0.0")  # wrist_3_link moves: needs mass
    assert has(errors_of(arm), "body.csv", "a body with joints needs mass", row=6, column="mass")


def test_a_robot_with_an_infinite_position_is_not_saved(arm: Path, tmp_path: Path) -> None:
    """Every table number of a robot built in memory must be finite to be saved: the
    folder's reader would refuse it. Named by table, row and CSV column."""
    import dataclasses
    import math

    from robotwright.hrdf.model import HRDF

    robot = HRDF.from_dir(arm)
    body = robot.bodies[3]
    robot.bodies[3] = dataclasses.replace(body, pos=(body.pos[0], body.pos[1], math.inf))
    with pytest.raises(HRDFError) as info:
        robot.save(tmp_path / "out")
    assert has(
        info.value.problems, "body.csv", "expected a finite number, got 'inf'", row=3, column="pos2"
    )
    assert not (tmp_path / "out").exists()
