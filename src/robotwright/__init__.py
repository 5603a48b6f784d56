"""robotwright: describe, generate, compose and sense robots for simulation."""

import sys as _sys

if _sys.argv[:1] == ["-m"]:
    # ``python -m robotwright`` in a robot's folder: Python put the working folder first
    # on sys.path, and a ``yaml.py`` or ``trimesh.py`` shipped with the robot would be
    # imported instead of the library. Take it off before anything is imported.
    from robotwright._no_working_folder import without_working_folder

    _sys.path[:] = without_working_folder(_sys.path)

__version__ = "0.1.0"

from robotwright._mujoco_gl import import_mujoco

import_mujoco()  # before any module imports mujoco: an unusable MUJOCO_GL must not stop it

from robotwright._atomic import mesh_size_limit  # noqa: E402
from robotwright._limits import keyframe_limit  # noqa: E402
from robotwright._paths import trusted_asset_roots  # noqa: E402

__all__ = ["__version__", "keyframe_limit", "mesh_size_limit", "trusted_asset_roots"]

#: Subpackages and modules reachable as attributes after ``import robotwright``
#: (``robotwright.view.show(...)``): each is imported on first use, so ``import
#: robotwright`` stays quick and imports no viewer, renderer or mesh library.
_SUBMODULES = frozenset(
    {
        "catalog",
        "errors",
        "generators",
        "grammar",
        "hrdf",
        "parsers",
        "proof",
        "render",
        "scene",
        "sensors",
        "sources",
        "tasks",
        "things",
        "view",
    }
)


def __getattr__(name: str) -> object:
    if name in _SUBMODULES:
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | _SUBMODULES)
