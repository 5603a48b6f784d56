"""MuJoCo Menagerie's robots by name (the mujoco-menagerie package's registry): those on
disk load in every command, one not downloaded gets one line saying how to fetch it.
The tests lay out a Menagerie folder themselves (``MENAGERIE_ROOT``); nothing is
downloaded."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

menagerie = pytest.importorskip("mujoco_menagerie", reason="mujoco-menagerie not installed")

ROBOT = """<mujoco model="{name}">
  <worldbody>
    <body name="base" pos="0 0 0.5">
      <freejoint name="root"/>
      <geom type="box" size="0.2 0.1 0.05" mass="5"/>
      <body name="leg" pos="0.15 0 -0.05">
        <joint name="hip" axis="0 1 0" range="-1 1"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.25" size="0.03" mass="0.5"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor name="hip" joint="hip" gear="10"/></actuator>
</mujoco>
"""


@pytest.fixture
def root(tmp_path, monkeypatch):
    """A Menagerie checkout holding one robot (the registry's first), at its default
    model's file."""
    name = menagerie.names()[0]
    robot = menagerie.get(name)
    file = tmp_path / "menagerie" / name / robot.entry(robot.default_model).file
    file.parent.mkdir(parents=True)
    file.write_text(ROBOT.format(name=name))
    monkeypatch.setenv("MENAGERIE_ROOT", str(tmp_path / "menagerie"))
    return name, file


def _run(*args):
    return subprocess.run(
        [sys.executable, "-m", "robotwright", *args],
        capture_output=True,
        text=True,
        env=os.environ.copy(),
    )


def test_a_menagerie_robot_on_disk_loads_by_name(root):
    from robotwright.catalog import find_entry
    from robotwright.sources import load_robot

    name, file = root
    entry = find_entry(name)
    assert entry is not None and entry.source == "menagerie" and entry.path == file
    hrdf = load_robot(name)
    assert [j.name for j in hrdf.joints if j.type != "free"] == ["hip"]
    info = _run("info", f"menagerie:{name}")  # the SOURCE:NAME form works too
    assert info.returncode == 0, info.stderr
    assert "2 bodies" in info.stdout


def test_robots_lists_the_registry_saying_what_is_on_disk(root):
    name, file = root
    run = _run("robots", "--source", "menagerie")
    assert run.returncode == 0, run.stderr
    rows = [ln.split() for ln in run.stdout.splitlines()[1:-1]]
    assert len(rows) == len(menagerie.names())
    on_disk = {r[0] for r in rows if "(not downloaded)" not in " ".join(r)}
    assert on_disk == {name}


def test_a_robot_not_downloaded_says_how_to_fetch_it(root, monkeypatch):
    missing = menagerie.names()[1]
    monkeypatch.delenv("MENAGERIE_ROOT")
    monkeypatch.setenv("MENAGERIE_CACHE_DIR", str(root[1].parents[2] / "empty-cache"))
    run = _run("info", missing)
    assert run.returncode == 2
    lines = [ln for ln in run.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, run.stderr
    assert f"prefetch {missing}" in lines[0] and "Traceback" not in run.stderr
