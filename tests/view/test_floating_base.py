"""``--floating-base`` on every command (a URDF's root gets a free joint), and a floating
robot shown standing on the floor: its lowest collision geom at z = 0, not its root."""

from __future__ import annotations

import subprocess
import sys

import mujoco
import pytest

from robotwright._mjmodel import lowest_collision_point
from robotwright.scene.load import load_source
from robotwright.sources import given_source_options

LEGGED = """<robot name="legged">
  <link name="base">
    <inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.2 0.1"/></geometry></collision>
  </link>
  <link name="leg">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -0.15"/><geometry><box size="0.05 0.05 0.3"/></geometry></collision>
  </link>
  <joint name="hip" type="revolute">
    <parent link="base"/><child link="leg"/><origin xyz="0.15 0 -0.05"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="10" velocity="5"/>
  </joint>
</robot>
"""


def _pose_bottom(scene) -> float:
    data = mujoco.MjData(scene.model)
    data.qpos[:] = scene.initial_qpos()
    mujoco.mj_kinematics(scene.model, data)
    return lowest_collision_point(scene.model, data)


def test_floating_base_stands_on_the_floor(tmp_path):
    (tmp_path / "legged.urdf").write_text(LEGGED)
    with given_source_options({"floating_base": True}):
        scene = load_source(str(tmp_path / "legged.urdf"))
    model = scene.model
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    # The leg reaches 0.05 + 0.3 m below the root: the root is raised to 0.35 m.
    assert _pose_bottom(scene) == pytest.approx(0.0, abs=1e-9)
    assert scene.initial_qpos()[2] == pytest.approx(0.35, abs=1e-9)
    assert any("placed up by 0.35 m" in n for n in scene.notes), scene.notes


def test_fixed_base_stays_where_the_file_puts_it(tmp_path):
    (tmp_path / "legged.urdf").write_text(LEGGED)
    scene = load_source(str(tmp_path / "legged.urdf"))
    assert not (scene.model.jnt_type == mujoco.mjtJoint.mjJNT_FREE).any()
    assert _pose_bottom(scene) == pytest.approx(-0.35, abs=1e-9)
    assert not any("placed" in n for n in scene.notes)


def test_floating_base_on_the_command_line(tmp_path):
    (tmp_path / "legged.urdf").write_text(LEGGED)
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", "convert", "legged.urdf", "-o", "out.xml",
         "--floating-base"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "out.xml"))
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    bad = subprocess.run(
        [sys.executable, "-m", "robotwright", "info", "arm6", "--floating-base"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert bad.returncode == 2 and "--floating-base" in bad.stderr
    assert "Traceback" not in bad.stderr
