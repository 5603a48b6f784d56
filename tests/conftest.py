"""Shared test fixtures: paths to real data, skipped with a reason when absent."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

PROJECT_ROOT = Path(__file__).resolve().parents[1]
SHARED_FIXTURES = PROJECT_ROOT.parent / "shared" / "fixtures"
HURODES_FIXTURES = SHARED_FIXTURES / "hurodes"
TESTDATA = PROJECT_ROOT / ".testdata"


def _need(path: Path, why: str) -> Path:
    if not path.exists():
        pytest.skip(f"{why}: {path} is absent")
    return path


@pytest.fixture
def g1_hrdf_dir() -> Path:
    """hurodes-written Unitree G1 (29 DoF) HRDF folder from ../shared/fixtures."""
    return _need(HURODES_FIXTURES / "g1_29", "hurodes G1 fixture not available")


@pytest.fixture
def synth_hrdf_dir() -> Path:
    """hurodes-written small synthetic hinge robot from ../shared/fixtures."""
    return _need(
        HURODES_FIXTURES / "synth_baseline_hinge", "hurodes synthetic fixture not available"
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
