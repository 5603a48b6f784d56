"""Reading MJCF into Things.

MuJoCo's own parser (``mujoco.MjSpec``) reads the file, so ``<include>``, default
classes, ``childclass``, ``fromto``, Euler angles, ``<frame>`` and degree units are
resolved exactly as MuJoCo resolves them. Each element becomes the Thing class whose
derived attributes match it (``<geom type="sphere">`` -> :class:`Sphere`,
``<joint type="slide">`` -> :class:`Slide`, a ``<general>`` whose gain/bias are a
position servo's -> :class:`Position`). Values are stored resolved: the written MJCF has
no default classes, uses radians and quaternions, and compiles to the same model.

Sections the Things do not model (``visual``, ``statistic``, ``size``, ``contact``,
``equality``, ``tendon``, ``keyframe``, and actuators/sensors on tendons or other
unmodelled targets) are carried verbatim as MuJoCo writes them, with the default classes
they use kept under a class of their own (``rw_carried``) so they cannot change the
Things' values. Anything else that cannot be represented (height fields, skins, flexes,
plugins, ...) is reported with a :class:`~robotwright.errors.ConversionWarning` naming it,
or raises :class:`~robotwright.errors.ConversionError` with ``strict=True``.

The input text is first checked with ``defusedxml`` (no entity expansion, no DTDs).
"""

from __future__ import annotations

import math
import os
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from robotwright._rotations import compose_pose
from robotwright.errors import (
    Problem,
    RobotwrightError,
)
from robotwright.things import actuators as A
from robotwright.things import sensors as S
from robotwright.things.assets import TEXTURE_FILE_ATTRS, Material, MeshAsset, Texture
from robotwright.things.base import BaseThing
from robotwright.things.body import Body
from robotwright.things.cameras import Camera
from robotwright.things.geoms import GEOM_CLASSES
from robotwright.things.joints import JOINT_CLASSES
from robotwright.things.lights import Light
from robotwright.things.precision import refine_listed
from robotwright.things.raw import RawElement
from robotwright.things.sites import Site
from robotwright.things.world import World

CARRIED_CLASS = "rw_carried"


class ThingXMLError(RobotwrightError, ValueError):
    """MJCF text could not be read (malformed, unsafe, or rejected by MuJoCo)."""


def _enum(value: Any, prefix: str) -> str:
    return value.name[len(prefix) :].lower()


def _f32(values: Any) -> list[float]:
    """float32 spec fields back to the shortest decimal that MJCF text would give."""
    return [float(np.format_float_positional(np.float32(v), unique=True)) for v in values]


