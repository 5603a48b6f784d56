"""Resolution of mesh URIs in URDF files: ``package://``, ``file://`` and relative paths.

``package://NAME/rest`` is looked up, in this order:

1. the ``package_map`` argument (``{"NAME": folder}``);
2. ``ROS_PACKAGE_PATH`` entries (a folder named ``NAME``, or one holding a
   ``package.xml`` whose ``<name>`` is ``NAME``, up to three levels below each entry);
3. ``AMENT_PREFIX_PATH`` entries (``<prefix>/share/NAME``);
4. the URDF's ancestor folders: an ancestor called ``NAME``, an ancestor holding a
   ``NAME`` sub-folder, or an ancestor whose ``package.xml`` names ``NAME``.

A resolved path must stay inside its package folder (``..`` may not climb out), and a
relative or ``file://`` path must stay inside the robot folder (see :func:`robot_root`).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path
from urllib.parse import unquote, urlparse

_NAME_RE = re.compile(r"<name>\s*([^<\s]+)\s*</name>")


class UnresolvedMesh(Exception):
    """A mesh URI could not be resolved (message says why)."""


@lru_cache(maxsize=4096)
def _package_xml_name(folder: str) -> str | None:
    path = Path(folder) / "package.xml"
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    # package.xml is small and only the <name> is needed; a regex avoids parsing an
    # untrusted XML document at all.
    match = _NAME_RE.search(text)
    return match.group(1) if match else None


def _search_root(root: Path, name: str, depth: int = 3) -> Path | None:
    if not root.is_dir():
        return None
    if root.name == name or _package_xml_name(str(root)) == name:
        return root
    if depth == 0:
        return None
    try:
        children = sorted(p for p in root.iterdir() if p.is_dir())
    except OSError:
        return None
    for child in children:
        found = _search_root(child, name, depth - 1)
        if found is not None:
            return found
    return None


def find_package(
    name: str, urdf_path: Path, package_map: Mapping[str, str | os.PathLike] | None = None
) -> Path | None:
    """Folder of ROS package ``name`` (see the module docstring for the order)."""
    if package_map and name in package_map:
        return Path(package_map[name])
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry:
            found = _search_root(Path(entry), name)
            if found is not None:
                return found
    for entry in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        if entry and (Path(entry) / "share" / name).is_dir():
            return Path(entry) / "share" / name
    for ancestor in urdf_path.resolve().parents:
        if ancestor.name == name:
            return ancestor
        if (ancestor / name).is_dir():
            return ancestor / name
        if _package_xml_name(str(ancestor)) == name:
            return ancestor
    return None


def robot_root(urdf_path: Path) -> Path:
    """The folder relative and ``file://`` mesh paths must stay inside: the nearest
    ancestor of the URDF holding a ``package.xml``, else the parent of the URDF's folder
    (the usual ``urdf/`` + ``meshes/`` layout)."""
    resolved = urdf_path.resolve()
    for ancestor in resolved.parents:
        if (ancestor / "package.xml").is_file():
            return ancestor
    return resolved.parent.parent


def _inside(path: Path, root: Path) -> bool:
    try:
        path.relative_to(root)
    except ValueError:
        return False
    return True


def resolve_uri(
    uri: str,
    urdf_path: Path,
    package_map: Mapping[str, str | os.PathLike] | None = None,
    root: Path | None = None,
) -> Path:
    """Absolute, existing path of a mesh URI of the URDF at ``urdf_path``.

    Raises:
        UnresolvedMesh: unknown package, missing file, or a path escaping its folder.
    """
    if uri.startswith("package://"):
        rest = uri[len("package://") :].lstrip("/")
        name, _, sub = rest.partition("/")
        pkg = find_package(name, urdf_path, package_map)
        if pkg is None:
            raise UnresolvedMesh(
                f"package '{name}' not found (package_map, ROS_PACKAGE_PATH, "
                f"AMENT_PREFIX_PATH, ancestors of {urdf_path})"
            )
        base = pkg.resolve()
        path = (base / unquote(sub)).resolve()
        if not _inside(path, base):
            raise UnresolvedMesh(f"'{uri}' escapes package folder {base}")
    else:
        path = Path(unquote(urlparse(uri).path)) if uri.startswith("file://") else Path(uri)
        if not path.is_absolute():
            path = urdf_path.resolve().parent / path
        path = path.resolve()
        base = (root or robot_root(urdf_path)).resolve()
        if not _inside(path, base):
            raise UnresolvedMesh(f"'{uri}' resolves to {path}, outside the robot folder {base}")
    if not path.is_file():
        raise UnresolvedMesh(f"'{uri}' resolves to {path}, which does not exist")
    return path
