"""benchmarks/gpu_suite.py end to end on the CPU with small sizes, in the MuJoCo 3.11 +
mjlab environment (marked ``mjlab``): every mjlab section gives finite figures, the
Isaac Lab ones are skipped with the reason, and the JSON summary is written."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

from robotwright.catalog import find_entry  # noqa: E402

SUITE = Path(__file__).resolve().parents[2] / "benchmarks" / "gpu_suite.py"


@pytest.mark.skipif(find_entry("go2") is None, reason="the Go2 comes from example-robot-data")
def test_the_gpu_suite_runs_its_mjlab_sections_on_the_cpu(tmp_path) -> None:
    out = tmp_path / "suite.json"
    cmd = [sys.executable, str(SUITE), "--device", "cpu", "--envs", "2", "--steps", "2"]
    cmd += ["--iterations", "2", "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=1500, cwd=tmp_path)
    assert done.returncode == 0, (done.stdout[-3000:], done.stderr[-3000:])
    summary = json.loads(out.read_text())
    assert summary["machine"]["versions"]["mjlab"] != "absent"
    lidar = summary["lidar_mjlab"]
    assert lidar["rays_per_step"] == 2 * 20_000
    assert lidar["ours_rays_per_s"] > 0 and math.isfinite(lidar["ours_over_stock"])
    nav = summary["nav_mjlab"]
    assert nav["env_steps_per_s"] > 0 and nav["step_s"] > 0
    train = summary["train_mjlab"]
    assert len(train["value_loss"]) == 2 and all(math.isfinite(v) for v in train["value_loss"])
    # rsl_rl prints an iteration's mean episode reward and length together, once an
    # episode has ended.
    assert len(train["mean_episode_length"]) == len(train["mean_reward"])
    for section in ("lidar_isaaclab", "nav_isaaclab", "train_isaaclab"):
        assert "not installed" in summary[section]["skipped"]


@pytest.mark.skipif(find_entry("go2") is None, reason="the Go2 comes from example-robot-data")
@pytest.mark.parametrize(
    ("device", "parsed"), [("cpu", None), ("cuda", [0]), ("cuda:0", [0]), ("cuda:3", [3])]
)
def test_the_suite_names_the_gpu_as_mjlab_train_parses_it(device, parsed) -> None:
    import mjlab
    import tyro
    from mjlab.scripts.train import TrainConfig

    sys.path.insert(0, str(SUITE.parent))
    from gpu_suite import mjlab_gpu_ids

    default = TrainConfig.from_task("Robotwright-Mjlab-SemanticNav-Go2")
    args = ["--gpu-ids", mjlab_gpu_ids(device)]
    cfg = tyro.cli(TrainConfig, args=args, default=default, config=mjlab.TYRO_FLAGS)
    assert cfg.gpu_ids == parsed
