"""One robot source for every command: a name, an HRDF folder, a URDF, xacro or MJCF file.

:func:`resolve_source` says what a text names: an existing path is read by its kind
(a folder with ``meta.yaml`` is HRDF; ``.urdf``, ``.xacro`` / ``.urdf.xacro``, ``.xml`` /
``.mjcf`` files); anything else is a robot name, looked up in
:mod:`robotwright.catalog` (``$HURODES_ASSETS_PATH``, bundled robots, installed
description packages; ``SOURCE:NAME`` picks one source). :func:`load_robot` reads it
into an :class:`~robotwright.hrdf.model.HRDF` with the project's readers.

The command line adds one option group to every command that reads a robot
(:func:`robotwright.cli.options.add_source_options`: ``--root-body``,
``--fixed-joints``, ``--floating-base``, ``--bound-mass``, ``--bound-inertia``,
``--inertia-from-geoms``, ``--density``, ``--xacro-arg``; with ``--asset-root`` and
``--package``) and hands the options to the readers for the command's run with
:func:`given_source_options`, as
``--package`` is handed with :func:`robotwright.parsers.packages.given_packages`. An
option that does not apply to the source's kind (``--bound-mass`` for an MJCF) is an
error naming it.
"""

from __future__ import annotations

import logging
import os
import warnings
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robotwright.errors import ConversionWarning, RobotwrightError

if TYPE_CHECKING:
    from robotwright.catalog import RobotEntry
    from robotwright.hrdf.model import HRDF

__all__ = [
    "ResolvedSource",
    "SourceNotFoundError",
    "given_source_options",
    "load_robot",
    "load_robot_with_notes",
    "resolve_source",
]

#: Robot file kinds by extension (``.urdf.xacro`` ends in ``.xacro``).
FILE_KINDS = {
    ".urdf": "urdf",
    ".xacro": "xacro",
    ".xml": "mjcf",
    ".mjcf": "mjcf",
    ".usd": "usd",
    ".usda": "usd",
    ".usdc": "usd",
}

#: Options of the shared group, by the source kinds they apply to.
URDF_OPTIONS = (
    "fixed_joints",
    "bound_mass",
    "bound_inertia",
    "inertia_from_geoms",
    "density",
    "floating_base",
    "actuators",
    "actuator_gains",
)
MJCF_OPTIONS = ("root_body",)
XACRO_OPTIONS = ("xacro_args",)

_GIVEN: ContextVar[dict[str, Any]] = ContextVar("robotwright_source_options", default={})  # noqa: B039


class SourceNotFoundError(RobotwrightError):
    """A robot source names no file, folder or known robot."""


@dataclass(frozen=True)
class ResolvedSource:
    """What a source text names.

    Attributes:
        kind: ``hrdf``, ``urdf``, ``xacro`` or ``mjcf``.
        path: the HRDF folder or robot file.
        title: a short name (robot name, folder or file name without extension).
        entry: the catalog entry when the text was a robot name.
    """

    kind: str
    path: Path
    title: str
    entry: RobotEntry | None = None


@contextmanager
def given_source_options(options: Mapping[str, Any]) -> Iterator[None]:
    """Within the block, :func:`load_robot` reads every source with ``options`` (after
    its own keyword arguments): the options of a command line."""
    token = _GIVEN.set(dict(options))
    try:
        yield
    finally:
        _GIVEN.reset(token)


