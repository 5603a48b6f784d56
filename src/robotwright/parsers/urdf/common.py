"""What every part of the URDF reader shares: its options (:class:`URDFOptions`), the geom
groups it writes, and the reading of numbers and poses from untrusted attributes (each
bad value named with its element)."""

from __future__ import annotations

import math
import os
import sys
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from robotwright._names import shown
from robotwright.errors import ConversionError, Problem
from robotwright.parsers import inertia as inr
from robotwright.parsers.report import Reporter
from robotwright.parsers.urdf import actuators as acts
from robotwright.parsers.urdf import inertia_from_geoms as geom_inertia
from robotwright.parsers.urdf.fixed import FIXED_POLICIES, FixedPolicy

VISUAL_GROUP = 2

COLLISION_GROUP = 3

#: Group of a geom read from a visual and collision pair (MuJoCo's default geom group).
DRAWN_COLLISION_GROUP = 0

# "spherical" is not in the URDF specification; pybullet and MuJoCo read it as a ball.
_JOINT_TYPES = {"revolute", "continuous", "prismatic", "fixed", "floating", "planar", "spherical"}


@dataclass(frozen=True)
class URDFOptions:
    """How a URDF is turned into HRDF.

    Attributes:
        fixed_joints: ``"keep"`` (a body per link, default), ``"merge"`` (a link on a
            fixed joint is merged into its parent: mass, centre of mass and inertia
            combined exactly, geoms re-posed, the link frame kept as a site named after
            it), or ``"site"`` (only massless leaf links on fixed joints become sites).
        package_map: ``{"package name": folder}`` tried first for ``package://`` URIs.
        mesh_root: folder relative and ``file://`` mesh paths must stay inside
            (default: see :func:`robotwright.parsers.packages.robot_root`).
        work_dir: folder where meshes are staged/converted (default: a new temp folder).
        actuators: ``"none"`` (default; URDF has no actuators) or ``"motor"`` (one torque
            motor per moving joint with an effort limit: peak_torque = effort,
            peak_velocity = velocity, ctrl_range = +-effort); ``"position"`` (PD servos),
            ``"velocity"`` or ``"auto"`` (the type each joint's ``<transmission>`` /
            ros2_control ``<command_interface>`` declares): see
            :mod:`robotwright.parsers.urdf.actuators`.
        actuator_gains: ``{"joint name pattern": (kp, kv)}`` for position/velocity
            servos (first matching ``fnmatch`` pattern wins).
        balance_inertia: repair A + B < C principal moments as MuJoCo's
            ``balanceinertia`` does (each repaired link is reported).
        bound_mass: raise body masses below this (kg) to it, as MuJoCo's ``boundmass``.
        bound_inertia: raise principal moments below this (kg m^2) to it, as MuJoCo's
            ``boundinertia``.
        floating_base: give the root body a free joint (URDF has no floating base unless
            a ``floating`` joint attaches it to a ``world`` link).
        join_obj_objects: convert an OBJ mesh split into several objects (``o``/``g``
            lines), of which MuJoCo reads the first only, into one mesh holding every
            object's triangles unchanged (each such mesh is reported; without the option
            the loss is reported).
        asset_roots: folders outside the robot folder that relative and ``file://``
            mesh paths may point into (trusted explicitly; see :mod:`robotwright._paths`).
        xacro_args: ``{"name": "value"}`` for the ``$(arg name)`` of a ``.xacro`` source
            (see :mod:`robotwright.parsers.xacro.expand`).
        inertia_from_geoms: a link without ``<inertial>`` gets the mass and inertia of
            its collision geoms at ``density``, computed by MuJoCo, as MuJoCo's URDF
            import does (``"auto"``, default; one note per link with the values), or
            none (``"never"``: mass 0, so a moving such link is refused). See
            :mod:`robotwright.parsers.urdf.inertia_from_geoms`.
        density: kg/m^3 of the collision geoms of such links (MuJoCo's default 1000).
    """

    fixed_joints: FixedPolicy = "keep"
    package_map: Mapping[str, str | os.PathLike] | None = None
    mesh_root: Path | None = None
    work_dir: Path | None = None
    actuators: Literal["none", "motor", "position", "velocity", "auto"] = "none"
    actuator_gains: Mapping[str, Any] | None = None
    balance_inertia: bool = False
    bound_mass: float | None = None
    bound_inertia: float | None = None
    floating_base: bool = False
    join_obj_objects: bool = False
    asset_roots: tuple[str | os.PathLike, ...] = ()
    xacro_args: Mapping[str, str] | None = None
    inertia_from_geoms: Literal["auto", "never"] = "auto"
    density: float = geom_inertia.DEFAULT_DENSITY

    def __post_init__(self) -> None:
        if self.inertia_from_geoms not in geom_inertia.INERTIA_FROM_GEOMS:
            raise ValueError(
                f"inertia_from_geoms={shown(self.inertia_from_geoms)}: expected one of "
                f"{list(geom_inertia.INERTIA_FROM_GEOMS)}"
            )
        object.__setattr__(self, "density", geom_inertia.check_density(self.density))
        if self.fixed_joints not in FIXED_POLICIES:
            raise ValueError(
                f"fixed_joints={shown(self.fixed_joints)}: expected one of {list(FIXED_POLICIES)}"
            )
        if self.actuators not in acts.ACTUATOR_MODES:
            raise ValueError(
                f"actuators={shown(self.actuators)}: expected one of {acts.ACTUATOR_MODES}"
            )
        object.__setattr__(self, "actuator_gains", acts.parse_gains(self.actuator_gains))
        for name in ("bound_mass", "bound_inertia"):
            value = getattr(self, name)
            if value is not None and not value >= 0:
                raise ValueError(f"{name}={shown(value)}: expected None or >= 0")


