"""URDF -> HRDF.

Frames: a URDF joint's ``<origin>`` is the child link frame in the parent link frame;
it becomes the child body's ``pos``/``quat`` and the joint sits at the body origin
(``pos`` 0) with its ``<axis>`` in the child frame, as MuJoCo's own URDF importer does.
Inertia tensors (``<inertial><origin rpy>`` honoured) are diagonalised exactly.

Visual geoms go to group 2 without contacts (contype = conaffinity = 0), collision geoms
to group 3 with contype = conaffinity = 1, so the two stay apart. A visual and a
collision of the same geometry and origin are one geom that is drawn and collides
(group 0, contype = conaffinity = 1, the visual's colour; see
:mod:`robotwright.parsers.geom_pairs`), as MuJoCo's own geoms are by default.
"""

from __future__ import annotations

import math
import os
import sys
import xml.etree.ElementTree as ET
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from robotwright._notes import name_list
from robotwright._paths import trusted_asset_roots
from robotwright._progress import steps
from robotwright._xmlsafe import describe
from robotwright.errors import ConversionError, Problem
from robotwright.hrdf.model import (
    HRDF,
    Actuator,
    Body,
    Joint,
    MeshGeom,
    Meta,
    SimpleGeom,
    Site,
)
from robotwright.parsers import inertia as inr
from robotwright.parsers import inertia_from_geoms as geom_inertia
from robotwright.parsers import urdf_actuators as acts
from robotwright.parsers.fixed import FIXED_POLICIES, FixedPolicy
from robotwright.parsers.geom_pairs import BOTH, merge_visual_collision
from robotwright.parsers.meshes import (
    MeshConversionError,
    conversion_is_cosmetic,
    conversion_note,
    mesh_store,
    rewrite_staged,
)
from robotwright.parsers.packages import UnresolvedMesh, resolve_uri
from robotwright.parsers.report import ParseResult, Reporter, warn_massless_moving
from robotwright.parsers.visuals import drop_unbuildable_visuals
from robotwright.parsers.xacro import read_robot_xml