class _Reader:
    def __init__(self, spec: mujoco.MjSpec, base_dir: Path, source: str, strict: bool) -> None:
        self.spec = spec
        self.base_dir = base_dir
        self.source = source
        self.strict = strict
        self.degree = bool(spec.compiler.degree)
        self.seq = spec.compiler.eulerseq
        self.problems: list[Problem] = []
        self.by_name: dict[tuple[str, str], BaseThing] = {}
        self.materials: dict[str, Material] = {}
        self.textures: dict[str, Texture] = {}
        self.used_hfields: set[str] = set()
        self.used_meshes: set[str] = set()
        self._compiled: mujoco.MjModel | None = None

    @property
    def compiled(self) -> mujoco.MjModel:
        """The source compiled by MuJoCo (what our MJCF must give), on first use only:
        models without carried sections or inherited ranges skip the compile."""
        if self._compiled is None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # to_xml() already showed MuJoCo's warnings
                self._compiled = self.spec.compile()
        return self._compiled

    # ------------------------------------------------------------------ helpers
    def lose(self, element: str, message: str) -> None:
        self.problems.append(Problem(self.source, message, element=element, severity="warning"))

    def quat(self, elem: Any, alt_name: str = "alt", quat_name: str = "quat") -> np.ndarray:
        alt = getattr(elem, alt_name)
        if alt.type == mujoco.mjtOrientation.mjORIENTATION_QUAT:
            return np.array(getattr(elem, quat_name), dtype=float)
        return np.array(self.spec.resolve_orientation(self.degree, self.seq, alt))

    def pose(self, elem: Any) -> tuple[np.ndarray, np.ndarray]:
        pos, quat = np.array(elem.pos, dtype=float), self.quat(elem)
        fromto = getattr(elem, "fromto", None)
        if fromto is not None and not np.isnan(fromto[0]):
            start, end = np.array(fromto[:3]), np.array(fromto[3:])
            pos = (start + end) / 2
            quat = np.zeros(4)
            mujoco.mju_quatZ2Vec(quat, end - start)
        return self.in_frame(elem, pos, quat)

    def in_frame(
        self, elem: Any, pos: np.ndarray, quat: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        frame = elem.frame
        while frame is not None:
            pos, quat = compose_pose(frame.pos, self.quat(frame), pos, quat)
            frame = frame.frame
        return pos, quat

    def name(self, elem: Any) -> str | None:
        return elem.name or None

    def path(self, file: str, subdir: str) -> str:
        full = Path(subdir) / file if subdir else Path(file)
        if not full.is_absolute():
            full = self.base_dir / full
        return os.path.normpath(str(full))

    def angle(self, value: float) -> float:
        return math.radians(value) if self.degree else float(value)

    # ------------------------------------------------------------------ assets
    def read_assets(self, world: World) -> None:
        spec = self.spec
        for tex in spec.textures:
            where = f'<texture name="{tex.name}">'
            if len(tex.data):
                self.lose(where, "embedded data of textures is not kept")
            kw: dict[str, Any] = {
                "type": {0: "2d", 1: "cube", 2: "skybox"}[int(tex.type)],
                "builtin": _enum(tex.builtin, "mjBUILTIN_"),
                "rgb1": tex.rgb1,
                "rgb2": tex.rgb2,
                "mark": _enum(tex.mark, "mjMARK_"),
                "markrgb": tex.markrgb,
                "random": tex.random,
                "width": tex.width,
                "height": tex.height,
                "gridsize": tex.gridsize,
            }
            if tex.file:
                kw["file"] = self.path(tex.file, spec.texturedir)
            for key, face in zip(TEXTURE_FILE_ATTRS[1:], tex.cubefiles):
                if face:
                    kw[key] = self.path(face, spec.texturedir)
            layout = "".join(tex.gridlayout)
            if layout and tuple(tex.gridsize) != (1, 1):
                kw["gridlayout"] = layout
            thing = Texture(self.name(tex), **kw)
            self.textures[tex.name] = thing
            world.assets.append(thing)
        for mat in spec.materials:
            textures = list(mat.textures)
            kw = {
                "rgba": _f32(mat.rgba),
                "emission": mat.emission,
                "specular": mat.specular,
                "shininess": mat.shininess,
                "reflectance": mat.reflectance,
                "metallic": mat.metallic,
                "roughness": mat.roughness,
                "texrepeat": _f32(mat.texrepeat),
                "texuniform": mat.texuniform,
            }
            if len(textures) > 1 and textures[1]:
                kw["texture"] = self.textures.get(textures[1], textures[1])
            if any(t for i, t in enumerate(textures) if i != 1):
                self.lose(
                    f'<material name="{mat.name}">', "layered (non-RGB) textures are not kept"
                )
            thing = Material(self.name(mat), **kw)
            self.materials[mat.name] = thing
            world.assets.append(thing)
        for kind in ("skins", "flexes"):
            for item in getattr(spec, kind):
                self.lose(
                    f'<{kind[:-1] if kind != "flexes" else "flex"} name="{item.name}">',
                    f"{kind} are not supported by Things; dropped",
                )

    def material(self, name: str) -> Any:
        if not name:
            return None
        return self.materials.get(name, name)

    # ------------------------------------------------------------------ tree
    def read_body_children(self, sbody: Any, node: BaseThing) -> None:
        for sj in sbody.joints:
            node.attach(self.joint(sj))
        for sg in sbody.geoms:
            geom = self.geom(sg)
            if geom is not None:
                node.attach(geom)
        for ss in sbody.sites:
            node.attach(self.site(ss))
        for sc in sbody.cameras:
            node.attach(self.camera(sc))
        for sl in sbody.lights:
            node.attach(self.light(sl))
        for child in sbody.bodies:
            node.attach(self.body(child))

    def body(self, sb: Any) -> Body:
        pos, quat = self.in_frame(sb, np.array(sb.pos, dtype=float), self.quat(sb))
        kw: dict[str, Any] = {"pos": pos, "quat": quat, "mocap": sb.mocap, "gravcomp": sb.gravcomp}
        if sb.explicitinertial:
            kw["mass"] = sb.mass
            kw["ipos"] = sb.ipos
            if not np.isnan(sb.fullinertia[0]):
                kw["fullinertia"] = sb.fullinertia
            else:
                kw["iquat"] = self.quat(sb, "ialt", "iquat")
                kw["inertia"] = sb.inertia
        body = Body(self.name(sb), **kw)
        self.register("body", sb.name, body)
        self.read_body_children(sb, body)
        return body

    def register(self, kind: str, name: str, thing: BaseThing) -> None:
        if name:
            self.by_name[(kind, name)] = thing

    def joint(self, sj: Any) -> BaseThing:
        jtype = _enum(sj.type, "mjJNT_")
        cls = _pick(JOINT_CLASSES, type=jtype)
        pos = np.array(sj.pos, dtype=float)
        axis = np.array(sj.axis, dtype=float)
        if sj.frame is not None:
            _, fquat = self.in_frame(sj, np.zeros(3), np.array([1.0, 0, 0, 0]))
            fpos, _ = self.in_frame(sj, pos, np.array([1.0, 0, 0, 0]))
            pos = fpos
            rotated = np.zeros(3)
            mujoco.mju_rotVecQuat(rotated, axis, fquat)
            axis = rotated
        angular = jtype in ("hinge", "ball")
        conv = self.angle if angular else float
        kw: dict[str, Any] = {
            "pos": pos,
            "stiffness": sj.stiffness,
            "damping": sj.damping,
            "frictionloss": sj.frictionloss,
            "armature": sj.armature,
            "margin": sj.margin,
            "group": sj.group,
            "solreflimit": sj.solref_limit,
            "solimplimit": sj.solimp_limit,
            "solreffriction": sj.solref_friction,
            "solimpfriction": sj.solimp_friction,
            "springdamper": sj.springdamper,
        }
        if jtype != "free":
            kw.update(
                range=[conv(sj.range[0]), conv(sj.range[1])],
                limited=_limited(sj.limited),
                ref=conv(sj.ref),
                springref=conv(sj.springref),
                actuatorfrcrange=sj.actfrcrange,
                actuatorfrclimited=_limited(sj.actfrclimited),
            )
        else:
            kw["align"] = _limited(sj.align)
        if jtype in ("hinge", "slide"):
            kw["axis"] = axis
        kw["actuatorgravcomp"] = bool(sj.actgravcomp)
        if "actuatorgravcomp" not in cls._MUJOCO_ATTR:
            kw.pop("actuatorgravcomp")
        joint = cls(self.name(sj), **kw)
        self.register("joint", sj.name, joint)
        return joint

    def geom(self, sg: Any) -> BaseThing | None:
        gtype = _enum(sg.type, "mjGEOM_")
        where = f'<geom name="{sg.name}" type="{gtype}">'
        try:
            cls = _pick(GEOM_CLASSES, type=gtype)
        except KeyError:
            self.lose(where, f"geom type {gtype!r} is not supported by Things; dropped")
            return None
        if sg.meshname and gtype != "mesh":
            self.lose(
                where,
                "a primitive fitted to a mesh is kept as the primitive with its size as given",
            )
        pos, quat = self.pose(sg)
        size = np.array(sg.size, dtype=float)
        if not np.isnan(sg.fromto[0]):
            half = float(np.linalg.norm(np.array(sg.fromto[3:]) - np.array(sg.fromto[:3]))) / 2
            if gtype in ("capsule", "cylinder"):
                size[1] = half
            elif gtype in ("box", "ellipsoid"):
                # MuJoCo's compiler: the two cross-section half-sizes both become size[0].
                size[1], size[2] = size[0], half
        kw: dict[str, Any] = {
            "size": size,
            "pos": pos,
            "quat": quat,
            "contype": sg.contype,
            "conaffinity": sg.conaffinity,
            "condim": sg.condim,
            "group": sg.group,
            "priority": sg.priority,
            "friction": sg.friction,
            "solmix": sg.solmix,
            "solref": sg.solref,
            "solimp": sg.solimp,
            "margin": sg.margin,
            "gap": sg.gap,
            "density": sg.density,
            "rgba": _f32(sg.rgba),
            "shellinertia": "true" if int(sg.typeinertia) == 1 else "false",
            "fluidshape": "ellipsoid" if sg.fluid_ellipsoid else "none",
            "fluidcoef": sg.fluid_coefs,
        }
        if not np.isnan(sg.mass):
            kw["mass"] = sg.mass
        if sg.material:
            kw["material"] = self.material(sg.material)
        if gtype == "mesh":
            kw.update(self.mesh_asset(sg.meshname, where))
        elif gtype == "hfield":
            kw.update(self.hfield_asset(sg.hfieldname, where))
        geom = cls(self.name(sg), **kw)
        self.register("geom", sg.name, geom)
        return geom

    def mesh_asset(self, meshname: str, where: str) -> dict[str, Any]:
        sm = self.spec.mesh(meshname)
        if sm is None:
            raise ThingXMLError(
                f"{self.source}: {where} refers to mesh {meshname!r}, which is not defined"
            )
        self.used_meshes.add(meshname)
        kw: dict[str, Any] = {
            "mesh": meshname,
            "scale": sm.scale,
            "maxhullvert": sm.maxhullvert,
            "meshinertia": _enum(sm.inertia, "mjMESH_INERTIA_"),
            "refpos": sm.refpos,
            "refquat": sm.refquat,
        }
        if sm.file:
            kw["file"] = self.path(sm.file, self.spec.meshdir)
        if len(sm.uservert):
            kw["vertex"] = _f32(sm.uservert)  # MuJoCo stores inline vertices as float32
        if len(sm.userface):
            kw["face"] = list(sm.userface)
        if len(sm.usernormal) or len(sm.usertexcoord) or sm.plugin.active or sm.content_type:
            self.lose(
                f'<mesh name="{meshname}">',
                "mesh normals, texture coordinates, content type and plugins are not kept",
            )
        return kw

    def unused_meshes(self, world: World) -> None:
        """Meshes no geom uses: MuJoCo still compiles them, so keep them as assets."""
        for sm in self.spec.meshes:
            # An unnamed file mesh is named after its file (MuJoCo 3.x leaves the spec's
            # name empty while geoms refer to it by that name).
            if (sm.name or Path(sm.file).stem) in self.used_meshes:
                continue
            kw = self.mesh_asset(sm.name, f'<mesh name="{sm.name}">')
            kw.pop("mesh")
            kw["inertia"] = kw.pop("meshinertia")
            world.assets.append(MeshAsset(sm.name or None, **kw))

    def hfield_asset(self, name: str, where: str) -> dict[str, Any]:
        sh = self.spec.hfield(name)
        if sh is None:
            raise ThingXMLError(
                f"{self.source}: {where} refers to hfield {name!r}, which is not defined"
            )
        self.used_hfields.add(name)
        kw: dict[str, Any] = {
            "hfield": name,
            "nrow": sh.nrow,
            "ncol": sh.ncol,
            "hfield_size": sh.size,
        }
        if sh.file:
            kw["file"] = self.path(sh.file, self.spec.meshdir)
        if len(sh.userdata):
            # MuJoCo's parser stores MJCF elevation rows bottom-up; flip back to MJCF order.
            rows = np.asarray(_f32(sh.userdata)).reshape(sh.nrow, sh.ncol)[::-1]
            kw["elevation"] = rows.ravel().tolist()
        if sh.content_type:
            self.lose(f'<hfield name="{name}">', "content_type is not kept")
        return kw

    def site(self, ss: Any) -> Site:
        pos, quat = self.pose(ss)
        size = np.array(ss.size, dtype=float)
        if not np.isnan(ss.fromto[0]):
            size[1] = float(np.linalg.norm(np.array(ss.fromto[3:]) - np.array(ss.fromto[:3]))) / 2
        site = Site(
            self.name(ss),
            type=_enum(ss.type, "mjGEOM_"),
            size=size,
            pos=pos,
            quat=quat,
            group=ss.group,
            rgba=_f32(ss.rgba),
            material=self.material(ss.material),
        )
        self.register("site", ss.name, site)
        return site

    def camera(self, sc: Any) -> Camera:
        pos, quat = self.pose(sc)
        if any(sc.sensor_size) or any(sc.intrinsic) or int(sc.proj) != 0:
            self.lose(
                f'<camera name="{sc.name}">',
                "sensor size, intrinsics and projection type are not kept",
            )
        cam = Camera(
            self.name(sc),
            pos=pos,
            quat=quat,
            mode=_enum(sc.mode, "mjCAMLIGHT_"),
            target=sc.targetbody or None,
            fovy=sc.fovy,
            ipd=sc.ipd,
            resolution=sc.resolution,
        )
        self.register("camera", sc.name, cam)
        return cam

    def light(self, sl: Any) -> Light:
        pos, quat = self.in_frame(sl, np.array(sl.pos, dtype=float), np.array([1.0, 0, 0, 0]))
        direction = np.zeros(3)
        mujoco.mju_rotVecQuat(direction, np.array(sl.dir, dtype=float), quat)
        if sl.texture:
            self.lose(f'<light name="{sl.name}">', "light textures are not kept")
        light = Light(
            self.name(sl),
            pos=pos,
            dir=direction,
            mode=_enum(sl.mode, "mjCAMLIGHT_"),
            target=sl.targetbody or None,
            type=_enum(sl.type, "mjLIGHT_"),
            castshadow=sl.castshadow,
            active=sl.active,
            attenuation=_f32(sl.attenuation),
            cutoff=_f32([sl.cutoff])[0],
            exponent=_f32([sl.exponent])[0],
            ambient=_f32(sl.ambient),
            diffuse=_f32(sl.diffuse),
            specular=_f32(sl.specular),
            bulbradius=_f32([sl.bulbradius])[0],
            intensity=_f32([sl.intensity])[0],
            range=_f32([sl.range])[0],
        )
        self.register("light", sl.name, light)
        return light

    # ------------------------------------------------------------------ sections
    def actuator(
        self, sa: Any, world: World, carried: dict[str, list[ET.Element]], index: int
    ) -> None:
        trn = _enum(sa.trntype, "mjTRN_")
        target = self.by_name.get(({"joint": "joint", "site": "site"}.get(trn, ""), sa.target))
        if target is None or sa.slidersite or sa.refsite and trn != "site":
            self._carry(world, "actuator", sa, carried, f"actuator on a {trn}", index)
            return
        cls, extra = _actuator_class(sa)
        kw: dict[str, Any] = {
            "gear": sa.gear,
            "ctrlrange": sa.ctrlrange,
            "ctrllimited": _limited(sa.ctrllimited),
            "forcerange": sa.forcerange,
            "forcelimited": _limited(sa.forcelimited),
            "actrange": sa.actrange,
            "actlimited": _limited(sa.actlimited),
            "group": sa.group,
            **extra,
        }
        if sa.refsite:
            kw["refsite"] = sa.refsite
        if sa.inheritrange > 0:
            # Whether and where the joint range is inherited (position servos: ctrlrange,
            # integrated velocity: actrange; a <motor> under a class whose <position>
            # default sets inheritrange: neither) is the compiler's decision: take its.
            model = self.compiled
            kw["ctrlrange"] = model.actuator_ctrlrange[index]
            kw["ctrllimited"] = "true" if model.actuator_ctrllimited[index] else "false"
            if model.actuator_actlimited[index]:
                kw["actrange"] = model.actuator_actrange[index]
                kw["actlimited"] = "true"
        lost = [f for f in ("armature", "cranklength", "delay") if getattr(sa, f)]
        lost += [f for f in ("damping", "lengthrange") if np.any(getattr(sa, f))]
        if lost:
            self.lose(f'<actuator name="{sa.name}">', f"attributes {', '.join(lost)} are not kept")
        act = cls(self.name(sa), **kw)
        target.attach(act)
        self.register("actuator", sa.name, act)

    def sensor(
        self, ss: Any, world: World, carried: dict[str, list[ET.Element]], index: int
    ) -> None:
        tag = _enum(ss.type, "mjSENS_")
        cls = S.SENSOR_CLASSES.get(tag)
        objtype = _enum(ss.objtype, "mjOBJ_")
        target = self.by_name.get(("body" if objtype == "xbody" else objtype, ss.objname))
        if (
            cls is None
            or target is None
            or (
                cls._TARGET_KINDS
                and (target._NAMESPACE or getattr(target, "_TARGET_AS", None))
                not in cls._TARGET_KINDS
            )
        ):
            self._carry(world, "sensor", ss, carried, f"{tag} sensor on a {objtype}", index)
            return
        kw: dict[str, Any] = {"noise": ss.noise, "cutoff": ss.cutoff}
        if issubclass(cls, S.FrameSensor):
            if objtype == "xbody":
                kw["objtype"] = "xbody"
            if ss.refname:
                kw["reftype"] = _enum(ss.reftype, "mjOBJ_")
                kw["refname"] = ss.refname
        if ss.delay or ss.nsample or any(ss.interval):
            self.lose(f'<{tag} name="{ss.name}">', "sensor delay/sampling settings are not kept")
        sensor = cls(self.name(ss), **kw)
        target.attach(sensor)

    def _carry(
        self,
        world: World,
        section: str,
        elem: Any,
        carried: dict[str, list[ET.Element]],
        what: str,
        index: int,
    ) -> None:
        queue = carried.get(section, [])
        if not queue:
            self.lose(f'<{section} name="{elem.name}">', f"{what} cannot be represented; dropped")
            return
        xml = queue.pop(0)
        refine_listed([xml], self.compiled, section, start=index)  # full precision
        _carried_class(xml)
        world.attach(RawElement(section=section, xml=ET.tostring(xml, encoding="unicode").strip()))


def _limited(value: Any) -> str:
    return {0: "false", 1: "true", 2: "auto"}[int(value)]


def _pick(classes: tuple[type, ...], **derived: Any) -> Any:
    for cls in classes:
        if all(getattr(cls, k, None) == v for k, v in derived.items()):
            return cls
    raise KeyError(derived)


def _actuator_class(sa: Any) -> tuple[type, dict[str, Any]]:
    gain, bias, dyn = sa.gaintype, sa.biastype, sa.dyntype
    gp, bp = np.array(sa.gainprm), np.array(sa.biasprm)
    plain = int(gain) == 0 and int(dyn) == 0 and not gp[1:].any() and not sa.actearly
    if plain and int(bias) == 0 and gp[0] == 1 and not bp.any():
        return A.Motor, {}
    if plain and int(bias) == 1 and bp[0] == 0 and not bp[3:].any():
        if bp[1] == -gp[0] and bp[2] <= 0:
            return A.Position, {"kp": gp[0], "kv": -bp[2]}
        if bp[1] == 0 and bp[2] == -gp[0]:
            return A.Velocity, {"kv": gp[0]}
    return A.General, {
        "dyntype": _enum(dyn, "mjDYN_"),
        "gaintype": _enum(gain, "mjGAIN_"),
        "biastype": _enum(bias, "mjBIAS_"),
        "dynprm": sa.dynprm,
        "gainprm": sa.gainprm,
        "biasprm": sa.biasprm,
        "actearly": sa.actearly,
        "actdim": sa.actdim,
    }


def _carried_class(elem: ET.Element) -> None:
    """Point a carried element without a class at the carried main defaults."""
    if elem.tag in _CLASSABLE and "class" not in elem.attrib:
        # MuJoCo writes class right after name; keep that order so output is stable.
        attrs = dict(elem.attrib)
        elem.attrib.clear()
        if "name" in attrs:
            elem.set("name", attrs.pop("name"))
        elem.set("class", CARRIED_CLASS)
        elem.attrib.update(attrs)


# Carried elements that take default classes (sensors, keys and excludes take none).
_CLASSABLE = frozenset(
    {
        "pair",
        "connect",
        "weld",
        "joint",
        "tendon",
        "flex",
        "spatial",
        "fixed",
        "general",
        "motor",
        "position",
        "velocity",
        "intvelocity",
        "damper",
        "cylinder",
        "muscle",
        "adhesion",
    }
)
