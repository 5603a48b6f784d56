"""A killed run leaves neither its reader nor its temporaries (issue 38, item 7), and
``xacro.abs_filename`` never writes the robot folder's absolute path (item 8)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from robotwright._confine import confinement
from robotwright._temporaries import prefix, sweep_stale, terminate_like_interrupt

CONFINED = confinement().startswith("landlock")

#: A parent that starts a confined reader which writes its process id, then sleeps.
PARENT = textwrap.dedent(
    """
    import os, sys, tempfile, time
    from robotwright._confine import run_confined
    from robotwright._temporaries import terminate_like_interrupt

    def step():
        with open(os.path.join(tempfile.gettempdir(), "reader.pid"), "w") as fh:
            fh.write(str(os.getpid()))
        time.sleep(120)

    with terminate_like_interrupt():
        try:
            run_confined(step, roots=[sys.argv[1]], what="test")
        except KeyboardInterrupt:
            sys.exit(143)
    """
)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie (dead, not yet reaped by its new parent) counts as gone.
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as fh:
            return fh.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


def _start(tmp_path: Path) -> tuple[subprocess.Popen, int, Path]:
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    env = dict(os.environ, TMPDIR=str(tmp))
    proc = subprocess.Popen([sys.executable, "-c", PARENT, str(tmp_path)], env=env)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        pids = list(tmp.glob("robotwright-read-*/reader.pid"))
        if pids and pids[0].read_text():
            return proc, int(pids[0].read_text()), tmp
        assert proc.poll() is None, "the parent ended before its reader started"
        time.sleep(0.05)
    proc.kill()
    raise AssertionError("the confined reader did not start within 60 s")


def _wait_gone(pid: int, seconds: float = 10) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if not _alive(pid):
            return True
        time.sleep(0.05)
    return False


@pytest.mark.skipif(not CONFINED, reason=f"no confined reader here: {confinement()}")
def test_sigterm_stops_the_reader_and_removes_temporaries(tmp_path) -> None:
    proc, reader, tmp = _start(tmp_path)
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=30) == 143
    assert _wait_gone(reader), "the reader runs on after its parent was terminated"
    assert list(tmp.iterdir()) == []


@pytest.mark.skipif(not CONFINED, reason=f"no confined reader here: {confinement()}")
def test_sigkill_kills_the_reader_and_the_next_start_sweeps(tmp_path) -> None:
    proc, reader, tmp = _start(tmp_path)
    proc.kill()
    proc.wait(timeout=30)
    assert _wait_gone(reader), "the reader runs on under PID 1 after its parent's SIGKILL"
    left = [p.name for p in tmp.iterdir()]
    assert left and all(n.startswith(f"robotwright-read-{proc.pid}-") for n in left)
    assert sweep_stale(str(tmp)) == []  # too recent: it might be another namespace's
    assert sorted(sweep_stale(str(tmp), min_age_s=0)) == sorted(left)
    assert list(tmp.iterdir()) == []


def test_the_sweep_leaves_running_processes_and_other_names_alone(tmp_path) -> None:
    mine = tmp_path / f"{prefix('convert')}abc"
    mine.mkdir()
    other = tmp_path / "robotwright-notes.txt"
    other.write_text("x")
    dead = tmp_path / "robotwright-convert-999999999-abc"  # no such process
    dead.mkdir()
    (dead / "f").write_text("x")
    link = tmp_path / "robotwright-mesh-999999998-x"
    target = tmp_path / "kept"
    target.mkdir()
    (target / "f").write_text("x")
    link.symlink_to(target)
    assert sweep_stale(str(tmp_path)) == []  # all fresh: none older than an hour
    removed = sweep_stale(str(tmp_path), min_age_s=0)
    assert sorted(removed) == sorted([dead.name, link.name])
    assert mine.is_dir() and other.is_file() and (target / "f").is_file()


def test_sigterm_unwinds_like_ctrl_c() -> None:
    # A test runner's worker may have a SIGTERM handler of its own: the command line
    # starts with the default one, so the test does too (and restores the runner's).
    runner = signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        cleaned = []
        with pytest.raises(KeyboardInterrupt), terminate_like_interrupt():
            try:
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(5)
            finally:
                cleaned.append(True)
        assert cleaned == [True]
        assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL
    finally:
        signal.signal(signal.SIGTERM, runner)


def _catches_sigterm(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as fh:
            caught = next(ln for ln in fh if ln.startswith("SigCgt:"))
    except (OSError, StopIteration):
        return False
    return bool(int(caught.split()[1], 16) >> (signal.SIGTERM - 1) & 1)


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="no /proc here")
def test_a_command_terminated_ends_with_one_line(tmp_path) -> None:
    """``robotwright`` itself: SIGTERM during a long command gives 'terminated', exit
    143, no traceback (the grammar count of many links runs for minutes)."""
    env = dict(os.environ, TMPDIR=str(tmp_path))
    cmd = [sys.executable, "-m", "robotwright", "grammar", "count", "--max-links", "12"]
    cmd += ["--enumerate"]
    proc = subprocess.Popen(cmd, env=env, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not _catches_sigterm(proc.pid):  # the command runs: its handler is set
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert "terminated" in err and "Traceback" not in err


XACRO = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="parts/part.xacro"/>
  <link name="${xacro.abs_filename('meshes/x.stl')}">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>
"""
PART = """<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="${abs_filename('y.stl')}">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="j" type="fixed"><parent link="meshes/x.stl"/><child link="parts/y.stl"/></joint>
</robot>
"""


def test_abs_filename_is_relative_to_the_robot_file(tmp_path) -> None:
    pytest.importorskip("xacro", reason="xacro (the test extra) is not installed")
    from robotwright.sources import load_robot

    robot = tmp_path / "robot"
    (robot / "parts").mkdir(parents=True)
    (robot / "r.urdf.xacro").write_text(XACRO, encoding="utf-8")
    (robot / "parts" / "part.xacro").write_text(PART, encoding="utf-8")
    hrdf = load_robot(robot / "r.urdf.xacro")
    names = {b.name for b in hrdf.bodies}
    assert {"meshes/x.stl", "parts/y.stl"} <= names, names
    assert not any(str(tmp_path) in n for n in names)
