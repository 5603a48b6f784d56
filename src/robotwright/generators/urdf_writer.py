"""Writing one robot's links and joints as URDF (shared by the single robot's generator and
the composite): names kept unique, ball and free joints expanded into chains of
massless links, and every value URDF cannot hold noted by its table row."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import replace

from robotwright.errors import GeneratorError, Problem
from robotwright.generators.mixin import HRDFMixin
from robotwright.generators.mjcf import imu_sites
from robotwright.generators.placement import qmul
from robotwright.generators.urdf_base import (
    WORLD_LINK,
    URDFGeneratorBase,
    inertia_tensor,
    quat_to_rpy,
    rotate,
)
from robotwright.generators.xmlfmt import fmt_float, fmt_vec, prefixed
from robotwright.hrdf.model import (
    HRDF,
    MUJOCO_SOLIMP,
    MUJOCO_SOLREF,
    WORLD,
    Actuator,
    Body,
    Geom,
    Joint,
    MeshGeom,
    SimpleGeom,
)

#: Mass (kg) and inertia (kg m^2) of the links that split a multi-joint body: MuJoCo
#: rejects massless moving bodies and SDFormat (Gazebo) drops massless links with their
#: joints, so the chain would break there. 1e-9 kg changes no FK and no realistic total mass.
DUMMY_LINK_MASS = 1e-9

DUMMY_LINK_INERTIA = 1e-12

_IDENTITY = (1.0, 0.0, 0.0, 0.0)

_ZERO = (0.0, 0.0, 0.0)

_DEFAULT_FRICTION = (1.0, 0.005, 0.0001)

#: Geom groups MuJoCo's viewer draws by default (``mjvOption.geomgroup`` is 1 1 1 0 0 0).
MUJOCO_DRAWN_GROUPS = (0, 1, 2)


def drawn_by_mujoco(g: Geom) -> bool:
    """Whether MuJoCo's default viewer draws the geom: its group is one of
    :data:`MUJOCO_DRAWN_GROUPS` and its colour is not fully transparent (rgba alpha > 0)."""
    return g.group in MUJOCO_DRAWN_GROUPS and float(g.rgba[3]) > 0.0


def _sub(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float]:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _origin(parent: ET.Element, xyz: tuple[float, ...], q: tuple[float, ...] = _IDENTITY) -> None:
    attrs = {"xyz": fmt_vec(xyz), "rpy": fmt_vec(quat_to_rpy(q))}  # type: ignore[arg-type]
    ET.SubElement(parent, "origin", attrs)


class _RobotWriter:
    """Writes one robot's links and joints (shared by the single and composite URDF)."""

    def __init__(
        self,
        gen: URDFGeneratorBase,
        hrdf: HRDF,
        prefix: str | None,
        relative: bool,
        losses: list[Problem],
        robot_gen: HRDFMixin | None = None,
    ) -> None:
        self.gen, self.hrdf, self.prefix = gen, hrdf, prefix
        owner = robot_gen if robot_gen is not None else gen
        # the generator that holds the robot (``gen`` itself, or one robot's generator
        # of a composite) knows where its meshes are
        assert isinstance(owner, HRDFMixin)
        self.mesh_path = owner.mesh_abspath
        self.relative, self.losses = relative, losses
        self.materials: dict[tuple[float, ...], str] = {}
        self.mesh_refs: dict[str, str] = {}
        # Names already used per kind; generated names avoid them (see _fresh).
        self.link_names: set[str] = set()
        self.joint_names: set[str] = set()
        #: site/IMU name -> the name of the link that carries it (before the prefix).
        self.frame_links: dict[str, str] = {}
        #: dummy link name (prefixed) -> the body whose joints it splits.
        self.dummy_links: dict[str, str] = {}
        #: ball joint name (prefixed) -> its x, y, z revolute joints (prefixed).
        self.split_joints: dict[str, tuple[str, str, str]] = {}

    def p(self, name: str) -> str:
        return prefixed(self.prefix, name)

    def write(
        self,
        root: ET.Element,
        parent_link: str = WORLD_LINK,
        placement: tuple[tuple[float, float, float], tuple[float, float, float, float]]
        | None = None,
        fixed_root: bool = False,
    ) -> None:
        """Append the robot's links and joints to ``root``; the root body hangs from
        ``parent_link`` at its own pose composed with ``placement`` (pos, quat), welded
        there when ``fixed_root``."""
        hrdf = self.hrdf
        self._reserve_names()
        joints: dict[str, list[Joint]] = {}
        for j in hrdf.joints:
            joints.setdefault(j.body, []).append(j)
        actuators: dict[str, Actuator] = {}
        for row, a in enumerate(hrdf.actuators):
            actuators.setdefault(a.joint, a)
            self._actuator_losses(a, row)
        geoms: dict[str, list[tuple[Geom, str, int]]] = {}
        for row, m in enumerate(hrdf.meshes):
            geoms.setdefault(m.body, []).append((m, "mesh.csv", row))
        for row, g in enumerate(hrdf.simple_geoms):
            geoms.setdefault(g.body, []).append((g, "simple_geom.csv", row))
        frames: dict[str, list[tuple[str, tuple[float, ...], tuple[float, ...]]]] = {}
        for row, s in enumerate(hrdf.sites):
            if s.body == WORLD:  # a URDF's links all belong to the robot's tree
                self.losses.append(
                    Problem(
                        "site.csv",
                        f"site '{s.name}' of the world: URDF has no frame outside the robot",
                        row=row,
                    )
                )
                continue
            frames.setdefault(s.body, []).append((s.name, s.pos, s.quat))
        for imu, (name, new) in zip(hrdf.meta.imu_config_list or [], imu_sites(hrdf), strict=True):
            if new:
                frames.setdefault(imu.body_name, []).append((name, imu.position, imu.orientation))
            self.losses.append(
                Problem(
                    "meta.yaml",
                    f"IMU '{name}': written as a frame link; its sensors have no URDF form",
                    column="imu_config_list",
                )
            )
        for s in hrdf.sensors:
            self.losses.append(
                Problem("sensor.csv", f"sensor '{s.name}' ({s.type}) has no URDF form")
            )
        if hrdf.mjcf_extra and hrdf.mjcf_extra.strip():
            self.losses.append(
                Problem("mjcf_extra", "tendons/equality/contact/keyframes have no URDF form")
            )
        links: list[ET.Element] = []
        jnts: list[ET.Element] = []
        offset: dict[int, tuple[float, float, float]] = {}
        for idx in _dfs(hrdf):
            b = hrdf.bodies[idx]
            own = [j for j in joints.get(b.name, ()) if j.type != "free"]
            if b.parent == -1:
                placed = b
                if placement is not None:
                    ppos = rotate(placement[1], b.pos)
                    placed = replace(
                        b,
                        pos=(
                            ppos[0] + placement[0][0],
                            ppos[1] + placement[0][1],
                            ppos[2] + placement[0][2],
                        ),
                        quat=qmul(placement[1], b.quat),
                    )
                free = [j for j in joints.get(b.name, ()) if j.type == "free"]
                if free or not own:
                    name = free[0].name if free and free[0].name else None
                    if name is None:
                        name = self._fresh(
                            "floating_base" if free else f"{b.name}_world_joint",
                            self.joint_names,
                        )
                    if free:
                        self._joint_losses(free[0])
                    jtype = "floating" if free and not fixed_root else "fixed"
                    el = ET.Element("joint", {"name": self.p(name), "type": jtype})
                    _origin(el, placed.pos, placed.quat)
                    ET.SubElement(el, "parent", {"link": parent_link})
                    ET.SubElement(el, "child", {"link": self.p(b.name)})
                    jnts.append(el)
                    offset[idx] = _ZERO
                else:
                    offset[idx] = self._body_joints(
                        placed, own, parent_link, _ZERO, actuators, links, jnts
                    )
            else:
                parent_off = offset[b.parent]
                parent_name = self.p(hrdf.bodies[b.parent].name)
                offset[idx] = self._body_joints(
                    b, own, parent_name, parent_off, actuators, links, jnts
                )
            links.append(self._link(b, offset[idx], geoms.get(b.name, [])))
            for name, fpos, fquat in frames.get(b.name, ()):
                link_name = self.frame_links[name]
                links.append(ET.Element("link", {"name": self.p(link_name)}))
                jname = self._fresh(f"{link_name}_joint", self.joint_names)
                el = ET.Element("joint", {"name": self.p(jname), "type": "fixed"})
                _origin(el, _sub(fpos, offset[idx]), fquat)
                ET.SubElement(el, "parent", {"link": self.p(b.name)})
                ET.SubElement(el, "child", {"link": self.p(link_name)})
                jnts.append(el)
        for mat_rgba, mat_name in self.materials.items():
            m = ET.SubElement(root, "material", {"name": mat_name})
            ET.SubElement(m, "color", {"rgba": fmt_vec(mat_rgba)})
        root.extend(links)
        root.extend(jnts)

    # -- names ----------------------------------------------------------------------------
    def _reserve_names(self) -> None:
        """Reserve body and joint names, and name the link of every site/IMU frame.

        URDF has one namespace for links, while MJCF keeps sites apart from bodies: a
        site named like a body (or ``world``) gets the link ``<site>_site`` (``_site2``,
        ... if that is taken too), reported."""
        hrdf = self.hrdf
        bodies = {b.name for b in hrdf.bodies}
        if WORLD_LINK in bodies:
            raise GeneratorError(
                f"robot '{hrdf.name}': a body is named '{WORLD_LINK}', which URDF reserves"
            )
        self.link_names = bodies | {WORLD_LINK}
        self.joint_names = {j.name for j in hrdf.joints if j.name}
        self.frame_links = {}
        frame_names = [s.name for s in hrdf.sites] + [n for n, new in imu_sites(hrdf) if new]
        renamed = []
        for name in frame_names:
            if name in self.link_names:
                link = self._fresh(f"{name}_site", self.link_names)
                renamed.append(f"'{name}' -> '{link}'")
            else:
                link = name
                self.link_names.add(name)
            self.frame_links[name] = link
        if renamed:
            self.losses.append(
                Problem(
                    "site.csv",
                    f"site/IMU frame link(s) renamed, their names being body link names "
                    f"(URDF has one namespace for links): {', '.join(renamed)}",
                    column="name",
                )
            )

    @staticmethod
    def _fresh(name: str, taken: set[str]) -> str:
        """``name`` if unused, else ``name2``, ``name3``, ...; reserved in ``taken``."""
        out, k = name, 1
        while out in taken:
            k += 1
            out = f"{name}{k}"
        taken.add(out)
        return out

    # -- joints ---------------------------------------------------------------------------
    def _body_joints(
        self,
        b: Body,
        own: list[Joint],
        parent_link: str,
        parent_off: tuple[float, float, float],
        actuators: dict[str, Actuator],
        links: list[ET.Element],
        jnts: list[ET.Element],
    ) -> tuple[float, float, float]:
        """Write the joints of body ``b`` (a chain through dummy links when several);
        return the offset of ``b``'s link frame from its body frame."""
        body_xyz = _sub(b.pos, parent_off)
        if not own:
            jname = self._fresh(f"{b.name}_fixed_joint", self.joint_names)
            el = ET.Element("joint", {"name": self.p(jname), "type": "fixed"})
            _origin(el, body_xyz, b.quat)
            ET.SubElement(el, "parent", {"link": parent_link})
            ET.SubElement(el, "child", {"link": self.p(b.name)})
            jnts.append(el)
            return _ZERO
        chain = self._expand(own)
        prev_link, prev_anchor = parent_link, None
        dummies: list[str] = []
        # A URDF joint turns its child link about the link's origin: when the last anchor
        # is off the body origin, the chain ends in a dummy link at the anchor and the
        # body's link hangs from it (fixed) at the body frame, so every body link keeps
        # its MJCF body frame.
        anchored = any(float(v) != 0.0 for v in own[-1].pos)
        for k, (j, jname, jtype, axis, rng) in enumerate(chain):
            last = k == len(chain) - 1
            if last and not anchored:
                child = self.p(b.name)
            else:
                child = self.p(self._fresh(f"{b.name}_dummy{k + 1}", self.link_names))
                dummies.append(child)
            el = ET.Element("joint", {"name": self.p(jname), "type": jtype})
            # MuJoCo moves the body by q - ref: the origin carries the motion by -ref.
            ref_xyz, ref_quat = _ref_motion(j)
            if prev_anchor is None:
                xyz = tuple(
                    x + y
                    for x, y in zip(body_xyz, rotate(b.quat, _add(j.pos, ref_xyz)), strict=True)
                )
                _origin(el, xyz, qmul(b.quat, ref_quat))
            else:
                _origin(el, _add(_sub(j.pos, prev_anchor), ref_xyz), ref_quat)
            ET.SubElement(el, "parent", {"link": prev_link})
            ET.SubElement(el, "child", {"link": child})
            ET.SubElement(el, "axis", {"xyz": fmt_vec(axis)})
            self._limit(el, j, jtype, rng, actuators.get(j.name or ""))
            dyn = {}
            if j.viscous_friction:
                dyn["damping"] = fmt_float(j.viscous_friction)
            if j.dynamic_friction:
                dyn["friction"] = fmt_float(j.dynamic_friction)
            if dyn:
                ET.SubElement(el, "dynamics", dyn)
            jnts.append(el)
            if child in dummies:
                links.append(self._dummy_link(child))
                self.dummy_links[child] = b.name
            prev_link, prev_anchor = child, j.pos
        if anchored:
            jname = self._fresh(f"{b.name}_anchor_joint", self.joint_names)
            el = ET.Element("joint", {"name": self.p(jname), "type": "fixed"})
            _origin(el, tuple(-float(v) for v in own[-1].pos))
            ET.SubElement(el, "parent", {"link": prev_link})
            ET.SubElement(el, "child", {"link": self.p(b.name)})
            jnts.append(el)
        if dummies:
            self.losses.append(
                Problem(
                    "joint.csv",
                    f"body '{b.name}' ({len(chain)} joint(s)"
                    + (", anchor off the body origin" if anchored else "")
                    + f"): written through link(s) {dummies} of {DUMMY_LINK_MASS:g} kg and {DUMMY_LINK_INERTIA:g} "
                    "kg m^2 each (massless moving links are refused by MuJoCo and dropped by "
                    "SDFormat)",
                    column="body",
                )
            )
        for j in own:
            self._joint_losses(j)
        return _ZERO

    def _expand(
        self, own: list[Joint]
    ) -> list[tuple[Joint, str, str, tuple[float, ...], tuple[float, float] | None]]:
        out: list[tuple[Joint, str, str, tuple[float, ...], tuple[float, float] | None]] = []
        for j in own:
            name = j.name or ""
            if j.type == "ball":
                rng = (-j.range[1], j.range[1]) if j.range is not None else None
                split = [self._fresh(f"{name}_{a}", self.joint_names) for a in "xyz"]
                for jname, axis in zip(split, ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))):
                    out.append((j, jname, "revolute" if rng else "continuous", axis, rng))
                self.split_joints[self.p(name)] = (
                    self.p(split[0]),
                    self.p(split[1]),
                    self.p(split[2]),
                )
                self.losses.append(
                    Problem(
                        "joint.csv",
                        f"ball joint '{name}': URDF has none; written as "
                        + ("revolute" if rng else "continuous")
                        + f" joints '{split[0]}', '{split[1]}', '{split[2]}' about the body's "
                        "x, y and z axes" + (" (each limited to the cone angle)" if rng else ""),
                        column="type",
                    )
                )
            elif j.type == "slide":
                out.append((j, name, "prismatic", j.axis, j.range))
            else:
                out.append(
                    (j, name, "revolute" if j.range is not None else "continuous", j.axis, j.range)
                )
        return out

    def _limit(
        self,
        el: ET.Element,
        j: Joint,
        jtype: str,
        rng: tuple[float, float] | None,
        act: Actuator | None,
    ) -> None:
        attrs: dict[str, str] = {}
        if rng is not None:
            attrs["lower"] = fmt_float(rng[0])
            attrs["upper"] = fmt_float(rng[1])
        elif jtype == "prismatic":
            self.losses.append(
                Problem(
                    "joint.csv",
                    f"slide joint '{j.name}' is unlimited; URDF readers may take the missing "
                    "lower/upper as 0",
                    column="range0",
                )
            )
        effort, velocity = _effort_velocity(act)
        frc = j.actuatorfrcrange
        if effort is None and frc is not None and frc[0] == -frc[1] and frc[1] > 0:
            effort = frc[1]  # MuJoCo 4's URDF import makes +-effort the joint's range
        elif frc is not None and (effort is None or (-effort, effort) != tuple(frc)):
            self.losses.append(
                Problem(
                    "joint.csv",
                    f"joint '{j.name}': actuatorfrcrange {tuple(frc)} has no URDF form "
                    "(only a symmetric range, as <limit effort>)",
                    column="actuatorfrcrange0",
                )
            )
        if effort is not None:
            attrs["effort"] = fmt_float(effort)
        if velocity is not None:
            attrs["velocity"] = fmt_float(velocity)
        if attrs or jtype in ("revolute", "prismatic"):
            ET.SubElement(el, "limit", attrs)

    def _joint_losses(self, j: Joint) -> None:
        if j.ref and j.type in ("hinge", "slide"):
            self.losses.append(
                Problem(
                    "joint.csv",
                    f"joint '{j.name}': ref {j.ref} baked into the joint origin (same joint "
                    "coordinate, limits and FK as MJCF); URDF has no initial position, so "
                    "its default pose is q = 0, not q = ref",
                    column="ref",
                )
            )
        for field_name, value in (
            ("armature", j.armature),
            ("stiffness", j.stiffness),
            ("springref", j.springref),
            ("ref", j.ref if j.type not in ("hinge", "slide") else 0.0),
        ):
            if value:
                self.losses.append(
                    Problem(
                        "joint.csv",
                        f"joint '{j.name}': {field_name} {value} has no URDF form",
                        column=field_name,
                    )
                )
        if j.static_friction and j.static_friction != j.dynamic_friction:
            self.losses.append(
                Problem(
                    "joint.csv",
                    f"joint '{j.name}': static_friction {j.static_friction} (friction = dynamic)",
                    column="static_friction",
                )
            )
        lost = [f for f, default in _JOINT_MUJOCO_ONLY if getattr(j, f) != default]
        if lost:
            self.losses.append(
                Problem(
                    "joint.csv",
                    f"joint '{j.name}': {', '.join(lost)} have no URDF form",
                    column=lost[0],
                )
            )
        if j.type == "free" and (j.viscous_friction or j.dynamic_friction):
            self.losses.append(
                Problem("joint.csv", "free joint damping/friction has no URDF form", column="type")
            )

    def _actuator_losses(self, a: Actuator, row: int) -> None:
        lost = []
        if a.type != "motor":
            lost.append(f"type {a.type}")
        if a.p_gain is not None:
            lost.append("p_gain")
        if a.d_gain is not None:
            lost.append("d_gain")
        if a.gear != 1.0:
            lost.append("gear")
        if a.ctrl_range is not None:
            lost.append("ctrl_range")
        if lost:
            self.losses.append(
                Problem(
                    "actuator.csv",
                    f"actuator on '{a.joint}': {', '.join(lost)} not written (URDF keeps "
                    "effort and velocity limits only)",
                    row,
                )
            )

    # -- links ----------------------------------------------------------------------------
    @staticmethod
    def _dummy_link(name: str) -> ET.Element:
        link = ET.Element("link", {"name": name})
        inertial = ET.SubElement(link, "inertial")
        _origin(inertial, _ZERO)
        ET.SubElement(inertial, "mass", {"value": fmt_float(DUMMY_LINK_MASS)})
        d = fmt_float(DUMMY_LINK_INERTIA)
        ET.SubElement(
            inertial,
            "inertia",
            {"ixx": d, "ixy": "0", "ixz": "0", "iyy": d, "iyz": "0", "izz": d},
        )
        return link

    def _link(
        self, b: Body, off: tuple[float, float, float], geoms: list[tuple[Geom, str, int]]
    ) -> ET.Element:
        link = ET.Element("link", {"name": self.p(b.name)})
        lost = [f for f, value in (("gravcomp", b.gravcomp), ("user", b.user)) if value]
        if lost:
            self.losses.append(
                Problem("body.csv", f"body '{b.name}': {', '.join(lost)} have no URDF form")
            )
        inertial = ET.SubElement(link, "inertial")
        _origin(inertial, _sub(b.inertial_pos, off))
        ET.SubElement(inertial, "mass", {"value": fmt_float(b.mass)})
        t = inertia_tensor(tuple(b.diag_inertia), tuple(b.inertial_quat))
        ET.SubElement(
            inertial,
            "inertia",
            dict(zip(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), map(fmt_float, t), strict=True)),
        )
        for g, table, row in geoms:
            self._geom(link, g, off, table, row)
        return link

    def _geom(
        self, link: ET.Element, g: Geom, off: tuple[float, float, float], table: str, row: int
    ) -> None:
        collide = bool(g.contact_type or g.contact_affinity)
        drawn = drawn_by_mujoco(g)
        # A visual for what MuJoCo draws (URDF viewers show visuals only) and for what
        # does not collide (else it would be lost); a collision for what collides.
        tags: tuple[str, ...] = ("visual",) if drawn or not collide else ()
        if collide:
            tags += ("collision",)
        self._geom_losses(g, collide, drawn, table, row)
        pos = _sub(g.pos, off)
        name = g.geom_name
        if isinstance(g, MeshGeom):
            src = self.mesh_path(g)
            ref = self.mesh_refs.get(src)
            if ref is None:
                ref = self.gen._reference(self.gen._mesh_file(src), self.relative)
                self.mesh_refs[src] = ref
            attrs = {"filename": ref}
            if g.scale != (1.0, 1.0, 1.0):
                attrs["scale"] = fmt_vec(g.scale)
            self._shape(link, tags, name, pos, g.quat, "mesh", attrs, g.rgba)
            return
        assert isinstance(g, SimpleGeom)
        name = name or g.name
        s = g.size
        if g.type == "box":
            self._shape(
                link, tags, name, pos, g.quat, "box", {"size": fmt_vec(2 * v for v in s)}, g.rgba
            )
        elif g.type == "sphere":
            self._shape(
                link, tags, name, pos, g.quat, "sphere", {"radius": fmt_float(s[0])}, g.rgba
            )
        elif g.type == "cylinder":
            attrs = {"radius": fmt_float(s[0]), "length": fmt_float(2 * s[1])}
            self._shape(link, tags, name, pos, g.quat, "cylinder", attrs, g.rgba)
        elif g.type == "capsule":
            self.losses.append(
                Problem(
                    table,
                    f"capsule '{name}': URDF has no capsule; written as a cylinder plus two "
                    "end spheres (same shape, three elements)",
                    row,
                    "type",
                )
            )
            attrs = {"radius": fmt_float(s[0]), "length": fmt_float(2 * s[1])}
            self._shape(link, tags, name, pos, g.quat, "cylinder", attrs, g.rgba)
            for k, sign in ((1, 1.0), (2, -1.0)):
                end = rotate(g.quat, (0.0, 0.0, sign * s[1]))
                end_pos = (pos[0] + end[0], pos[1] + end[1], pos[2] + end[2])
                self._shape(
                    link, tags, f"{name}_end{k}" if name else None, end_pos, _IDENTITY,
                    "sphere", {"radius": fmt_float(s[0])}, g.rgba,
                )  # fmt: skip
        else:
            self.losses.append(
                Problem(table, f"{g.type} '{name}': URDF has no {g.type}; dropped", row, "type")
            )

    def _shape(
        self,
        link: ET.Element,
        tags: tuple[str, ...],
        name: str | None,
        pos: tuple[float, ...],
        quat: tuple[float, ...],
        shape: str,
        attrs: dict[str, str],
        rgba: tuple[float, ...],
    ) -> None:
        """One ``<visual>`` and/or ``<collision>`` (``tags``) of the same geometry and
        origin. The geom's name goes on the collision when there is one: MuJoCo's URDF
        import drops visuals by default, and with ``discardvisual="false"`` it warns about
        a visual and a collision of the same name."""
        for tag in tags:
            el = ET.SubElement(link, tag)
            if name and (tag == "collision" or "collision" not in tags):
                el.set("name", self.p(name))
            _origin(el, pos, quat)
            geometry = ET.SubElement(el, "geometry")
            ET.SubElement(geometry, shape, attrs)
            if tag == "visual":
                key = tuple(float(v) for v in rgba)
                mat = self.materials.get(key)
                if mat is None:
                    mat = self.p(f"material_{len(self.materials)}")
                    self.materials[key] = mat
                ET.SubElement(el, "material", {"name": mat})

    def _geom_losses(self, g: Geom, collide: bool, drawn: bool, table: str, row: int) -> None:
        lost = []
        if collide and (g.contact_type, g.contact_affinity) != (1, 1):
            lost.append(f"contype/conaffinity {g.contact_type}/{g.contact_affinity}")
        if (
            collide
            and (g.static_friction, g.torsional_friction, g.rolling_friction) != _DEFAULT_FRICTION
        ):
            lost.append("friction")
        if g.condim != 3:
            lost.append(f"condim {g.condim}")
        if g.group and not drawn and not collide:
            lost.append(
                f"group {g.group} (hidden by MuJoCo's default viewer; written as a <visual>, "
                "which URDF viewers show)"
            )
        elif g.group:
            lost.append(f"group {g.group}")
        if collide and not drawn and tuple(g.rgba) != (0.5, 0.5, 0.5, 1.0):
            lost.append(
                "colour (not drawn by MuJoCo: collision only, and URDF collisions have none)"
            )
        if g.restitution is not None:
            lost.append("restitution")
        lost += [f for f, default in _GEOM_MUJOCO_ONLY if getattr(g, f) != default]
        if lost:
            self.losses.append(
                Problem(table, f"geom on '{g.body}': {', '.join(lost)} not written", row)
            )


