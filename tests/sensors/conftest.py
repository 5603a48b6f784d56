"""Fixtures of the LiDAR tests; helpers live in lidar_scenes.py next to this file."""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import pytest

# The project runs pytest with --import-mode=importlib: make lidar_scenes importable.
sys.path.insert(0, str(Path(__file__).parent))

import lidar_scenes  # noqa: E402


@pytest.fixture
def analytic_model() -> mujoco.MjModel:
    return lidar_scenes.analytic_model()


@pytest.fixture
def clutter_model() -> mujoco.MjModel:
    return lidar_scenes.clutter_model()
