"""One overwrite rule for every command that writes files.

The rule (README, "Command line"): a command never replaces an existing output file or
non-empty output folder unless ``--overwrite`` is given; an empty folder is used as is.
It is checked before any work, so a refused run writes nothing. ``robotwright demo``
is the one exception: it refreshes its own output folder (see :mod:`robotwright.demo`).

Writers called from Python take ``overwrite=`` keyword arguments with the same meaning;
this module is the command line's side of it, importable without MuJoCo or numpy.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Iterable
from pathlib import Path

from robotwright.errors import OutputExistsError

__all__ = ["add_overwrite_flag", "check_overwrite", "existing_output"]

OVERWRITE_HELP = "replace an existing output (without it an existing output is refused)"


def add_overwrite_flag(parser: argparse.ArgumentParser) -> None:
    """Add ``--overwrite`` (``args.overwrite``, default False) to a command's parser."""
    parser.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP)


def existing_output(path: str | os.PathLike[str]) -> bool:
    """Whether writing ``path`` would replace something: a file (or link), or a folder
    that holds anything. A missing path or an empty folder replaces nothing."""
    p = Path(path)
    if p.is_symlink() or p.is_file():
        return True
    if p.is_dir():
        return any(p.iterdir())
    return p.exists()


def check_overwrite(
    paths: str | os.PathLike[str] | Iterable[str | os.PathLike[str] | None],
    overwrite: bool,
) -> None:
    """Raise :class:`OutputExistsError` naming the first of ``paths`` (``None`` skipped)
    that exists, unless ``overwrite``; the message names the ``--overwrite`` flag."""
    if overwrite:
        return
    items = [paths] if isinstance(paths, (str, os.PathLike)) else list(paths)
    for path in items:
        if path is not None and existing_output(path):
            what = "folder is not empty" if Path(path).is_dir() else "exists"
            raise OutputExistsError(
                f"{path}: {what}; not replacing it (give --overwrite to replace it, or "
                "another output path)"
            )
