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
    from robotwright.parsers.urdf import URDFOptions, parse_urdf

    return _confined(parse_urdf, path, URDFOptions(**options), strict, "urdf", options)


def urdf_to_hrdf(path: str | os.PathLike, *, strict: bool = False, **options: Any) -> HRDF:
    """Parse a URDF into an HRDF (see :func:`urdf_to_hrdf_with_warnings`)."""
    return urdf_to_hrdf_with_warnings(path, strict=strict, **options).hrdf


def mjcf_to_hrdf_with_warnings(
    path: str | os.PathLike, *, strict: bool = False, **options: Any
) -> ParseResult:
    """Parse an MJCF; ``options`` are the fields of :class:`~robotwright.parsers.mjcf.MJCFOptions`."""
    from robotwright.parsers.mjcf import MJCFOptions, parse_mjcf

    return _confined(parse_mjcf, path, MJCFOptions(**options), strict, "mjcf", options)


def mjcf_to_hrdf(path: str | os.PathLike, *, strict: bool = False, **options: Any) -> HRDF:
    """Parse an MJCF into an HRDF (see :func:`mjcf_to_hrdf_with_warnings`)."""
    return mjcf_to_hrdf_with_warnings(path, strict=strict, **options).hrdf


def usd_to_hrdf_with_warnings(
    path: str | os.PathLike, *, strict: bool = False, **options: Any
) -> ParseResult:
    """Read an OpenUSD robot (``.usd``, ``.usda``, ``.usdc``) with Newton's USD importer;
    ``options`` are the fields of :class:`~robotwright.parsers.usd.USDOptions`."""
    from robotwright.parsers.usd import USDOptions, parse_usd

    return _confined(parse_usd, path, USDOptions(**options), strict, "usd", options)


def usd_to_hrdf(path: str | os.PathLike, *, strict: bool = False, **options: Any) -> HRDF:
    """Read an OpenUSD robot into an HRDF (see :func:`usd_to_hrdf_with_warnings`)."""
    return usd_to_hrdf_with_warnings(path, strict=strict, **options).hrdf


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
    if kind == "usd":
        from robotwright.parsers.usd import prepare_confined_read

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
