"""Folders we write load in hurodes itself (needs a Python with hurodes: $HURODES_PYTHON)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import uuid
from pathlib import Path

import mujoco
import pytest

from robotwright.hrdf import HRDF

pytestmark = [
    pytest.mark.hurodes,
    pytest.mark.filterwarnings("ignore::robotwright.hrdf.io.HRDFWarning"),
]

HURODES_EXPORT = """
import json, sys, warnings
warnings.simplefilter("ignore")
from pathlib import Path
from hurodes.hrdf.hrdf import HRDF
from hurodes.generators.mjcf_generator.mjcf_humanoid_generator import MJCFHumanoidGenerator
path = Path(sys.argv[1])
out = path / "exported" / "robot.xml"
out.parent.mkdir(exist_ok=True)
MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(path)).export(out)
print(json.dumps({"xml": str(out)}))
"""


def test_g1_written_by_us_loads_in_hurodes(
    g1_hrdf_dir: Path, hurodes_python: str, tmp_path: Path
) -> None:
    # hurodes reads robots only under $HURODES_ASSETS_PATH/robots: a temporary one, so
    # that the test writes nothing into the user's ~/.hurodes.
    robots = tmp_path / "robots"
    name = f"rw_test_{uuid.uuid4().hex[:8]}"
    try:
        HRDF.from_dir(g1_hrdf_dir).save(robots / name)
        out = subprocess.run(
            [hurodes_python, "-c", HURODES_EXPORT, str(robots / name)],
            capture_output=True,
            text=True,
            check=True,
            env={**os.environ, "HURODES_ASSETS_PATH": str(tmp_path)},
        )
        xml = json.loads(out.stdout.strip().splitlines()[-1])["xml"]
        ours = mujoco.MjModel.from_xml_path(xml)
        reference = mujoco.MjModel.from_xml_path(str(g1_hrdf_dir / "exported" / "robot.xml"))
        assert ours.nbody == reference.nbody and ours.njnt == reference.njnt
        assert ours.nu == reference.nu
        assert (ours.body_mass == reference.body_mass).all()
        assert (ours.body_inertia == reference.body_inertia).all()
        assert (ours.jnt_range == reference.jnt_range).all()
    finally:
        shutil.rmtree(robots / name, ignore_errors=True)
