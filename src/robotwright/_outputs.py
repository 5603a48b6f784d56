"""One overwrite rule for every command that writes files.

The rule (README, "Command line"): a command never replaces an existing output file or
non-empty output folder unless ``--overwrite`` is given; an empty folder is used as is.
``--overwrite`` replaces a file, never a folder, where the output is a file; where the
output is a folder it replaces only a folder robotwright wrote as that kind of output
(recognised by the :data:`MARKER` file every output folder gets, which lists the files
written), never a folder holding anything else, a folder that holds the working folder or
the home folder, or a symbolic link. It is checked before any work, so a refused run
writes nothing. ``robotwright demo`` refreshes its own output folder without the flag
(see :mod:`robotwright.cli.demo`), under the same rule.

Files copied next to a file output (``export``/``compose --copy-meshes``, ``convert`` to
a model file: ``meshes/<robot>/...``; ``things``: ``assets/...``) follow the rule too:
without ``--overwrite`` an existing file at a copy's name is refused unless it already
holds the same bytes (a repeated export is not refused for its own copies); with it, it
is replaced. Other files in those folders are never touched. See
:func:`check_copy_destination`.

Writers called from Python take ``overwrite=`` keyword arguments with the same meaning;
this module is the command line's side of it, importable without MuJoCo or numpy.
"""

from __future__ import annotations

import json
import os
import re
import stat
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path

from robotwright.errors import OutputExistsError

__all__ = [
    "MARKER",
    "check_copy_destination",
    "check_folder_output",
    "check_overwrite",
    "copies_replace",
    "existing_output",
    "write_marker",
]

#: The file every output folder gets: ``{"written_by": "robotwright", "kind": KIND,
#: "files": [...]}`` (the files and folders written, relative, ``/``-separated, folders
#: ending in ``/``). Readers of HRDF
#: folders skip hidden files, so it is ignored there.
MARKER = ".robotwright"
_MAX_MARKER_CHARS = 1 << 24
_KIND_NAMES = {
    "hrdf": "an HRDF folder",
    "design": "a design folder",
    "designs": "a folder of designs",
    "demo": "a demo folder",
}
#: Kinds of output folder, and (for folders written before the marker existed) the
#: file that identifies one and the names allowed at its top level.
_LEGACY: dict[str, tuple[str, re.Pattern[str]]] = {
    "hrdf": (
        "meta.yaml",
        re.compile(r"meta\.yaml|[a-z_]+\.csv|meshes|extra\.xml|joint_mapping\.yaml|exported"),
    ),
    "design": (
        "design.txt",
        re.compile(r"design\.(txt|json)|tree\.dot|picture\.png|warnings\.txt|[^/]+\.(xml|urdf)"),
    ),
    "demo": (
        "summary.json",
        re.compile(
            r"summary\.json|conversion_notes\.txt|robots|srl|scene|lidar|pictures|\w+_info\.txt"
        ),
    ),
    "designs": ("", re.compile(r"\d+_[0-9a-f]+")),
}


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
    *,
    kind: str | None = None,
) -> None:
    """Raise :class:`OutputExistsError` naming the first of ``paths`` (``None`` skipped)
    that exists, unless ``overwrite``; the message names the ``--overwrite`` flag.

    ``kind`` names the kind of output folder the paths are (``"hrdf"``, ``"design"``,
    ``"designs"``, ``"demo"``; ``None``: files). With ``overwrite`` a file output may
    replace a file (or a symbolic link, itself) but never a folder, and a folder output
    only a folder of its own kind (:func:`check_folder_output`).
    """
    items = [paths] if isinstance(paths, (str, os.PathLike)) else list(paths)
    for path in items:
        if path is None:
            continue
        if kind is not None:
            check_folder_output(path, kind, overwrite=overwrite)
            continue
        p = Path(path)
        if overwrite and p.is_dir() and not p.is_symlink():
            raise OutputExistsError(
                f"{path}: is a folder; --overwrite replaces a file, never a folder"
            )
        if not overwrite and existing_output(path):
            what = "folder is not empty" if p.is_dir() else "exists"
            raise OutputExistsError(
                f"{path}: {what}; not replacing it (give --overwrite to replace it, or "
                "another output path)"
            )


def _encloses_a_protected_folder(path: Path) -> str | None:
    """What ``path`` (an existing folder) holds that must never be replaced: the working
    folder or the home folder (or it is the file system's root)."""
    real = path.resolve()
    if real.parent == real:
        return "is the root folder"
    for what, where in (("the working folder", Path.cwd), ("your home folder", Path.home)):
        try:
            inner = where().resolve()
        except (OSError, RuntimeError, KeyError):  # deleted working folder, no home known
            continue
        if inner == real or real in inner.parents:
            return f"is or holds {what} ({inner})"
    return None


def _listing(folder: Path) -> set[str]:
    """Every file, link and folder under ``folder`` (relative, ``/``-separated), links
    not followed; folders end in ``/``."""
    found: set[str] = set()
    for root, dirs, files in os.walk(folder, followlinks=False):
        rel = Path(root).relative_to(folder).as_posix()
        prefix = "" if rel == "." else f"{rel}/"
        for name in dirs:
            full = Path(root, name)
            found.add(f"{prefix}{name}" + ("" if full.is_symlink() else "/"))
        found.update(f"{prefix}{name}" for name in files)
    return found


