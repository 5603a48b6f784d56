"""Isaac Lab tests share one process: register mujoco-usd-converter's USD schemas first.

The converter registers its schema plugins (MjcPhysics) when imported; USD's schema
registry does not take plugins registered after a stage has been made, and the LiDAR
tests make Isaac Lab stages. So the converter is imported before any test runs (a user's
process that both simulates and exports does the same; docs/generators.md).

The folder's helper modules (``isaaclab_scenes``, ``usd_robots``) are importable by name
(pytest runs in importlib mode, which does not put test folders on the path).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

if importlib.util.find_spec("mujoco_usd_converter") is not None:
    import mujoco_usd_converter  # noqa: F401
