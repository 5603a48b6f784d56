"""The free base a user asks for (``--floating-base``) is not a difference: the proof's
reference, MuJoCo's import of the URDF, gets the same free joint (issue 40, item 3)."""

from __future__ import annotations

import mujoco
import pytest

from robotwright.catalog import find_entry
from robotwright.cli import main

_URDF = """<robot name="hopper">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.02" iyy="0.02" izz="0.02"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="leg"><inertial><origin xyz="0 0 -0.1"/><mass value="0.5"/><inertia ixx="0.002"
    iyy="0.002" izz="0.0005" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -0.1"/><geometry><cylinder radius="0.02" length="0.2"/>
    </geometry></collision></link>
  <joint name="hip" type="continuous"><parent link="base"/><child link="leg"/>
    <origin xyz="0 0 -0.05"/><axis xyz="0 1 0"/></joint>
</robot>
"""


def test_a_requested_free_base_passes_strict(tmp_path, capsys) -> None:
    (tmp_path / "hopper.urdf").write_text(_URDF)
    out = tmp_path / "hopper.xml"
    argv = ["convert", str(tmp_path / "hopper.urdf"), "-o", str(out), "--floating-base"]
    assert main([*argv, "--strict", "-v"]) == 0, capsys.readouterr().err
    assert "proof" not in capsys.readouterr().err
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    assert model.joint(0).name == "floating_base"


@pytest.mark.skipif(find_entry("go2") is None, reason="go2 comes from example-robot-data")
def test_the_go2_with_a_free_base_has_no_proof_notes(tmp_path, capsys) -> None:
    argv = ["convert", "go2", "--floating-base", "-o", str(tmp_path / "go2.xml"), "-v"]
    assert main(argv) == 0
    assert "proof:" not in capsys.readouterr().err