def resolve_source(text: str | os.PathLike[str]) -> ResolvedSource:
    """What ``text`` names (see the module docstring).

    Raises:
        SourceNotFoundError: no such file, a file of no robot kind, or no such robot.
    """
    raw = os.fspath(text)
    path = Path(raw)
    suffix = path.suffix.lower()
    if path.is_dir():
        if (path / "meta.yaml").is_file():
            return ResolvedSource("hrdf", path, path.resolve().name)
        entry = _catalog_entry(raw) if not _looks_like_path(raw) else None
        if entry is not None:
            return _from_entry(entry)
        raise SourceNotFoundError(
            f"{path}: a folder without meta.yaml: expected an HRDF folder, a URDF, xacro or "
            "MJCF file, or a robot name ('robotwright robots' lists them)"
        )
    if path.exists():
        kind = FILE_KINDS.get(suffix)
        if kind is None:
            raise SourceNotFoundError(
                f"{path}: a '{suffix or 'extensionless'}' file: expected a URDF (.urdf), "
                "xacro (.xacro), MJCF (.xml, .mjcf) or USD (.usd, .usda, .usdc) file, an "
                "HRDF folder or a robot name"
            )
        return ResolvedSource(kind, path, _stem(path))
    if suffix in FILE_KINDS or _looks_like_path(raw):
        raise SourceNotFoundError(f"{path}: no such file or folder")
    entry = _catalog_entry(raw)
    if entry is None:
        from robotwright._suggest import did_you_mean
        from robotwright.catalog import list_robots

        entries = list_robots()
        refs = [e.ref for e in entries]
        raise SourceNotFoundError(
            f"no robot named '{raw}' and no such file or folder ('robotwright robots' lists "
            f"the {len(refs)} robots known by name)"
            + did_you_mean(raw, refs)
            + _more_robots({e.source for e in entries})
        )
    return _from_entry(entry)


#: Packages that bring robots by name, when they are not installed: (the catalog's
#: source name, what they hold, how to install them).
_ROBOT_PACKAGES = (
    (
        "example-robot-data",
        "go2, solo12, talos, anymal, a1, ur5 and 50 more",
        "pip install example-robot-data",
    ),
    (
        "menagerie",
        "MuJoCo Menagerie's: unitree_go2, unitree_g1, franka_emika_panda, ...",
        "pip install 'robotwright[menagerie]'",
    ),
)


def _more_robots(sources: set[str]) -> str:
    """Where robots the user may be looking for come from, for the packages missing."""
    missing = [
        f"{what} with `{how}`" for source, what, how in _ROBOT_PACKAGES if source not in sources
    ]
    return f"; more robots by name: {'; '.join(missing)}" if missing else ""


def _looks_like_path(text: str) -> bool:
    return text.startswith((".", "~", os.sep)) or (os.altsep is not None and os.altsep in text)


def _stem(path: Path) -> str:
    name = path.name
    for suffix in (".urdf.xacro", *FILE_KINDS):
        if name.lower().endswith(suffix):
            return name[: -len(suffix)]
    return path.stem


def _catalog_entry(text: str) -> RobotEntry | None:
    from robotwright.catalog import RobotEntry, find_entry

    # $HURODES_ASSETS_PATH and the bundled robots first, without a scan of the
    # installed packages (nested names, a/b, are found there only).
    if ":" not in text:
        from robotwright.hrdf.assets import RobotNotFoundError, find_robot

        try:
            folder = find_robot(text)
        except RobotNotFoundError:
            pass
        else:
            return RobotEntry(text, "assets-or-bundled", "hrdf", folder, text)
    return find_entry(text)


def _from_entry(entry: RobotEntry) -> ResolvedSource:
    from robotwright.catalog import not_downloaded

    missing = not_downloaded(entry)
    if missing is not None:
        raise SourceNotFoundError(missing)
    title = entry.path.name if entry.format == "hrdf" else _stem(entry.path)
    return ResolvedSource(entry.format, entry.path, title, entry)


@contextmanager
def _quiet_parser_log() -> Iterator[None]:
    """The parsers log each note; a command reports them as warnings instead (one
    summary line), so the log is kept from the console while a source is read."""
    log = logging.getLogger("robotwright.parsers")
    old = log.propagate
    handler = logging.NullHandler()
    log.addHandler(handler)
    log.propagate = False
    try:
        yield
    finally:
        log.removeHandler(handler)
        log.propagate = old


def _check_applies(source: ResolvedSource, options: Mapping[str, Any]) -> None:
    applies = {
        "hrdf": (),
        "urdf": URDF_OPTIONS,
        "xacro": (*URDF_OPTIONS, *XACRO_OPTIONS),
        "mjcf": MJCF_OPTIONS,
        "usd": (),
    }[source.kind]
    unknown = sorted(k for k in options if k not in applies and k not in _PASSED)
    if unknown:
        flags = ", ".join(
            "--" + k.replace("_", "-").replace("xacro-args", "xacro-arg") for k in unknown
        )
        what = {"hrdf": "an HRDF folder", "mjcf": "an MJCF file", "usd": "a USD file"}.get(
            source.kind, "a URDF"
        )
        raise RobotwrightError(f"{source.path}: {flags} do(es) not apply to {what}")


