"""Resolution of mesh URIs in URDF files: ``package://``, ``file://`` and relative paths.

``package://NAME/rest`` is looked up, in this order:

1. the ``package_map`` argument (``{"NAME": folder}``);
2. ``ROS_PACKAGE_PATH`` entries (a folder named ``NAME``, or one holding a
   ``package.xml`` whose ``<name>`` is ``NAME``, up to three levels below each entry);
3. ``AMENT_PREFIX_PATH`` entries (``<prefix>/share/NAME``);
4. the URDF's ancestor folders: an ancestor called ``NAME``, an ancestor holding a
   ``NAME`` sub-folder, or an ancestor whose ``package.xml`` names ``NAME``.

A resolved path must stay inside its package folder (``..`` may not climb out), and a
relative or ``file://`` path must stay inside the robot folder (see :func:`robot_root`),
symbolic links followed, unless it lies in a folder trusted explicitly (see
:mod:`robotwright._paths`). A package found among the URDF's ancestors (step 4) must
hold a ``package.xml`` or lie inside the robot folder, so that ``package://etc/passwd``
cannot name ``/etc``.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path
from urllib.parse import unquote, urlparse

from robotwright._paths import resolve_inside
from robotwright.errors import UnsafePathError

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
    root = robot_root(urdf_path)

    def is_package(folder: Path) -> bool:
        # Any folder on the way up (/etc, /home) is not a package: it needs a package.xml
        # or must lie inside the robot folder.
        return folder.resolve().is_relative_to(root) or (folder / "package.xml").is_file()

    for ancestor in urdf_path.resolve().parents:
        if ancestor.name == name and is_package(ancestor):
            return ancestor
        if (ancestor / name).is_dir() and is_package(ancestor / name):
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
        try:
            path = resolve_inside(
                unquote(sub), base=pkg, root=pkg, what=f"the folder of package '{name}'"
            )
        except UnsafePathError as exc:
            raise UnresolvedMesh(f"'{uri}': {exc}") from None
    else:
        raw = Path(unquote(urlparse(uri).path)) if uri.startswith("file://") else Path(uri)
        try:
            path = resolve_inside(
                raw, base=urdf_path.resolve().parent, root=root or robot_root(urdf_path)
            )
        except UnsafePathError as exc:
            raise UnresolvedMesh(str(exc) if str(raw) == uri else f"'{uri}': {exc}") from None
    if not path.is_file():
        raise UnresolvedMesh(f"'{uri}' resolves to {path}, which does not exist")
    return path