#: MuJoCo fields URDF cannot hold, with their defaults (reported when set).
_JOINT_MUJOCO_ONLY = (
    ("margin", 0.0),
    ("actuatorgravcomp", False),
    ("solreflimit", MUJOCO_SOLREF),
    ("solimplimit", MUJOCO_SOLIMP),
    ("solreffriction", MUJOCO_SOLREF),
    ("solimpfriction", MUJOCO_SOLIMP),
    ("user", ()),
)

_GEOM_MUJOCO_ONLY = (
    ("solref", MUJOCO_SOLREF),
    ("solimp", MUJOCO_SOLIMP),
    ("margin", 0.0),
    ("gap", 0.0),
    ("priority", 0),
    ("solmix", 1.0),
    ("user", ()),
)


def _effort_velocity(act: Actuator | None) -> tuple[float | None, float | None]:
    """URDF ``effort`` and ``velocity`` of a joint from its actuator (``None`` = unknown)."""
    if act is None:
        return None, None
    effort = act.peak_torque
    if effort is None and act.force_range is not None:
        effort = max(abs(v) for v in act.force_range)
    if effort is None and act.type == "motor" and act.ctrl_range is not None:
        effort = max(abs(v) for v in act.ctrl_range) * abs(act.gear)
    return effort, act.peak_velocity


def _add(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float]:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _ref_motion(j: Joint) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """The joint's motion by ``-ref`` (translation in m, rotation as w, x, y, z) in its body
    frame: hinge -> rotation about the axis, slide -> translation along the unit axis."""
    if not j.ref or j.type not in ("hinge", "slide"):
        return _ZERO, _IDENTITY
    n = math.sqrt(sum(float(v) * float(v) for v in j.axis))
    u = (j.axis[0] / n, j.axis[1] / n, j.axis[2] / n)
    if j.type == "slide":
        return (-j.ref * u[0], -j.ref * u[1], -j.ref * u[2]), _IDENTITY
    s = math.sin(-j.ref / 2)
    return _ZERO, (math.cos(-j.ref / 2), s * u[0], s * u[1], s * u[2])


def _dfs(hrdf: HRDF) -> list[int]:
    """Body indices parents-first (depth first, children in table order)."""
    children: dict[int, list[int]] = {}
    for i, b in enumerate(hrdf.bodies):
        children.setdefault(b.parent, []).append(i)
    out: list[int] = []
    stack = list(reversed(children.get(-1, [])))
    while stack:
        i = stack.pop()
        out.append(i)
        stack.extend(reversed(children.get(i, [])))
    return out
