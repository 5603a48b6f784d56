"""Actuators made for a URDF (``actuators="position" | "velocity" | "auto"``): compiled
MuJoCo actuators compared with the values read from the URDF itself (``<limit>``,
``<transmission>``, ros2_control ``<command_interface>``) and the user's gains."""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.cli import main
from robotwright.errors import ConversionError
from robotwright.parsers import urdf_to_hrdf, urdf_to_hrdf_with_warnings
from robotwright.parsers.urdf.reader import URDFOptions
from robotwright.proof.roundtrip.run import our_mjcf_model

PYBULLET = Path(__file__).resolve().parents[2] / ".testdata/pybullet/pybullet_data"


def _real(rel: str) -> Path:
    path = PYBULLET / rel
    if not path.is_file():
        pytest.skip(f"pybullet test data not fetched (run python tools/fetch_test_data.py): {path}")
    return path


def _limits(path: Path) -> dict[str, dict[str, float]]:
    """Each joint's <limit> attributes, read independently of the parser."""
    out = {}
    for j in ET.parse(path).getroot().iter("joint"):
        limit = j.find("limit")
        if limit is not None:
            out[j.get("name")] = {k: float(v) for k, v in limit.attrib.items()}
    return out


def _actuated_joint(model: mujoco.MjModel, i: int) -> str:
    return model.joint(model.actuator_trnid[i, 0]).name


# ---------------------------------------------------------------- real robots
@pytest.mark.realdata
def test_a1_effort_transmissions_make_torque_motors() -> None:
    path = _real("a1/a1.urdf")
    model = our_mjcf_model(urdf_to_hrdf(path, actuators="auto"))
    limits = _limits(path)
    assert model.nu == 12
    for i in range(model.nu):
        joint = _actuated_joint(model, i)
        effort = limits[joint]["effort"]
        assert model.actuator_biastype[i] == mujoco.mjtBias.mjBIAS_NONE
        np.testing.assert_array_equal(model.actuator_ctrlrange[i], [-effort, effort])
        assert model.actuator_gear[i, 0] == 1.0 and model.actuator_gainprm[i, 0] == 1.0


@pytest.mark.realdata
def test_xarm6_position_transmissions_make_pd_servos_with_user_gains(caplog) -> None:
    path = _real("xarm/xarm6_robot.urdf")
    caplog.set_level(logging.INFO, logger="robotwright.parsers")
    result = urdf_to_hrdf_with_warnings(
        path,
        actuators="auto",
        actuator_gains={"joint[1-3]": (300.0, 30.0), "joint*": (100.0, 5.0)},
        balance_inertia=True,
    )
    model = our_mjcf_model(result.hrdf)
    limits = _limits(path)
    assert model.nu == 6
    for i in range(model.nu):
        joint = _actuated_joint(model, i)
        kp, kv = (300.0, 30.0) if joint in ("joint1", "joint2", "joint3") else (100.0, 5.0)
        lim = limits[joint]
        assert model.actuator_gainprm[i, 0] == kp
        np.testing.assert_array_equal(model.actuator_biasprm[i, :3], [0.0, -kp, -kv])
        np.testing.assert_array_equal(model.actuator_ctrlrange[i], [lim["lower"], lim["upper"]])
        np.testing.assert_array_equal(model.actuator_forcerange[i], [-lim["effort"], lim["effort"]])
        assert model.actuator_forcelimited[i] and model.actuator_ctrllimited[i]
    messages = [str(w) for w in result.warnings]
    assert any("mechanicalReduction 100 not applied" in m for m in messages)
    assert not any("<transmission> element(s) dropped" in m for m in messages)
    made = [r.getMessage() for r in caplog.records if "position actuator" in r.getMessage()]
    assert len(made) == 6 and "gains of 'joint[1-3]'" in made[0]


# ---------------------------------------------------------------- written here
ROBOT = """<robot name="r">
  <link name="base"><inertial><mass value="3"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  {links}
  {extra}
</robot>"""

LINK = """<link name="l{i}"><inertial><origin xyz="0 0 0.1"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j{i}" type="{type}"><parent link="{parent}"/><child link="l{i}"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-{lo}" upper="{hi}" effort="{effort}" velocity="{vel}"/></joint>"""


def _robot(tmp_path: Path, extra: str = "", types: tuple[str, ...] = ("revolute",) * 4) -> Path:
    links = "\n".join(
        LINK.format(
            i=i,
            type=t,
            parent="base" if i == 0 else f"l{i - 1}",
            lo=0.5 + i,
            hi=1.25 + i,
            effort=10 * (i + 1),
            vel=2 + i,
        )
        for i, t in enumerate(types)
    )
    path = tmp_path / "urdf" / "r.urdf"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(ROBOT.format(links=links, extra=extra))
    return path


