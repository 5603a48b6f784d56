"""Build a design into a kinematic limb (bodies, joints, DH tables) and an HRDF model.

Traversal (the original grammar's rule): walk the design tree from the root. A connector node is
*deferred*: its joint DoFs are remembered, and added to the body of the next link (or
end part) reached below it, in order from the root. Each link or end part is one body.

Frames: the base body frame is the mount frame (the pinned face, z up). The first joint
frame sits on the base's top face. A link extends along its body x; the next joint
frame is at the link's far end, twisted about the link axis by the link's ``rotation``
plus the connector DoF's ``twist``. A joint moves about/along the z axis of its frame
at the frame origin. Every joint frame therefore follows the previous one by one
modified-DH row, and each branch (base to one end part) has a DH table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from robotwright._rotations import mat_to_quat
from robotwright.errors import GrammarError, Problem
from robotwright.grammar.design import Design, DesignNode
from robotwright.grammar.dh import DHRow, fk, rot_x
from robotwright.grammar.library import Component
from robotwright.grammar.rules import Grammar
from robotwright.hrdf.model import (
    HRDF,
    Actuator,
    Body,
    Joint,
    Meta,
    SimpleGeom,
    Site,
)

# Gripper proportions relative to its finger length; a parallel-jaw hand, drawn simply.
_PALM_FRACTION = 0.4
_FINGER_WIDTH_FRACTION = 0.25
# Gap (m) between the base's top face and a connector housing standing on it.
_CLEARANCE = 0.002


_EYE4 = np.eye(4)


def trans(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    T = _EYE4.copy()
    T[:3, 3] = (x, y, z)
    return T


def mat2quat(R: np.ndarray) -> tuple[float, float, float, float]:
    """Quaternion (w >= 0, so equal rotations give equal text) of a rotation matrix, with
    float noise rounded away."""
    return _clean_floats(mat_to_quat(R))  # type: ignore[return-value]


def _clean(v: np.ndarray) -> np.ndarray:
    """Round away float noise (1e-17) so exported files are stable and readable."""
    return np.where(np.abs(v) < 1e-12, 0.0, np.round(v, 12))


def _clean_floats(v) -> tuple[float, ...]:  # noqa: ANN001 - any iterable of numbers
    """:func:`_clean` on plain floats: numpy's round(x, 12) is rint(x * 1e12) / 1e12,
    which Python's round() to an int (exact below 2**53) followed by the division
    repeats, without numpy's cost on a few values (the search builds thousands)."""
    return tuple([0.0 if abs(x) < 1e-12 else round(x * 1e12) / 1e12 for x in map(float, v)])


def _vec(v: np.ndarray) -> tuple[float, float, float]:
    return _clean_floats(v)  # type: ignore[return-value]


def _rigid_inv(T: np.ndarray) -> np.ndarray:
    """Inverse of a rigid transform (rotation and translation): R^T and -R^T p."""
    out = _EYE4.copy()
    rt = T[:3, :3].T
    out[:3, :3] = rt
    out[:3, 3] = -rt @ T[:3, 3]
    return out


_GEOM_TYPES = {
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    "box": mujoco.mjtGeom.mjGEOM_BOX,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
}


def _quat_mat(quat: tuple[float, float, float, float]) -> np.ndarray:
    """Rotation matrix of a quaternion (w, x, y, z), normalised first."""
    q = np.asarray(quat, dtype=float)
    out = np.zeros(9)
    mujoco.mju_quat2Mat(out, q / np.linalg.norm(q))
    return out.reshape(3, 3)


# Quaternion turning a geom's z axis onto body x (cylinders along a link).
_Z_TO_X = mat2quat(np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]))


@dataclass
class LimbGeom:
    """A primitive geom on a limb body (pose in the body frame, MuJoCo half-sizes)."""

    name: str
    type: str
    size: tuple[float, float, float]
    pos: tuple[float, float, float]
    quat: tuple[float, float, float, float]
    rgba: tuple[float, float, float, float]
    density: float


@dataclass
class LimbJoint:
    """One joint DoF of the limb (pose in its body frame)."""

    name: str
    body: str
    type: str
    pos: tuple[float, float, float]
    axis: tuple[float, float, float]
    range: tuple[float, float]
    peak_torque: float
    peak_velocity: float
    node: int
    #: What the joint's bearing (hinge) or guide (slide) carries besides the motor's
    #: axis: force [N] (a slide's: across its axis) and moment [N m] (a hinge's: about
    #: the axes across its own); ``inf`` where the component gives no rating.
    peak_bearing_force: float = math.inf
    peak_bearing_moment: float = math.inf


