"""Quiet by default: one summary line of notes at most, a closed pipe ends quietly."""

from __future__ import annotations

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
    assert capsys.readouterr().err == ""


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