def test_position_mode_gains_per_pattern(tmp_path: Path) -> None:
    path = _robot(tmp_path)
    gains = {"j0": (500.0, 0.0), "j[12]": (200.0, 4.0), "*": (50.0, 1.5)}
    model = our_mjcf_model(urdf_to_hrdf(path, actuators="position", actuator_gains=gains))
    assert model.nu == 4
    expected = [(500.0, 0.0), (200.0, 4.0), (200.0, 4.0), (50.0, 1.5)]
    for i, (kp, kv) in enumerate(expected):
        assert _actuated_joint(model, i) == f"j{i}"
        np.testing.assert_array_equal(model.actuator_gainprm[i, :1], [kp])
        np.testing.assert_array_equal(model.actuator_biasprm[i, :3], [0.0, -kp, -kv])
        np.testing.assert_allclose(model.actuator_ctrlrange[i], [-(0.5 + i), 1.25 + i])
        np.testing.assert_array_equal(model.actuator_forcerange[i], [-10 * (i + 1), 10 * (i + 1)])


def test_velocity_mode(tmp_path: Path) -> None:
    path = _robot(tmp_path, types=("revolute", "prismatic"))
    model = our_mjcf_model(urdf_to_hrdf(path, actuators="velocity", actuator_gains={"*": (0, 7)}))
    assert model.nu == 2
    for i in range(2):
        assert model.actuator_gainprm[i, 0] == 7.0
        np.testing.assert_array_equal(model.actuator_biasprm[i, :3], [0.0, 0.0, -7.0])
        np.testing.assert_array_equal(model.actuator_ctrlrange[i], [-(2 + i), 2 + i])
        np.testing.assert_array_equal(model.actuator_forcerange[i], [-10 * (i + 1), 10 * (i + 1)])


ROS2_CONTROL = """<ros2_control name="arm" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="j0"><command_interface name="position">
        <param name="min">-0.25</param><param name="max">0.75</param></command_interface>
      <state_interface name="position"/></joint>
    <joint name="j1"><command_interface name="velocity"/><command_interface name="effort"/>
    </joint>
    <joint name="j2"><command_interface name="effort"/></joint>
  </ros2_control>"""


def test_auto_reads_ros2_control_command_interfaces(tmp_path: Path) -> None:
    path = _robot(tmp_path, extra=ROS2_CONTROL)
    result = urdf_to_hrdf_with_warnings(path, actuators="auto", actuator_gains={"*": (80.0, 2.0)})
    model = our_mjcf_model(result.hrdf)
    assert [_actuated_joint(model, i) for i in range(model.nu)] == ["j0", "j1", "j2"]
    # j0: position servo, control range from the interface's min/max params
    np.testing.assert_array_equal(model.actuator_ctrlrange[0], [-0.25, 0.75])
    np.testing.assert_array_equal(model.actuator_biasprm[0, :3], [0.0, -80.0, -2.0])
    # j1: the first command interface (velocity) decides; kv = 2, ctrl +-velocity limit
    np.testing.assert_array_equal(model.actuator_biasprm[1, :3], [0.0, 0.0, -2.0])
    np.testing.assert_array_equal(model.actuator_ctrlrange[1], [-3.0, 3.0])
    # j2: effort -> torque motor, +-effort
    assert model.actuator_biastype[2] == mujoco.mjtBias.mjBIAS_NONE
    np.testing.assert_array_equal(model.actuator_ctrlrange[2], [-30.0, 30.0])
    messages = [str(w) for w in result.warnings]
    assert any("2 command interfaces" in m and "j1" in m for m in messages)
    assert any("j3" in m and "get no actuator" in m for m in messages)  # no interface


def test_missing_gain_is_an_error_naming_the_joint(tmp_path: Path) -> None:
    path = _robot(tmp_path)
    with pytest.raises(ConversionError, match="no pattern of actuator_gains") as exc:
        urdf_to_hrdf(path, actuators="position", actuator_gains={"j[01]": (10, 1)})
    text = str(exc.value)
    assert "'j2'" in text and "'j3'" in text and "'j0'" not in text


def test_options_are_validated() -> None:
    with pytest.raises(ValueError, match="actuators='servo'"):
        URDFOptions(actuators="servo")
    with pytest.raises(ValueError, match=r"actuator_gains\['x'\]"):
        URDFOptions(actuators="position", actuator_gains={"x": (-1.0, 0.0)})
    with pytest.raises(ValueError, match=r"actuator_gains\['x'\]"):
        URDFOptions(actuators="position", actuator_gains={"x": ("a", 0)})
    assert URDFOptions(actuator_gains={"x": 5}).actuator_gains == {"x": (5.0, 0.0)}


def test_cli_position_actuators(tmp_path: Path, capsys) -> None:
    path = _robot(tmp_path)
    out = tmp_path / "r.xml"
    argv = ["convert", str(path), "--actuators", "position", "--actuator-gain", "j*=60,3"]
    assert main([*argv, "-o", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nu == 4
    np.testing.assert_array_equal(model.actuator_gainprm[:, 0], [60.0] * 4)
    np.testing.assert_array_equal(model.actuator_biasprm[:, 2], [-3.0] * 4)
    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:
        main([*argv[:-1], "j*=fast", "-o", str(tmp_path / "b.xml")])
    assert exc.value.code == 2
    assert "expected PATTERN=KP,KV" in capsys.readouterr().err
    # gains missing: a clear error, exit 2, no output
    assert (
        main(["convert", str(path), "--actuators", "position", "-o", str(tmp_path / "c.xml")]) == 2
    )
    assert "no pattern of actuator_gains" in capsys.readouterr().err
    assert not (tmp_path / "c.xml").exists()
