"""``robotwright things``: MJCF -> MJCF, MJCF -> HRDF, HRDF -> MJCF."""

from __future__ import annotations

from pathlib import Path

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


def test_cli_bad_inputs_and_outputs_are_clear_errors(tmp_path, capsys):
    src = tmp_path / "arm.xml"
    src.write_text(_ARM)
    urdf = tmp_path / "robot.xml"
    urdf.write_text('<robot name="r"><link name="a"/></robot>')
    plain = tmp_path / "plain.txt"
    plain.write_text("keep")

    # A URDF given as MJCF: MuJoCo would compile it into an empty world.
    assert main(["things", str(urdf), str(tmp_path / "o.xml")]) == 2
    assert "root element <robot>: expected <mujoco> (MJCF)" in capsys.readouterr().err
    # Output under a file, output with an unknown extension, output folder already there.
    assert main(["things", str(src), str(plain / "o.xml")]) == 2
    assert "plain.txt is a file, not a folder" in capsys.readouterr().err
    assert main(["things", str(src), str(tmp_path / "o.txt")]) == 2
    assert "o.txt: expected a .xml file (MJCF) or a folder name" in capsys.readouterr().err
    (tmp_path / "hrdf").mkdir()
    (tmp_path / "hrdf" / "x").write_text("x")
    assert main(["things", str(src), str(tmp_path / "hrdf")]) == 2
    err = capsys.readouterr().err
    assert "hrdf" in err and "overwrite" in err  # names the folder and the way out
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "arm.xml",
        "hrdf",
        "plain.txt",
        "robot.xml",
    ]
    assert [p.name for p in (tmp_path / "hrdf").iterdir()] == ["x"]


def test_urdf_with_meshes_to_mjcf_and_hrdf(tmp_path: Path, capsys) -> None:
    """A URDF's meshes are staged while it is parsed; they are still there when the
    Things output is written (the staging folder lived only as long as the parsed robot,
    which was gone before the export: 'asset file ... does not exist')."""
    import struct

    tri = [(0, 0, 0), (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    stl = bytearray(b"\0" * 80 + struct.pack("<I", len(faces)))
    for f in faces:
        stl += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *tri[i]) for i in f)
        stl += b"\0\0"
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "m.stl").write_bytes(bytes(stl))
    urdf = tmp_path / "src" / "r.urdf"
    urdf.write_text(
        '<robot name="r"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<visual><geometry><mesh filename="m.stl"/></geometry></visual></link></robot>'
    )
    out = tmp_path / "out" / "r.xml"
    assert main(["things", str(urdf), str(out)]) == 0, capsys.readouterr().err
    assert mujoco.MjModel.from_xml_path(str(out)).nmesh == 1
    folder = tmp_path / "out" / "r_hrdf"
    assert main(["things", str(urdf), str(folder)]) == 0, capsys.readouterr().err
    assert len(list(folder.rglob("*.stl"))) == 1