@dataclass
class LimbBody:
    """A limb body: its zero-pose frame in the mount frame, parent index, geoms."""

    name: str
    parent: int
    frame: np.ndarray
    node: int
    component: str
    geoms: list[LimbGeom] = field(default_factory=list)


@dataclass
class Branch:
    """One branch from the base to an end part.

    ``base_frame @ fk(rows, q, tool)`` is the tool point in the mount frame for the
    values ``q`` of ``joints`` (in order).
    """

    rows: list[DHRow]
    joints: list[str]
    base_frame: np.ndarray
    tool: np.ndarray
    site: str

    def tool_pose(self, q: np.ndarray) -> np.ndarray:
        """Tool point pose(s) in the mount frame, ``q`` of shape ``(..., n)``."""
        return self.base_frame @ fk(self.rows, q, self.tool)


@dataclass
class Limb:
    """The built kinematic model of a design."""

    name: str
    bodies: list[LimbBody]
    joints: list[LimbJoint]
    sites: list[Site]
    branches: list[Branch]
    design: Design

    @property
    def dof(self) -> int:
        return len(self.joints)

    def joint_ranges(self) -> np.ndarray:
        return np.array([j.range for j in self.joints], dtype=float).reshape(-1, 2)

    def to_spec(self, motors: bool = False) -> mujoco.MjSpec:
        """A bare MjSpec of the limb (fixed base, geoms with densities); used to compute
        mass properties with MuJoCo. User-facing MJCF goes through the generators."""
        spec = mujoco.MjSpec()
        spec.compiler.degree = False
        spec.modelname = self.name
        self.add_to(spec, spec.worldbody, motors=motors)
        return spec

    def add_to(
        self,
        spec: mujoco.MjSpec,
        parent: mujoco.MjsBody,
        pos: tuple[float, float, float] = (0.0, 0.0, 0.0),
        quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0),
        prefix: str = "",
        motors: bool = False,
    ) -> list[str]:
        """Add the limb's bodies, geoms and joints under ``parent`` of ``spec`` (angles
        in radians), its base placed at ``pos``/``quat`` (m; w, x, y, z) in the
        parent's frame, every name prefixed with ``prefix``. With ``motors``, one motor
        per joint with ``ctrlrange`` and joint ``actuatorfrcrange`` +-peak torque (N m,
        or N for a slide), so MuJoCo clips commands to the component's limit.

        Returns:
            The names of the bodies added, in the limb's order.
        """
        made: list = []
        by_body: dict[str, list[LimbJoint]] = {}
        for j in self.joints:
            by_body.setdefault(j.body, []).append(j)
        hinge, slide = mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE
        limited = mujoco.mjtLimited.mjLIMITED_TRUE
        added_joints: list[tuple[str, float]] = []
        for b in self.bodies:
            if b.parent < 0:
                root = b.frame
                base = np.eye(4)
                base[:3, :3] = _quat_mat(quat)
                base[:3, 3] = pos
                rel = base @ root
                into = parent
            else:
                rel = _rigid_inv(self.bodies[b.parent].frame) @ b.frame
                into = made[b.parent]
            body = into.add_body(name=prefix + b.name, pos=rel[:3, 3], quat=mat2quat(rel[:3, :3]))
            for g in b.geoms:
                body.add_geom(
                    name=prefix + g.name,
                    type=_GEOM_TYPES.get(g.type)
                    or getattr(mujoco.mjtGeom, f"mjGEOM_{g.type.upper()}"),
                    size=g.size,
                    pos=g.pos,
                    quat=g.quat,
                    rgba=g.rgba,
                    density=g.density,
                )
            for j in by_body.get(b.name, ()):
                joint = body.add_joint(
                    name=prefix + j.name,
                    type=hinge if j.type == "hinge" else slide,
                    pos=j.pos,
                    axis=j.axis,
                    range=j.range,
                    limited=limited,
                )
                if motors:
                    joint.actfrclimited = limited
                    joint.actfrcrange = (-j.peak_torque, j.peak_torque)
                added_joints.append((prefix + j.name, j.peak_torque))
            made.append(body)
        if motors:
            for name, peak in added_joints:
                act = spec.add_actuator(name=f"{name}_motor", target=name)
                act.trntype = mujoco.mjtTrn.mjTRN_JOINT
                act.ctrllimited = limited
                act.ctrlrange = (-peak, peak)
        return [prefix + b.name for b in self.bodies]

    def mass_properties(self) -> list[dict[str, tuple[float, ...] | float]]:
        """Mass (kg), centre of mass, principal inertia (kg m^2) and its frame per body,
        computed by MuJoCo from the geoms and their densities."""
        model = self.to_spec().compile()
        out = []
        for b in self.bodies:
            i = model.body(b.name).id
            out.append(
                {
                    "mass": float(model.body_mass[i]),
                    "inertial_pos": _vec(model.body_ipos[i]),
                    "inertial_quat": _clean_floats(model.body_iquat[i]),
                    "diag_inertia": _vec(model.body_inertia[i]),
                }
            )
        return out

    def to_hrdf(self) -> HRDF:
        """The limb as an HRDF robot with a fixed base (root body without a free joint)."""
        props = self.mass_properties()
        bodies = []
        for b, p in zip(self.bodies, props):
            rel = b.frame if b.parent < 0 else _rigid_inv(self.bodies[b.parent].frame) @ b.frame
            bodies.append(
                Body(
                    name=b.name,
                    parent=b.parent,
                    pos=_vec(rel[:3, 3]),
                    quat=mat2quat(rel[:3, :3]),
                    mass=p["mass"],  # type: ignore[arg-type]
                    inertial_pos=p["inertial_pos"],  # type: ignore[arg-type]
                    inertial_quat=p["inertial_quat"],  # type: ignore[arg-type]
                    diag_inertia=p["diag_inertia"],  # type: ignore[arg-type]
                )
            )
        joints = [
            Joint(name=j.name, body=j.body, type=j.type, pos=j.pos, axis=j.axis, range=j.range)
            for j in self.joints
        ]
        actuators = [
            Actuator(
                joint=j.name,
                name=f"{j.name}_motor",
                type="motor",
                peak_torque=j.peak_torque,
                peak_velocity=j.peak_velocity,
            )
            for j in self.joints
        ]
        geoms = [
            SimpleGeom(
                body=b.name,
                pos=g.pos,
                quat=g.quat,
                rgba=g.rgba,
                name=g.name,
                geom_name=g.name,
                type=g.type,
                size=g.size,
            )
            for b in self.bodies
            for g in b.geoms
        ]
        meta = Meta()
        meta.extra = {
            "grammar": {"design_hash": self.design.hash(), "design": self.design.to_dict()}
        }
        return HRDF(
            name=self.name,
            bodies=bodies,
            joints=joints,
            actuators=actuators,
            simple_geoms=geoms,
            sites=list(self.sites),
            meta=meta,
        )


