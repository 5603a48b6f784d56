"""Parsers: MJCF, URDF and USD files into the in-memory HRDF model.

>>> from robotwright.parsers import urdf_to_hrdf, mjcf_to_hrdf
>>> robot = urdf_to_hrdf("panda.urdf")                      # HRDF; warnings are logged
>>> robot, warnings = urdf_to_hrdf_with_warnings("panda.urdf")  # ParseResult
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.parsers.api import (
        mjcf_to_hrdf,
        mjcf_to_hrdf_with_warnings,
        urdf_to_hrdf,
        urdf_to_hrdf_with_warnings,
        usd_to_hrdf,
        usd_to_hrdf_with_warnings,
    )
    from robotwright.parsers.report import ParseResult
    from robotwright.parsers.urdf import URDFOptions

__all__ = [
    "ParseResult",
    "URDFOptions",
    "mjcf_to_hrdf",
    "mjcf_to_hrdf_with_warnings",
    "urdf_to_hrdf",
    "urdf_to_hrdf_with_warnings",
    "usd_to_hrdf",
    "usd_to_hrdf_with_warnings",
]

attach(__name__, __file__)
