"""A robot as the round trip compares it: a :class:`RobotView` of a compiled ``MjModel``
(bodies, joints, actuators and the rest by name), whatever file it came from."""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np

from robotwright._mjmodel import actuator_count

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
    # ``root`` as the parsers name it: an unnamed top-level body is 'body_<id>'.
    rid = top[0] if root is None else next(i for i in top if body_name(model, i) == root)
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
        # Names looked up once (``bodies``), not per call: a model accessor per body per
        # configuration dominated round trips of large robots.
        xpos, xmat = data.xpos.copy(), data.xmat.reshape(-1, 3, 3).copy()
        out = {name: (xpos[i], xmat[i]) for i, name in enumerate(bodies, start=1)}
        for i, s in enumerate(sites):
            out.setdefault(s, (data.site_xpos[i].copy(), data.site_xmat[i].reshape(3, 3).copy()))
        return out

    actuators = []
    for i in range(actuator_count(model)):
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
