"""Joints (MJCF ``<joint>``): degrees of freedom between a body and its parent.

Angles are radians, lengths metres. The class fixes ``type``: :class:`Hinge`,
:class:`Slide`, :class:`Ball`, :class:`Free`. After the World is built, ``qpos`` and
``qvel`` read (and set) the joint's state in ``world.data``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.things.attrs import Choice, Flag, Integer, Real, Text, Vector
from robotwright.things.base import BaseThing
from robotwright.things.runtime import sim_index

_LIMITED = Choice("auto", "true", "false")
_JOINT_ATTR: dict[str, Any] = {
    "pos": Vector(3),
    "axis": Vector(3, nonzero=True),
    "range": Vector(2, ordered=True),
    "limited": _LIMITED,
    "ref": Real(),
    "springref": Real(),
    "stiffness": Vector(3, trim=1),
    "damping": Vector(3, nonneg=True, trim=1),
    "frictionloss": Real(nonneg=True),
    "armature": Real(nonneg=True),
    "margin": Real(),
    "group": Integer(minimum=0),
    "solreflimit": Vector(2),
    "solimplimit": Vector(5),
    "solreffriction": Vector(2),
    "solimpfriction": Vector(5),
    "springdamper": Vector(2),
    "actuatorfrcrange": Vector(2, ordered=True),
    "actuatorfrclimited": _LIMITED,
    "actuatorgravcomp": Flag(),
}
_JOINT_DEFAULTS: dict[str, Any] = {
    "type": "hinge",
    "pos": np.zeros(3),
    "axis": np.array([0.0, 0, 1]),
    "range": np.zeros(2),
    "limited": "auto",
    "ref": 0.0,
    "springref": 0.0,
    "stiffness": np.zeros(3),
    "damping": np.zeros(3),
    "frictionloss": 0.0,
    "armature": 0.0,
    "margin": 0.0,
    "group": 0,
    "solreflimit": np.array([0.02, 1.0]),
    "solimplimit": np.array([0.9, 0.95, 0.001, 0.5, 2.0]),
    "solreffriction": np.array([0.02, 1.0]),
    "solimpfriction": np.array([0.9, 0.95, 0.001, 0.5, 2.0]),
    "springdamper": np.zeros(2),
    "actuatorfrcrange": np.zeros(2),
    "actuatorfrclimited": "auto",
    "actuatorgravcomp": False,
}


class Joint(BaseThing):
    """Base of all joints. ``pos`` and ``axis`` are in the body frame; ``range`` in
    radians (hinge/ball) or metres (slide)."""

    _NAMESPACE = "joint"
    _TAG = "joint"
    _CHILD_KINDS = frozenset({"actuator", "sensor"})
    _NEW_MUJOCO_ATTR = {"type": Text(), **_JOINT_ATTR}
    _NEW_BLUEPRINTS_ATTR = _JOINT_ATTR
    _NEW_DERIVED_ATTR = {"type"}
    _NEW_DEFAULT_VALS = _JOINT_DEFAULTS
    type: str = ""

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)

    def _qpos_slice(self) -> tuple[Any, slice, slice]:
        model, data, i = sim_index(self)
        width = {0: 7, 1: 4}.get(int(model.jnt_type[i]), 1)
        vwidth = {0: 6, 1: 3}.get(int(model.jnt_type[i]), 1)
        qa, va = int(model.jnt_qposadr[i]), int(model.jnt_dofadr[i])
        return data, slice(qa, qa + width), slice(va, va + vwidth)

    @property
    def qpos(self) -> np.ndarray:
        """Current joint position(s) in ``world.data`` (radians or m), copy."""
        data, qs, _ = self._qpos_slice()
        return data.qpos[qs].copy()

    @qpos.setter
    def qpos(self, value: Any) -> None:
        data, qs, _ = self._qpos_slice()
        data.qpos[qs] = value

    @property
    def qvel(self) -> np.ndarray:
        data, _, vs = self._qpos_slice()
        return data.qvel[vs].copy()

    @qvel.setter
    def qvel(self, value: Any) -> None:
        data, _, vs = self._qpos_slice()
        data.qvel[vs] = value


class Hinge(Joint):
    """Rotation about ``axis`` through ``pos``; range in radians."""

    type = "hinge"


class Slide(Joint):
    """Translation along ``axis``; range in metres."""

    type = "slide"


class Ball(Joint):
    """Ball joint (3 rotational DoF, qpos a quaternion); ``range = [0, max angle]``."""

    type = "ball"
    _DEL_MUJOCO_ATTR = {"axis"}
    _DEL_BLUEPRINTS_ATTR = {"axis"}


class Free(Joint):
    """Free joint (6 DoF, qpos = position + quaternion) of a root body."""

    type = "free"
    _FREE_ONLY = {
        "axis",
        "range",
        "limited",
        "ref",
        "springref",
        "actuatorfrcrange",
        "actuatorfrclimited",
    }
    _DEL_MUJOCO_ATTR = _FREE_ONLY
    _DEL_BLUEPRINTS_ATTR = _FREE_ONLY
    _NEW_MUJOCO_ATTR = {"align": Choice("auto", "true", "false")}
    _NEW_BLUEPRINTS_ATTR = {"align": Choice("auto", "true", "false")}
    _NEW_DEFAULT_VALS = {"align": "auto"}


JOINT_CLASSES: tuple[type[Joint], ...] = (Hinge, Slide, Ball, Free)
