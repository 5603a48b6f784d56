"""Counts of a compiled ``mujoco.MjModel`` that differ between MuJoCo releases."""

from __future__ import annotations

from typing import Any


def actuator_count(model: Any) -> int:
    """Number of actuators of ``model``.

    MuJoCo 4 counts actuators (``nactuator``) apart from controls (``nu``): an ``so3``
    actuator on a ball joint takes three controls. MuJoCo 3.11 has one control per
    actuator and no ``nactuator``.
    """
    return int(getattr(model, "nactuator", model.nu))
