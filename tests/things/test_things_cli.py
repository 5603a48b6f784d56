"""``robotwright things``: MJCF -> MJCF, MJCF -> HRDF, HRDF -> MJCF."""

from __future__ import annotations

import mujoco

from robotwright.cli import main
from robotwright.hrdf import HRDF

from ._compare import assert_same_model

_ARM = """<mujoco model="arm"><compiler angle="degree"/>
<default><joint damping="0.2" range="-90 90"/></default>
<worldbody><body name="base"><geom type="cylinder" size="0.05 0.02"/>
<body name="link" pos="0 0 0.05"><joint name="j" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.02"/></body></body></worldbody>
<actuator><motor joint="j" ctrlrange="-1 1" gear="30"/></actuator></mujoco>"""


def test_cli_converts_mjcf_and_hrdf(tmp_path, capsys):
    src = tmp_path / "arm.xml"
    src.write_text(_ARM)
    assert main(["things", str(src), str(tmp_path / "out" / "arm.xml")]) == 0
    original = mujoco.MjModel.from_xml_path(str(src))
    assert_same_model(original, mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "arm.xml")))
    assert main(["things", str(src), str(tmp_path / "arm_hrdf")]) == 0
    robot = HRDF.from_dir(tmp_path / "arm_hrdf")
    assert [j.name for j in robot.joints] == ["j"] and robot.joints[0].range[1] > 1.5
    assert main(["things", str(tmp_path / "arm_hrdf"), str(tmp_path / "back.xml")]) == 0
    back = mujoco.MjModel.from_xml_path(str(tmp_path / "back.xml"))
    assert back.nu == 1 and back.body_mass.sum() == original.body_mass.sum()
    assert "arm.xml ->" in capsys.readouterr().out
    assert main(["things", str(tmp_path / "missing.xml"), str(tmp_path / "x.xml")]) == 2
    assert not (tmp_path / "x.xml").exists()
