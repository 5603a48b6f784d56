"""Readers: MJCF, URDF (and xacro) and USD files into the in-memory HRDF model.

>>> from robotwright.parsers import urdf_to_hrdf, mjcf_to_hrdf
>>> robot = urdf_to_hrdf("panda.urdf")                      # HRDF; warnings are logged
>>> robot, warnings = urdf_to_hrdf_with_warnings("panda.urdf")  # ParseResult

One package per format (``mjcf``, ``urdf``, ``xacro``, ``usd``), each naming its entry
points; ``api`` runs them in a confined reader. The helpers the formats share live here:
``meshes`` (mesh files read and checked), ``packages`` (``package://`` and the folders
a file may read), ``collision`` (opt-in collision mesh repairs), ``inertia`` (exact
diagonalisation), ``reference`` and ``robot_view`` (a source as MuJoCo's own importers
read it), ``mujoco_probes`` (what the installed MuJoCo does), ``report`` (notes and
:class:`ParseResult`). Readers import no writer.

``convert``, ``prove`` and ``roundtrip`` are names of the proof layer
(:mod:`robotwright.proof`), which compares a source with what the writers make of it;
they stay reachable here for code written before the proof had its own package, and
are imported only when used.
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
    from robotwright.parsers.urdf.common import URDFOptions
    from robotwright.proof.compare import prove
    from robotwright.proof.convert import convert
    from robotwright.proof.roundtrip.run import roundtrip

__all__ = [
    "ParseResult",
    "URDFOptions",
    "convert",
    "mjcf_to_hrdf",
    "mjcf_to_hrdf_with_warnings",
    "prove",
    "roundtrip",
    "urdf_to_hrdf",
    "urdf_to_hrdf_with_warnings",
    "usd_to_hrdf",
    "usd_to_hrdf_with_warnings",
]

attach(__name__, __file__)
