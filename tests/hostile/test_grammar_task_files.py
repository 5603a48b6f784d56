"""Hostile task files given to ``grammar search --task``: refused with exit 2 and one
error naming the file and field, before anything outside the file's folder is read."""

from __future__ import annotations

import pytest

from robotwright.cli import main
from robotwright.grammar import task as task_module


@pytest.mark.parametrize(
    "robot",
    ["../../../etc", "/etc", "mini_humanoid/../arm6", "robots/../../x", ""],
)
def test_a_carrier_robot_is_a_bundled_name_never_a_path(tmp_path, capsys, monkeypatch, robot):
    looked: list[object] = []
    monkeypatch.setattr(task_module, "_carrier_xml", lambda c: looked.append(c))
    path = tmp_path / "task.yaml"
    path.write_text(f"task: t\ncarrier: {{robot: {robot!r}}}\n", encoding="utf-8")
    code = main(["grammar", "search", "--task", str(path), "--budget", "1"])
    err = capsys.readouterr().err
    assert code == 2 and "carrier.robot" in err and str(path) in err
    assert "Traceback" not in err and looked == []  # no robot folder was opened


def test_a_huge_or_deep_task_file_is_refused(tmp_path, capsys):
    deep = tmp_path / "deep.yaml"
    deep.write_text("task: t\ntrack: " + "[" * 5000 + "]" * 5000 + "\n", encoding="utf-8")
    assert main(["grammar", "search", "--task", str(deep), "--budget", "1"]) == 2
    err = capsys.readouterr().err
    assert str(deep) in err and "Traceback" not in err
    many = tmp_path / "many.yaml"
    points = ", ".join("[0, 0, 0]" for _ in range(2000))
    many.write_text(f"task: t\ntrack: {{path: [{points}]}}\n", encoding="utf-8")
    assert main(["grammar", "search", "--task", str(many), "--budget", "1"]) == 2
    assert "track.path" in capsys.readouterr().err
