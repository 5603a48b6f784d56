"""Kinematic and inertial views of a robot for fidelity checks.

A :class:`RobotView` answers, for one robot, the questions the round-trip table asks:
body names and masses, world-frame inertia at the reference configuration, joints
(type, axis, range), and forward kinematics at a given joint configuration. Views are
built from a compiled ``mujoco.MjModel`` (the source compiled by MuJoCo, or our output
compiled) or from a URDF through ``yourdfpy`` (an independent kinematics library, used
when MuJoCo cannot import the source).

Frames: every pose is in the frame of the robot's root (MuJoCo world = URDF root link).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from robotwright.parsers.packages import UnresolvedMesh, resolve_uri
from robotwright.parsers.xmlsafe import parse_xml

_MJ_JOINT = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}
#: Actuator transmission type -> MuJoCo object type of its target.
_TRN_OBJ = {
    0: mujoco.mjtObj.mjOBJ_JOINT,
    1: mujoco.mjtObj.mjOBJ_JOINT,
    3: mujoco.mjtObj.mjOBJ_TENDON,
    4: mujoco.mjtObj.mjOBJ_SITE,
    5: mujoco.mjtObj.mjOBJ_BODY,
}


@dataclass
class JointInfo:
    """A 1-DoF or multi-DoF joint: type, axis in its body frame, range or None, and (for
    MuJoCo views) its dynamics: armature, damping, frictionloss, stiffness, springref and
    qpos0 of its first degree of freedom."""

    name: str
    type: str
    body: str
    axis: np.ndarray
    range: tuple[float, float] | None
    dynamics: np.ndarray | None = None


@dataclass
class RobotView:
    """What the fidelity table compares (see the module docstring).

    Attributes:
        kind: where the view comes from (``"mujoco"``, ``"yourdfpy"``).
        bodies: body names in model order (world excluded).
        mass: body name -> mass (kg).
        inertia_world: body name -> (com in world (m), inertia tensor about the com in
            world axes (kg m^2)) at the zero configuration.
        joints: moving joints in model order.
        sites: site names.
        fk: callable ``q -> {name: (pos, rot)}`` for bodies and sites, ``q`` a dict of
            joint name -> value (rad or m; free/ball joints take quaternion arrays).
        actuators: list of dicts (name, type, joint, gains, ranges), MuJoCo views only.
        sensors: list of (name, type, object name), MuJoCo views only.
    """

    kind: str
    bodies: list[str]
    mass: dict[str, float]
    inertia_world: dict[str, tuple[np.ndarray, np.ndarray]]
    joints: list[JointInfo]
    sites: list[str]
    fk: object
    actuators: list[dict] = field(default_factory=list)
    sensors: list[tuple[str, str, str]] = field(default_factory=list)
    site_body: dict[str, str] = field(default_factory=dict)
    model: mujoco.MjModel | None = None


def body_name(model: mujoco.MjModel, i: int) -> str:
    """A body's name, or ``body_<id>`` for an unnamed one (as the MJCF parser names it)."""
    return model.body(i).name or f"body_{i}"


def joint_name(model: mujoco.MjModel, i: int) -> str:
    return model.joint(i).name or f"joint_{i}"


def _actuator_type(model: mujoco.MjModel, i: int) -> str:
    bias = model.actuator_biasprm[i]
    gain = model.actuator_gainprm[i]
    if model.actuator_biastype[i] == 0 and model.actuator_gaintype[i] == 0:
        return "motor" if gain[0] == 1.0 else "motor(gain)"
    if model.actuator_biastype[i] == 1 and bias[1] == -gain[0] and bias[1] != 0:
        return "position"
    if model.actuator_biastype[i] == 1 and bias[1] == 0 and bias[2] == -gain[0]:
        return "velocity"
    return "general"


