"""The working folder taken off ``sys.path`` (see ``robotwright/__init__.py``)."""

from __future__ import annotations

import os


def without_working_folder(path: list[str]) -> list[str]:
    """``path`` less its entries that are the working folder (``""`` included)."""
    cwd = os.path.realpath(os.getcwd())
    return [p for p in path if p and os.path.realpath(p) != cwd]
