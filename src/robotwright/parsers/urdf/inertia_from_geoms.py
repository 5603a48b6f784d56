"""Mass and inertia of a URDF link without ``<inertial>``, computed by MuJoCo itself from
the link's collision geoms, as MuJoCo's own URDF import does (``inertiafromgeom="auto"``).

MuJoCo's URDF import gives each ``<collision>`` geom the default density (1000 kg/m^3)
and each ``<visual>`` geom density 0, so a link with visual geoms only, or with none,
gets no mass there. Here the link's collision geoms are put, in the link frame, on the
one body of a fresh :class:`mujoco.MjSpec` and compiled: the body's mass, centre of mass
and principal moments are MuJoCo's own (mesh volumes and inertias included), never a
formula of ours.

Units: mass in kg, lengths in m, density in kg/m^3, inertia in kg m^2 about the centre
of mass, expressed in the link frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robotwright._names import shown

#: MuJoCo's default geom density (kg/m^3), which its URDF import gives collision geoms.
DEFAULT_DENSITY = 1000.0
#: Values of ``URDFOptions.inertia_from_geoms`` (``--inertia-from-geoms``).
INERTIA_FROM_GEOMS = ("auto", "never")


@dataclass(frozen=True)
class GeomShape:
    """One collision geom in its link's frame.

    Attributes:
        type: ``box``, ``sphere``, ``cylinder``, ``capsule`` or ``mesh``.
        size: MuJoCo's size (half extents, radius, half length), m; unused for a mesh.
        pos: position in the link frame, m.
        quat: orientation in the link frame (w, x, y, z).
        file: the mesh file (absolute) for a mesh.
        scale: the mesh scale.
    """

    type: str
    size: tuple[float, float, float]
    pos: tuple[float, float, float]
    quat: tuple[float, float, float, float]
    file: Path | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class LinkInertia:
    """What MuJoCo computed: ``mass`` (kg), ``com`` (m, link frame), ``tensor`` (3x3,
    kg m^2, about the centre of mass, link frame), the principal ``moments`` and the
    principal frame ``iquat`` in the link frame (w, x, y, z), as MuJoCo orders them."""

    mass: float
    com: np.ndarray
    tensor: np.ndarray
    moments: tuple[float, float, float]
    iquat: tuple[float, float, float, float]


class InertiaFromGeomsError(Exception):
    """MuJoCo refuses to compute the inertia of these geoms (its message)."""


def check_density(value: float) -> float:
    """``value`` as a density: a finite number > 0 (kg/m^3). Raises ValueError."""
    try:
        density = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"density={shown(value)}: expected a finite number > 0 (kg/m^3)") from None
    if not (math.isfinite(density) and density > 0):
        raise ValueError(f"density={shown(value)}: expected a finite number > 0 (kg/m^3)")
    return density


def inertia_of_geoms(shapes: list[GeomShape], density: float = DEFAULT_DENSITY) -> LinkInertia:
    """Mass, centre of mass and inertia of ``shapes`` at ``density``, compiled by MuJoCo.

    Raises:
        InertiaFromGeomsError: MuJoCo refuses the geoms (a size <= 0, a mesh without
            volume), or what it computes is not finite (sizes of 1e150 m).
    """
    import mujoco

    from robotwright._rotations import quat_to_mat

    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body()
    body.name = "link"
    for i, s in enumerate(shapes):
        geom = body.add_geom()
        geom.pos = s.pos
        geom.quat = s.quat
        geom.density = density
        if s.type == "mesh":
            mesh = spec.add_mesh()
            mesh.name = f"mesh_{i}"
            mesh.file = str(s.file)
            mesh.scale = s.scale
            geom.type = mujoco.mjtGeom.mjGEOM_MESH
            geom.meshname = mesh.name
        else:
            geom.type = getattr(mujoco.mjtGeom, f"mjGEOM_{s.type.upper()}")
            geom.size = s.size
    try:
        model = spec.compile()
    except Exception as exc:  # noqa: BLE001 - MuJoCo's refusal, reported by the caller
        raise InertiaFromGeomsError(str(exc).splitlines()[0]) from exc
    moments = np.array(model.body_inertia[1], dtype=float)
    values = np.concatenate(([model.body_mass[1]], model.body_ipos[1], moments))
    if not np.all(np.isfinite(values)):
        raise InertiaFromGeomsError(f"MuJoCo's mass and inertia are not finite: {values.tolist()}")
    iquat = tuple(float(v) for v in model.body_iquat[1])
    rot = quat_to_mat(iquat)
    return LinkInertia(
        mass=float(model.body_mass[1]),
        com=np.array(model.body_ipos[1], dtype=float),
        tensor=rot @ np.diag(moments) @ rot.T,
        moments=(float(moments[0]), float(moments[1]), float(moments[2])),
        iquat=(iquat[0], iquat[1], iquat[2], iquat[3]),
    )
