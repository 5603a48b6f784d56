"""See the robots: a browser viewer (viser) for any robot source.

``show(source)`` loads a bundled robot name, an HRDF folder, an MJCF or URDF file, a
composed scene, a grammar design folder or a scan ``.npz`` (with ``scene=``) and serves
a page drawing it with MuJoCo's colours, body and site frames, joint sliders (MuJoCo
forward kinematics) and, for a scan, the points coloured by semantic class::

    from robotwright.view import show

    viewer = show("mini_humanoid")
    print(viewer.url)        # open it in a browser
    viewer.set_joint("left_knee", 0.8)
    viewer.stop()
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import mujoco

    from robotwright.hrdf.model import HRDF
    from robotwright.scene.load import ScanCloud, ViewError, ViewScene, load_source
    from robotwright.view.server import Viewer, ViewerConfig

__all__ = [
    "ScanCloud",
    "ViewError",
    "ViewScene",
    "Viewer",
    "ViewerConfig",
    "load_source",
    "show",
]

#: Exported name -> module; imported on first use, so that importing this package
#: (as the command line does to register ``robotwright view``) loads neither MuJoCo nor
#: viser.
_LAZY = {
    "ScanCloud": "robotwright.scene.load",
    "ViewError": "robotwright.scene.load",
    "ViewScene": "robotwright.scene.load",
    "load_source": "robotwright.scene.load",
    "Viewer": "robotwright.view.server",
    "ViewerConfig": "robotwright.view.server",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def show(
    source: str | os.PathLike[str] | HRDF | mujoco.MjModel,
    *,
    scene: str | os.PathLike[str] | None = None,
    port: int | None = None,
    host: str = "127.0.0.1",
    asset_roots: tuple[str | os.PathLike[str], ...] = (),
    **config: Any,
) -> Viewer:
    """Serve a page showing ``source``; returns at once with the running :class:`Viewer`
    (``.url``, ``.stop()``, ``.set_joint(name, value)``).

    Args:
        source: robot name, HRDF folder, MJCF/URDF file, design folder, scan ``.npz``,
            or an ``HRDF`` / ``mujoco.MjModel`` object (see
            :func:`~robotwright.scene.load.load_source`).
        scene: the MJCF scene a scan was taken in.
        port: TCP port, that one only (a :class:`ViewError` when it is taken); None:
            8080 or the next free one; 0 for any free port.
        host: address to listen on (``127.0.0.1``: this machine only; another address
            warns that other machines can see the model).
        asset_roots: folders outside the source's folder its files may come from.
        config: other :class:`ViewerConfig` fields (``geom_groups``, ``body_frames``...).
    """
    from robotwright.scene.load import load_source
    from robotwright.view.server import Viewer, ViewerConfig

    cfg = ViewerConfig(host=host, port=port, **config)
    viewer = Viewer(load_source(source, scene=scene, asset_roots=asset_roots), cfg)
    if viewer.exposure:
        import warnings

        warnings.warn(viewer.exposure, UserWarning, stacklevel=2)
    return viewer
