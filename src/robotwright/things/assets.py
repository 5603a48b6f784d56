"""Shared assets: materials and textures (mesh assets come from :class:`Mesh` geoms).

Assets are not part of the kinematic tree: geoms and sites refer to them, copies of a
geom share the same asset object, and the World writes each referenced asset once in
``<asset>``. Changing an asset makes every World rebuild on its next use.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.things.attrs import Choice, Flag, Integer, Real, Ref, Text, Vector
from robotwright.things.base import BaseThing

_TEXTURE_ATTR: dict[str, Any] = {
    "type": Choice("2d", "cube", "skybox"),
    "builtin": Choice("none", "gradient", "checker", "flat"),
    "rgb1": Vector(3),
    "rgb2": Vector(3),
    "mark": Choice("none", "edge", "cross", "random"),
    "markrgb": Vector(3),
    "random": Real(),
    "width": Integer(minimum=0),
    "height": Integer(minimum=0),
    "file": Text(),
    "gridsize": Vector(2, integer=True),
    "gridlayout": Text(),
    # One image file per cube face (MJCF order: right, left, up, down, front, back).
    "fileright": Text(),
    "fileleft": Text(),
    "fileup": Text(),
    "filedown": Text(),
    "filefront": Text(),
    "fileback": Text(),
}

#: Texture attributes that name files (copied on export like a mesh file).
TEXTURE_FILE_ATTRS = (
    "file",
    "fileright",
    "fileleft",
    "fileup",
    "filedown",
    "filefront",
    "fileback",
)


class Texture(BaseThing):
    """A texture: a ``builtin`` pattern, an image ``file`` (absolute or relative path), or
    for a cube/skybox one image per face (``fileright``, ``fileleft``, ``fileup``,
    ``filedown``, ``filefront``, ``fileback``)."""

    _TAG = "texture"
    _ASSET_KIND = "texture"
    _NEW_MUJOCO_ATTR = _TEXTURE_ATTR
    _NEW_BLUEPRINTS_ATTR = _TEXTURE_ATTR
    _NEW_DEFAULT_VALS = {
        "type": "cube",
        "builtin": "none",
        "rgb1": np.full(3, 0.8),
        "rgb2": np.full(3, 0.5),
        "mark": "none",
        "markrgb": np.zeros(3),
        "random": 0.01,
        "width": 0,
        "height": 0,
        "file": None,
        "gridsize": np.array([1, 1]),
        "gridlayout": None,
        **{key: None for key in TEXTURE_FILE_ATTRS[1:]},
    }

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)


_MATERIAL_ATTR: dict[str, Any] = {
    "rgba": Vector(4, nonneg=True),
    "emission": Real(),
    "specular": Real(),
    "shininess": Real(),
    "reflectance": Real(),
    "metallic": Real(),
    "roughness": Real(),
    "texture": Ref(Texture),
    "texrepeat": Vector(2),
    "texuniform": Flag(),
}


class Material(BaseThing):
    """A material (colour, shading, optional texture) that geoms and sites refer to."""

    _TAG = "material"
    _ASSET_KIND = "material"
    _NEW_MUJOCO_ATTR = _MATERIAL_ATTR
    _NEW_BLUEPRINTS_ATTR = _MATERIAL_ATTR
    _NEW_DEFAULT_VALS = {
        "rgba": np.ones(4),
        "emission": 0.0,
        "specular": 0.5,
        "shininess": 0.5,
        "reflectance": 0.0,
        "metallic": -1.0,
        "roughness": -1.0,
        "texture": None,
        "texrepeat": np.ones(2),
        "texuniform": False,
    }

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)


#: The <mesh> asset's attributes (a Mesh geom writes the same, see geoms.py).
MESH_ATTR: dict[str, Any] = {
    "file": Text(),
    "scale": Vector(3),
    "vertex": Vector(None, optional=True),
    "face": Vector(None, optional=True, integer=True),
    "maxhullvert": Integer(minimum=-1),
    "inertia": Choice("convex", "exact", "legacy", "shell"),
    "refpos": Vector(3),
    "refquat": Vector(4, nonzero=True),
}


class MeshAsset(BaseThing):
    """A ``<mesh>`` asset that no geom uses (a geom owns its mesh: see
    :class:`~robotwright.things.geoms.Mesh`). MuJoCo compiles such meshes into the model
    (``nmesh``, mesh ids), so reading MJCF keeps them in ``World.assets``; ``file`` is
    copied on export like any mesh file. Units: ``scale`` is unitless, ``refpos`` in m."""

    _TAG = "mesh"
    _ASSET_KIND = "mesh"
    _NEW_MUJOCO_ATTR = MESH_ATTR
    _NEW_BLUEPRINTS_ATTR = MESH_ATTR
    _NEW_DEFAULT_VALS = {
        "file": None,
        "scale": np.ones(3),
        "vertex": None,
        "face": None,
        "maxhullvert": -1,
        "inertia": "legacy",
        "refpos": np.zeros(3),
        "refquat": np.array([1.0, 0, 0, 0]),
    }

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)
