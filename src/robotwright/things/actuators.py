"""Actuators (MJCF ``<actuator>`` children), attached to what they drive.

Attach an actuator to a :class:`~robotwright.things.joints.Joint` (joint transmission)
or a :class:`~robotwright.things.sites.Site` (site transmission); it moves with its
target when the subtree is copied or re-attached, and is written in the MJCF
``<actuator>`` section referring to the target's resolved name.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.things.attrs import Choice, Flag, Integer, Real, Ref, Vector
from robotwright.things.base import BaseThing
from robotwright.things.runtime import sim_index

_LIMITED = Choice("auto", "true", "false")
_ACT_ATTR: dict[str, Any] = {
    "gear": Vector(6, trim=1),
    "ctrlrange": Vector(2, ordered=True),
    "ctrllimited": _LIMITED,
    "forcerange": Vector(2, ordered=True),
    "forcelimited": _LIMITED,
    "actrange": Vector(2, ordered=True),
    "actlimited": _LIMITED,
    "group": Integer(minimum=0),
    "refsite": Ref(),
}
_ACT_DEFAULTS: dict[str, Any] = {
    "gear": np.array([1.0, 0, 0, 0, 0, 0]),
    "ctrlrange": np.zeros(2),
    "ctrllimited": "auto",
    "forcerange": np.zeros(2),
    "forcelimited": "auto",
    "actrange": np.zeros(2),
    "actlimited": "auto",
    "group": 0,
    "refsite": None,
}


class Actuator(BaseThing):
    """Base of all actuators. ``gear`` scales the transmission; ``ctrlrange`` and
    ``forcerange`` clamp control and force (N or N m). ``ctrl`` reads/sets the control
    in ``world.data`` once built."""

    _NAMESPACE = "actuator"
    _CHILD_KINDS = frozenset({"sensor"})
    _NAMES_PARENT = True
    _TARGET_KINDS = frozenset({"joint", "site"})
    _NEW_MUJOCO_ATTR = _ACT_ATTR
    _NEW_BLUEPRINTS_ATTR = _ACT_ATTR
    _NEW_DEFAULT_VALS = _ACT_DEFAULTS

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)

    @property
    def ctrl(self) -> float:
        _, data, i = sim_index(self)
        return float(data.ctrl[i])

    @ctrl.setter
    def ctrl(self, value: float) -> None:
        _, data, i = sim_index(self)
        data.ctrl[i] = value

    @property
    def force(self) -> float:
        """Actuator force after the last step (N or N m)."""
        _, data, i = sim_index(self)
        return float(data.actuator_force[i])


class Motor(Actuator):
    """Direct force/torque: force = gear * ctrl."""

    _TAG = "motor"


class Position(Actuator):
    """Position servo: force = kp * (ctrl - q) - kv * qdot."""

    _TAG = "position"
    _NEW_MUJOCO_ATTR = {"kp": Real(nonneg=True), "kv": Real(nonneg=True)}
    _NEW_BLUEPRINTS_ATTR = {"kp": Real(nonneg=True), "kv": Real(nonneg=True)}
    _NEW_DEFAULT_VALS = {"kp": 1.0, "kv": 0.0}


class Velocity(Actuator):
    """Velocity servo: force = kv * (ctrl - qdot)."""

    _TAG = "velocity"
    _NEW_MUJOCO_ATTR = {"kv": Real(nonneg=True)}
    _NEW_BLUEPRINTS_ATTR = {"kv": Real(nonneg=True)}
    _NEW_DEFAULT_VALS = {"kv": 1.0}


_GENERAL_ATTR: dict[str, Any] = {
    "dyntype": Choice("none", "integrator", "filter", "filterexact", "muscle", "user"),
    "gaintype": Choice("fixed", "affine", "muscle", "user"),
    "biastype": Choice("none", "affine", "muscle", "user"),
    "dynprm": Vector(10, trim=1),
    "gainprm": Vector(10, trim=1),
    "biasprm": Vector(10, trim=1),
    "actearly": Flag(),
    "actdim": Integer(minimum=-1),
}


class General(Actuator):
    """MuJoCo's general actuator (dynamics, gain and bias types with their parameters)."""

    _TAG = "general"
    _NEW_MUJOCO_ATTR = _GENERAL_ATTR
    _NEW_BLUEPRINTS_ATTR = _GENERAL_ATTR
    _NEW_DEFAULT_VALS = {
        "dyntype": "none",
        "gaintype": "fixed",
        "biastype": "none",
        "dynprm": np.array([1.0] + [0.0] * 9),
        "gainprm": np.array([1.0] + [0.0] * 9),
        "biasprm": np.zeros(10),
        "actearly": False,
        "actdim": -1,
    }


ACTUATOR_CLASSES: tuple[type[Actuator], ...] = (Motor, Position, Velocity, General)
