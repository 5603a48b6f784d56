"""benchmarks/gpu_suite.py end to end on the CPU with small sizes, in the Isaac Lab
environment: every Isaac Lab section gives finite figures, the mjlab ones are skipped
with the reason, and the JSON summary is written."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip("isaaclab_newton", reason="Isaac Lab 3 not installed")
    pytest.importorskip("mujoco_usd_converter", reason="mujoco-usd-converter not installed")

from robotwright.catalog import find_entry  # noqa: E402

SUITE = Path(__file__).resolve().parents[2] / "benchmarks" / "gpu_suite.py"


@pytest.mark.skipif(find_entry("go2") is None, reason="the Go2 comes from example-robot-data")
def test_the_gpu_suite_runs_its_isaaclab_sections_on_the_cpu(tmp_path) -> None:
    out = tmp_path / "suite.json"
    cmd = [sys.executable, str(SUITE), "--device", "cpu", "--envs", "2", "--steps", "2"]
    cmd += ["--iterations", "1", "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=1500, cwd=tmp_path)
    assert done.returncode == 0, (done.stdout[-3000:], done.stderr[-3000:])
    summary = json.loads(out.read_text())
    lidar = summary["lidar_isaaclab"]
    assert lidar["stock"]["x_stock"] == 1.0
    contenders = {k: v for k, v in lidar.items() if k != "section_s"}
    assert {"stock", "semantic", "see_through"} <= set(contenders)
    assert all(v["rays_per_s"] > 0 for v in contenders.values())
    nav = summary["nav_isaaclab"]
    assert nav["env_steps_per_s"] > 0 and math.isfinite(nav["lidar_share"])
    train = summary["train_isaaclab"]
    assert len(train["value_loss"]) == 1 and math.isfinite(train["value_loss"][0])
    for section in ("lidar_mjlab", "nav_mjlab", "train_mjlab"):
        assert "not installed" in summary[section]["skipped"]