def view_from_model(
    model: mujoco.MjModel, kind: str = "mujoco", root: str | None = None
) -> RobotView:
    """A view of a compiled MuJoCo model; with ``root`` (a top-level body name), only that
    body's subtree and the joints, sites, actuators and sensors on it. Without it, the
    only top-level body's subtree (world sites and geoms are scene, not robot)."""
    view = _view_from_model(model, kind)
    top = [i for i in range(1, model.nbody) if model.body_parentid[i] == 0]
    if root is None and len(top) != 1:
        return view
    rid = top[0] if root is None else model.body(root).id
    keep = {body_name(model, i) for i in range(1, model.nbody) if model.body_rootid[i] == rid}
    view.bodies = [b for b in view.bodies if b in keep]
    view.mass = {k: v for k, v in view.mass.items() if k in keep}
    view.inertia_world = {k: v for k, v in view.inertia_world.items() if k in keep}
    view.joints = [j for j in view.joints if j.body in keep]
    view.sites = [s for s in view.sites if view.site_body[s] in keep]
    jn = {j.name for j in view.joints}
    # Actuators on other transmissions (tendons, sites) stay: dropping them is a loss.
    view.actuators = [a for a in view.actuators if a["joint"] is None or a["joint"] in jn]
    return view


def _view_from_model(model: mujoco.MjModel, kind: str = "mujoco") -> RobotView:
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    bodies = [body_name(model, i) for i in range(1, model.nbody)]
    mass = {body_name(model, i): float(model.body_mass[i]) for i in range(1, model.nbody)}
    inertia = {}
    for i in range(1, model.nbody):
        rot = data.ximat[i].reshape(3, 3)
        inertia[body_name(model, i)] = (
            data.xipos[i].copy(),
            rot @ np.diag(model.body_inertia[i]) @ rot.T,
        )
    joints = []
    for i in range(model.njnt):
        t = _MJ_JOINT[int(model.jnt_type[i])]
        joints.append(
            JointInfo(
                joint_name(model, i),
                t,
                body_name(model, int(model.jnt_bodyid[i])),
                model.jnt_axis[i].copy(),
                tuple(model.jnt_range[i]) if model.jnt_limited[i] else None,
                np.array(
                    [
                        model.dof_armature[model.jnt_dofadr[i]],
                        model.dof_damping[model.jnt_dofadr[i]],
                        model.dof_frictionloss[model.jnt_dofadr[i]],
                        model.jnt_stiffness[i],
                        model.qpos_spring[model.jnt_qposadr[i]],
                        model.qpos0[model.jnt_qposadr[i]],
                    ]
                ),
            )
        )
    sites = [model.site(i).name or f"site_{i}" for i in range(model.nsite)]
    adr = {joint_name(model, i): int(model.jnt_qposadr[i]) for i in range(model.njnt)}

    def fk(q: dict[str, np.ndarray | float]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        data.qpos[:] = model.qpos0
        for name, value in q.items():
            a = adr[name]
            v = np.atleast_1d(np.asarray(value, dtype=float))
            data.qpos[a : a + v.size] = v
        mujoco.mj_kinematics(model, data)
        out = {
            body_name(model, i): (data.xpos[i].copy(), data.xmat[i].reshape(3, 3).copy())
            for i in range(1, model.nbody)
        }
        for i, s in enumerate(sites):
            out.setdefault(s, (data.site_xpos[i].copy(), data.site_xmat[i].reshape(3, 3).copy()))
        return out

    actuators = []
    for i in range(model.nu):
        jid = int(model.actuator_trnid[i, 0])
        actuators.append(
            {
                "name": model.actuator(i).name,
                "type": _actuator_type(model, i),
                "joint": joint_name(model, jid) if model.actuator_trntype[i] == 0 else None,
                "kinds": (
                    int(model.actuator_trntype[i]),
                    int(model.actuator_dyntype[i]),
                    int(model.actuator_gaintype[i]),
                    int(model.actuator_biastype[i]),
                    int(model.actuator_group[i]),
                    _obj_name(model, _TRN_OBJ.get(int(model.actuator_trntype[i]), 0), jid),
                ),
                "gear": model.actuator_gear[i].copy(),
                "gainprm": model.actuator_gainprm[i].copy(),
                "biasprm": model.actuator_biasprm[i].copy(),
                "dynprm": model.actuator_dynprm[i].copy(),
                "actrange": model.actuator_actrange[i].copy()
                if model.actuator_actlimited[i]
                else None,
                "ctrlrange": model.actuator_ctrlrange[i].copy()
                if model.actuator_ctrllimited[i]
                else None,
                "forcerange": model.actuator_forcerange[i].copy()
                if model.actuator_forcelimited[i]
                else None,
            }
        )
    sensors = []
    for i in range(model.nsensor):
        sensors.append(
            (
                model.sensor(i).name,
                str(mujoco.mjtSensor(int(model.sensor_type[i]))),
                _obj_name(model, int(model.sensor_objtype[i]), int(model.sensor_objid[i])),
            )
        )
    site_body = {s: body_name(model, int(model.site_bodyid[i])) for i, s in enumerate(sites)}
    return RobotView(
        kind, bodies, mass, inertia, joints, sites, fk, actuators, sensors, site_body, model
    )


def _obj_name(model: mujoco.MjModel, objtype: int, objid: int) -> str:
    if objid < 0:
        return ""
    name = mujoco.mj_id2name(model, objtype, objid)
    return name or f"#{objid}"


# -- URDF references ----------------------------------------------------------------------
def urdf_for_mujoco(
    path: Path,
    package_map=None,
    *,
    balance_inertia: bool = False,
    bound_mass=None,
    bound_inertia=None,
) -> str:
    """The URDF text with mesh URIs made absolute and a ``<mujoco><compiler>`` block that
    keeps every link a body (``fusestatic="false"``), takes inertia only from
    ``<inertial>`` (``inertiafromgeom="false"``) and drops visual geoms."""
    root = parse_xml(path)
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename")
        if uri:
            try:
                resolved = resolve_uri(uri, path, package_map, Path("/"))
            except UnresolvedMesh:
                continue  # left as written: MuJoCo's own error then names the file
            mesh.set("filename", str(resolved))
    for old in root.findall("mujoco"):
        root.remove(old)
    mj = ET.SubElement(root, "mujoco")
    attrs = {
        "fusestatic": "false",
        "discardvisual": "true",
        "inertiafromgeom": "false",
        "strippath": "false",
        "balanceinertia": "true" if balance_inertia else "false",
    }
    if bound_mass is not None:
        attrs["boundmass"] = repr(float(bound_mass))
    if bound_inertia is not None:
        attrs["boundinertia"] = repr(float(bound_inertia))
    ET.SubElement(mj, "compiler", attrs)
    return ET.tostring(root, encoding="unicode")


def urdf_mujoco_view(path: Path, package_map=None, **compiler) -> RobotView:
    """MuJoCo's own URDF import of ``path`` (raises ValueError when MuJoCo refuses it)."""
    text = urdf_for_mujoco(path, package_map, **compiler)
    return view_from_model(mujoco.MjModel.from_xml_string(text), "mujoco")


def _repair(
    mass: float, tensor: np.ndarray, balance_inertia: bool, bound_mass, bound_inertia
) -> tuple[float, np.ndarray]:
    """MuJoCo's compiler repairs (balanceinertia, boundmass, boundinertia) applied to one
    body's mass and tensor: moments are frame-invariant, so any frame works."""
    if not (balance_inertia or bound_mass is not None or bound_inertia is not None):
        return mass, tensor
    values, vectors = np.linalg.eigh(tensor)
    if balance_inertia and mass > 0 and values.min() > 0:
        a, b, c = values
        if a + b < c or a + c < b or b + c < a:
            values = np.full(3, values.mean())
    if bound_mass is not None:
        mass = max(mass, float(bound_mass))
    if bound_inertia is not None:
        values = np.maximum(values, float(bound_inertia))
    return mass, vectors @ np.diag(values) @ vectors.T


def urdf_yourdfpy_view(
    path: Path,
    *,
    balance_inertia: bool = False,
    bound_mass: float | None = None,
    bound_inertia: float | None = None,
) -> RobotView:
    """An independent reference: ``yourdfpy`` kinematics and the URDF's inertials (with
    the same repairs as the parser options, when given)."""
    import yourdfpy

    robot = yourdfpy.URDF.load(
        str(path),
        load_meshes=False,
        load_collision_meshes=False,
        build_scene_graph=True,
        build_collision_scene_graph=False,
        filename_handler=lambda fname: fname,
    )
    base = robot.base_link
    # MuJoCo's convention: a URDF root link called "world" is the world itself.
    links = [n for n in robot.link_map if n != "world" or base != "world"]
    mass, inertia = {}, {}
    robot.update_cfg(np.zeros(len(robot.actuated_joint_names)))
    for n in links:
        link = robot.link_map[n]
        tf = robot.get_transform(n, base)
        if link.inertial is None:
            mass[n] = 0.0
            inertia[n] = (tf[:3, 3].copy(), np.zeros((3, 3)))
            continue
        origin = link.inertial.origin if link.inertial.origin is not None else np.eye(4)
        world = tf @ origin
        rot = world[:3, :3]
        mass[n] = float(link.inertial.mass or 0.0)
        inertia[n] = (world[:3, 3].copy(), rot @ np.asarray(link.inertial.inertia) @ rot.T)
    for n in links:
        m, t = _repair(mass[n], inertia[n][1], balance_inertia, bound_mass, bound_inertia)
        mass[n], inertia[n] = m, (inertia[n][0], t)
    joints = []
    for jn, j in robot.joint_map.items():
        if j.type in ("fixed",):
            continue
        t = {
            "revolute": "hinge",
            "continuous": "hinge",
            "prismatic": "slide",
            "floating": "free",
        }.get(j.type, j.type)
        rng = None
        if (
            j.type in ("revolute", "prismatic")
            and j.limit is not None
            and j.limit.lower is not None
        ):
            rng = (float(j.limit.lower), float(j.limit.upper))
        axis = np.asarray(j.axis if j.axis is not None else (1, 0, 0), dtype=float)
        joints.append(JointInfo(jn, t, j.child, axis / np.linalg.norm(axis), rng))
    actuated = list(robot.actuated_joint_names)

    def fk(q: dict[str, float]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        robot.update_cfg(np.array([float(q.get(n, 0.0)) for n in actuated]))
        out = {}
        for n in links:
            tf = robot.get_transform(n, base)
            out[n] = (tf[:3, 3].copy(), tf[:3, :3].copy())
        return out

    return RobotView("yourdfpy", links, mass, inertia, joints, [], fk)


def mimic_map(path: Path) -> dict[str, tuple[str, float, float]]:
    """URDF mimic joints: name -> (mimicked joint, multiplier, offset)."""
    out = {}
    if path.suffix.lower() != ".urdf":
        return out
    for j in parse_xml(path).findall("joint"):
        m = j.find("mimic")
        if m is not None:
            out[j.get("name")] = (
                m.get("joint"),
                float(m.get("multiplier", "1")),
                float(m.get("offset", "0")),
            )
    return out


def quat_angle(r1: np.ndarray, r2: np.ndarray) -> float:
    """Rotation angle (rad) between two rotation matrices."""
    c = (np.trace(r1.T @ r2) - 1.0) / 2.0
    # acos loses precision near 1; use the skew part for small angles
    s = (
        np.linalg.norm(
            np.array(
                [
                    (r1.T @ r2)[2, 1] - (r1.T @ r2)[1, 2],
                    (r1.T @ r2)[0, 2] - (r1.T @ r2)[2, 0],
                    (r1.T @ r2)[1, 0] - (r1.T @ r2)[0, 1],
                ]
            )
        )
        / 2.0
    )
    return float(np.arctan2(s, c))
