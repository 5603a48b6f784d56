"""Quiet by default: one summary line of notes at most, a closed pipe ends quietly."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from robotwright.cli import main


@pytest.mark.parametrize("robot", ["mini_humanoid", "arm6"])
def test_bundled_robots_export_with_one_summary_line(robot: str, tmp_path: Path, capsys) -> None:
    """A bundled robot's actuator speed limits have no MJCF field: exporting it to MJCF
    says so in one line (each with -v), not one line per actuator."""
    out = tmp_path / f"{robot}.xml"
    assert main(["export", robot, "-o", str(out)]) == 0
    assert out.is_file()
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "peak_velocity" in err[0] and "-v lists each" in err[0]


@pytest.mark.parametrize("robot", ["mini_humanoid", "arm6"])
def test_bundled_robots_render_with_no_notes(robot: str, tmp_path: Path, capsys) -> None:
    """render only shows the robot: what an export would not keep is not its business."""
    out = tmp_path / f"{robot}.png"
    assert main(["render", robot, "-o", str(out), "--size", "96x72"]) == 0
    assert out.is_file()
    # Nothing but the progress of a slow drawing (a busy machine): "  drawing X (2 s)".
    err = capsys.readouterr().err.splitlines()
    assert [ln for ln in err if not re.match(r"^  drawing \S+ \(\d[^()]*\)$", ln)] == []


def _closed_reader(argv: list[str]) -> subprocess.CompletedProcess:
    """Run ``robotwright ARGV`` with stdout a pipe whose reader is already gone."""
    import os

    read, write = os.pipe()
    os.close(read)
    try:
        return subprocess.run(
            [sys.executable, "-m", "robotwright", *argv],
            stdout=write,
            stderr=subprocess.PIPE,
            text=True,
            timeout=300,
        )
    finally:
        os.close(write)


@pytest.mark.parametrize(
    "argv", [["info", "mini_humanoid"], ["robots"], ["--version"], ["export", "--help"]]
)
def test_closed_pipe_ends_quietly_with_exit_0(argv: list[str]) -> None:
    """``robotwright info mini_humanoid | head -5``: the reader leaves, the command ends
    with exit 0 and says nothing (no 'Broken pipe', no traceback)."""
    done = _closed_reader(argv)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""


def test_bad_input_still_exits_2_with_a_closed_pipe(tmp_path: Path) -> None:
    """A closed stdout does not hide an error: it still goes to stderr with exit 2."""
    done = _closed_reader(["info", str(tmp_path / "missing")])
    assert done.returncode == 2
    assert done.stderr.startswith("error: ")


_COMPOSITE_EXAMPLE = """
from robotwright.generators import MJCFGeneratorComposite, MJCFHumanoidGenerator, Placement