VISUAL_GROUP = 2
#: Joints from a root link named "world" that stay on its child when the root is dropped.
_WORLD_CHILD_JOINTS = ("revolute", "continuous", "prismatic")
COLLISION_GROUP = 3
#: Group of a geom read from a visual and collision pair (MuJoCo's default geom group).
DRAWN_COLLISION_GROUP = 0
_KNOWN_TOP = {"link", "joint", "material"}
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
            :mod:`robotwright.parsers.urdf_actuators`.
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
            (see :mod:`robotwright.parsers.xacro`).
        inertia_from_geoms: a link without ``<inertial>`` gets the mass and inertia of
            its collision geoms at ``density``, computed by MuJoCo, as MuJoCo's URDF
            import does (``"auto"``, default; one note per link with the values), or
            none (``"never"``: mass 0, so a moving such link is refused). See
            :mod:`robotwright.parsers.inertia_from_geoms`.
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
                f"inertia_from_geoms={self.inertia_from_geoms!r}: expected one of "
                f"{list(geom_inertia.INERTIA_FROM_GEOMS)}"
            )
        object.__setattr__(self, "density", geom_inertia.check_density(self.density))
        if self.fixed_joints not in FIXED_POLICIES:
            raise ValueError(
                f"fixed_joints={self.fixed_joints!r}: expected one of {list(FIXED_POLICIES)}"
            )
        if self.actuators not in acts.ACTUATOR_MODES:
            raise ValueError(f"actuators={self.actuators!r}: expected one of {acts.ACTUATOR_MODES}")
        object.__setattr__(self, "actuator_gains", acts.parse_gains(self.actuator_gains))
        for name in ("bound_mass", "bound_inertia"):
            value = getattr(self, name)
            if value is not None and not value >= 0:
                raise ValueError(f"{name}={value!r}: expected None or >= 0")


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
        raise ValueError(f"{text!r} is not a finite number")
    if value != 0 and abs(value) < sys.float_info.min:
        from robotwright.parsers.reference import mujoco_xml_reads_subnormals

        if not mujoco_xml_reads_subnormals():
            import mujoco

            raise _Unreadable(
                f"MuJoCo {mujoco.__version__} reads no nonzero number smaller than "
                f"{sys.float_info.min!r} in magnitude"
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
                    rep.file, f"{what} = {text!r}: expected {n} finite numbers{why}", element=where
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


@dataclass
class _LinkData:
    """A link converted to body-frame quantities, before the fixed-joint policy."""

    name: str
    mass: float
    com: np.ndarray
    tensor: np.ndarray  # about the com, link frame
    geoms: list[tuple[str, _Pose, dict]]  # kind ("visual"/"collision"/BOTH), pose, fields
    has_inertial: bool
    # (moments, iquat) as MuJoCo computed them from the geoms, kept as they are when the
    # link is a body of its own, so that its principal axes come out in MuJoCo's order.
    principal: tuple[tuple[float, float, float], tuple[float, float, float, float]] | None = None


def _link_inertial(link: ET.Element, rep: Reporter) -> tuple[float, np.ndarray, np.ndarray, bool]:
    inertial = link.find("inertial")
    where = describe(link)
    if inertial is None:
        return 0.0, np.zeros(3), np.zeros((3, 3)), False
    pose = _origin(inertial.find("origin"), rep, where)
    mass_el = inertial.find("mass")
    mass = 0.0
    if mass_el is not None:
        try:
            mass = _finite(mass_el.get("value", "0"))
        except ValueError as exc:
            problem = f"mass {mass_el.get('value')!r}: expected a finite number{_why(exc)}"
            raise ConversionError([Problem(rep.file, problem, element=where)]) from exc
    i_el = inertial.find("inertia")
    tensor = np.zeros((3, 3))
    if i_el is not None:
        try:
            v = {k: _finite(i_el.get(k, "0")) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        except ValueError as exc:
            problem = f"inertia: expected finite numbers ixx..izz{_why(exc)}"
            raise ConversionError([Problem(rep.file, problem, element=where)]) from exc
        local = np.array(
            [
                [v["ixx"], v["ixy"], v["ixz"]],
                [v["ixy"], v["iyy"], v["iyz"]],
                [v["ixz"], v["iyz"], v["izz"]],
            ]
        )
        tensor = pose.rot @ local @ pose.rot.T
    return mass, pose.pos, tensor, True


class _URDFReader:
    def __init__(self, path: Path, options: URDFOptions, rep: Reporter) -> None:
        self.path = path
        self.opt = options
        self.rep = rep
        self.store = mesh_store(options.work_dir, options.join_obj_objects)
        self.materials: dict[str, tuple[float, float, float, float]] = {}
        self.unresolved: list[Problem] = []
        self.mesh_names: dict[tuple[str, tuple[float, float, float]], str] = {}
        self.mesh_name_used: set[str] = set()
        self.noted: set[str] = set()

    # -- geometry -------------------------------------------------------------------------
    def _material(self, elem: ET.Element | None, where: str) -> tuple | None:
        if elem is None:
            return None
        color = elem.find("color")
        if elem.find("texture") is not None:
            self.rep.warn("material texture dropped (HRDF geoms carry a colour only)", where)
        if color is not None:
            rgba = _floats(
                color.get("rgba"), 4, (0.5, 0.5, 0.5, 1), where, "<color rgba>", self.rep
            )
            return tuple(float(x) for x in np.clip(rgba, 0.0, 1.0))
        name = elem.get("name")
        if name is not None and name in self.materials:
            return self.materials[name]
        return None

    def _mesh_name(self, staged_rel: str, scale: tuple[float, float, float]) -> str:
        key = (staged_rel, scale)
        if key not in self.mesh_names:
            stem = Path(staged_rel).stem
            name, k = stem, 1
            while name in self.mesh_name_used:
                name, k = f"{stem}_{k}", k + 1
            self.mesh_name_used.add(name)
            self.mesh_names[key] = name
        return self.mesh_names[key]

    def _geom(self, elem: ET.Element, kind: str, link: str) -> tuple[str, _Pose, dict] | None:
        where = f'<link name="{link}"> <{kind}' + (
            f' name="{elem.get("name")}">' if elem.get("name") else ">"
        )
        pose = _origin(elem.find("origin"), self.rep, where)
        geometry = elem.find("geometry")
        shape = None if geometry is None else next(iter(geometry), None)
        if shape is None:
            self.rep.warn(f"{kind} without <geometry> dropped", where)
            return None
        fields: dict = {"geom_name": elem.get("name")}
        if kind == "visual":
            rgba = self._material(elem.find("material"), where)
            if rgba is not None:
                fields["rgba"] = rgba
        tag = shape.tag

        def num(attr: str) -> float:
            try:
                return _finite(shape.get(attr, ""))
            except ValueError as exc:
                problem = f"<{tag} {attr}>: expected a finite number{_why(exc)}"
                raise ConversionError([Problem(self.rep.file, problem, element=where)]) from exc

        if tag == "box":
            size = _floats(shape.get("size"), 3, (0, 0, 0), where, "<box size>", self.rep)
            fields.update(type="box", size=_t(size / 2.0))
        elif tag == "sphere":
            fields.update(type="sphere", size=(num("radius"), 0.0, 0.0))
        elif tag in ("cylinder", "capsule"):
            fields.update(type=tag, size=(num("radius"), num("length") / 2.0, 0.0))
        elif tag == "mesh":
            uri = shape.get("filename")
            if not uri:
                self.rep.warn("mesh without filename dropped", where)
                return None
            scale = _t(_floats(shape.get("scale"), 3, (1, 1, 1), where, "<mesh scale>", self.rep))
            try:
                path = resolve_uri(uri, self.path, self.opt.package_map, self.opt.mesh_root)
                if any(v < 0 for v in scale):
                    signs = tuple(-1.0 if v < 0 else 1.0 for v in scale)
                    staged = self.store.add_mirrored(path, signs)
                    scale = tuple(abs(v) for v in scale)
                    self.rep.warn(
                        f"mesh '{uri}' with negative scale: mirrored copy written "
                        f"({staged.rel}), scale {scale} kept",
                        where,
                    )
                else:
                    staged = self.store.add(path)
            except UnresolvedMesh as exc:
                self.unresolved.append(Problem(self.rep.file, str(exc), element=where))
                return None
            except MeshConversionError as exc:
                if "holds no triangles" in str(exc):
                    self.rep.warn(f"{kind} dropped: {exc}", where)
                else:
                    self.unresolved.append(Problem(self.rep.file, str(exc), element=where))
                return None
            if staged.rel not in self.noted:
                self.noted.add(staged.rel)
                note = conversion_note(staged)
                if note:
                    cosmetic = conversion_is_cosmetic(staged)
                    self.rep.warn(f"mesh '{uri}': {note}", where, cosmetic=cosmetic)
            fields.update(
                mesh=True, name=self._mesh_name(staged.rel, scale), file=staged.rel, scale=scale
            )
        else:
            self.rep.warn(f"unknown geometry <{tag}> dropped", where)
            return None
        return kind, pose, fields

    # -- links --------------------------------------------------------------------------
    def link_data(self, link: ET.Element) -> _LinkData:
        name = link.get("name", "")
        mass, com, tensor, has = _link_inertial(link, self.rep)
        geoms = []
        for kind in ("visual", "collision"):
            for elem in link.findall(kind):
                g = self._geom(elem, kind, name)
                if g is not None:
                    geoms.append(g)
        principal = None
        if not has and self.opt.inertia_from_geoms == "auto":
            mass, com, tensor, has, principal = self._inertia_from_geoms(name, geoms)
        return _LinkData(name, mass, com, tensor, merge_visual_collision(geoms), has, principal)

    def _inertia_from_geoms(
        self, name: str, geoms: list[tuple[str, _Pose, dict]]
    ) -> tuple[float, np.ndarray, np.ndarray, bool, Any]:
        """A link without ``<inertial>``: the inertia of its collision geoms, computed by
        MuJoCo as its URDF import does (visual geoms carry no mass there); reported.
        Returns mass, centre of mass, tensor, whether it has mass, (moments, iquat)."""
        where = f'<link name="{name}">'
        shapes = []
        for kind, pose, fields in geoms:
            if kind != "collision":
                continue
            if fields.get("mesh"):
                shape = geom_inertia.GeomShape(
                    "mesh",
                    (0.0, 0.0, 0.0),
                    _t(pose.pos),
                    pose.quat,
                    file=self.store.root / fields["file"],
                    scale=fields["scale"],
                )
            else:
                shape = geom_inertia.GeomShape(
                    fields["type"], fields["size"], _t(pose.pos), pose.quat
                )
            shapes.append(shape)
        empty = (0.0, np.zeros(3), np.zeros((3, 3)), False, None)
        if not shapes:
            if geoms:  # a frame link (no geoms) has nothing to compute: no note
                self.rep.warn(
                    "no <inertial> and no collision geoms: mass 0, as MuJoCo's URDF import "
                    "gives it (it takes mass from collision geoms only)",
                    where,
                )
            return empty
        density = self.opt.density
        try:
            got = geom_inertia.inertia_of_geoms(shapes, density)
        except geom_inertia.InertiaFromGeomsError as exc:
            # MuJoCo's own import refuses the file then: so do we, naming the link.
            problem = (
                f"no <inertial>, and MuJoCo computes no mass from its {len(shapes)} collision "
                f"geom(s): {exc} (inertia_from_geoms='never', --inertia-from-geoms never, "
                "leaves the link massless)"
            )
            raise ConversionError([Problem(self.rep.file, problem, element=where)]) from None
        self.rep.warn(
            f"no <inertial>: mass {got.mass!r} kg, centre of mass {_t(got.com)} m, principal "
            f"moments {got.moments} kg m^2 computed by MuJoCo from its {len(shapes)} "
            f"collision geom(s) at density {density!r} kg/m^3, as MuJoCo's URDF import "
            "does (inertia_from_geoms='never', --inertia-from-geoms never, leaves it massless)",
            where,
        )
        principal = (got.moments, got.iquat) if got.mass > 0 else None
        return got.mass, got.com, got.tensor, got.mass > 0, principal


def _make_geom(body: str, kind: str, pose: _Pose, fields: dict) -> MeshGeom | SimpleGeom:
    common = {
        "body": body,
        "pos": _t(pose.pos),
        "quat": pose.quat,
        "group": {"visual": VISUAL_GROUP, BOTH: DRAWN_COLLISION_GROUP}.get(kind, COLLISION_GROUP),
        "contact_type": 0 if kind == "visual" else 1,
        "contact_affinity": 0 if kind == "visual" else 1,
        "geom_name": fields.get("geom_name"),
    }
    if "rgba" in fields:
        common["rgba"] = fields["rgba"]
    if fields.get("mesh"):
        return MeshGeom(name=fields["name"], file=fields["file"], scale=fields["scale"], **common)
    return SimpleGeom(name="", type=fields["type"], size=fields["size"], **common)


@dataclass
class _Tree:
    """The link tree of a URDF: elements by name, joints, and depth-first link order."""

    links: dict[str, ET.Element]
    joints: list[ET.Element]
    parent_of: dict[str, ET.Element]
    children: dict[str, list[ET.Element]]
    order: list[str]
    roots: list[str]


def _read_tree(root: ET.Element, path: Path) -> _Tree:
    """Links and joints checked (names, references, one parent each, one root, no cycle).

    Raises:
        ConversionError: listing every problem found.
    """
    errors: list[Problem] = []
    links: dict[str, ET.Element] = {}
    for link in root.findall("link"):
        name = link.get("name")
        if not name:
            errors.append(Problem(str(path), "link without a name", element="<link>"))
        elif name in links:
            errors.append(Problem(str(path), "duplicate link name", element=describe(link)))
        else:
            links[name] = link
    joints: list[ET.Element] = []
    parent_of: dict[str, ET.Element] = {}
    seen_joint: set[str] = set()
    for j in root.findall("joint"):
        where = describe(j)
        jname, jtype = j.get("name"), j.get("type")
        par = j.find("parent")
        chi = j.find("child")
        if not jname:
            errors.append(Problem(str(path), "joint without a name", element=where))
            continue
        if jname in seen_joint:
            errors.append(Problem(str(path), "duplicate joint name", element=where))
            continue
        seen_joint.add(jname)
        if jtype not in _JOINT_TYPES:
            errors.append(
                Problem(
                    str(path),
                    f"type {jtype!r}: expected one of {sorted(_JOINT_TYPES)}",
                    element=where,
                )
            )
            continue
        if par is None or chi is None:
            errors.append(
                Problem(str(path), "expected <parent link> and <child link>", element=where)
            )
            continue
        p, c = par.get("link"), chi.get("link")
        for role, ln in (("parent", p), ("child", c)):
            if ln not in links:
                errors.append(
                    Problem(str(path), f"{role} link {ln!r} is not defined", element=where)
                )
        if c in parent_of:
            errors.append(Problem(str(path), f"link '{c}' has two parent joints", element=where))
            continue
        if p in links and c in links:
            parent_of[c] = j
            joints.append(j)
    roots = [n for n in links if n not in parent_of]
    if not errors and not links:
        errors.append(Problem(str(path), "the robot has no links"))
    elif not errors and len(roots) != 1:
        errors.append(
            Problem(str(path), f"expected exactly one root link, found {roots or 'none (cycle)'}")
        )
    if errors:
        raise ConversionError(errors, summary=f"invalid URDF {path}")

    children: dict[str, list[ET.Element]] = {n: [] for n in links}
    for j in joints:
        children[j.find("parent").get("link")].append(j)

    # Depth-first order from the root (document order of joints among siblings).
    order: list[str] = []
    stack = [roots[0]]
    while stack:
        n = stack.pop()
        order.append(n)
        stack.extend(reversed([j.find("child").get("link") for j in children[n]]))
    if len(order) != len(links):
        raise ConversionError([Problem(str(path), "the joints do not form a tree (cycle)")])

    return _Tree(links, joints, parent_of, children, order, roots)


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
                    f"<{elem.tag} {attr}={elem.get(attr)!r}>: expected a finite number" + _why(exc),
                    element=where,
                )
            ]
        ) from exc


