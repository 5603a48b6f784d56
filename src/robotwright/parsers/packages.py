"""Resolution of mesh URIs in URDF files: ``package://``, ``file://`` and relative paths.

A URDF or xacro file downloaded from the web is untrusted: the paths it names must not
make robotwright read or copy files next to it that are not part of the robot (a
``robot.urdf`` saved in ``~/Downloads`` must not copy ``~/work/private.stl``). Its
*root* (:func:`robot_root`) is the folder it may read from: the ROS package folder that
holds it (the nearest ancestor with a ``package.xml``: ``my_robot_description/urdf/``
+ ``my_robot_description/meshes/``), else the URDF's own folder. Sibling and parent
folders are reachable only when the user names them: ``asset_roots`` /
``--asset-root DIR``, or a package given with ``package_map`` / ``--package NAME=DIR``.

``package://NAME/rest`` (and xacro's ``$(find NAME)``) is looked up, in this order:

1. the ``package_map`` argument (``{"NAME": folder}``), then the packages given with
   :func:`given_packages` (``robotwright --package NAME=DIR``);
2. ``ROS_PACKAGE_PATH`` entries (a folder named ``NAME``, or one holding a
   ``package.xml`` whose ``<name>`` is ``NAME``, up to three levels below each entry);
3. ``AMENT_PREFIX_PATH`` entries (``<prefix>/share/NAME``);
4. inside the root only: the root itself when its ``package.xml`` names ``NAME``, an
   ancestor of the URDF inside the root called ``NAME``, or a sub-folder ``NAME`` of
   such an ancestor (symbolic links followed: it must lie inside the root);
5. the ROS layout without its ``package.xml`` in an installed Python package: a URDF
   in a folder ``urdf`` whose parent folder is called ``NAME`` and lies in the Python
   installation (``site-packages/jvrc_description/urdf/jvrc1.urdf`` naming
   ``package://jvrc_description/meshes/...``, as pip installs it) gets that parent
   folder.

Steps 1 to 3 are the user's choice (arguments, command line, environment); step 4 never
leaves the root, and step 5 only takes a folder that the URI names exactly, one level
above the URDF's ``urdf`` folder, and only where the user installed it with pip: the
same layout anywhere else (``~/urdf/robot.urdf`` naming ``package://NAME/...`` with
the home folder called ``NAME``) reaches nothing above the URDF's folder.

A resolved path must stay inside its package folder (``..`` may not climb out), and a
relative or ``file://`` path must stay inside the root, symbolic links followed, unless
it lies in a folder trusted explicitly (see :mod:`robotwright._paths`).
"""

from __future__ import annotations

import contextlib
import os
import re
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from functools import lru_cache
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlparse

from robotwright._assets import check_asset_file
from robotwright._names import shown
from robotwright._paths import resolve_folder, resolve_inside
from robotwright.errors import InputFileError, UnsafePathError

_NAME_RE = re.compile(r"<name>\s*([^<\s]+)\s*</name>")

_GIVEN: ContextVar[tuple[tuple[str, Path], ...]] = ContextVar(
    "robotwright_given_packages", default=()
)


@contextmanager
def given_packages(packages: Mapping[str, str | os.PathLike[str]]) -> Iterator[dict[str, Path]]:
    """Within the block, ``package://NAME`` and ``$(find NAME)`` of every reader resolve
    to the folder ``packages[NAME]`` (after a reader's own ``package_map`` argument):
    the packages the user named (``robotwright --package NAME=DIR``). Yields every
    package given in the block.

    Raises:
        UnsafePathError: a folder does not exist, or a name is not a package name.
    """
    added = []
    for name, folder in packages.items():
        check_package_name(name)
        added.append((name, resolve_folder(folder, f"package '{name}': {folder}")))
    token = _GIVEN.set(tuple(added) + _GIVEN.get())
    try:
        yield dict(reversed(_GIVEN.get()))
    finally:
        _GIVEN.reset(token)


def given_package_map(
    package_map: Mapping[str, str | os.PathLike] | None = None,
) -> dict[str, str]:
    """``package_map`` over the packages of the enclosing :func:`given_packages` blocks
    (for a reader that runs in another process: the xacro expansion)."""
    merged = {name: str(folder) for name, folder in reversed(_GIVEN.get())}
    merged.update({str(k): str(v) for k, v in (package_map or {}).items()})
    return merged


_PACKAGE_NAME_RE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+-]*")


def check_package_name(name: str) -> str:
    """``name`` if it can name a package (letters, digits, ``_ . + -``, not starting with
    ``.`` or ``-``; no ``/``).

    Raises:
        UnsafePathError: otherwise.
    """
    if not _PACKAGE_NAME_RE.fullmatch(name or ""):
        raise UnsafePathError(
            f"package name {shown(name)}: expected letters, digits, '_', '.', '+' or '-' "
            "(not starting with '.' or '-')"
        )
    return name


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
    """Folder of ROS package ``name`` (see the module docstring for the order), or
    ``None``: not found, or only outside the URDF's root and not named by the user."""
    if package_map and name in package_map:
        return Path(package_map[name])
    for given, folder in _GIVEN.get():
        if given == name:
            return folder
    if not name or name in (".", "..") or "/" in name or "\0" in name:
        return None
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry:
            found = _search_root(Path(entry), name)
            if found is not None:
                return found
    for entry in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        if entry and (Path(entry) / "share" / name).is_dir():
            return Path(entry) / "share" / name
    return _package_inside_root(name, urdf_path)


