"""Hostile inputs on the USD surfaces (issue 38): a robot's name never becomes a path in
``export -o robot.usda`` or ``isaaclab-cfg``, both write through the output gate (a link
planted at any name is never followed), and a USD layer that is a FIFO is refused before
usd-core opens it. Runs in Isaac Lab's environment; skipped elsewhere."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip(
        "mujoco_usd_converter", reason="mujoco-usd-converter not installed (Isaac Lab stage)"
    )

from robotwright.cli import main  # noqa: E402

URDF = """<robot name="{name}">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><origin xyz="0 0 0.1"/><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.05 0.05 0.2"/></geometry></collision>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="2"/></joint>
</robot>
"""

NAMES = {
    "traversal": "../../../../../../../../../../{victim}",
    "absolute": "{victim}",
    "backslash": "..\\..\\{victim}",
    "dot": ".",
    "long": "r" * 5000,
}


def _files(folder: Path) -> set[Path]:
    return {p for p in folder.rglob("*") if p.is_file() or p.is_symlink()}


@pytest.mark.parametrize("label", list(NAMES))
@pytest.mark.parametrize("command", ["export", "isaaclab-cfg"])
def test_a_robot_name_never_becomes_a_path(tmp_path, capsys, label, command) -> None:
    victim = tmp_path / "home" / "victim"
    victim.parent.mkdir()
    for suffix in (".xml", ".urdf", ".usd", ".py"):
        victim.with_suffix(suffix).write_text("precious")
    src = tmp_path / "src" / "robot.urdf"
    src.parent.mkdir()
    name = NAMES[label].format(victim=str(victim).lstrip("/"))
    src.write_text(URDF.format(name=name), encoding="utf-8")
    before = _files(tmp_path)
    out = tmp_path / "out"
    target = out / ("robot.usda" if command == "export" else "robot_cfg.py")
    code = main([command, str(src), "-o", str(target)])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert code == 0, err
    new = _files(tmp_path) - before
    assert new and all(p.is_relative_to(out) for p in new), sorted(new)
    expected = {target} if command == "export" else {target, out / "robot_cfg.usd"}
    assert new == expected
    assert all(victim.with_suffix(s).read_text() == "precious" for s in (".xml", ".urdf"))


def test_isaaclab_cfg_never_writes_through_a_planted_link(tmp_path, capsys) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    out = tmp_path / "out"
    out.mkdir()
    for planted in (".robot_cfg.py.partial", ".robot_cfg.usd.partial.usd"):
        (out / planted).symlink_to(victim)
    code = main(["isaaclab-cfg", "arm6", "-o", str(out / "robot_cfg.py")])
    err = capsys.readouterr().err
    assert code == 0, err
    assert victim.read_text() == "precious"
    assert (out / "robot_cfg.py").is_file() and not (out / "robot_cfg.py").is_symlink()
    assert (out / "robot_cfg.usd").is_file() and not (out / "robot_cfg.usd").is_symlink()
    # A link at the output's own name is refused without --overwrite, replaced with it.
    (out / "robot_cfg.py").unlink()
    (out / "robot_cfg.py").symlink_to(victim)
    assert main(["isaaclab-cfg", "arm6", "-o", str(out / "robot_cfg.py")]) == 2
    assert "exists" in capsys.readouterr().err
    code = main(["isaaclab-cfg", "arm6", "-o", str(out / "robot_cfg.py"), "--overwrite"])
    assert code == 0 and victim.read_text() == "precious"
    assert not (out / "robot_cfg.py").is_symlink()


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
def test_a_usd_layer_that_is_a_fifo_is_refused(tmp_path, capsys) -> None:
    from robotwright.tasks import load_robot

    robot = tmp_path / "robot"
    robot.mkdir()
    assert main(["export", "arm6", "-o", str(robot / "arm6.usda")]) == 0
    capsys.readouterr()
    os.mkfifo(robot / "pipe.usda")
    top = robot / "top.usda"
    top.write_text("#usda 1.0\n(\n    subLayers = [@./pipe.usda@, @./arm6.usda@]\n)\n")
    code = main(["info", str(top)])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error:") and "FIFO" in err and "Traceback" not in err
    with pytest.raises(Exception, match="FIFO"):
        load_robot(robot / "pipe.usda")
