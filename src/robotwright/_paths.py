"""Where a file path read from a robot may point: one containment check.

Robot folders, MJCF and URDF files are shared on the web, so a path written inside them
(an HRDF ``mesh.csv`` ``file`` cell or mesh ``name``, an MJCF ``<mesh file>``,
``meshdir`` or ``<include>``, a URDF ``<mesh filename>``) is untrusted: it must not make
robotwright read, compile or copy a file from elsewhere on disk (``/etc/passwd``,
``~/.ssh/id_rsa``). Every reader (HRDF loading and validation, the MJCF and URDF
parsers, the Things MJCF reader) and every copier (``HRDF.save``, generator
``export(copy_meshes=True)``) uses :func:`resolve_inside`:

- the path is resolved the way it will be opened: relative to its base folder, ``..``
  collapsed and symbolic links followed, so a link inside ``meshes/`` that points to
  ``/etc``, or a ``meshes/`` that is itself such a link, counts as outside;
- the resolved path must lie inside the robot's folder, or inside a folder the caller
  trusts explicitly: the ``asset_roots`` argument of the Python readers, a
  :func:`trusted_asset_roots` block, or ``robotwright --asset-root DIR`` on the command
  line (which opens such a block around the command).

Robots built in memory by Python code (no folder) are trusted: their absolute mesh paths
are the caller's own.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path

from robotwright.errors import UnsafePathError

__all__ = ["resolve_inside", "trusted_asset_roots", "trusted_roots"]

PathLike = str | os.PathLike[str]

_TRUSTED: ContextVar[tuple[Path, ...]] = ContextVar("robotwright_trusted_roots", default=())


def _root(folder: PathLike) -> Path:
    path = Path(folder).expanduser()
    try:
        resolved = path.resolve()
    except (OSError, RuntimeError) as exc:
        raise UnsafePathError(f"{folder}: trusted asset root cannot be resolved: {exc}") from None
    if not resolved.is_dir():
        raise UnsafePathError(f"{folder}: trusted asset root is not a folder")
    return resolved


@contextmanager
def trusted_asset_roots(roots: Iterable[PathLike]) -> Iterator[tuple[Path, ...]]:
    """Within the block, paths that resolve inside one of ``roots`` are accepted by every
    reader and copier, in addition to the robot's own folder (opt-in for shared mesh
    libraries outside the robot folder). Yields every root trusted in the block.

    Raises:
        UnsafePathError: a root is not an existing folder.
    """
    token = _TRUSTED.set(_TRUSTED.get() + tuple(_root(r) for r in roots))
    try:
        yield _TRUSTED.get()
    finally:
        _TRUSTED.reset(token)


def trusted_roots(extra: Iterable[PathLike] | None = None) -> tuple[Path, ...]:
    """The folders trusted here: ``extra`` (resolved) and those of the enclosing
    :func:`trusted_asset_roots` blocks."""
    return tuple(_root(r) for r in extra or ()) + _TRUSTED.get()


def resolve_inside(
    file: PathLike,
    *,
    base: PathLike,
    root: PathLike,
    trusted: Sequence[Path] | None = None,
) -> Path:
    """The resolved path of ``file`` (a relative one is taken from folder ``base``),
    which must lie inside folder ``root`` or a trusted folder.

    Args:
        file: the path as written in the input.
        base: the folder a relative ``file`` is relative to.
        root: the folder the path must stay inside (the robot's folder).
        trusted: resolved folders also allowed; ``None``: :func:`trusted_roots`.

    Raises:
        UnsafePathError: the path leaves ``root`` (the message says where it resolves
            to, and whether a symbolic link took it there) or cannot be resolved (a
            link loop). The caller adds the file and element the path came from.
    """
    given = Path(file)
    full = given if given.is_absolute() else Path(base) / given
    try:
        resolved = full.resolve()
        root_path = Path(root).resolve()
    except (OSError, RuntimeError) as exc:  # a symbolic link loop
        raise UnsafePathError(f"'{file}': cannot be resolved: {exc}") from None
    if resolved.is_relative_to(root_path):
        return resolved
    allowed = trusted_roots() if trusted is None else trusted
    if any(resolved.is_relative_to(t) for t in allowed):
        return resolved
    lexical = Path(os.path.normpath(os.path.abspath(full)))
    how = (
        " through a symbolic link"
        if lexical.is_relative_to(os.path.abspath(root)) or lexical.is_relative_to(root_path)
        else ""
    )
    raise UnsafePathError(
        f"'{file}' resolves{how} to {resolved}: expected a path inside the robot folder "
        f"{root_path} (a folder outside it can be trusted with asset_roots / --asset-root)"
    )