def _foreign_files(folder: Path, kind: str) -> list[str] | str:
    """The entries of ``folder`` that an output of ``kind`` did not write (empty when it
    may be replaced), or a sentence saying why it is not an output of ``kind``."""
    marker = folder / MARKER
    if marker.is_symlink() or (marker.exists() and not marker.is_file()):
        return f"{MARKER} is not a file robotwright wrote"
    if marker.is_file():
        try:
            with open(marker, encoding="utf-8") as fh:
                data = json.loads(fh.read(_MAX_MARKER_CHARS))
            written, was = set(map(str, data["files"])), str(data["kind"])
        except (OSError, ValueError, KeyError, TypeError):
            return f"its {MARKER} file cannot be read"
        if was != kind:
            return f"robotwright wrote it as {_KIND_NAMES.get(was, 'another kind of output')}"
        present = _listing(folder) - {MARKER}
        folders = {
            "/".join(parts[:i]) + "/"
            for parts in (str(f).split("/") for f in written)
            for i in range(1, len(parts))
        }
        return sorted(present - written - folders)
    # Written before output folders were marked: recognised by what such an output holds.
    required, names = _LEGACY[kind]
    entries = sorted(os.listdir(folder))
    foreign = [n for n in entries if not names.fullmatch(n)]
    if kind == "designs":
        foreign += [
            n for n in entries if n not in foreign and not (folder / n / "design.txt").is_file()
        ]
    if required and required not in entries:
        return entries  # not recognisably an output of this kind: all of it is foreign
    return foreign


def check_folder_output(path: str | os.PathLike[str], kind: str, *, overwrite: bool) -> None:
    """Raise :class:`OutputExistsError` unless the folder output ``path`` of ``kind`` may
    be written: it is missing, an empty folder, or (with ``overwrite``) a folder that
    robotwright wrote as a ``kind`` output and that holds nothing else.

    A folder output is never a file, a symbolic link, or a folder holding the working
    folder or the home folder."""
    p = Path(path)
    if not (p.exists() or p.is_symlink()):
        return
    refuse = "not replacing it: give a new or empty folder"
    if kind != "demo":  # the demo refreshes its own output without a flag
        refuse += f" (--overwrite replaces only {_KIND_NAMES[kind]} robotwright wrote)"
    if p.is_symlink():
        raise OutputExistsError(f"{path}: is a symbolic link; {refuse}")
    if not p.is_dir():
        raise OutputExistsError(f"{path}: is a file; expected a folder for the output")
    protected = _encloses_a_protected_folder(p)
    if protected is not None:
        raise OutputExistsError(f"{path}: {protected}; {refuse}")
    if not any(p.iterdir()):
        return
    foreign = _foreign_files(p, kind)
    if isinstance(foreign, str):
        raise OutputExistsError(f"{path}: folder is not empty and {foreign}; {refuse}")
    if foreign:
        listed = ", ".join(foreign[:3]) + (
            f" and {len(foreign) - 3} more" if len(foreign) > 3 else ""
        )
        raise OutputExistsError(
            f"{path}: folder holds files robotwright did not write ({listed}); {refuse}"
        )
    if not overwrite:
        raise OutputExistsError(
            f"{path}: folder is not empty; not replacing it (give --overwrite to replace it, "
            "or another output path)"
        )


def write_marker(folder: str | os.PathLike[str], kind: str) -> None:
    """Write :data:`MARKER` into ``folder`` (an output being built), listing every file in
    it: the folder can later be replaced by an output of the same ``kind``."""
    folder = Path(folder)
    files = sorted(_listing(folder) - {MARKER})
    text = json.dumps({"written_by": "robotwright", "kind": kind, "files": files}, indent=1)
    (folder / MARKER).write_text(text + "\n", encoding="utf-8")


#: Whether a copied file may replace a different file of the same name: True for Python
#: callers (``export(path)`` replaces its output), the command's ``--overwrite`` on the
#: command line (:func:`copies_replace`, set around every command that has the flag).
_REPLACE_COPIES: ContextVar[bool] = ContextVar("robotwright_replace_copies", default=True)


@contextmanager
def copies_replace(allowed: bool) -> Iterator[None]:
    """Within the block, files copied into an output replace different files of the same
    name only when ``allowed`` (see :func:`check_copy_destination`)."""
    token = _REPLACE_COPIES.set(bool(allowed))
    try:
        yield
    finally:
        _REPLACE_COPIES.reset(token)


def _same_bytes(a: Path, b: Path) -> bool:
    """Whether regular files ``a`` and ``b`` hold the same bytes (sizes compared first)."""
    if os.stat(a).st_size != os.stat(b).st_size:
        return False
    with open(a, "rb") as fa, open(b, "rb") as fb:
        while True:
            x, y = fa.read(1 << 20), fb.read(1 << 20)
            if x != y:
                return False
            if not x:
                return True


def check_copy_destination(dst: str | os.PathLike[str], src: str | os.PathLike[str]) -> None:
    """Raise :class:`OutputExistsError` when copying ``src`` to ``dst`` would replace
    something else and replacing is not allowed (:func:`copies_replace`): ``dst`` exists
    and is not a regular file holding exactly the bytes of ``src`` (a link, a folder, a
    FIFO, or a file with other content). Only ``lstat`` is asked of anything that is not
    a regular file: nothing there is opened or followed."""
    if _REPLACE_COPIES.get():
        return
    dst = Path(dst)
    try:
        mode = os.lstat(dst).st_mode
    except FileNotFoundError:
        return
    except OSError:
        mode = 0  # unreadable: not known to hold the same bytes
    if stat.S_ISREG(mode):
        try:
            if _same_bytes(Path(src), dst):
                return
        except OSError:
            pass  # cannot be compared: refused below
        what = "exists with other content"
    else:
        what = "exists and is not a regular file"
    raise OutputExistsError(
        f"{dst}: {what}; not replacing a file the output copies there (give --overwrite to "
        "replace it, or another output path)"
    )
