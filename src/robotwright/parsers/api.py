"""Public entry points: file path in, :class:`~robotwright.hrdf.model.HRDF` out.

``*_to_hrdf`` return the robot and log each warning on the ``robotwright.parsers``
logger; ``*_with_warnings`` return a :class:`ParseResult` (``hrdf, warnings = ...``).
With ``strict=True`` any warning becomes one :class:`~robotwright.errors.ConversionError`
listing all of them.
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

    return parse_urdf(path, URDFOptions(**options), strict=strict)


def urdf_to_hrdf(path: str | os.PathLike, *, strict: bool = False, **options: Any) -> HRDF:
    """Parse a URDF into an HRDF (see :func:`urdf_to_hrdf_with_warnings`)."""
    return urdf_to_hrdf_with_warnings(path, strict=strict, **options).hrdf


def mjcf_to_hrdf_with_warnings(
    path: str | os.PathLike, *, strict: bool = False, **options: Any
) -> ParseResult:
    """Parse an MJCF; ``options`` are the fields of :class:`~robotwright.parsers.mjcf.MJCFOptions`."""
    from robotwright.parsers.mjcf import MJCFOptions, parse_mjcf

    return parse_mjcf(path, MJCFOptions(**options), strict=strict)


def mjcf_to_hrdf(path: str | os.PathLike, *, strict: bool = False, **options: Any) -> HRDF:
    """Parse an MJCF into an HRDF (see :func:`mjcf_to_hrdf_with_warnings`)."""
    return mjcf_to_hrdf_with_warnings(path, strict=strict, **options).hrdf
