"""Public entry points: file path in, :class:`~robotwright.hrdf.model.HRDF` out.

``*_to_hrdf`` return the robot and log each warning on the ``robotwright.parsers``
logger; ``*_with_warnings`` return a :class:`ParseResult` (``hrdf, warnings = ...``).
With ``strict=True`` any warning becomes one :class:`~robotwright.errors.ConversionError`
listing all of them.

The file and everything it names are read by a confined reader
(:func:`robotwright._confine.run_confined`): a process that may read only the file's
folder (a URDF's ROS package) and the folders the caller trusted.
"""

from __future__ import annotations

import os
from typing import Any

from robotwright.hrdf.model import HRDF
from robotwright.parsers.report import ParseResult


def urdf_to_hrdf_with_warnings(
    path: str | os.PathLike, *, strict: bool = False, **options: Any
) -> ParseResult:
    """Parse a URDF; ``options`` are the fields of :class:`~robotwright.parsers.URDFOptions`."""
    from robotwright.parsers.urdf.reader import URDFOptions, parse_urdf

    return _confined(parse_urdf, path, URDFOptions(**options), strict, "urdf", options)


def urdf_to_hrdf(path: str | os.PathLike, *, strict: bool = False, **options: Any) -> HRDF:
    """Parse a URDF into an HRDF (see :func:`urdf_to_hrdf_with_warnings`)."""
    return urdf_to_hrdf_with_warnings(path, strict=strict, **options).hrdf


def mjcf_to_hrdf_with_warnings(
    path: str | os.PathLike, *, strict: bool = False, **options: Any
) -> ParseResult:
    """Parse an MJCF; ``options`` are the fields of :class:`~robotwright.parsers.mjcf.reader.MJCFOptions`."""
    from robotwright.parsers.mjcf.reader import MJCFOptions, parse_mjcf

    return _confined(parse_mjcf, path, MJCFOptions(**options), strict, "mjcf", options)


def mjcf_to_hrdf(path: str | os.PathLike, *, strict: bool = False, **options: Any) -> HRDF:
    """Parse an MJCF into an HRDF (see :func:`mjcf_to_hrdf_with_warnings`)."""
    return mjcf_to_hrdf_with_warnings(path, strict=strict, **options).hrdf


def usd_to_hrdf_with_warnings(
    path: str | os.PathLike, *, strict: bool = False, **options: Any
) -> ParseResult:
    """Read an OpenUSD robot (``.usd``, ``.usda``, ``.usdc``) with Newton's USD importer;
    ``options`` are the fields of :class:`~robotwright.parsers.usd.reader.USDOptions`."""
    from robotwright.parsers.usd.reader import USDOptions, parse_usd

    return _confined(parse_usd, path, USDOptions(**options), strict, "usd", options)


def usd_to_hrdf(path: str | os.PathLike, *, strict: bool = False, **options: Any) -> HRDF:
    """Read an OpenUSD robot into an HRDF (see :func:`usd_to_hrdf_with_warnings`)."""
    return usd_to_hrdf_with_warnings(path, strict=strict, **options).hrdf


#: Modules of the readers' packages that are not read in a confined copy (USD's reader
#: needs Newton and prepares itself: :func:`robotwright.parsers.usd.reader.prepare_confined_read`).
_NOT_PREPARED = ("robotwright.parsers.usd",)
_prepared = False


def prepare_read() -> None:
    """Before a reader runs in a confined copy of this process: import here the modules
    the readers use and ask MuJoCo, here, the questions they ask it
    (:mod:`robotwright.parsers.mujoco_probes`, remembered). A copy keeps nothing of what
    it imports or learns, and may not write Python's bytecode cache (it may write no
    code), so without this every read would import, compile and ask again. Once per
    process; cheap after that."""
    global _prepared
    if _prepared:
        return
    import importlib
    import pkgutil

    import trimesh  # noqa: F401 - the mesh readers use it

    import robotwright.hrdf
    import robotwright.parsers
    from robotwright.parsers import mujoco_probes

    for package in (robotwright.hrdf, robotwright.parsers):
        for info in pkgutil.walk_packages(package.__path__, f"{package.__name__}."):
            if not info.name.startswith(_NOT_PREPARED):
                importlib.import_module(info.name)
    for name in dir(mujoco_probes):
        if name.startswith("mujoco_"):
            getattr(mujoco_probes, name)()
    _prepared = True


def _confined(
    parse: Any, path: str | os.PathLike, opts: Any, strict: bool, kind: str, options: dict
) -> ParseResult:
    """``parse(path, opts, strict=strict)`` in a confined reader that may read the
    source's root and the folders ``options`` trusts, and write its ``work_dir``."""
    from robotwright._confine import run_confined
    from robotwright._mesh_reader import reading_root
    from robotwright.parsers.packages import source_read_roots

    roots = source_read_roots(path, kind, options)
    work = options.get("work_dir")
    prepare_read()
    if kind == "usd":
        from robotwright.parsers.usd.reader import prepare_confined_read

        prepare_confined_read()
    with reading_root(roots[0]):
        return run_confined(
            parse,
            path,
            opts,
            strict=strict,
            roots=roots,
            writable=[work] if work else [],
            what=os.fspath(path),
        )
