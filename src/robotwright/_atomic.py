"""All-or-nothing file and folder writing: write to a temporary name, then rename.

Readers never see a partial file, and a failed write (an exception, Ctrl-C) leaves
neither the temporary nor a half-written target behind; an existing target is only
replaced once the new content is complete. The temporary lives in the target's folder
so that the final rename stays on one file system (``os.replace`` is atomic there).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

from robotwright.errors import OutputPathError

__all__ = [
    "atomic_dir",
    "atomic_open",
    "atomic_path",
    "check_output_path",
    "copy_file_atomic",
    "write_text_atomic",
]


def check_output_path(path: str | os.PathLike[str], *, folder: bool = False) -> None:
    """Raise :class:`OutputPathError` when ``path`` cannot become a file (or a folder).

    Catches, before any work is done, the mistakes that would otherwise surface as a
    bare ``OSError`` half-way through: a file output that is an existing folder, and a
    parent path one of whose components is a file. A missing parent folder is fine
    (writers create it).
    """
    path = Path(path)
    if not folder and path.is_dir():
        raise OutputPathError(f"{path}: is a folder; expected the path of a file to write")
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise OutputPathError(f"{path}: cannot create it: {parent} is a file, not a folder")
            break


def _mkstemp(path: Path, **kw: Any) -> tuple[int, str]:
    check_output_path(path)
    try:
        return tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent, **kw)
    except OSError as exc:
        raise OutputPathError(
            f"{path}: cannot write in folder {path.parent}: {exc.strerror or exc}"
        ) from exc


@contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield an empty temporary file next to ``path``; on success rename it onto ``path``.

    The caller writes the temporary by name (for writers that only take a path).
    On any exception the temporary is removed and ``path`` is left as it was.
    The folder of ``path`` must exist.
    """
    path = Path(path)
    fd, tmp = _mkstemp(path)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


@contextmanager
def atomic_open(path: str | os.PathLike[str], mode: str = "w") -> Iterator[IO[Any]]:
    """Open a temporary file next to ``path`` for writing (``"w"`` UTF-8 text or ``"wb"``);
    it is renamed onto ``path`` when the block ends without an exception."""
    if mode not in ("w", "wb"):
        raise ValueError(f"atomic_open: mode must be 'w' or 'wb', got {mode!r}")
    encoding = "utf-8" if mode == "w" else None
    with atomic_path(path) as tmp, open(tmp, mode, encoding=encoding) as fh:
        yield fh


def write_text_atomic(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path``, creating its folder; see :func:`atomic_path`."""
    check_output_path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_open(path, "w") as fh:
        fh.write(text)


def copy_file_atomic(src: Path, dst: Path) -> None:
    """Copy ``src`` to ``dst``, creating its folder; see :func:`atomic_path`.

    Only a regular file is copied: a FIFO or a device as ``src`` raises
    :class:`~robotwright.errors.InputFileError` before anything is read or written.
    """
    from robotwright._inputs import copy_regular_file

    check_output_path(dst)
    dst.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(dst) as tmp:
        copy_regular_file(src, tmp)


@contextmanager
def atomic_dir(target: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield an empty temporary folder next to ``target``; on success it becomes ``target``.

    An existing ``target`` (file or folder) is replaced only after the block succeeded;
    callers decide beforehand whether replacing is allowed. On any exception the
    temporary folder is removed and ``target`` is left as it was. Creates the parent folder.
    """
    target = Path(target)
    check_output_path(target, folder=True)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    except OSError as exc:
        raise OutputPathError(
            f"{target}: cannot create a folder in {target.parent}: {exc.strerror or exc}"
        ) from exc
    try:
        yield tmp
        if target.exists():
            # Move the old one aside first: os.replace cannot overwrite a non-empty folder.
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old.", dir=target.parent))
            os.replace(target, old / "x")
            os.replace(tmp, target)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
