"""Geoms: collision and visual shapes (MJCF ``<geom>``), one class per ``type``.

Sizes follow MJCF: half-sizes and radii in metres. The class fixes ``type`` (a derived
attribute): ``Sphere().type == "sphere"``; reading MJCF maps ``<geom type="sphere">``
back to :class:`Sphere`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.things.assets import MESH_ATTR
from robotwright.things.attrs import Choice, Integer, Real, Ref, Text, Vector
from robotwright.things.base import BaseThing
from robotwright.things.pose import POS, QUAT, PoseMixin
from robotwright.things.runtime import sim_index

_GEOM_ATTR: dict[str, Any] = {
    "size": Vector(3, nonneg=True, trim=1),
    "pos": POS,
    "quat": QUAT,
    "contype": Integer(minimum=0),
    "conaffinity": Integer(minimum=0),
    "condim": Integer(minimum=1),
    "group": Integer(minimum=0),
    "priority": Integer(),
    "friction": Vector(3, nonneg=True),
    "solmix": Real(nonneg=True),
    "solref": Vector(2),
    "solimp": Vector(5),
    "margin": Real(nonneg=True),
    "gap": Real(nonneg=True),
    "mass": Real(nonneg=True, optional=True),
    "density": Real(nonneg=True),
    "shellinertia": Choice("false", "true"),
    "rgba": Vector(4, nonneg=True),
    "material": Ref(),
    "fluidshape": Choice("none", "ellipsoid"),
    "fluidcoef": Vector(5),
}

_GEOM_DEFAULTS: dict[str, Any] = {
    "size": np.zeros(3),
    "pos": np.zeros(3),
    "quat": np.array([1.0, 0, 0, 0]),
    "contype": 1,
    "conaffinity": 1,
    "condim": 3,
    "group": 0,
    "priority": 0,
    "friction": np.array([1.0, 0.005, 0.0001]),
    "solmix": 1.0,
    "solref": np.array([0.02, 1.0]),
    "solimp": np.array([0.9, 0.95, 0.001, 0.5, 2.0]),
    "margin": 0.0,
    "gap": 0.0,
    "mass": None,
    "density": 1000.0,
    "shellinertia": "false",
    "rgba": np.array([0.5, 0.5, 0.5, 1.0]),
    "material": None,
    "fluidshape": "none",
    "fluidcoef": np.array([0.5, 0.25, 1.5, 1.0, 1.0]),
}


class Geom(PoseMixin, BaseThing):
    """Base of all geoms: pose in the body frame, contact and inertia parameters.

    ``mass`` (kg) overrides ``density`` (kg/m^3) when set. ``material`` names a material
    or is a :class:`~robotwright.things.assets.Material`.
    """

    _NAMESPACE = "geom"
    _TAG = "geom"
    _CHILD_KINDS = frozenset({"sensor"})
    _NEW_MUJOCO_ATTR = {"type": Text(), **_GEOM_ATTR}
    _NEW_BLUEPRINTS_ATTR = _GEOM_ATTR
    _NEW_DERIVED_ATTR = {"type"}
    _NEW_DEFAULT_VALS = {"type": "sphere", **_GEOM_DEFAULTS}
    type: str = ""

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)

    @property
    def xpos(self) -> np.ndarray:
        """Simulated geom position in the world frame (m), copy."""
        _, data, i = sim_index(self)
        return data.geom_xpos[i].copy()

    @property
    def xmat(self) -> np.ndarray:
        _, data, i = sim_index(self)
        return data.geom_xmat[i].reshape(3, 3).copy()


class Sphere(Geom):
    """Sphere; ``size = [radius]`` or ``radius=`` (m)."""

    type = "sphere"

    def __init__(
        self,
        name: str | None = None,
        parent: BaseThing | None = None,
        radius: float | None = None,
        **kwargs: Any,
    ):
        if radius is not None:
            kwargs["size"] = [radius, 0.0, 0.0]
        super().__init__(name=name, parent=parent, **kwargs)

    @property
    def radius(self) -> float:
        """Radius (m), ``size[0]``."""
        return float(self.size[0])

    @radius.setter
    def radius(self, value: float) -> None:
        self.size = [value, *self.size[1:]]


class Capsule(Geom):
    """Capsule along the local z axis; ``radius`` and ``half_length`` (m)."""

    type = "capsule"

    def __init__(
        self,
        name: str | None = None,
        parent: BaseThing | None = None,
        radius: float | None = None,
        half_length: float | None = None,
        **kwargs: Any,
    ):
        if radius is not None or half_length is not None:
            kwargs["size"] = [radius or 0.0, half_length or 0.0, 0.0]
        super().__init__(name=name, parent=parent, **kwargs)

    @property
    def radius(self) -> float:
        """Radius (m), ``size[0]``."""
        return float(self.size[0])

    @radius.setter
    def radius(self, value: float) -> None:
        self.size = [value, *self.size[1:]]

    @property
    def half_length(self) -> float:
        """Half length of the cylindrical part along local z (m), ``size[1]``."""
        return float(self.size[1])

    @half_length.setter
    def half_length(self, value: float) -> None:
        self.size = [self.size[0], value, self.size[2]]


class Cylinder(Capsule):
    """Cylinder along the local z axis; ``radius`` and ``half_length`` (m)."""

    type = "cylinder"


class Box(Geom):
    """Box; ``size`` are the three half-sizes (m)."""

    type = "box"


class Ellipsoid(Geom):
    """Ellipsoid; ``size`` are the three radii (m)."""

    type = "ellipsoid"


class Plane(Geom):
    """Infinite plane (collides as a half-space); ``size = [x half, y half, grid spacing]``
    only affects rendering."""

    type = "plane"


# The <mesh> asset's attributes (as on a MeshAsset), plus the asset name; a geom calls
# the asset's ``inertia`` ``meshinertia`` (a geom has no ``inertia`` of its own).
_MESH_ASSET_ATTR: dict[str, Any] = {
    "mesh": Text(),
    **{("meshinertia" if key == "inertia" else key): kind for key, kind in MESH_ATTR.items()},
}


class Mesh(Geom):
    """Mesh geom. ``file`` is the mesh file (STL/OBJ/MSH; absolute or relative to the
    working directory), or give ``vertex`` (flat x y z list, m) and optionally ``face``.

    ``mesh`` is the asset name written to MJCF (default: the file stem). ``scale`` scales
    the file's vertices. Geoms with equal asset attributes share one ``<mesh>`` asset.
    """

    type = "mesh"
    #: The geom owns a ``<mesh>`` asset made of these attributes (MJCF names in _ASSET_XML).
    _ASSET_TAG = "mesh"
    _ASSET_ATTR = tuple(_MESH_ASSET_ATTR)
    _ASSET_XML = {"meshinertia": "inertia"}
    _NEW_MUJOCO_ATTR = _MESH_ASSET_ATTR
    _NEW_BLUEPRINTS_ATTR = _MESH_ASSET_ATTR
    _NEW_DEFAULT_VALS = {
        "mesh": None,
        "file": None,
        "scale": np.ones(3),
        "vertex": None,
        "face": None,
        "maxhullvert": -1,
        "meshinertia": "legacy",
        "refpos": np.zeros(3),
        "refquat": np.array([1.0, 0, 0, 0]),
    }


_HFIELD_ASSET_ATTR: dict[str, Any] = {
    "hfield": Text(),
    "file": Text(),
    "nrow": Integer(minimum=0),
    "ncol": Integer(minimum=0),
    "hfield_size": Vector(4, nonneg=True),
    "elevation": Vector(None, optional=True),
}


class HField(Geom):
    """Height field geom. ``hfield_size = [x half, y half, z top, z bottom]`` (m); heights
    from an image/binary ``file``, from ``elevation`` (``nrow * ncol`` values, row-major,
    scaled to [0, 1] by MuJoCo), or all zero when only ``nrow``/``ncol`` are given (to be
    filled at run time in ``model.hfield_data``). ``hfield`` is the asset name."""

    type = "hfield"
    _ASSET_TAG = "hfield"
    _ASSET_ATTR = tuple(_HFIELD_ASSET_ATTR)
    _ASSET_XML = {"hfield_size": "size"}
    _NEW_MUJOCO_ATTR = _HFIELD_ASSET_ATTR
    _NEW_BLUEPRINTS_ATTR = _HFIELD_ASSET_ATTR
    _NEW_DEFAULT_VALS = {
        "hfield": None,
        "file": None,
        "nrow": 0,
        "ncol": 0,
        "hfield_size": np.zeros(4),
        "elevation": None,
    }


GEOM_CLASSES: tuple[type[Geom], ...] = (
    Sphere, Capsule, Cylinder, Box, Ellipsoid, Plane, Mesh, HField,
)  # fmt: skip
