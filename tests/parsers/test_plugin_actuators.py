"""Plugin actuators (MuJoCo's ``mujoco.pid``) travel through HRDF as the plugin they
are, with their instance's configuration, instead of becoming plain motors; the proof
compares the plugin and its configuration."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robotwright.generators import MJCFHumanoidGenerator
from robotwright.hrdf.model import HRDF
from robotwright.parsers import mjcf_to_hrdf
from robotwright.proof.compare import compare_models
from robotwright.proof.convert import convert

PID = """<mujoco model="pid">
  <extension>
    <plugin plugin="mujoco.pid">
      <instance name="pid1">
        <config key="kp" value="40"/>
        <config key="ki" value="5"/>
        <config key="kd" value="2"/>
      </instance>
    </plugin>
  </extension>
  <worldbody>
    <body name="arm">
      <joint name="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/>
      <body name="tip" pos="0.3 0 0">
        <joint name="wrist" axis="0 1 0"/>
        <geom type="sphere" size="0.04" mass="0.3"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="plain" joint="wrist" gear="1"/>
    <plugin name="held" joint="hinge" plugin="mujoco.pid" instance="pid1" actdim="1"/>
    <plugin name="inline" joint="wrist" plugin="mujoco.pid" actdim="0">
      <config key="kp" value="4"/>
    </plugin>
  </actuator>
</mujoco>
"""


def _settle(path_or_model, steps=1500):
    model = (
        path_or_model
        if isinstance(path_or_model, mujoco.MjModel)
        else mujoco.MjModel.from_xml_path(str(path_or_model))
    )
    data = mujoco.MjData(model)
    data.ctrl[:] = [0.0, 0.5, -0.2]  # PID targets [rad]; the motor idle
    out = []
    for _ in range(steps):
        mujoco.mj_step(model, data)
        out.append(data.qpos.copy())
    return model, np.array(out)


@pytest.fixture
def pid_file(tmp_path):
    path = tmp_path / "pid.xml"
    path.write_text(PID)
    return path


def test_pid_actuators_convert_as_plugins_and_hold_the_same_pose(pid_file, tmp_path):
    messages = convert(pid_file, tmp_path / "out.xml")
    assert not any("differ" in m or "plugin instance" in m for m in messages), messages
    source, before = _settle(pid_file)
    result, after = _settle(tmp_path / "out.xml")
    assert list(result.actuator_plugin >= 0) == [False, True, True]
    assert list(result.actuator_actnum) == list(source.actuator_actnum) == [0, 1, 0]
    assert not compare_models(source, result)
    assert np.abs(after - before).max() < 1e-9  # same dynamics, step by step
    assert after[-1, 0] == pytest.approx(0.5, abs=0.05)  # held near its target (a motor spins)


def test_pid_actuators_survive_an_hrdf_folder(pid_file, tmp_path):
    mjcf_to_hrdf(pid_file).save(tmp_path / "pid_hrdf")
    loaded = HRDF.from_dir(tmp_path / "pid_hrdf")
    MJCFHumanoidGenerator.from_hrdf(loaded).export(tmp_path / "again.xml", add_scene=False)
    source, before = _settle(pid_file)
    _, after = _settle(tmp_path / "again.xml")
    assert np.abs(after - before).max() < 1e-9


def test_proof_sees_a_changed_pid_gain(pid_file, tmp_path):
    convert(pid_file, tmp_path / "out.xml")
    text = (tmp_path / "out.xml").read_text().replace('value="40"', 'value="41"')
    changed = mujoco.MjModel.from_xml_string(text)
    found = compare_models(mujoco.MjModel.from_xml_path(str(pid_file)), changed)
    assert [d.field for d in found] == ["actuator_plugin"]
    assert "'40'" in found[0].source and "'41'" in found[0].result


def test_two_robots_with_pid_instances_compose(pid_file, tmp_path):
    """Prefixed names reach the plugin instances and the actuators naming them."""
    hrdf = mjcf_to_hrdf(pid_file)
    text = MJCFHumanoidGenerator.from_hrdf(hrdf).export(None, prefix="left", add_scene=False)
    assert 'instance name="left_pid1"' in text and 'instance="left_pid1"' in text
    mujoco.MjModel.from_xml_string(text)  # compiles: the instance is found by its name
