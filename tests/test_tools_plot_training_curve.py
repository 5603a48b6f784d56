"""tools/plot_training_curve.py: the curve of a run's TensorBoard event files.

Skipped with a reason where tensorboard is absent (it is in the mjlab environment).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("tensorboard", reason="tensorboard not installed (the mjlab environment)")
pytest.importorskip("matplotlib", reason="matplotlib not installed")

from tensorboard.compat.proto.event_pb2 import Event  # noqa: E402
from tensorboard.compat.proto.summary_pb2 import Summary  # noqa: E402
from tensorboard.summary.writer.event_file_writer import EventFileWriter  # noqa: E402

TOOL = Path(__file__).resolve().parents[1] / "tools" / "plot_training_curve.py"


def _write_run(folder: Path, series: dict[str, list[float]]) -> None:
    writer = EventFileWriter(str(folder))
    for tag, values in series.items():
        for step, value in enumerate(values):
            summary = Summary(value=[Summary.Value(tag=tag, simple_value=value)])
            writer.add_event(Event(wall_time=1.0 + step, step=step, summary=summary))
    writer.close()


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(TOOL), *args], capture_output=True, text=True, timeout=300
    )


def test_plots_reward_and_length_and_prints_their_values(tmp_path):
    reward = [-1.5, -1.0, -0.25, -0.5]
    length = [20.0, 40.0, 80.0, 60.0]
    _write_run(tmp_path / "run", {"Train/mean_reward": reward, "Train/mean_episode_length": length})
    out = tmp_path / "curve.png"
    done = _run(str(tmp_path / "run"), str(out), "--window", "2")
    assert done.returncode == 0, done.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    lines = done.stdout.splitlines()
    assert lines[0] == (
        "Train/mean_reward: 4 iterations, first -1.500, last -0.500, "
        "max -0.250 (iteration 2), last-2 mean -0.375"
    )
    assert lines[1] == (
        "Train/mean_episode_length: 4 iterations, first 20.000, last 60.000, "
        "max 80.000 (iteration 2), last-2 mean 70.000"
    )


@pytest.mark.parametrize("series", [None, {"Train/mean_reward": [1.0, 2.0]}])
def test_a_folder_without_the_curve_is_an_error_and_writes_nothing(tmp_path, series):
    run = tmp_path / "run"
    run.mkdir()
    if series is not None:  # events, but no episode length
        _write_run(run, series)
    out = tmp_path / "curve.png"
    done = _run(str(run), str(out))
    assert done.returncode == 2
    assert done.stderr.startswith("error: ") and str(run) in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    assert not out.exists()
