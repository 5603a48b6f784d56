"""The URDF reader's links: each link's inertial, visuals and collisions (meshes resolved
within the robot's folder and converted where MuJoCo cannot read them) and the geoms
they become."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robotwright._names import shown
from robotwright._xmlsafe import describe
from robotwright.errors import ConversionError, Problem
from robotwright.hrdf.model import (
    MeshGeom,
    SimpleGeom,
)
from robotwright.parsers.meshes import (
    MeshConversionError,
    conversion_is_cosmetic,
    conversion_note,
    mesh_store,
)
from robotwright.parsers.packages import UnresolvedMesh, resolve_uri
from robotwright.parsers.report import Reporter
from robotwright.parsers.urdf import inertia_from_geoms as geom_inertia
from robotwright.parsers.urdf.common import (
    COLLISION_GROUP,
    DRAWN_COLLISION_GROUP,
    VISUAL_GROUP,
    URDFOptions,
    _finite,
    _floats,
    _origin,
    _Pose,
    _t,
    _why,
)
from robotwright.parsers.urdf.geom_pairs import BOTH, merge_visual_collision


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
            problem = f"mass {shown(mass_el.get('value'))}: expected a finite number{_why(exc)}"
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
                # A negative scale (a mirrored mesh) is kept as MuJoCo reads it.
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
            f"no <inertial>: mass {shown(got.mass)} kg, centre of mass {_t(got.com)} m, principal "
            f"moments {got.moments} kg m^2 computed by MuJoCo from its {len(shapes)} "
            f"collision geom(s) at density {shown(density)} kg/m^3, as MuJoCo's URDF import "
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