def _joint_record(
    j: ET.Element, body: str, opt: URDFOptions, rep: Reporter
) -> tuple[Joint, Actuator | None, tuple[str, str, float, float] | None, bool]:
    """A moving URDF joint as an HRDF joint, its motor (``actuators="motor"``), its mimic
    ``(follower, leader, multiplier, offset)`` and whether effort/velocity were dropped."""
    where = describe(j)
    jtype = j.get("type")
    axis_el = j.find("axis")
    axis = _floats(
        axis_el.get("xyz") if axis_el is not None else None, 3, (1, 0, 0), where, "<axis xyz>", rep
    )
    if np.linalg.norm(axis) < 1e-12:
        raise ConversionError([Problem(rep.file, "axis is zero", element=where)])
    limit = j.find("limit")
    rng = None
    if jtype in ("revolute", "prismatic"):
        if limit is None or limit.get("lower") is None and limit.get("upper") is None:
            rep.warn(f"{jtype} joint without <limit lower upper>: kept unlimited", where)
        else:
            rng = (_num(limit, "lower", 0.0, where, rep), _num(limit, "upper", 0.0, where, rep))
            if rng[0] == rng[1]:
                rep.warn(
                    f"lower = upper = {rng[0]}: limit ignored, joint kept unlimited "
                    "(as MuJoCo's URDF importer does)",
                    where,
                )
                rng = None
    if jtype == "spherical" and limit is not None and limit.get("lower") is not None:
        rep.warn("<limit> of a spherical joint dropped (a ball joint, as MuJoCo imports it)", where)
    dyn = j.find("dynamics")
    joint = Joint(
        name=j.get("name"),
        body=body,
        type={"prismatic": "slide", "spherical": "ball"}.get(jtype, "hinge"),
        axis=_t(axis),
        range=rng,
        dynamic_friction=_num(dyn, "friction", 0.0, where, rep),
        viscous_friction=_num(dyn, "damping", 0.0, where, rep),
    )
    effort = _num(limit, "effort", 0.0, where, rep)
    velocity = _num(limit, "velocity", 0.0, where, rep)
    if effort and jtype != "spherical":
        # MuJoCo's URDF importer (3.11, 4.x) clamps the joint's actuator force to +-|effort|.
        joint = replace(joint, actuatorfrcrange=(-abs(effort), abs(effort)))
    actuator = None
    if opt.actuators == "motor" and effort > 0 and jtype != "spherical":
        actuator = Actuator(
            joint=joint.name,
            name=joint.name,
            type="motor",
            peak_torque=effort,
            peak_velocity=velocity if velocity > 0 else None,
            ctrl_range=(-effort, effort),
        )
        acts.LOG.info("%s: %s", rep.file, acts.describe([actuator])[0])
    for tag in ("safety_controller", "calibration"):
        if j.find(tag) is not None:
            rep.warn(f"<{tag}> dropped (no HRDF equivalent)", where)
    mimic_el = j.find("mimic")
    mimic = None
    if mimic_el is not None:
        mimic = (
            joint.name,
            mimic_el.get("joint"),
            _num(mimic_el, "multiplier", 1.0, where, rep),
            _num(mimic_el, "offset", 0.0, where, rep),
        )
    return joint, actuator, mimic, actuator is None and (effort > 0 or velocity > 0)


