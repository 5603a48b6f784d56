"""Camera (MJCF ``<camera>``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.things.attrs import Choice, Real, Ref, Vector
from robotwright.things.base import BaseThing
from robotwright.things.pose import POS, QUAT, PoseMixin

_CAMERA_ATTR: dict[str, Any] = {
    "pos": POS,
    "quat": QUAT,
    "mode": Choice("fixed", "track", "trackcom", "targetbody", "targetbodycom"),
    "target": Ref(),
    "fovy": Real(nonneg=True),
    "ipd": Real(nonneg=True),
    "resolution": Vector(2, integer=True),
}


class Camera(PoseMixin, BaseThing):
    """A camera looking along its local -z axis, up = local +y. ``fovy`` in degrees (as
    MJCF, whatever the compiler angle unit). ``target`` is a body name or Body for the
    ``targetbody*`` modes."""

    _NAMESPACE = "camera"
    _TAG = "camera"
    _CHILD_KINDS = frozenset({"sensor"})
    _NEW_MUJOCO_ATTR = _CAMERA_ATTR
    _NEW_BLUEPRINTS_ATTR = _CAMERA_ATTR
    _NEW_DEFAULT_VALS = {
        "pos": np.zeros(3),
        "quat": np.array([1.0, 0, 0, 0]),
        "mode": "fixed",
        "target": None,
        "fovy": 45.0,
        "ipd": 0.068,
        "resolution": np.array([1, 1]),
    }

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)
