"""Every robot robotwright can load by name, and where each comes from.

Robots are found, in this order of precedence (a name taken by an earlier source is
given to the later ones' robots as ``SOURCE:NAME``):

1. ``assets``: HRDF folders under ``$HURODES_ASSETS_PATH/robots/`` (the seed's variable);
2. ``bundled``: the HRDF robots shipped with robotwright;
3. installed Python packages named ``*_description`` (``jvrc_description``): their
   ``urdf/``, ``mjcf/`` and ``robots/`` folders;
4. installed description packages under a ``share/`` folder (of this Python's prefix,
   of cmeel's prefix, and of each ``AMENT_PREFIX_PATH`` entry), as example-robot-data
   installs itself (``share/example-robot-data/robots/<package>/urdf/*.urdf``): their
   ``urdf/``, ``robots/``, ``mjcf/`` folders and those of their ``robots/*/``;
5. ``robot_descriptions``: the repositories robot_descriptions has already downloaded
   into its cache (``$ROBOT_DESCRIPTIONS_CACHE``, else ``~/.cache/robot_descriptions``);
   nothing is downloaded;
6. ``menagerie``: with the ``mujoco-menagerie`` package installed, every robot of its
   registry by its name there (``unitree_go2``), as its default model file: under
   ``$MENAGERIE_ROOT/<name>/`` when that is set (a Menagerie checkout), else in the
   package's download cache. Nothing is downloaded: one not on disk is listed (``robots``
   says "not downloaded") and loading it says how to fetch it.

A robot file's name is its file name without extension (``solo12``); two files of one
source with the same name are named ``PACKAGE/NAME`` (the folder under the source
holding each). A package holding one robot is also known by the package's name without
``_description`` / ``_data``; example-robot-data's own loader names (``talos``,
``hyq``, ``ur5``, ...) name the file its Python loader loads.

The scan reads folder listings only (and the first bytes of ``.xml`` files, to tell MJCF
from other XML); nothing is cached on disk, and no robot is parsed.
"""

from __future__ import annotations

import os
import site
import sys
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["MENAGERIE", "RobotEntry", "find_entry", "list_robots", "not_downloaded"]

#: Sub-folders of a description package that hold robot files.
_ROBOT_FOLDERS = ("urdf", "robots", "mjcf", "xml")
#: Robot file extensions and their format (``.xml`` only when it is MJCF).
_FORMATS = {".urdf": "urdf", ".xacro": "xacro", ".xml": "mjcf", ".mjcf": "mjcf"}
#: Folders of one repository searched below its top for robot files (robot_descriptions).
_REPO_DEPTH = 3
#: Most files of one folder looked at (a folder of thousands of meshes is not a robot's).
_MAX_ENTRIES = 2000

#: example-robot-data's loader names (its Python ``load(name)``) that differ from a
#: file name: ``name -> (package folder, file name without extension)``.
_ERD_ALIASES: dict[str, tuple[str, str]] = {
    "talos": ("talos_data", "talos_reduced"),
    "talos_box": ("talos_data", "talos_reduced_box"),
    "talos_full": ("talos_data", "talos_full_v2"),
    "talos_full_box": ("talos_data", "talos_full_v2_box"),
    "talos_arm": ("talos_data", "talos_left_arm"),
    "anymal": ("anymal_b_simple_description", "anymal"),
    "anymal_c": ("anymal_c_simple_description", "anymal"),
    "anymal_kinova": ("anymal_b_simple_description", "anymal-kinova"),
    "hyq": ("hyq_description", "hyq_no_sensors"),
    "ur3": ("ur_description", "ur3_robot"),
    "ur5": ("ur_description", "ur5_robot"),
    "ur10": ("ur_description", "ur10_robot"),
    "g1": ("g1_description", "g1_29dof_rev_1_0"),
    "hector": ("hector_description", "quadrotor_base"),
    "asr_twodof": ("asr_twodof_description", "TwoDofs"),
}


@dataclass(frozen=True)
class RobotEntry:
    """One robot that can be loaded by name.

    Attributes:
        name: the robot's name in its source (file name without extension, an HRDF
            folder's name, or an alias).
        source: where it was found: ``assets``, ``bundled``, or the installed package
            (``example-robot-data``, ``jvrc_description``, ``robot_descriptions``).
        format: ``hrdf``, ``urdf``, ``xacro`` or ``mjcf``.
        path: the HRDF folder or robot file.
        ref: what to type in a command: ``name``, or ``SOURCE:NAME`` when an earlier
            source has a robot of that name.
    """

    name: str
    source: str
    format: str
    path: Path
    ref: str = field(default="", compare=False)

    @property
    def qualified(self) -> str:
        """``SOURCE:NAME``: names this robot whatever other sources hold."""
        return f"{self.source}:{self.name}"


