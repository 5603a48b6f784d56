"""Every script in examples/ runs and writes what it says."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import mujoco
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("script", sorted(p.name for p in EXAMPLES.glob("*.py")))
def test_example_runs(script: str, tmp_path: Path) -> None:
    run = subprocess.run(
        [sys.executable, str(EXAMPLES / script), str(tmp_path / "out")],
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
