"""Light (MJCF ``<light>``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.things.attrs import Choice, Flag, Real, Ref, Vector
from robotwright.things.base import BaseThing

_LIGHT_ATTR: dict[str, Any] = {
    "pos": Vector(3),
    "dir": Vector(3, nonzero=True),
    "mode": Choice("fixed", "track", "trackcom", "targetbody", "targetbodycom"),
    "target": Ref(),
    "type": Choice("spot", "directional", "point", "image"),
    "castshadow": Flag(),
    "active": Flag(),
    "attenuation": Vector(3),
    "cutoff": Real(),
    "exponent": Real(),
    "ambient": Vector(3, nonneg=True),
    "diffuse": Vector(3, nonneg=True),
    "specular": Vector(3, nonneg=True),
    "bulbradius": Real(nonneg=True),
    "intensity": Real(nonneg=True),
    "range": Real(nonneg=True),
}


class Light(BaseThing):
    """A light at ``pos`` (m) shining along ``dir``, both in the parent body frame."""

    _NAMESPACE = "light"
    _TAG = "light"
    _NEW_MUJOCO_ATTR = _LIGHT_ATTR
    _NEW_BLUEPRINTS_ATTR = _LIGHT_ATTR
    _NEW_DEFAULT_VALS = {
        "pos": np.zeros(3),
        "dir": np.array([0.0, 0, -1]),
        "mode": "fixed",
        "target": None,
        "type": "spot",
        "castshadow": True,
        "active": True,
        "attenuation": np.array([1.0, 0, 0]),
        "cutoff": 45.0,
        "exponent": 10.0,
        "ambient": np.zeros(3),
        "diffuse": np.full(3, 0.7),
        "specular": np.full(3, 0.3),
        "bulbradius": 0.02,
        "intensity": 0.0,
        "range": 10.0,
    }

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)
