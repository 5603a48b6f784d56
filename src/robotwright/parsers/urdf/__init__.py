"""The URDF reader: a URDF file (or a xacro file, expanded first) into an HRDF.

Entry points: :func:`parse_urdf` with :class:`URDFOptions`. Most callers go through
:func:`robotwright.parsers.urdf_to_hrdf`, which runs the reader in a confined process.
Modules: ``reader`` (the entry point), ``joints``, ``links`` (inertials, visuals and
collisions), ``actuators`` (from ``<transmission>``, ``ros2_control`` and the options),
``common`` (options and value helpers), and what only URDF needs: ``fixed`` (fixed joint
policies), ``geom_pairs`` (a visual and a collision of one shape made one geom),
``inertia_from_geoms`` (a link's inertia from its geoms where none is given),
``visuals`` and ``unresolved`` (meshes that cannot be built or found).
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.parsers.urdf.common import URDFOptions
    from robotwright.parsers.urdf.reader import parse_urdf

__all__ = ["URDFOptions", "parse_urdf"]

attach(__name__, __file__)
