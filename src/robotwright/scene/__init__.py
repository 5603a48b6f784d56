"""Loading anything the drawing commands show, below both :mod:`robotwright.render` and
:mod:`robotwright.view`: a robot source, a grammar design folder or a LiDAR scan with its
scene, compiled to a MuJoCo model (:mod:`robotwright.scene.load`); the physics a model
is shown with (:mod:`robotwright.scene.display`); and the triangles of MuJoCo's
primitive shapes and height fields (:mod:`robotwright.scene.geometry`)."""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.scene.load import ScanCloud, ViewError, ViewScene, compile_mjcf, load_source

__all__ = ["ScanCloud", "ViewError", "ViewScene", "compile_mjcf", "load_source"]

attach(__name__, __file__)