scene = MJCFGeneratorComposite(
    {
        "h": MJCFHumanoidGenerator.from_robot_name("mini_humanoid"),
        "arm": MJCFHumanoidGenerator.from_robot_name("arm6"),
    },
    placements={"arm": Placement(parent="h", frame="back_mount")},
)
model = scene.to_model()
print(model.nbody)
"""


def test_readme_composite_example_shows_one_line_per_warning() -> None:
    """The README's Python composite example: Python shows each robot's losses as one
    line (head and counts), not one line per value."""
    done = subprocess.run(
        [sys.executable, "-W", "default", "-c", _COMPOSITE_EXAMPLE],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    shown = [line for line in done.stderr.splitlines() if "ConversionWarning" in line]
    assert len(shown) == 2
    assert "20 value(s) not written: 20 actuator.csv peak_velocity" in shown[0]
    assert "6 value(s) not written: 6 actuator.csv peak_velocity" in shown[1]
    # The display lines and the source line Python shows under each, nothing else.
    assert len(done.stderr.splitlines()) == 4
    assert int(done.stdout) > 20


def test_conversion_warning_keeps_every_value_for_programs() -> None:
    """str() of the same warning lists every value, one line each."""
    import warnings

    from robotwright.errors import ConversionWarning
    from robotwright.generators import MJCFHumanoidGenerator

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        MJCFHumanoidGenerator.from_robot_name("mini_humanoid").generate()
    (w,) = [w for w in caught if issubclass(w.category, ConversionWarning)]
    text = str(w.message)
    assert len(text.splitlines()) == 21
    assert all(f"row {i}: column 'peak_velocity'" in text for i in range(20))
    assert f"{w.message}".count("\n") == 0
    assert f"{w.message}".endswith("str(warning) lists each")


def test_a_warning_without_a_list_is_shown_as_it_is() -> None:
    from robotwright.errors import ConversionWarning

    w = ConversionWarning("robot 'x': one thing\nover two lines")
    assert f"{w}" == str(w)


#: An OBJ whose faces name texture coordinates for some corners only: MuJoCo warns that
#: it discards them (through its C warning handler, not an error).
_PARTIAL_UV_OBJ = """v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
vt 0 0
vt 1 0
f 1/1 2/2 3
f 1/1 2/2 4
f 1/1 3 4
f 2 3 4
"""
_MESH_URDF = (
    '<robot name="r"><link name="base"><inertial><mass value="1"/>'
    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
    '<visual><geometry><mesh filename="tri.obj"/></geometry></visual></link></robot>'
)


def test_mujoco_warnings_are_notes_of_the_one_summary_line(
    tmp_path: Path, monkeypatch, capsys
) -> None:
    """MuJoCo's own warnings join the notes' summary line (each with -v) and leave no
    MUJOCO_LOG.TXT in the working folder; MuJoCo's handler is put back after."""
    import mujoco

    (tmp_path / "tri.obj").write_text(_PARTIAL_UV_OBJ)
    (tmp_path / "r.urdf").write_text(_MESH_URDF)
    monkeypatch.chdir(tmp_path)
    before = mujoco.get_mju_user_warning()
    # MuJoCo 4's OBJ decoder warns about this file; MuJoCo 3.11's reads it silently. What
    # the installed MuJoCo says of it, asked directly, is what the notes must hold.
    said: list[str] = []
    mujoco.set_mju_user_warning(said.append)
    try:
        mujoco.MjModel.from_xml_string(
            f'<mujoco><asset><mesh name="m" file="{tmp_path / "tri.obj"}"/></asset>'
            '<worldbody><body><geom type="mesh" mesh="m" mass="1"/></body></worldbody></mujoco>'
        )
    finally:
        mujoco.set_mju_user_warning(before)
    assert main(["export", "r.urdf", "-o", "r.xml", "--no-scene"]) == 0
    err = capsys.readouterr().err.splitlines()
    if said:
        assert len(err) == 1 and "1 MuJoCo warning" in err[0] and "-v lists each" in err[0]
    else:
        assert err == []
    assert main(["export", "r.urdf", "-o", "r2.xml", "--no-scene", "-v"]) == 0
    err = capsys.readouterr().err.splitlines()
    listed = [line for line in err if line.startswith("note: MuJoCo: ")]
    assert len(listed) == len(said) and all("tri.obj" in line for line in listed)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
    assert mujoco.get_mju_user_warning() is before
    assert mujoco.MjModel.from_xml_path("r.xml").nmesh == 1


def test_view_of_a_bundled_robot_prints_at_most_one_note_line(tmp_path: Path) -> None:
    """view only shows the robot: no conversion notes without -v, and what the page
    cannot draw in one line. Waits for the address line (readiness), not for a time."""
    import signal

    with (tmp_path / "stderr.txt").open("w+") as errors:
        proc = subprocess.Popen(
            [sys.executable, "-m", "robotwright", "view", "mini_humanoid", "--port", "0"],
            stdout=subprocess.PIPE,
            stderr=errors,
            text=True,
        )
        try:
            assert proc.stdout is not None
            for line in proc.stdout:
                if "Ctrl-C" in line:
                    break
            proc.send_signal(signal.SIGINT)
            proc.communicate(timeout=600)  # a hang guard only
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        errors.seek(0)
        err = errors.read()
    assert proc.returncode == 0, err
    assert "conversion note" not in err and "peak_velocity" not in err
    assert len(err.splitlines()) <= 1, err
