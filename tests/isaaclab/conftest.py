"""Isaac Lab tests share one process: register mujoco-usd-converter's USD schemas first.

The converter registers its schema plugins (MjcPhysics) when imported; USD's schema
registry does not take plugins registered after a stage has been made, and the LiDAR
tests make Isaac Lab stages. So the converter is imported before any test runs (a user's
process that both simulates and exports does the same; docs/generators.md).
"""

from __future__ import annotations

import importlib.util

if importlib.util.find_spec("mujoco_usd_converter") is not None:
    import mujoco_usd_converter  # noqa: F401