def _package_inside_root(name: str, urdf_path: Path) -> Path | None:
    """Steps 4 and 5 of the module docstring: no folder outside the URDF's root, but the
    ``NAME/urdf/`` layout's ``NAME``."""
    resolved = urdf_path.resolve()
    root = robot_root(urdf_path)
    for ancestor in resolved.parents:
        if not ancestor.is_relative_to(root):
            break
        if ancestor.name == name or (ancestor == root and _package_xml_name(str(root)) == name):
            return ancestor
        child = ancestor / name
        if child.is_dir() and child.resolve().is_relative_to(root):
            return child
    folder = resolved.parent
    if (
        root == folder
        and folder.name == "urdf"
        and folder.parent.name == name
        and _in_python_installation(folder.parent)
    ):
        return folder.parent
    return None


def _in_python_installation(folder: Path) -> bool:
    """Whether ``folder`` is an installed Python package's: strictly inside a
    site-packages folder of this interpreter (where pip installs), never a shared
    folder itself."""
    from robotwright._confine import site_package_folders

    return any(
        folder != base and folder.is_relative_to(base) and base not in _shared_folders()
        for base in site_package_folders()
    )


def robot_root(urdf_path: Path) -> Path:
    """The folder a URDF or xacro file may read from (relative and ``file://`` mesh
    paths, xacro includes and ``load_yaml``): the nearest ancestor of the file holding a
    ``package.xml`` (the ROS package it belongs to), else the file's own folder.

    The search looks at most :data:`PACKAGE_SEARCH_DEPTH` folders up and never takes a
    shared folder (``/``, the home folder, the system's temporary folder) as a package:
    a ``package.xml`` planted there by someone else must not widen every robot below it
    to the whole shared folder."""
    resolved = urdf_path.resolve()
    for ancestor in resolved.parents[:PACKAGE_SEARCH_DEPTH]:
        if ancestor in _shared_folders():
            break
        if (ancestor / "package.xml").is_file():
            return ancestor
    return resolved.parent


def source_read_roots(
    path: str | os.PathLike[str], kind: str, options: Mapping[str, Any] | None = None
) -> list[Path]:
    """The folders a reader of the source ``path`` may read (the roots of its confined
    reader, see :mod:`robotwright._confine`): first the source's own root (an HRDF
    folder; an MJCF file's folder; a URDF or xacro file's :func:`robot_root`), then the
    folders ``options`` trusts (``asset_roots``, ``package_map``) and the packages the
    user named (:func:`given_packages`, ``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH``)."""
    path = Path(path)
    if kind == "hrdf":
        root = path.resolve()
    elif kind in ("mjcf", "usd"):
        root = path.resolve().parent
    else:
        root = robot_root(path)
    options = options or {}
    trusted = [*(options.get("asset_roots") or ())]
    trusted += given_package_map(options.get("package_map")).values()
    for variable in ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"):
        trusted += [p for p in os.environ.get(variable, "").split(os.pathsep) if p]
    return [root, *(Path(p) for p in trusted)]


#: Folders searched for a URDF's ``package.xml``, its own first (ROS keeps robot files a
#: few levels deep: ``urdf/``, ``urdf/xacro/``, ``robots/NAME/urdf/``; xacro's own test
#: robots sit four below theirs).
PACKAGE_SEARCH_DEPTH = 6


def _shared_folders() -> frozenset[Path]:
    """Folders many users or programs write into, never a robot's package."""
    # A confined reader's temporary folder is its staging folder: the system's is
    # passed on in ROBOTWRIGHT_SYSTEM_TMP (see robotwright._confine).
    temps = [tempfile.gettempdir(), os.environ.get("ROBOTWRIGHT_SYSTEM_TMP") or "/tmp"]
    folders = {Path("/"), *(Path(t).resolve() for t in temps)}
    with contextlib.suppress(RuntimeError, KeyError, OSError):
        folders.add(Path.home().resolve())
    return frozenset(folders)


def resolve_uri(
    uri: str,
    urdf_path: Path,
    package_map: Mapping[str, str | os.PathLike] | None = None,
    root: Path | None = None,
) -> Path:
    """Absolute, existing path of a mesh URI of the URDF at ``urdf_path``.

    Raises:
        UnresolvedMesh: unknown package, missing file, or a path escaping its folder.
        robotwright.errors.InputFileError: the file is larger than the mesh size limit
            (``--max-mesh-mb``; see :mod:`robotwright._assets`).
    """
    if uri.startswith("package://"):
        rest = uri[len("package://") :].lstrip("/")
        name, _, sub = rest.partition("/")
        pkg = find_package(name, urdf_path, package_map)
        if pkg is None:
            raise UnresolvedMesh(package_not_found(name, urdf_path))
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
        if path.exists():
            raise UnresolvedMesh(f"'{uri}' resolves to {path}, which is not a regular file")
        raise UnresolvedMesh(f"'{uri}' resolves to {path}, which does not exist")
    try:
        # Not an unresolved mesh (a caller may leave those to MuJoCo): a refusal.
        return check_asset_file(path)
    except InputFileError as exc:
        raise InputFileError(f"{urdf_path}: mesh '{uri}': {exc.path}", exc.reason) from None


def package_not_found(name: str, urdf_path: Path) -> str:
    """Why package ``name`` named by the file at ``urdf_path`` was not found, and how
    to name it."""
    return (
        f"package '{name}' not found inside {robot_root(urdf_path)} (the folder of "
        f"{urdf_path.name}, or the ROS package holding it), nor in package_map, "
        "ROS_PACKAGE_PATH or AMENT_PREFIX_PATH; name its folder with --package "
        f"{_shown_name(name)}=DIR (package_map in Python)"
    )


def _shown_name(name: str) -> str:
    return name if _PACKAGE_NAME_RE.fullmatch(name or "") else "NAME"
