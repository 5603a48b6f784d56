"""Shared test fixtures: paths to real data, skipped with a reason when absent."""

from __future__ import annotations

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