def _mimic_extra(
    mimics: list[tuple[str, str, float, float]], moving: set[str], rep: Reporter
) -> str | None:
    """``<equality>`` joint couplings ``q_follower = offset + multiplier * q_leader``."""
    lines = []
    for follower, leader, mult, off in mimics:
        if leader not in moving or follower not in moving:
            rep.warn(
                f"mimic of joint '{leader}' dropped: no moving joint of that name",
                f'<joint name="{follower}">',
            )
            continue
        lines.append(
            f'    <joint joint1="{follower}" joint2="{leader}" polycoef="{off!r} {mult!r} 0 0 0"/>'
        )
    if not lines:
        return None
    return "<mujoco>\n  <equality>\n" + "\n".join(lines) + "\n  </equality>\n</mujoco>\n"


def _body_record(
    name: str, b: dict, index: dict[str, int], opt: URDFOptions, rep: Reporter
) -> Body:
    """One body: its parts (link inertials, merged ones included) combined and
    diagonalised, with the repairs the options ask for (each reported)."""
    if len(b["parts"]) == 1:
        mass, com, tensor = b["parts"][0]
    elif b["parts"]:
        mass, com, tensor = inr.combine(b["parts"])
    else:
        mass, com, tensor = 0.0, np.zeros(3), np.zeros((3, 3))
    if len(b["parts"]) == 1 and b.get("principal") is not None:
        diag, iquat = b["principal"]  # MuJoCo's own, from the link's geoms
    else:
        diag, iquat = inr.diagonalize(tensor)
    where = f'<link name="{name}">'
    if mass > 0 and not inr.is_physical(diag):
        if opt.balance_inertia and min(diag) > 0:
            fixed = inr.balance(diag)
            rep.warn(f"principal moments {diag} violate A + B >= C: balanced to {fixed}", where)
            diag = fixed
        else:
            rep.warn(
                f"non-physical inertia: principal moments {diag} (negative or A + B < C)", where
            )
    if opt.bound_mass is not None and mass < opt.bound_mass:
        rep.warn(f"mass {mass} raised to bound_mass {opt.bound_mass}", where)
        mass = opt.bound_mass
    if opt.bound_inertia is not None and min(diag) < opt.bound_inertia:
        new = tuple(max(v, opt.bound_inertia) for v in diag)
        rep.warn(f"principal moments {diag} raised to bound_inertia: {new}", where)
        diag = new
    pose = b["pose"]
    return Body(
        name=name,
        parent=-1 if b["parent"] is None else index[b["parent"]],
        pos=_t(pose.pos),
        quat=pose.quat,
        mass=float(mass),
        inertial_pos=_t(com),
        inertial_quat=iquat,
        diag_inertia=diag,
    )


