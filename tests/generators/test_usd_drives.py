"""The joint drive each MuJoCo actuator defines (what the USD export writes and its
proof expects Newton to read), worked out here by hand from the actuator laws."""

from __future__ import annotations

import math

import mujoco
import pytest

from robotwright.generators.usd_drives import joint_drives

_ARM = """
<mujoco>
  <compiler angle="radian"/>
  <worldbody>
    <body name="a">
      <joint name="servo" type="hinge" axis="0 0 1"/>
      <geom type="capsule" size="0.02" fromto="0 0 0 0.2 0 0" mass="1"/>
      <body name="b" pos="0.2 0 0">
        <joint name="geared" type="hinge" axis="0 1 0"/>
        <geom type="capsule" size="0.02" fromto="0 0 0 0.2 0 0" mass="1"/>
        <body name="c" pos="0.2 0 0">
          <joint name="rail" type="slide" axis="1 0 0" actuatorfrcrange="-3 3"/>
          <geom type="box" size="0.02 0.02 0.02" mass="0.5"/>
          <body name="d">
            <joint name="both" type="hinge" axis="1 0 0"/>
            <joint name="wrist" type="ball"/>
            <geom type="sphere" size="0.02" mass="0.2"/>
            <site name="tip"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="pair"><joint joint="servo" coef="1"/><joint joint="geared" coef="1"/></fixed></tendon>
  <actuator>
    <position name="p" joint="servo" kp="40" kv="2" forcerange="-5 5"/>
    <position name="pg" joint="geared" kp="10" gear="3"/>
    <motor name="m" joint="rail" gear="2" ctrlrange="-4 4"/>
    <position name="bp" joint="both" kp="7"/>
    <velocity name="bv" joint="both" kv="0.5" forcerange="-1 1"/>
    <motor name="on_ball" joint="wrist"/>
    <motor name="on_tendon" tendon="pair"/>
    <motor name="on_site" site="tip"/>
    <general name="filtered" joint="servo" dyntype="filter" dynprm="0.1"/>
    <general name="odd" joint="geared" gainprm="1" biastype="affine" biasprm="0 -2 0"/>
  </actuator>
</mujoco>
"""


@pytest.fixture(scope="module")
def drives():
    return joint_drives(mujoco.MjModel.from_xml_string(_ARM))


def test_position_velocity_and_motor_laws_become_gains_in_joint_units(drives):
    found, _ = drives
    servo = found["servo"]
    assert (servo.axis, servo.kinds, servo.actuators) == ("angular", ["position"], ["p"])
    assert (servo.stiffness, servo.damping, servo.max_force) == (40.0, 2.0, 5.0)
    # gear 3: the joint feels kp * 3 * (ctrl - 3 q), a stiffness of 90 N m/rad.
    assert found["geared"].stiffness == pytest.approx(90.0)
    assert math.isinf(found["geared"].max_force)
    # A motor of gain 1, gear 2 and ctrlrange 4 gives up to 8 N, capped at the joint's 3 N.
    rail = found["rail"]
    assert (rail.axis, rail.kinds, rail.stiffness, rail.damping) == ("linear", ["motor"], 0, 0)
    assert rail.max_force == pytest.approx(3.0)
    # A position and a velocity actuator on one joint add up into one drive; the
    # velocity one's force range bounds its share only, the position one is unbounded.
    both = found["both"]
    assert both.kinds == ["position", "velocity"] and both.actuators == ["bp", "bv"]
    assert (both.stiffness, both.damping) == (7.0, 0.5) and math.isinf(both.max_force)


def test_what_no_drive_holds_is_named_actuator_by_actuator(drives):
    found, notes = drives
    text = "\n".join(notes)
    assert "actuator 'on_ball' drives ball joint 'wrist'" in text
    assert "actuator 'on_tendon' drives a tendon, not a joint" in text
    assert "actuator 'on_site' drives a site, not a joint" in text
    assert "actuator 'filtered' on joint 'servo': no USD drive, its activation dynamics (filter)" in text  # fmt: skip
    assert "actuator 'odd' on joint 'geared': no USD drive, its gain and bias" in text
    assert len(notes) == 5
    assert "wrist" not in found and found["servo"].actuators == ["p"]
