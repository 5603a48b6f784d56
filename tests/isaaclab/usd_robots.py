"""The robots the USD tests export and read back: two bundled, the G1 fixture and two of
example-robot-data's (each skipped with a reason where absent)."""

from __future__ import annotations

from pathlib import Path

import pytest

from robotwright.catalog import find_entry
from robotwright.sources import load_robot

ROBOTS = ["arm6", "mini_humanoid", "go2", "talos", "g1"]
#: The hurodes G1 fixture (HRDF made from mjlab's G1 by tools/fetch_test_data.py).
G1 = Path(__file__).resolve().parents[2] / ".testdata" / "hurodes-fixtures" / "g1_29"


def robot(name: str):
    """The robot ``name`` as an HRDF (URDF robots with torque motors and a free base)."""
    if name == "g1":
        if not (G1 / "meta.yaml").is_file():
            pytest.skip("the G1 fixture comes from tools/fetch_test_data.py (not fetched)")
        return load_robot(str(G1))
    if name in ("go2", "talos") and find_entry(name) is None:
        pytest.skip(f"{name} comes from example-robot-data (not installed)")
    if name in ("go2", "talos"):
        from robotwright.parsers import urdf_to_hrdf

        # Torque motors from the URDF's effort and velocity limits (drives to carry), and
        # the free base a legged robot has.
        return urdf_to_hrdf(find_entry(name).path, actuators="motor", floating_base=True)
    return load_robot(name)
