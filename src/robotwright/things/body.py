"""Body: a node of the kinematic tree (MJCF ``<body>``) with its optional inertial."""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.things.attrs import Flag, Real, Vector
from robotwright.things.base import BaseThing
from robotwright.things.pose import POS, QUAT, PoseMixin
from robotwright.things.runtime import sim_index

_BODY_ATTR = {
    "pos": POS,
    "quat": QUAT,
    "mocap": Flag(),
    "gravcomp": Real(),
    # The inertial: all None means "computed from the geoms" (no <inertial> element).
    "mass": Real(nonneg=True, optional=True),
    "ipos": Vector(3, optional=True),
    "iquat": Vector(4, nonzero=True, optional=True),
    "inertia": Vector(3, nonneg=True, optional=True),
    "fullinertia": Vector(6, optional=True),
}


class Body(PoseMixin, BaseThing):
    """A rigid body, placed by ``pos`` (m) and ``quat`` (w, x, y, z) in its parent's frame.

    Attach geoms, joints, sites, cameras, lights and child bodies with :meth:`attach`.
    ``mass`` (kg), ``ipos``/``iquat`` (inertial frame in the body frame) and ``inertia``
    (principal moments, kg m^2) or ``fullinertia`` (Ixx Iyy Izz Ixy Ixz Iyz) write an
    explicit ``<inertial>``; when ``mass`` is None MuJoCo derives it from the geoms.

    After the World is built, ``xpos``/``xquat``/``xmat`` give the simulated pose in the
    world frame.
    """

    _NAMESPACE = "body"
    _TAG = "body"
    _CHILD_KINDS = frozenset({"body", "geom", "joint", "site", "camera", "light", "sensor"})
    _INERTIAL = ("mass", "ipos", "iquat", "inertia", "fullinertia")
    _NEW_MUJOCO_ATTR = _BODY_ATTR
    _NEW_BLUEPRINTS_ATTR = _BODY_ATTR
    _NEW_DEFAULT_VALS = {
        "pos": np.zeros(3),
        "quat": np.array([1.0, 0, 0, 0]),
        "mocap": False,
        "gravcomp": 0.0,
        "mass": None,
        "ipos": None,
        "iquat": None,
        "inertia": None,
        "fullinertia": None,
    }

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)

    # -- views of the subtree ------------------------------------------------------
    @property
    def bodies(self) -> list[Body]:
        """Direct child bodies."""
        return [c for c in self._children if c._NAMESPACE == "body"]

    @property
    def geoms(self) -> list[Any]:
        return [c for c in self._children if c._NAMESPACE == "geom"]

    @property
    def joints(self) -> list[Any]:
        return [c for c in self._children if c._NAMESPACE == "joint"]

    @property
    def sites(self) -> list[Any]:
        return [c for c in self._children if c._NAMESPACE == "site"]

    def all_joints(self) -> list[Any]:
        """Every joint in this subtree, MJCF order."""
        return [t for t in self.walk() if t._NAMESPACE == "joint"]

    def all_geoms(self) -> list[Any]:
        """Every geom in this subtree, MJCF order."""
        return [t for t in self.walk() if t._NAMESPACE == "geom"]

    def all_bodies(self) -> list[Body]:
        return [t for t in self.walk() if t._NAMESPACE == "body"]

    def set_all(self, kind: str, **values: Any) -> int:
        """Bulk edit: set attributes on every Thing of namespace ``kind`` in this subtree.

        Example: ``arm.set_all("joint", damping=[0.5, 0, 0], armature=0.01)``. Every value
        is validated per Thing. Returns how many Things were changed.
        """
        targets = [t for t in self.walk() if kind == t._NAMESPACE]
        for thing in targets:
            for key, value in values.items():
                if key not in thing._MUJOCO_ATTR:
                    raise AttributeError(f"{thing._label()} has no MuJoCo attribute {key!r}")
                setattr(thing, key, value)
        return len(targets)

    # -- runtime ---------------------------------------------------------------------
    @property
    def xpos(self) -> np.ndarray:
        """Simulated body frame position in the world frame (m), copy."""
        _, data, i = sim_index(self)
        return data.xpos[i].copy()

    @property
    def xquat(self) -> np.ndarray:
        """Simulated body orientation in the world frame (w, x, y, z), copy."""
        _, data, i = sim_index(self)
        return data.xquat[i].copy()

    @property
    def xmat(self) -> np.ndarray:
        _, data, i = sim_index(self)
        return data.xmat[i].reshape(3, 3).copy()

    @property
    def total_mass(self) -> float:
        """Mass of this body as compiled by MuJoCo (kg)."""
        model, _, i = sim_index(self)
        return float(model.body_mass[i])
