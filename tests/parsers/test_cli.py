"""``robotwright convert`` and ``robotwright roundtrip`` on small inputs."""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest

from robotwright.cli import main
from robotwright.proof.convert import convert


def test_convert_mjcf_to_hrdf_to_urdf_and_mjcf(probe: Path, tmp_path: Path, capsys) -> None:
    folder = tmp_path / "out_hrdf"
    assert main(["convert", str(probe), "-o", str(folder), "-v"]) == 0
    captured = capsys.readouterr()
    assert f"wrote {folder}" in captured.out
    # The losses go to stderr: each note with -v, then the summary line counting them.
    notes = [line for line in captured.err.splitlines() if line.startswith("note: ")]
    assert any("worldbody" in line for line in notes)
    assert captured.err.splitlines()[-1].startswith(f"{len(notes)} conversion note(s)")
    assert (folder / "body.csv").is_file() and any((folder / "meshes").iterdir())
    xml = tmp_path / "again.xml"
    assert main(["convert", str(folder), "-o", str(xml)]) == 0
    again = mujoco.MjModel.from_xml_path(str(xml))
    source = mujoco.MjModel.from_xml_path(str(probe))
    assert again.nbody == source.nbody and again.nu == source.nu
    assert abs(again.body_mass.sum() - source.body_mass.sum()) <= 1e-12
    urdf = tmp_path / "robot.urdf"
    assert main(["convert", str(folder), "-o", str(urdf)]) == 0
    assert urdf.is_file()


def test_convert_refuses_to_overwrite_and_unknown_types(
    probe: Path, tmp_path: Path, capsys
) -> None:
    out = tmp_path / "x.xml"
    out.write_text("keep me")
    # A clean exit 2 naming the file and the flag, not a FileExistsError traceback.
    assert main(["convert", str(probe), "-o", str(out)]) == 2
    assert f"{out}: exists; not replacing it (give --overwrite" in capsys.readouterr().err
    with pytest.raises(FileExistsError):  # the library call still raises a FileExistsError
        convert(probe, out)
    assert out.read_text() == "keep me"
    assert main(["convert", str(probe), "-o", str(tmp_path / "x.obj")]) == 2


