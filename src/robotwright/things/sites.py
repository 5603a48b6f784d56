"""Site (MJCF ``<site>``): a named frame on a body for sensors, actuators and markers."""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.things.attrs import Choice, Integer, Ref, Vector
from robotwright.things.base import BaseThing
from robotwright.things.pose import POS, QUAT, PoseMixin
from robotwright.things.runtime import sim_index

_SITE_ATTR: dict[str, Any] = {
    "type": Choice("sphere", "capsule", "ellipsoid", "cylinder", "box"),
    "size": Vector(3, nonneg=True),
    "pos": POS,
    "quat": QUAT,
    "group": Integer(minimum=0),
    "rgba": Vector(4, nonneg=True),
    "material": Ref(),
}


class Site(PoseMixin, BaseThing):
    """A frame on a body: ``pos`` (m) and ``quat`` (w, x, y, z) in the body frame.

    ``type``/``size`` only shape its rendering. Attach sensors (IMU, touch, force) and
    site-transmission actuators to it.
    """

    _NAMESPACE = "site"
    _TAG = "site"
    _CHILD_KINDS = frozenset({"sensor", "actuator"})
    _NEW_MUJOCO_ATTR = _SITE_ATTR
    _NEW_BLUEPRINTS_ATTR = _SITE_ATTR
    _NEW_DEFAULT_VALS = {
        "type": "sphere",
        "size": np.full(3, 0.005),
        "pos": np.zeros(3),
        "quat": np.array([1.0, 0, 0, 0]),
        "group": 0,
        "rgba": np.array([0.5, 0.5, 0.5, 1.0]),
        "material": None,
    }

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)

    @property
    def xpos(self) -> np.ndarray:
        """Simulated site position in the world frame (m), copy."""
        _, data, i = sim_index(self)
        return data.site_xpos[i].copy()

    @property
    def xmat(self) -> np.ndarray:
        _, data, i = sim_index(self)
        return data.site_xmat[i].reshape(3, 3).copy()
