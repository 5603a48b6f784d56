"""Without the USD converter (every environment but Isaac Lab's), USD export says what
to install, exits 2 and writes nothing."""

from __future__ import annotations

import importlib.util
import subprocess
import sys

import pytest


@pytest.mark.skipif(
    importlib.util.find_spec("mujoco_usd_converter") is not None,
    reason="the converter is installed here: tests/isaaclab/test_usd_export.py exports",
)
def test_usd_export_without_converter_names_what_to_install(tmp_path):
    out = tmp_path / "arm6.usda"
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", "export", "arm6", "-o", str(out)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert run.returncode == 2
    assert "mujoco-usd-converter" in run.stderr and "pip install 'robotwright[usd]'" in run.stderr
    assert "Python 3.12" in run.stderr
    assert "Traceback" not in run.stderr
    assert not out.exists()


@pytest.mark.skipif(
    importlib.util.find_spec("newton") is not None,
    reason="Newton is installed here: tests/isaaclab/test_usd_import.py reads USD",
)
def test_usd_input_without_newton_names_what_to_install(tmp_path):
    (tmp_path / "robot.usda").write_text('#usda 1.0\n\ndef Xform "robot"\n{\n}\n')
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", "convert", "robot.usda", "-o", "out"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert run.returncode == 2, run.stderr
    assert "Newton" in run.stderr and "robotwright[usd]" in run.stderr
    assert "Traceback" not in run.stderr
    assert not (tmp_path / "out").exists()
