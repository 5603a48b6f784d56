"""The round trip: a source read into an HRDF, written back as our MJCF and URDF, each
compiled and compared with the source as MuJoCo (or an independent URDF library) reads
it.

Entry point: :func:`roundtrip` (``robotwright roundtrip``), giving a
:class:`RoundTripReport`. Modules: ``run`` (the entry point), ``sides`` (the source, our
MJCF and our URDF as models), ``compare`` (bodies, joints and forward kinematics at
random configurations), ``geoms`` and ``report`` (rows and tolerances).
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.proof.roundtrip.report import RoundTripReport, Row
    from robotwright.proof.roundtrip.run import roundtrip
    from robotwright.proof.roundtrip.sides import our_mjcf_model

__all__ = ["RoundTripReport", "Row", "our_mjcf_model", "roundtrip"]

attach(__name__, __file__)
