"""``robotwright info`` and ``--help`` on every subcommand."""

from __future__ import annotations

import subprocess
import sys

import pytest

from robotwright.cli import build_parser


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "robotwright", *args], capture_output=True, text=True
    )


def test_info_table() -> None:
    out = run("info", "arm6")
    assert out.returncode == 0, out.stderr
    assert (
        "robot arm6: 7 bodies, 6 joints, 6 actuators, 6 DoF, total mass 7.700 kg, fixed base"
        in out.stdout
    )
    # Limits carry their units; masses use one format (3 decimals) in every table.
    assert "shoulder_pan_servo   position  shoulder_pan_joint   60 N m" in out.stdout
    assert "3 rad/s" in out.stdout and "[-2.9, 2.9] rad" in out.stdout
    assert "base_link       -               2.000" in out.stdout


def test_info_names_unnamed_actuators_and_units() -> None:
    out = run("info", "mini_humanoid")
    assert out.returncode == 0, out.stderr
    rows = [line for line in out.stdout.splitlines() if "knee_joint" in line and "motor" in line]
    assert len(rows) == 2 and all(r.startswith("(unnamed)") and "80 N m" in r for r in rows)
    assert "pelvis" in out.stdout and "3.000" in out.stdout and "28.200 kg" in out.stdout


def test_info_unknown_robot_is_clear_error() -> None:
    out = run("info", "no_such_robot")
    assert out.returncode == 2
    assert "no robot named 'no_such_robot'" in out.stderr


def test_every_subcommand_has_help() -> None:
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    assert {"validate", "info", "demo"} <= set(sub.choices)
    for name, p in sub.choices.items():
        text = p.format_help()
        assert text.startswith("usage: robotwright " + name), name
        assert p.description, f"{name} has no description"


@pytest.mark.parametrize("cmd", ["validate", "info", "demo"])
def test_help_exits_zero(cmd: str) -> None:
    out = run(cmd, "--help")
    assert out.returncode == 0 and "usage:" in out.stdout


@pytest.mark.parametrize("command", ["validate", "info", "export"])
def test_file_or_plain_folder_given_as_robot_is_named(tmp_path, capsys, command) -> None:
    from robotwright.cli import main

    (tmp_path / "robot.urdf").write_text("<robot name='r'/>", encoding="utf-8")
    (tmp_path / "empty").mkdir()
    extra = ["-o", str(tmp_path / "o.xml")] if command == "export" else []
    # A URDF is read as one (every command takes any robot source): this one has no
    # links, which is bad input (validate: an invalid robot, exit 1, its problem listed).
    code = main([command, str(tmp_path / "robot.urdf"), *extra])
    captured = capsys.readouterr()
    assert code == (1 if command == "validate" else 2)
    assert "robot.urdf" in captured.err + captured.out
    assert main([command, str(tmp_path / "empty"), *extra]) == 2
    assert "empty: a folder without meta.yaml" in capsys.readouterr().err
    assert not (tmp_path / "o.xml").exists()
