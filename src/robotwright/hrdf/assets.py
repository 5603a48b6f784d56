"""Finding robots by name: ``$HURODES_ASSETS_PATH/robots/<name>``, then bundled robots."""

from __future__ import annotations

import os
from pathlib import Path

from robotwright._suggest import did_you_mean
from robotwright.errors import RobotwrightError

#: Folder of the robots shipped with robotwright.
BUNDLED_ROBOTS_DIR = Path(__file__).resolve().parents[1] / "robots"
#: Environment variable naming the assets root (as hurodes names it).
ASSETS_ENV = "HURODES_ASSETS_PATH"


class RobotNotFoundError(RobotwrightError):
    """No robot of that name under any assets root."""


def search_roots() -> list[Path]:
    """Folders searched for ``<name>``, in order."""
    roots = []
    env = os.environ.get(ASSETS_ENV)
    if env:
        roots.append(Path(env) / "robots")
    roots.append(BUNDLED_ROBOTS_DIR)
    return roots


def bundled_robot_names() -> list[str]:
    """Names of the robots shipped with robotwright."""
    return sorted(p.name for p in BUNDLED_ROBOTS_DIR.iterdir() if (p / "meta.yaml").is_file())


def find_robot(name: str) -> Path:
    """The folder of robot ``name`` (names may contain ``/`` for nested folders)."""
    tried = []
    for root in search_roots():
        candidate = root / name
        tried.append(str(candidate))
        if (candidate / "meta.yaml").is_file():
            return candidate
    known = bundled_robot_names() + [
        p.name for root in search_roots() if root.is_dir() for p in root.iterdir() if p.is_dir()
    ]
    raise RobotNotFoundError(
        f"no robot named '{name}': looked in {tried}; bundled robots: {bundled_robot_names()}"
        + did_you_mean(name, known)
    )


def resolve_robot(name_or_path: str | Path) -> Path:
    """A robot folder from either a path to an HRDF folder or a robot name."""
    path = Path(name_or_path)
    if (path / "meta.yaml").is_file():
        return path
    try:
        return find_robot(str(name_or_path))
    except RobotNotFoundError:
        # Something is there, so the user meant a path: say what is wrong with it
        # rather than that no robot has this name.
        if path.is_dir():
            raise RobotNotFoundError(
                f"{path}: not an HRDF folder: it has no meta.yaml (and no robot has this name)"
            ) from None
        if path.exists():
            raise RobotNotFoundError(
                f"{path}: is a file; expected an HRDF folder (with meta.yaml) or a robot name"
                + (
                    " (convert a URDF/MJCF first with 'robotwright convert')"
                    if path.suffix.lower() in (".urdf", ".xml")
                    else ""
                )
            ) from None
        raise