class _Unreadable(ValueError):
    """A finite number the installed MuJoCo's XML reader refuses (its message says why)."""


def _finite(text: str) -> float:
    """A URDF number, finite as an HRDF holds it ("1e400", "inf" and "nan" are refused;
    MuJoCo's reader refuses the first and takes the others). A subnormal number (nonzero,
    below ``sys.float_info.min`` in magnitude) is refused where the installed MuJoCo's
    XML reader refuses it (3.11 does; found by a probe): an HRDF is written and read back
    as MJCF. Raises ValueError (:class:`_Unreadable` for the latter)."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{shown(text)} is not a finite number")
    if value != 0 and abs(value) < sys.float_info.min:
        from robotwright.parsers.reference import mujoco_xml_reads_subnormals

        if not mujoco_xml_reads_subnormals():
            import mujoco

            raise _Unreadable(
                f"MuJoCo {mujoco.__version__} reads no nonzero number smaller than "
                f"{shown(sys.float_info.min)} in magnitude"
            )
    return value


def _why(exc: ValueError) -> str:
    """`` (the reason)`` for a number MuJoCo cannot read, else nothing."""
    return f" ({exc})" if isinstance(exc, _Unreadable) else ""


def _floats(
    text: str | None, n: int, default: tuple[float, ...], where: str, what: str, rep
) -> np.ndarray:
    """``n`` finite numbers of attribute ``what`` (e.g. ``<box size>``) of element ``where``;
    ``default`` when absent. Raises ConversionError naming both."""
    if text is None:
        return np.array(default, dtype=float)
    why = ""
    try:
        values = [_finite(v) for v in text.split()]
    except ValueError as exc:
        values, why = [], _why(exc)
    if len(values) != n:
        raise ConversionError(
            [
                Problem(
                    rep.file,
                    f"{what} = {shown(text)}: expected {n} finite numbers{why}",
                    element=where,
                )
            ],
        )
    return np.array(values, dtype=float)


@dataclass
class _Pose:
    pos: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rot: np.ndarray = field(default_factory=lambda: np.eye(3))

    def compose(self, other: _Pose) -> _Pose:
        return _Pose(self.pos + self.rot @ other.pos, self.rot @ other.rot)

    @property
    def quat(self) -> tuple[float, float, float, float]:
        return inr.mat_to_quat(self.rot)


def _origin(elem: ET.Element | None, rep: Reporter, where: str) -> _Pose:
    if elem is None:
        return _Pose()
    xyz = _floats(elem.get("xyz"), 3, (0, 0, 0), where, "<origin xyz>", rep)
    rpy = _floats(elem.get("rpy"), 3, (0, 0, 0), where, "<origin rpy>", rep)
    return _Pose(xyz, inr.quat_to_mat(inr.rpy_to_quat(rpy)))


def _t(v: np.ndarray | tuple) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _num(elem: ET.Element | None, attr: str, default: float, where: str, rep: Reporter) -> float:
    """A numeric attribute (``default`` when the element or attribute is absent)."""
    if elem is None or elem.get(attr) is None:
        return default
    try:
        return _finite(elem.get(attr))
    except ValueError as exc:
        raise ConversionError(
            [
                Problem(
                    rep.file,
                    f"<{elem.tag} {attr}={shown(elem.get(attr))}>: expected a finite number"
                    + _why(exc),
                    element=where,
                )
            ]
        ) from exc