#: Keyword arguments :func:`load_robot` passes on to every reader whatever the kind.
_PASSED = ("asset_roots", "package_map", "work_dir", "strict_kinds")


def load_robot_with_notes(
    source: str | os.PathLike[str],
    *,
    strict: bool = False,
    asset_roots: tuple[str | os.PathLike[str], ...] = (),
    **options: Any,
) -> tuple[HRDF, list[str]]:
    """Read ``source`` (a robot name, HRDF folder, URDF, xacro or MJCF file) into an HRDF;
    returns it and the readers' notes (values or elements not kept), one line each.

    ``options`` are those of :class:`~robotwright.parsers.URDFOptions` or
    :class:`~robotwright.parsers.mjcf.reader.MJCFOptions` (over the command line's, see
    :func:`given_source_options`).

    Raises:
        SourceNotFoundError: ``source`` names nothing loadable.
        RobotwrightError: what the readers raise (naming file, element and field), or an
            option that does not apply to the source's kind.
    """
    from robotwright._confine import run_confined
    from robotwright.parsers.packages import source_read_roots

    resolved = resolve_source(source)
    opts = {**_GIVEN.get(), **options}
    _check_applies(resolved, opts)
    roots = tuple(asset_roots)
    work = opts.get("work_dir")
    from robotwright.parsers.api import prepare_read

    prepare_read()
    if resolved.kind == "usd":
        from robotwright.parsers.usd.reader import prepare_confined_read

        prepare_confined_read()
    return run_confined(
        _read_source,
        resolved,
        strict,
        roots,
        opts,
        roots=source_read_roots(resolved.path, resolved.kind, {"asset_roots": roots}),
        writable=[work] if work else [],
        what=str(resolved.path),
    )


def _read_source(
    resolved: ResolvedSource, strict: bool, roots: tuple, opts: dict[str, Any]
) -> tuple[HRDF, list[str]]:
    """The reading step of :func:`load_robot_with_notes` (run confined): the HRDF and
    the readers' notes."""
    from robotwright.hrdf.model import HRDF

    if resolved.kind == "hrdf":
        from robotwright.hrdf.io import HRDFWarning

        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", HRDFWarning)
            hrdf = HRDF.from_dir(resolved.path, asset_roots=list(roots) or None)
        notes = [str(w.message) for w in caught if issubclass(w.category, HRDFWarning)]
        for w in caught:
            if not issubclass(w.category, HRDFWarning):
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return hrdf, notes
    from robotwright.parsers.api import (
        mjcf_to_hrdf_with_warnings,
        urdf_to_hrdf_with_warnings,
        usd_to_hrdf_with_warnings,
    )

    parse = {"mjcf": mjcf_to_hrdf_with_warnings, "usd": usd_to_hrdf_with_warnings}.get(
        resolved.kind, urdf_to_hrdf_with_warnings
    )
    if roots:
        opts = {**opts, "asset_roots": roots}
    with _quiet_parser_log():
        result = parse(resolved.path, strict=strict, **opts)
    return result.hrdf, [str(w) for w in result.warnings]


def load_robot(
    source: str | os.PathLike[str] | HRDF,
    *,
    strict: bool = False,
    asset_roots: tuple[str | os.PathLike[str], ...] = (),
    **options: Any,
) -> HRDF:
    """Read ``source`` into an HRDF (an HRDF is returned as is); each note of the readers
    is issued as a :class:`~robotwright.errors.ConversionWarning` (the command line
    counts them in one summary line). See :func:`load_robot_with_notes`."""
    from robotwright.hrdf.model import HRDF

    if isinstance(source, HRDF):
        return source
    hrdf, notes = load_robot_with_notes(source, strict=strict, asset_roots=asset_roots, **options)
    for note in notes:
        warnings.warn(note, ConversionWarning, stacklevel=2)
    return hrdf


def wants_parse() -> bool:
    """Whether the command line asked for the robot read out of an MJCF file
    (``--root-body``) rather than the file compiled by MuJoCo as it stands."""
    return any(k in _GIVEN.get() for k in MJCF_OPTIONS)