def list_robots() -> list[RobotEntry]:
    """Every robot loadable by name, in order of precedence, each with its ``ref``."""
    taken: set[str] = set()
    out: list[RobotEntry] = []
    for entry in _scan():
        ref = entry.name if entry.name not in taken else entry.qualified
        taken.add(entry.name)
        out.append(RobotEntry(entry.name, entry.source, entry.format, entry.path, ref))
    return out


def find_entry(text: str) -> RobotEntry | None:
    """The robot named ``text`` (``NAME`` or ``SOURCE:NAME``), or ``None``."""
    source, sep, name = text.rpartition(":")
    for entry in list_robots():
        if (sep and entry.source == source and entry.name == name) or entry.ref == text:
            return entry
    return None


def _scan() -> Iterator[RobotEntry]:
    from robotwright.hrdf.assets import ASSETS_ENV, BUNDLED_ROBOTS_DIR

    env = os.environ.get(ASSETS_ENV)
    if env:
        yield from _hrdf_folders(Path(env) / "robots", "assets")
    yield from _hrdf_folders(BUNDLED_ROBOTS_DIR, "bundled")
    seen: set[Path] = set()
    for folder in _site_folders():
        for pkg in _children(folder):
            if pkg.name.endswith("_description") and _new(pkg, seen):
                yield from _named(pkg.name, _package_files(pkg), pkg.name)
    for share in _share_folders():
        for pkg in _children(share):
            if not _new(pkg, seen):
                continue
            files = list(_package_files(pkg))
            for sub in _children(pkg / "robots"):
                files += _package_files(sub)
            if files:
                yield from _named(pkg.name, files, pkg.name)
    cache = _robot_descriptions_cache()
    if cache is not None:
        files = [f for repo in _children(cache) for f in _repo_files(repo, _REPO_DEPTH)]
        yield from _named("robot_descriptions", files, None)
    yield from _menagerie()


#: The source name of Menagerie's robots.
MENAGERIE = "menagerie"


def _menagerie() -> Iterator[RobotEntry]:
    """Menagerie's robots from the mujoco-menagerie package's registry (no download):
    each the file of its default model, where it is or would be on disk."""
    import importlib.util

    if importlib.util.find_spec("mujoco_menagerie") is None:
        return
    import mujoco_menagerie as menagerie

    cache = menagerie.Cache()
    for name in menagerie.names():
        robot = menagerie.get(name)
        file = robot.entry(robot.default_model).file
        folder = cache.root / name if cache.root else cache.model_path(robot)
        yield RobotEntry(name, MENAGERIE, "mjcf", folder / file)


def not_downloaded(entry: RobotEntry) -> str | None:
    """For a Menagerie robot not on disk: one line saying how to fetch it; else None."""
    if entry.source != MENAGERIE or entry.path.is_file():
        return None
    where = os.environ.get("MENAGERIE_ROOT")
    if where:
        return (
            f"Menagerie's robot '{entry.name}' is not under MENAGERIE_ROOT={where} "
            f"(expected {entry.path})"
        )
    return (
        f"Menagerie's robot '{entry.name}' is not downloaded: `python -m mujoco_menagerie "
        f"prefetch {entry.name}` fetches it (or set MENAGERIE_ROOT to a Menagerie checkout)"
    )


def _new(path: Path, seen: set[Path]) -> bool:
    try:
        key = path.resolve()
    except OSError:
        return False
    if key in seen:
        return False
    seen.add(key)
    return True


def _children(folder: Path) -> list[Path]:
    """Sub-folders of ``folder``, sorted (none when it cannot be listed)."""
    try:
        with os.scandir(folder) as it:
            names = [e.name for e, _ in zip(it, range(_MAX_ENTRIES)) if _is_dir(e)]
    except OSError:
        return []
    return [folder / n for n in sorted(names) if not n.startswith(".")]


def _is_dir(entry: os.DirEntry[str]) -> bool:
    try:
        return entry.is_dir()
    except OSError:
        return False


def _hrdf_folders(root: Path, source: str) -> Iterator[RobotEntry]:
    for folder in _children(root):
        if (folder / "meta.yaml").is_file():
            yield RobotEntry(folder.name, source, "hrdf", folder)


def _robot_files(folder: Path) -> list[tuple[Path, str]]:
    """The robot files directly in ``folder`` with their format."""
    try:
        with os.scandir(folder) as it:
            entries = [e for e, _ in zip(it, range(_MAX_ENTRIES))]
    except OSError:
        return []
    out = []
    for e in sorted(entries, key=lambda e: e.name):
        path = Path(e.path)
        suffix = path.suffix.lower()
        fmt = _FORMATS.get(suffix)
        if fmt is None or e.name.startswith(".") or not e.is_file():
            continue
        if fmt == "mjcf" and not _is_mjcf(path):
            continue
        out.append((path, fmt))
    return out


def _is_mjcf(path: Path) -> bool:
    """An ``.xml`` whose first element is ``<mujoco>`` (looked for in its first 4 kB)."""
    try:
        with path.open("rb") as f:
            head = f.read(4096)
    except OSError:
        return False
    return b"<mujoco" in head


