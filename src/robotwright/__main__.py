"""``python -m robotwright``: the command line, with the working folder taken off
``sys.path`` first (``python -m`` puts it there): a robot folder that ships ``yaml.py``
or ``trimesh.py`` must not be imported when the command runs in it."""

import os
import sys


def _without_working_folder(path: list[str]) -> list[str]:
    cwd = os.path.realpath(os.getcwd())
    return [p for p in path if p and os.path.realpath(p) != cwd]


sys.path[:] = _without_working_folder(sys.path)

from robotwright.cli import main  # noqa: E402 - after sys.path is made safe

sys.exit(main())
