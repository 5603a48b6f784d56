"""``robotwright export`` and ``robotwright compose``."""

from __future__ import annotations

import mujoco
import pytest

from robotwright.cli import main
from robotwright.cli.export import parse_robot_spec

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")


def test_export_mjcf_with_prefix_and_no_scene(tmp_path, capsys):
    out = tmp_path / "arm.xml"
    assert main(["export", "arm6", "--prefix", "p", "--no-scene", "-o", str(out)]) == 0
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.body("p_base_link").id == 1
    assert m.ngeom == 7  # no floor
    assert "wrote" in capsys.readouterr().out


def test_export_urdf_from_path(synth_hrdf_dir, tmp_path):
    out = tmp_path / "r.urdf"
    assert main(["export", str(synth_hrdf_dir), "--format", "urdf", "-o", str(out)]) == 0
    assert mujoco.MjModel.from_xml_path(str(out)).nq == 8


def test_compose_with_poses(tmp_path):
    out = tmp_path / "scene.xml"
    argv = [
        "compose",
        "mini_humanoid",
        "mini_humanoid@1,0,0,3.14159",
        "arm=arm6@0,1.5,0",
        "-o",
        str(out),
    ]
    assert main(argv) == 0
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    assert d.xpos[m.body("mini_humanoid2_pelvis").id][0] == pytest.approx(1.0)
    assert d.xpos[m.body("arm_base_link").id][1] == pytest.approx(1.5)


def test_compose_unknown_robot_exit_code(tmp_path, capsys):
    assert main(["compose", "no_such_robot", "-o", str(tmp_path / "s.xml")]) == 2
    assert "no robot named 'no_such_robot'" in capsys.readouterr().err
    assert not (tmp_path / "s.xml").exists()


def test_parse_robot_spec():
    assert parse_robot_spec("k=arm6@1,2,3")[0:2] == ("k", "arm6")
    key, robot, p = parse_robot_spec("/some/path@0,0,1,0.5")
    assert key is None and robot == "/some/path" and p.yaw == 0.5 and p.pos == (0, 0, 1)


def test_export_prints_one_notes_summary_and_each_note_with_v(tmp_path, capsys):
    assert main(["export", "arm6", "--format", "urdf", "-o", str(tmp_path / "a.urdf")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "conversion note(s)" in err[0] and "-v lists each" in err[0]
    count = int(err[0].split()[0])
    assert main(["export", "arm6", "-o", str(tmp_path / "b.urdf"), "-v"]) == 0
    err = capsys.readouterr().err.splitlines()
    # The writer's notes, then the proof's (each value MuJoCo's import of the URDF holds
    # otherwise than our MJCF and the writer did not report).
    notes = [line for line in err if line.startswith("note:")]
    assert len(notes) == count and any("capsule" in line for line in notes)
    assert any(line.startswith("note: robot 'arm6' to URDF:") for line in notes)
    assert err[-1].startswith(f"{count} conversion note(s)")


@pytest.mark.parametrize("command", ["export", "compose"])
def test_output_that_is_a_folder_or_under_a_file_is_a_clear_error(tmp_path, capsys, command):
    (tmp_path / "taken.xml").mkdir()
    (tmp_path / "plain.txt").write_text("keep", encoding="utf-8")
    assert main([command, "arm6", "-o", str(tmp_path / "taken.xml")]) == 2
    assert "taken.xml: is a folder; expected the path of a file" in capsys.readouterr().err
    assert main([command, "arm6", "-o", str(tmp_path / "plain.txt" / "out.xml")]) == 2
    assert "plain.txt is a file, not a folder" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain.txt", "taken.xml"]
    assert not any((tmp_path / "taken.xml").iterdir())


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["export", "arm6", "-o", "OUT/a.txt"], "expected a file name ending in .xml or .mjcf"),
        (["export", "arm6", "-o", "OUT/a.txt"], ".usd, .usda, .usdc (OpenUSD)"),
        (["export", "arm6", "--format", "urdf", "-o", "OUT/a.sdf"], "ending in .urdf or .xml"),
        (["compose", "arm6", "-o", "OUT/scene"], "cannot tell the format from '(no extension)'"),
        (["compose", "arm6", "--format", "mjcf", "-o", "OUT/scene"], "got '(none)'"),
    ],
)
def test_wrong_output_extension_is_refused(tmp_path, capsys, argv, expected):
    argv = [a.replace("OUT", str(tmp_path)) for a in argv]
    assert main(argv) == 2
    assert expected in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
