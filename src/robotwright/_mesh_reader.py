"""Mesh files read with trimesh, their side files held to the same rules as the mesh.

A mesh file may name other files: a glTF's ``buffers[].uri`` and ``images[].uri``, an
OBJ's ``mtllib`` and the textures its material library names, a COLLADA file's
``<init_from>`` images. trimesh opens them through a *resolver*; the one given here
(:func:`contained_resolver`) opens a side file only when it resolves inside the folder
the mesh may read from (:func:`reading_root`: the robot's folder or ROS package while a
robot is read, else the mesh's own folder) or a trusted folder, is a regular file (a
FIFO never blocks), and is within the asset size cap. trimesh 5 refuses paths outside
the mesh's folder itself; trimesh 4.4, which the project still allows, does not.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Any

from robotwright._assets import check_asset_file
from robotwright._paths import check_regular, resolve_inside

__all__ = ["contained_resolver", "load_mesh_file", "reading_root"]

_ROOT: ContextVar[Path | None] = ContextVar("robotwright_mesh_reading_root", default=None)


@contextmanager
def reading_root(root: str | os.PathLike[str]) -> Iterator[Path]:
    """Within the block, side files of meshes may come from anywhere inside ``root``
    (the folder of the robot being read), not only the mesh's own folder."""
    token = _ROOT.set(Path(root).resolve())
    try:
        yield _ROOT.get()
    finally:
        _ROOT.reset(token)


def _resolver_base() -> type:
    import trimesh.resolvers

    return trimesh.resolvers.FilePathResolver


def contained_resolver(source: str | os.PathLike[str], root: Path | None = None) -> Any:
    """A trimesh ``FilePathResolver`` for ``source`` whose reads follow the rules of the
    module docstring (``root``: where side files may lie; default :func:`reading_root`
    or the mesh's folder)."""
    base = _resolver_base()
    folder = Path(source).resolve().parent
    allowed = root or _ROOT.get() or folder

    class _Contained(base):  # type: ignore[misc, valid-type]
        def get(self, name: str) -> bytes:
            path = Path(self.parent) / str(name)
            try:
                resolved = check_regular(
                    resolve_inside(path, base=self.parent, root=allowed, what="the mesh's folder")
                )
            except ValueError as exc:  # UnsafePathError is a ValueError
                raise ValueError(f"mesh {source}: side file '{name}': {exc}") from None
            check_asset_file(resolved, image=False)
            return resolved.read_bytes()

        def namespaced(self, namespace: str) -> Any:
            return contained_resolver(Path(self.parent) / namespace / "_", allowed)

        def write(self, name: str, data: Any) -> None:
            raise PermissionError(f"mesh {source}: a mesh reader may not write '{name}'")

    return _Contained(str(Path(source).resolve()))


def load_mesh_file(source: str | os.PathLike[str], **kwargs: Any) -> Any:
    """``trimesh.load(source, **kwargs)`` with the side files of the mesh read through
    :func:`contained_resolver`."""
    import trimesh

    return trimesh.load(str(source), resolver=contained_resolver(source), **kwargs)