def parse_urdf(
    path: str | os.PathLike, options: URDFOptions | None = None, *, strict: bool = False
) -> ParseResult:
    """Parse a URDF file into an HRDF (see :class:`URDFOptions`).

    Raises:
        ConversionError: malformed or unsafe XML, an invalid tree, unresolved meshes or
            mesh paths leaving the robot folder (all listed in one error), or, with
            ``strict=True``, any warning.
    """
    opt = options or URDFOptions()
    with trusted_asset_roots(opt.asset_roots):
        return _parse_urdf(Path(path), opt, strict)


def _parse_urdf(path: Path, opt: URDFOptions, strict: bool) -> ParseResult:
    rep = Reporter(str(path))
    root = read_robot_xml(path, opt, rep)  # a .xacro file is expanded first
    if root.tag != "robot":
        raise ConversionError([Problem(str(path), f"root element <{root.tag}>: expected <robot>")])
    reader = _URDFReader(path, opt, rep)

    for mat in root.findall("material"):
        rgba = reader._material(mat, describe(mat))
        if rgba is not None and mat.get("name"):
            reader.materials[mat.get("name")] = rgba
    reads = acts.INTERFACE_TAGS if opt.actuators in acts.MODES else ()  # read below
    dropped = Counter(c.tag for c in root if c.tag not in _KNOWN_TOP and c.tag not in reads)
    for tag, count in sorted(dropped.items()):
        rep.warn(f"{count} top-level <{tag}> element(s) dropped (not robot structure)")

    tree = _read_tree(root, path)
    links, joints, parent_of, children = tree.links, tree.joints, tree.parent_of, tree.children
    order, roots = tree.order, tree.roots
    # A robot of many links with large meshes takes a while: progress past 2 s.
    data = {n: reader.link_data(links[n]) for n in steps(order, len(order), "links read")}
    if reader.unresolved:
        from robotwright.parsers.unresolved import group_unresolved

        raise ConversionError(
            group_unresolved(reader.unresolved),
            summary=f"{len(reader.unresolved)} mesh(es) of {path} not resolved",
        )

    # A massless, geometry-free root link (usually "world") only anchors the robot: its
    # single child becomes the root, placed at the joint origin.
    root_name = roots[0]
    root_pose = _Pose()
    free_root = opt.floating_base
    free_name: str | None = None
    dropped_root: tuple[str, str] | None = None
    # A root link named "world" is MuJoCo's world: its moving joint stays on the child.
    root_joint: ET.Element | None = None
    r = data[root_name]
    # (With bound_mass the root is not massless: it stays, as in MuJoCo's importer.)
    if (
        (not r.has_inertial or r.mass == 0.0)
        and opt.bound_mass is None
        and not r.geoms
        and len(children[root_name]) == 1
    ):
        j = children[root_name][0]
        moving_from_world = root_name == "world" and j.get("type") in _WORLD_CHILD_JOINTS
        if j.get("type") in ("fixed", "floating") or moving_from_world:
            child = j.find("child").get("link")
            root_pose = _origin(j.find("origin"), rep, describe(j))
            if j.get("type") == "floating":
                free_root, free_name = True, j.get("name")
            if moving_from_world:
                root_joint = j
            kept = (
                ", the joint kept on it (a root link named 'world' is MuJoCo's world)"
                if moving_from_world
                else ""
            )
            rep.warn(
                f"massless root link '{root_name}' dropped; '{child}' is the root, placed at "
                f"the pose of {j.get('type')} joint '{j.get('name')}'{kept}",
                describe(links[root_name]),
            )
            order.remove(root_name)
            dropped_root = (root_name, child)
            root_name = child
            parent_of.pop(child)
            joints.remove(j)

    mimics: list[tuple[str, str, float, float]] = []
    sites: list[Site] = []
    if dropped_root is not None and dropped_root[0] != "world":
        # Keep the dropped root's frame as a site on the new root (MuJoCo's convention
        # makes only a root link called "world" the world itself).
        inv = _Pose(-root_pose.rot.T @ root_pose.pos, root_pose.rot.T)
        sites.append(
            Site(name=dropped_root[0], body=dropped_root[1], pos=_t(inv.pos), quat=inv.quat)
        )
    hrdf_joints: list[Joint] = []
    actuators: list[Actuator] = []
    # owner[link] = (body name, pose of the link frame in the owner body frame)
    owner: dict[str, tuple[str, _Pose]] = {}
    bodies: dict[str, dict] = {}
    body_order: list[str] = []
    dropped_limits: list[str] = []
    for name in order:
        d = data[name]
        j = parent_of.get(name)
        if j is None:
            pose, jtype, parent_body = root_pose, "root", None
        else:
            pose = _origin(j.find("origin"), rep, describe(j))
            jtype = j.get("type")
            parent_body, parent_pose = owner[j.find("parent").get("link")]
            pose = parent_pose.compose(pose)
        if jtype == "floating":
            raise ConversionError(
                [
                    Problem(
                        str(path),
                        "floating joint below the root: HRDF allows a free joint on the root only",
                        element=describe(j),
                    )
                ]
            )
        if jtype == "planar":
            raise ConversionError(
                [
                    Problem(
                        str(path),
                        "planar joints are not supported (no HRDF equivalent)",
                        element=describe(j),
                    )
                ]
            )
        massless = not d.has_inertial or (d.mass == 0.0 and not d.tensor.any())
        leaf = not children[name]
        as_site = jtype == "fixed" and (
            opt.fixed_joints == "merge" or (opt.fixed_joints == "site" and massless and leaf)
        )
        if as_site:
            owner[name] = (parent_body, pose)
            target = bodies[parent_body]
            if d.mass > 0 or d.tensor.any():  # a massless inertia is kept as written
                target["parts"].append(
                    (d.mass, pose.pos + pose.rot @ d.com, pose.rot @ d.tensor @ pose.rot.T)
                )
            for kind, gpose, fields in d.geoms:
                target["geoms"].append((kind, pose.compose(gpose), fields))
            sites.append(Site(name=name, body=parent_body, pos=_t(pose.pos), quat=pose.quat))
            continue
        owner[name] = (name, _Pose())
        bodies[name] = {
            "parent": parent_body,
            "pose": pose,
            "parts": [(d.mass, d.com, d.tensor)] if d.mass > 0 or d.tensor.any() else [],
            "geoms": list(d.geoms),
            "principal": d.principal if d.mass > 0 or d.tensor.any() else None,
        }
        body_order.append(name)
        if j is None and root_joint is not None:
            j, jtype = root_joint, root_joint.get("type")
        if j is None:
            if free_root:
                if free_name is None:
                    # The name our URDF generator gives it, so our MJCF names it alike.
                    taken = {x.get("name") for x in joints}
                    free_name = "floating_base"
                    while free_name in taken:
                        free_name += "_"
                hrdf_joints.append(Joint(name=free_name, body=name, type="free"))
            continue
        if jtype == "fixed":
            continue
        joint, actuator, mimic, limits_dropped = _joint_record(j, name, opt, rep)
        hrdf_joints.append(joint)
        if actuator is not None:
            actuators.append(actuator)
        if limits_dropped:
            dropped_limits.append(joint.name)
        if mimic is not None:
            mimics.append(mimic)
    if opt.actuators in acts.MODES:
        actuators, kept = acts.make_actuators(
            root, hrdf_joints, opt.actuators, opt.actuator_gains, rep
        )
        dropped_limits = [n for n in dropped_limits if n not in kept]
    if dropped_limits:
        rep.warn(
            f"effort/velocity limits of {len(dropped_limits)} joint(s) not kept as motors "
            "(effort is kept as the joint's actuatorfrcrange, velocity dropped; keep both "
            "on motors with actuators='motor', or convert's --actuators motor): "
            + name_list(dropped_limits)
        )
    clamped = [j.name for j in hrdf_joints if j.actuatorfrcrange is not None]
    from robotwright.parsers.reference import mujoco_urdf_clamps_effort

    if clamped and not mujoco_urdf_clamps_effort():
        import mujoco  # the running version decides what its own URDF import does

        rep.warn(
            f"actuatorfrcrange +-effort set on {len(clamped)} joint(s) from <limit effort>, "
            f"as MuJoCo 3.11's and 4's URDF imports do; MuJoCo {mujoco.__version__}'s import "
            "leaves them unclamped: " + name_list(clamped)
        )

    hrdf_bodies: list[Body] = []
    index = {n: i for i, n in enumerate(body_order)}
    geoms_mesh: list[MeshGeom] = []
    geoms_simple: list[SimpleGeom] = []
    for name in body_order:
        b = bodies[name]
        hrdf_bodies.append(_body_record(name, b, index, opt, rep))
        for kind, gpose, fields in b["geoms"]:
            g = _make_geom(name, kind, gpose, fields)
            (geoms_mesh if isinstance(g, MeshGeom) else geoms_simple).append(g)
    for i, g in enumerate(geoms_simple):
        geoms_simple[i] = _replace_name(g, f"geom_{i}", "name")
    # Geom names must be unique in MJCF; URDF repeats them freely.
    seen_names: Counter[str] = Counter()
    for table in (geoms_mesh, geoms_simple):
        for i, g in enumerate(table):
            if g.geom_name is None:
                continue
            seen_names[g.geom_name] += 1
            if seen_names[g.geom_name] > 1:
                new_name = f"{g.geom_name}_{seen_names[g.geom_name] - 1}"
                rep.warn(f"geom name '{g.geom_name}' repeated: renamed '{new_name}'", cosmetic=True)
                table[i] = _replace_name(g, new_name, "geom_name")
    extra = _mimic_extra(mimics, {j.name for j in hrdf_joints}, rep)
    geoms_mesh, geoms_simple = drop_unbuildable_visuals(
        geoms_mesh,
        geoms_simple,
        reader.store.root,
        rep,
        lambda rel: rewrite_staged(reader.store, rel),
    )
    tables = (hrdf_bodies, hrdf_joints, geoms_mesh, geoms_simple, sites)
    _rename_world_body(tables, {x.get("name") for x in links.values()}, rep)
    hrdf = HRDF(
        name=root.get("name") or path.stem,
        bodies=hrdf_bodies,
        joints=hrdf_joints,
        actuators=actuators,
        meshes=geoms_mesh,
        simple_geoms=geoms_simple,
        sites=sites,
        meta=Meta(simulator_config=None, body_name_config=None),
        mjcf_extra=extra,
        root_dir=reader.store.root,
        temp_assets=reader.store.lifetime,
    )
    warn_massless_moving(hrdf, rep, '<link name="{}">')
    warnings = rep.finish(strict)
    return ParseResult(hrdf, warnings, str(path))


def _rename_world_body(tables: tuple[list, ...], taken: set[str], rep: Reporter) -> None:
    """A link named ``world`` that stays a body (it has mass, geometry, a parent or
    several children) is renamed: ``world`` is MuJoCo's world body, our MJCF would not
    compile. Renamed in place in (bodies, joints, meshes, simple geoms, sites)."""
    from dataclasses import replace

    bodies, *others = tables
    if not any(b.name == "world" for b in bodies):
        return
    new = "world_link"
    while new in taken:
        new += "_"
    rep.warn(
        f"link 'world' renamed '{new}' ('world' is MuJoCo's world body)", '<link name="world">'
    )
    bodies[:] = [replace(b, name=new) if b.name == "world" else b for b in bodies]
    for table in others:
        table[:] = [replace(x, body=new) if x.body == "world" else x for x in table]


def _replace_name(g, name: str, field_name: str):
    from dataclasses import replace

    return replace(g, **{field_name: name})