def test_convert_strict_fails_without_output(probe: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "strict.xml"
    assert main(["convert", str(probe), "-o", str(out), "--strict"]) == 2
    assert "worldbody" in capsys.readouterr().err
    assert not out.exists()


def test_roundtrip_command_prints_table(arm_mjcf: Path, probe: Path, capsys) -> None:
    assert main(["roundtrip", str(arm_mjcf), "--configs", "5"]) == 0
    out = capsys.readouterr().out
    assert "MJCF: FK" in out and "URDF: total mass" in out and "result:    PASS" in out
    # Two joints on one body need extra URDF links; their small masses are allowed for in
    # the total and named in the table.
    assert main(["roundtrip", str(probe), "--configs", "5"]) == 0
    out = capsys.readouterr().out
    assert "result:    PASS" in out and "links the URDF form adds allowed" in out


def test_convert_keeps_massless_frame_link_or_merges_it(tmp_path: Path, capsys) -> None:
    urdf = tmp_path / "r" / "urdf" / "tool.urdf"
    urdf.parent.mkdir(parents=True)
    urdf.write_text(
        '<robot name="t"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        '<link name="arm"><inertial><mass value="1"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        '<link name="tcp"/>'
        '<joint name="j" type="continuous"><parent link="base"/><child link="arm"/></joint>'
        '<joint name="f" type="fixed"><parent link="arm"/><child link="tcp"/>'
        '<origin xyz="0 0 .3"/></joint></robot>'
    )
    out = tmp_path / "tool.xml"
    # Default policy keeps the fixed child as a welded, massless frame body.
    assert main(["convert", str(urdf), "-o", str(out)]) == 0
    kept = mujoco.MjModel.from_xml_path(str(out))
    assert kept.body("tcp").mass[0] == 0.0 and kept.nbody == 4
    out = tmp_path / "tool_merged.xml"
    assert main(["convert", str(urdf), "-o", str(out), "--fixed-joints", "merge"]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.site("tcp").id >= 0 and model.nbody == 3


def test_convert_urdf_only_option_on_mjcf_source_is_named(probe: Path, tmp_path: Path, capsys):
    out = tmp_path / "x.urdf"
    assert main(["convert", str(probe), "-o", str(out), "--bound-mass", "0.01"]) == 2
    err = capsys.readouterr().err
    assert "bound_mass (--bound-mass) do not apply to a MJCF source" in err
    assert "Traceback" not in err and not out.exists()


# Our words only: what expat or defusedxml add after them is theirs to change.
@pytest.mark.parametrize(
    ("name", "content", "expected"),
    [
        ("missing.urdf", None, "missing.urdf: file not found: expected a .urdf or .xml file"),
        ("model.txt", "x", "model.txt: expected a .urdf, .xacro or .xml (MJCF) file"),
        ("empty.xml", "", "empty.xml: not well-formed XML"),
        ("cut.urdf", "<robot name='r'><link name='a'>", "cut.urdf: not well-formed XML"),
        (
            "bomb.xml",
            '<!DOCTYPE m [<!ENTITY a "aa"><!ENTITY b "&a;&a;">]><mujoco model="&b;"/>',
            "bomb.xml: unsafe XML refused",
        ),
    ],
)
def test_roundtrip_bad_input_is_exit_2_on_stderr(tmp_path, capsys, name, content, expected):
    path = tmp_path / name
    if content is not None:
        path.write_text(content, encoding="utf-8")
    assert main(["roundtrip", str(path)]) == 2
    captured = capsys.readouterr()
    assert expected in captured.err and "Traceback" not in captured.err
    assert captured.out == ""  # no half table


def test_roundtrip_input_the_parser_refuses_is_exit_2_on_stderr(tmp_path, capsys) -> None:
    """A file that is well-formed but that the parser refuses (here a mesh that does not
    exist) is bad input as for ``convert``: exit 2, the reason on stderr, no table."""
    path = tmp_path / "nomesh.urdf"
    path.write_text(
        '<robot name="r"><link name="a"><collision><geometry><mesh filename="gone.stl"/>'
        "</geometry></collision></link></robot>"
    )
    assert main(["roundtrip", str(path)]) == 2
    captured = capsys.readouterr()
    assert "'gone.stl' resolves to" in captured.err and "does not exist" in captured.err
    assert captured.out == "" and "Traceback" not in captured.err
    assert main(["convert", str(path), "-o", str(tmp_path / "out")]) == 2


def test_roundtrip_needs_at_least_one_configuration(probe: Path, capsys) -> None:
    assert main(["roundtrip", str(probe), "--configs", "0"]) == 2
    assert "configs: expected at least 1 configuration, got 0" in capsys.readouterr().err


def test_roundtrip_rows_that_compare_nothing_are_not_passes(tmp_path: Path, capsys) -> None:
    from robotwright.generators import URDFHumanoidGenerator

    urdf = tmp_path / "arm6.urdf"
    with pytest.warns(UserWarning):  # values URDF cannot hold are reported, as always
        URDFHumanoidGenerator.from_robot_name("arm6").export(urdf)
    assert main(["roundtrip", str(urdf), "--configs", "3"]) == 0
    table = capsys.readouterr().out.splitlines()
    # arm6 has no tendon, equality, exclude or keyframe: that row is n/a, not ok.
    (extras,) = [line for line in table if "equality/tendon/contact/keyframe" in line]
    assert extras.lstrip().startswith("n/a")
    assert "result:    PASS" in table


def test_roundtrip_names_sites_carried_as_urdf_links(tmp_path: Path, capsys) -> None:
    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.proof.roundtrip.run import roundtrip

    xml = tmp_path / "arm6.xml"
    with pytest.warns(UserWarning):
        MJCFHumanoidGenerator.from_robot_name("arm6").export(xml)
    report = roundtrip(xml, configs=3)
    (row,) = [r for r in report.rows if r.check == "URDF: bodies (ref/ours)"]
    assert row.value == "7/8" and row.ok and "1 site(s) as massless links: ['tool0']" in row.note
    assert len(report.passed()) < len(report.rows)  # the n/a rows are not counted


def test_convert_reports_the_actuators_it_made(tmp_path, capsys) -> None:
    """--actuators is reported: one line with the count, each actuator with -v; the
    parsers' logger is left as it was."""
    import logging

    from robotwright.cli import main

    links = "".join(
        f'<link name="l{i}"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        for i in range(3)
    )
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="7" velocity="2"/></joint>'
        for i in (1, 2)
    )
    urdf = tmp_path / "two.urdf"
    urdf.write_text(f'<robot name="two">{links}{joints}</robot>')
    log = logging.getLogger("robotwright.parsers")
    before = (log.level, log.propagate, list(log.handlers))
    out = tmp_path / "two.xml"
    assert main(["convert", str(urdf), "-o", str(out), "--actuators", "motor"]) == 0
    captured = capsys.readouterr()
    # What the option made is part of what was written (stdout); stderr keeps the notes.
    assert "2 actuator(s) made by --actuators (-v lists each)" in captured.out
    assert "made: " not in captured.err
    assert (
        main(["convert", str(urdf), "-o", str(out), "--overwrite", "--actuators", "motor", "-v"])
        == 0
    )
    err = capsys.readouterr().err
    assert "motor actuator 'j1' on joint 'j1' ctrlrange=[-7, 7]" in err
    assert "motor actuator 'j2'" in err
    assert (log.level, log.propagate, list(log.handlers)) == before
