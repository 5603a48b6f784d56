"""Every script in examples/ runs and writes what it says."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import mujoco
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
#: Examples that need mjlab (the MuJoCo 3.11 environment), run shorter than by default.
MJLAB_EXAMPLES = {"mjlab_go1_semantic_lidar.py": ["--envs", "2", "--steps", "20"]}
#: Examples that need Isaac Lab 3 (its Python 3.12 environment of .ci/run).
ISAACLAB_EXAMPLES = {"isaaclab_semantic_lidar.py": ["--envs", "2", "--steps", "10"]}


@pytest.mark.parametrize("script", sorted(p.name for p in EXAMPLES.glob("*.py")))
def test_example_runs(script: str, tmp_path: Path) -> None:
    if script in MJLAB_EXAMPLES and importlib.util.find_spec("mjlab") is None:
        pytest.skip("needs mjlab (pip install 'robotwright[mjlab]'; the MuJoCo 3.11 environment)")
    if script in ISAACLAB_EXAMPLES and importlib.util.find_spec("isaaclab_newton") is None:
        pytest.skip("needs Isaac Lab 3 (pip install 'robotwright[isaaclab]'; Python 3.12)")
    run = subprocess.run(
        [
            sys.executable,
            str(EXAMPLES / script),
            str(tmp_path / "out"),
            *MJLAB_EXAMPLES.get(script, []),
            *ISAACLAB_EXAMPLES.get(script, []),
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    written = list((tmp_path / "out").rglob("*"))
    usage = (EXAMPLES / script).read_text().split('"""')[1]
    if "OUT_DIR" in usage or "output_dir" in usage:
        assert written, f"{script} wrote nothing"
    for xml in (p for p in written if p.suffix in (".xml", ".urdf")):
        # Everything an example writes loads in MuJoCo as it is.
        mujoco.MjModel.from_xml_path(str(xml))
    if script == "lidar_batched_envs.py" and importlib.util.find_spec("mujoco_warp"):
        # Both engines cast the same frame; the script exits 1 when they disagree.
        assert "engines agree on 46080 rays" in run.stdout, run.stdout
    if script in ISAACLAB_EXAMPLES:
        assert (tmp_path / "out" / "scan_env0.png").stat().st_size > 10_000
        assert "dynamic_obstacle" in run.stdout and "terrain" in run.stdout, run.stdout
    if script.startswith("lidar_") or script in ISAACLAB_EXAMPLES:
        assert "{'" not in run.stdout, "a raw dict is no output for a user"


def test_every_example_takes_an_output_folder() -> None:
    for script in sorted(EXAMPLES.glob("*.py")):
        usage = script.read_text().split('"""')[1]
        assert "[OUT_DIR]" in usage or "output_dir" in usage, script.name