def _package_files(pkg: Path) -> list[tuple[Path, str]]:
    return [f for sub in _ROBOT_FOLDERS for f in _robot_files(pkg / sub)]


def _repo_files(folder: Path, depth: int) -> list[tuple[Path, str]]:
    files = _robot_files(folder)
    if depth > 0:
        for child in _children(folder):
            files += _repo_files(child, depth - 1)
    return files


def _named(source: str, files: list[tuple[Path, str]], package: str | None) -> list[RobotEntry]:
    """Entries of one source's files: named by file stem (``.urdf.xacro`` -> its stem
    without ``.urdf``); a stem held by several files is named ``PACKAGE/STEM``."""
    stems: dict[str, list[tuple[Path, str]]] = {}
    for path, fmt in files:
        stem = path.name[: -len(path.suffix)]
        stem = stem[:-5] if stem.lower().endswith(".urdf") else stem
        stems.setdefault(stem, []).append((path, fmt))
    out: list[RobotEntry] = []
    for stem, found in sorted(stems.items()):
        if len(found) == 1:
            out.append(RobotEntry(stem, source, found[0][1], found[0][0]))
            continue
        # Several files of one name: a .urdf next to its .xacro is the same robot.
        by_folder: dict[Path, tuple[Path, str]] = {}
        for path, fmt in sorted(found, key=lambda x: x[1] != "urdf"):
            by_folder.setdefault(path.parent, (path, fmt))
        if len(by_folder) == 1:
            path, fmt = next(iter(by_folder.values()))
            out.append(RobotEntry(stem, source, fmt, path))
            continue
        for path, fmt in by_folder.values():
            out.append(RobotEntry(_folder_name(path, stem, by_folder), source, fmt, path))
    names = {e.name for e in out}
    out += _aliases(source, out, names, package)
    return out


def _folder_name(path: Path, stem: str, others: dict[Path, tuple[Path, str]]) -> str:
    """``FOLDER/STEM`` with as many folders above the file (``urdf``/``robots``/... left
    out) as make it differ from the other files of that stem."""

    def folders(p: Path) -> list[str]:
        return [f for f in p.parent.parts if f not in _ROBOT_FOLDERS]

    mine = folders(path)
    rest = [folders(p) for p, _ in others.values() if p != path]
    for k in range(1, len(mine) + 1):
        if all(r[-k:] != mine[-k:] for r in rest):
            return "/".join([*mine[-k:], stem])
    return "/".join([*mine, stem])


def _package_of(path: Path) -> str:
    """The package folder holding a robot file: the one above ``urdf``/``robots``/..."""
    parent = path.parent
    return parent.parent.name if parent.name in _ROBOT_FOLDERS else parent.name


def _short(package: str) -> str:
    for suffix in ("_simple_description", "_description", "_data"):
        if package.endswith(suffix):
            return package[: -len(suffix)]
    return package


def _aliases(
    source: str, entries: list[RobotEntry], names: set[str], package: str | None
) -> list[RobotEntry]:
    """Package names of one-robot packages, and example-robot-data's loader names."""
    out: list[RobotEntry] = []
    by_package: dict[str, list[RobotEntry]] = {}
    for e in entries:
        by_package.setdefault(_package_of(e.path), []).append(e)
    for pkg, held in sorted(by_package.items()):
        short = _short(pkg)
        if len(held) == 1 and short not in names and short != pkg:
            out.append(RobotEntry(short, source, held[0].format, held[0].path))
            names.add(short)
    if source == "example-robot-data":
        for alias, (pkg, stem) in _ERD_ALIASES.items():
            match = [
                e
                for e in entries
                if _package_of(e.path) == pkg and e.path.name.startswith(stem + ".")
            ]
            if match and alias not in names:
                out.append(RobotEntry(alias, source, match[0].format, match[0].path))
                names.add(alias)
    return out


def _site_folders() -> list[Path]:
    """This Python's package folders (site-packages)."""
    folders = [*site.getsitepackages(), site.getusersitepackages()]
    folders += [p for p in sys.path if p.endswith(("site-packages", "dist-packages"))]
    return [Path(p) for p in dict.fromkeys(folders) if p and Path(p).is_dir()]


def _share_folders() -> list[Path]:
    """``share/`` folders that may hold description packages."""
    prefixes = [Path(sys.prefix), *(Path(p) / "cmeel.prefix" for p in map(str, _site_folders()))]
    prefixes += [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return [p / "share" for p in dict.fromkeys(prefixes) if (p / "share").is_dir()]


def _robot_descriptions_cache() -> Path | None:
    env = os.environ.get("ROBOT_DESCRIPTIONS_CACHE")
    path = Path(env).expanduser() if env else Path.home() / ".cache" / "robot_descriptions"
    return path if path.is_dir() else None
