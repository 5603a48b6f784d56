"""``convert`` to MJCF writes the robot and nothing else: no floor appears under a robot
that falls freely in its source (issue: a converted go2 stood on a floor its source did
not have). ``--scene`` adds floor, light and sky, and says so."""

from __future__ import annotations

import subprocess
import sys

import mujoco
import numpy as np

FALLING = """<mujoco model="faller">
  <worldbody>
    <body name="trunk" pos="0 0 0.5">
      <freejoint name="root"/>
      <geom type="box" size="0.2 0.1 0.05" mass="6"/>
      <body name="leg" pos="0.2 0 -0.05">
        <joint name="hip" axis="0 1 0" range="-1 1" damping="0.1"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="0.5"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def _trajectory(path, steps=200):
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qvel[6] = 1.0  # swing the leg
    out = []
    for _ in range(steps):
        mujoco.mj_step(model, data)
        out.append(data.qpos.copy())
    return model, np.array(out)


def _convert(tmp_path, *extra):
    return subprocess.run(
        [sys.executable, "-m", "robotwright", "convert", "faller.xml", "-o", "out.xml", *extra],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )


def test_convert_writes_the_robot_alone_and_it_falls_as_before(tmp_path):
    (tmp_path / "faller.xml").write_text(FALLING)
    run = _convert(tmp_path, "--strict")
    assert run.returncode == 0, run.stderr
    source, before = _trajectory(tmp_path / "faller.xml")
    result, after = _trajectory(tmp_path / "out.xml")
    assert result.ngeom == source.ngeom == 2  # no floor
    assert not (result.geom_type == mujoco.mjtGeom.mjGEOM_PLANE).any()
    assert result.nlight == 0
    assert np.abs(after - before).max() < 1e-9  # 200 steps, same initial state
    assert after[-1, 2] < 0.0  # it fell through where a floor would have held it


def test_scene_is_added_only_when_asked_and_said(tmp_path):
    (tmp_path / "faller.xml").write_text(FALLING)
    run = _convert(tmp_path, "--scene", "-v")
    assert run.returncode == 0, run.stderr
    result = mujoco.MjModel.from_xml_path(str(tmp_path / "out.xml"))
    assert (result.geom_type == mujoco.mjtGeom.mjGEOM_PLANE).sum() == 1
    assert "scene added" in run.stderr and "floor" in run.stderr
    hrdf = subprocess.run(
        [sys.executable, "-m", "robotwright", "convert", "faller.xml", "-o", "folder", "--scene"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert hrdf.returncode == 2 and "applies to MJCF output" in hrdf.stderr
    assert "Traceback" not in hrdf.stderr and not (tmp_path / "folder").exists()