class _Builder:
    def __init__(self, grammar: Grammar, prefix: str) -> None:
        self.g = grammar
        self.prefix = prefix
        self.bodies: list[LimbBody] = []
        self.joints: list[LimbJoint] = []
        self.sites: list[Site] = []
        self.branches: list[Branch] = []
        self.counts: dict[str, int] = {}

    def name(self, stem: str) -> str:
        k = self.counts.get(stem, 0)
        self.counts[stem] = k + 1
        return (
            f"{self.prefix}{stem}{k + 1}"
            if stem not in ("base", "mount")
            else (f"{self.prefix}{stem}" if k == 0 else f"{self.prefix}{stem}{k + 1}")
        )

    def comp(self, node: DesignNode) -> Component:
        if node.component is None:
            raise GrammarError(
                [
                    Problem(
                        self.g.source,
                        f"node {node.id} ({node.symbol}) has no component; the design is not complete",
                    )
                ]
            )
        return self.g.library.components[node.component]

    def build(self, root: DesignNode) -> None:
        comp = self.comp(root)
        if comp.kind != "base":
            raise GrammarError(
                [
                    Problem(
                        self.g.library.source,
                        f"the design's root must be a 'base' component, got '{comp.name}' (kind {comp.kind})",
                        element=f"component '{comp.name}'",
                    )
                ]
            )
        p = root.params
        r, t = p["diameter"] / 2, p["thickness"]
        body = LimbBody(self.name("base"), -1, np.eye(4), root.id, comp.name)
        body.geoms.append(
            LimbGeom(
                f"{body.name}_geom",
                "cylinder",
                (r, t / 2, 0.0),
                (0.0, 0.0, t / 2),
                (1.0, 0.0, 0.0, 0.0),
                comp.rgba,
                comp.density,
            )
        )
        self.bodies.append(body)
        for child in root.children:
            # A connector stands on the base's top face: its joint frame is raised so
            # that its housing and the first link clear the base (MuJoCo does not
            # filter contacts between a fixed base and its children).
            standoff = 0.0
            if child.component is not None and self.comp(child).kind == "connector":
                h = self.comp(child).housing
                standoff = max(h["length"], h["diameter"]) / 2 + _CLEARANCE
            base_frame = trans(z=t + standoff)
            self.visit(
                child,
                body_index=0,
                frame=base_frame,
                acc=(0.0, 0.0),
                pending=[],
                rows=[],
                base_frame=base_frame,
            )

    def visit(
        self,
        node: DesignNode,
        body_index: int,
        frame: np.ndarray,
        acc: tuple[float, float],
        pending: list[tuple[DesignNode, Component, int, np.ndarray, DHRow]],
        rows: list[DHRow],
        base_frame: np.ndarray,
    ) -> None:
        """``frame``: current frame (mount coordinates, zero pose); ``acc``: (a, alpha)
        accumulated since the last joint frame; ``pending``: deferred joint DoFs."""
        comp = self.comp(node)
        kind = comp.kind
        if kind == "mount":
            body = self.bodies[body_index]
            rel = _rigid_inv(body.frame) @ frame if body_index else _EYE4.copy()
            self.sites.append(
                Site(
                    name=self.name("mount"),
                    body=body.name,
                    pos=_vec(rel[:3, 3]),
                    quat=mat2quat(rel[:3, :3]),
                    size=(0.01, 0.0, 0.0),
                )
            )
            return
        if kind == "connector":
            pending = list(pending)
            rows = list(rows)
            a, alpha = acc
            for k, dof in enumerate(comp.dofs):
                row = DHRow(a=a, alpha=alpha + dof.twist, d=0.0, theta=0.0, type=dof.type, name="")
                frame = frame @ rot_x(row.alpha) @ trans(x=row.a)
                pending.append((node, comp, k, frame, row))
                rows.append(row)
                a, alpha = 0.0, 0.0
            for child in node.children:
                self.visit(child, body_index, frame, (0.0, 0.0), pending, rows, base_frame)
            return
        # A link or an end part: a body; the deferred joints are added to it now.
        stem = {"link": "link", "gripper": "gripper", "tool": "tool"}[kind]
        if kind != "link" and acc != (0.0, 0.0) or kind == "link" and not pending:
            frame = frame @ rot_x(acc[1]) @ trans(x=acc[0])
            acc = (0.0, 0.0)
        body = LimbBody(self.name(stem), body_index, frame, node.id, comp.name)
        inv = _rigid_inv(frame)
        rows = list(rows)
        for i, (jnode, jcomp, k, jframe, row) in enumerate(pending):
            rel = inv @ jframe
            lo, hi = jcomp.dofs[k].resolve_range(jnode.params)
            jname = self.name("joint")
            rows[len(rows) - len(pending) + i] = DHRow(
                row.a, row.alpha, row.d, row.theta, row.type, jname
            )
            self.joints.append(
                LimbJoint(
                    jname,
                    body.name,
                    jcomp.dofs[k].type,
                    _vec(rel[:3, 3]),
                    _vec(rel[:3, 2]),
                    (lo, hi),
                    jcomp.actuator["peak_torque"],
                    jcomp.actuator["peak_velocity"],
                    jnode.id,
                    jcomp.actuator.get("peak_bearing_force", math.inf),
                    jcomp.actuator.get("peak_bearing_moment", math.inf),
                )
            )
            h = jcomp.housing
            body.geoms.append(
                LimbGeom(
                    f"{jname}_housing",
                    "cylinder",
                    (h["diameter"] / 2, h["length"] / 2, 0.0),
                    _vec(rel[:3, 3]),
                    mat2quat(rel[:3, :3]),
                    jcomp.rgba,
                    jcomp.density,
                )
            )
        p = node.params
        if kind == "link":
            length, r = p["length"], p["diameter"] / 2
            body.geoms.append(
                LimbGeom(
                    f"{body.name}_geom",
                    "cylinder",
                    (r, length / 2, 0.0),
                    (length / 2, 0.0, 0.0),
                    _Z_TO_X,
                    comp.rgba,
                    comp.density,
                )
            )
            self.bodies.append(body)
            idx = len(self.bodies) - 1
            out_acc = (length, p["rotation"])
            for child in node.children:
                self.visit(child, idx, frame, out_acc, [], rows, base_frame)
            if not node.children:
                # A link that ends a branch without an end part still gets a tool point.
                tip = frame @ rot_x(out_acc[1]) @ trans(x=out_acc[0])
                rel = inv @ tip
                site = Site(
                    name=self.name("tip"),
                    body=body.name,
                    pos=_vec(rel[:3, 3]),
                    quat=mat2quat(rel[:3, :3]),
                    size=(0.008, 0.0, 0.0),
                    rgba=(1.0, 0.1, 0.1, 1.0),
                )
                self.sites.append(site)
                self._branch(rows, frame, tip, base_frame, site.name)
            return
        if kind == "gripper":
            f = p["finger_length"]
            palm = _PALM_FRACTION * f
            w = _FINGER_WIDTH_FRACTION * f
            body.geoms.append(
                LimbGeom(
                    f"{body.name}_palm",
                    "box",
                    (palm / 2, 1.5 * w, w / 2),
                    (palm / 2, 0.0, 0.0),
                    (1.0, 0.0, 0.0, 0.0),
                    comp.rgba,
                    comp.density,
                )
            )
            for side, y in (("l", 1.0), ("r", -1.0)):
                body.geoms.append(
                    LimbGeom(
                        f"{body.name}_finger_{side}",
                        "box",
                        (f / 2, w / 4, w / 2),
                        (palm + f / 2, y * 1.25 * w, 0.0),
                        (1.0, 0.0, 0.0, 0.0),
                        comp.rgba,
                        comp.density,
                    )
                )
            tip = palm + f
        else:
            length = p["length"]
            body.geoms.append(
                LimbGeom(
                    f"{body.name}_geom",
                    "cylinder",
                    (0.01, length / 2, 0.0),
                    (length / 2, 0.0, 0.0),
                    _Z_TO_X,
                    comp.rgba,
                    comp.density,
                )
            )
            tip = length
        self.bodies.append(body)
        site = Site(
            name=self.name("tcp"),
            body=body.name,
            pos=(tip, 0.0, 0.0),
            size=(0.008, 0.0, 0.0),
            rgba=(1.0, 0.1, 0.1, 1.0),
        )
        self.sites.append(site)
        self._branch(rows, frame, frame @ trans(x=tip), base_frame, site.name)

    def _branch(
        self,
        rows: list[DHRow],
        last_frame: np.ndarray,
        tip: np.ndarray,
        base_frame: np.ndarray,
        site: str,
    ) -> None:
        # last_frame is the last joint frame when the body directly follows joints;
        # the tool transform is taken from the frame fk() ends in.
        n = len(rows)
        end = base_frame @ fk(rows, np.zeros(n)) if n else base_frame
        tool = _rigid_inv(end) @ tip
        self.branches.append(
            Branch(list(rows), [r.name for r in rows], base_frame, _clean(tool), site)
        )


def build(
    grammar: Grammar, design: Design | DesignNode, *, name: str = "srl", prefix: str = ""
) -> Limb:
    """Build a design (checked against the grammar) into a :class:`Limb`.

    Args:
        grammar: the grammar and library the design was derived in.
        design: a complete design, or its replayed tree.
        name: robot name of the limb.
        prefix: prefix for every body, joint, geom and site name (to mount several).
    """
    from robotwright.grammar.derive import replay

    if isinstance(design, Design):
        root = replay(grammar, design)
        d = design
    else:
        root, d = design, Design(grammar.name, ())
    b = _Builder(grammar, prefix)
    b.build(root)
    return Limb(name, b.bodies, b.joints, b.sites, b.branches, d)


def build_hrdf(grammar: Grammar, design: Design, *, name: str = "srl", prefix: str = "") -> HRDF:
    """Build a design straight into an HRDF robot (fixed base at the mount frame)."""
    return build(grammar, design, name=name, prefix=prefix).to_hrdf()
