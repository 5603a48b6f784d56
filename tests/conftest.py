"""Shared test fixtures: paths to real data, skipped with a reason when absent."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

PROJECT_ROOT = Path(__file__).resolve().parents[1]
TESTDATA = PROJECT_ROOT / ".testdata"
#: HRDF folders written by hurodes 0.1.9 (tools/fetch_test_data.py makes them):
#: ``g1_29`` (+ ``exported/robot.xml``, hurodes' own MJCF of it), ``synth_baseline_hinge``,
#: and ``sources/`` with the MJCF files hurodes converted. ``$ROBOTWRIGHT_HURODES_FIXTURES``
#: points elsewhere.
HURODES_FIXTURES = Path(
    os.environ.get("ROBOTWRIGHT_HURODES_FIXTURES") or TESTDATA / "hurodes-fixtures"
)
FETCH_HINT = "run python tools/fetch_test_data.py"


def _need(path: Path, why: str) -> Path:
    if not path.exists():
        pytest.skip(f"{why}: {path} is absent")
    return path


@pytest.fixture
def g1_hrdf_dir() -> Path:
    """hurodes-written Unitree G1 (29 DoF) HRDF folder (mjlab's G1 MJCF converted)."""
    return _need(HURODES_FIXTURES / "g1_29", f"hurodes G1 fixture not made ({FETCH_HINT})")


@pytest.fixture
def g1_source_mjcf() -> Path:
    """The MJCF file hurodes converted into ``g1_hrdf_dir``: the reference for its values."""
    return _need(HURODES_FIXTURES / "sources" / "g1_29.xml", f"G1 source absent ({FETCH_HINT})")


@pytest.fixture
def synth_hrdf_dir() -> Path:
    """hurodes-written small synthetic hinge robot (two bodies, one motor)."""
    return _need(
        HURODES_FIXTURES / "synth_baseline_hinge",
        f"hurodes synthetic fixture not made ({FETCH_HINT})",
    )


@pytest.fixture
def testdata_dir() -> Path:
    """Folder filled by tools/fetch_test_data.py (mjlab wheel contents, ...)."""
    return _need(TESTDATA, "test data not fetched (run python tools/fetch_test_data.py)")


@pytest.fixture
def hurodes_python() -> str:
    """A python with hurodes 0.1.9: ``$HURODES_PYTHON``, else the venv fetch_test_data makes."""
    env = os.environ.get("HURODES_PYTHON")
    if env:
        return env
    candidate = TESTDATA / "hurodes-venv" / "bin" / "python"
    if not candidate.exists():
        pytest.skip(
            "hurodes not available: run tools/fetch_test_data.py (makes .testdata/hurodes-venv) "
            "or set HURODES_PYTHON to a python with hurodes 0.1.9"
        )
    return str(candidate)
