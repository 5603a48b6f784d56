"""The MJCF reader's kinematic tree: which top-level body is the robot, its bodies and
joints, its sites (frames included), its sensors and keyframes."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np

from robotwright._mjmodel import actuator_count
from robotwright.errors import ConversionError, Problem
from robotwright.hrdf.model import (
    SENSOR_OBJTYPES,
    WORLD,
    Body,
    Joint,
    Sensor,
    Site,
)
from robotwright.parsers import inertia as inr
from robotwright.parsers.mjcf.common import (
    MJCFOptions,
    _differs,
    _five,
    _fmt,
    _pair,
    _reparent,
    _t3,
    _t4,
    _user,
)
from robotwright.parsers.reference import body_name, joint_name
from robotwright.parsers.report import Reporter

_JOINT = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}

_SITE = {2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box"}

_OBJ = {
    mujoco.mjtObj.mjOBJ_BODY: "body",
    mujoco.mjtObj.mjOBJ_XBODY: "xbody",
    mujoco.mjtObj.mjOBJ_JOINT: "joint",
    mujoco.mjtObj.mjOBJ_GEOM: "geom",
    mujoco.mjtObj.mjOBJ_SITE: "site",
    mujoco.mjtObj.mjOBJ_CAMERA: "camera",
    mujoco.mjtObj.mjOBJ_ACTUATOR: "actuator",
    mujoco.mjtObj.mjOBJ_TENDON: "tendon",
}

#: MJCF element names that differ from MuJoCo's sensor enum names (mjSENS_*).
_SENSOR_ELEMENT = {"jointactfrc": "jointactuatorfrc", "tendonactfrc": "tendonactuatorfrc"}

#: Joint fields HRDF has no column for: (MJCF attribute, model array, per-dof?).
_JOINT_UNHELD = (
    ("group", "jnt_group", False),
    ("stiffnesspoly", "jnt_stiffnesspoly", False),
    ("springyield", "jnt_springyield", False),
    ("dampingpoly", "dof_dampingpoly", True),
)


def _keyframes(
    model: mujoco.MjModel, keep: list[int], actuators: list[int], rep: Reporter
) -> ET.Element:
    """``<keyframe>`` rebuilt from the compiled model, restricted to the robot: the qpos
    and qvel of its joints and the ctrl/act of its actuators, in model order."""
    kept = set(keep)
    qpos_idx: list[int] = []
    dof_idx: list[int] = []
    for j in range(model.njnt):
        if int(model.jnt_bodyid[j]) in kept:
            nq = {0: 7, 1: 4}.get(int(model.jnt_type[j]), 1)
            nv = {0: 6, 1: 3}.get(int(model.jnt_type[j]), 1)
            qpos_idx += range(int(model.jnt_qposadr[j]), int(model.jnt_qposadr[j]) + nq)
            dof_idx += range(int(model.jnt_dofadr[j]), int(model.jnt_dofadr[j]) + nv)
    act_idx: list[int] = []
    for i in actuators:
        adr, num = int(model.actuator_actadr[i]), int(model.actuator_actnum[i])
        if adr >= 0:
            act_idx += range(adr, adr + num)
    if len(qpos_idx) != model.nq or len(actuators) != actuator_count(model):
        rep.warn("keyframes restricted to the robot's joints and actuators (the rest dropped)")
    section = ET.Element("keyframe")
    for k in range(model.nkey):
        attrs = {}
        if model.key(k).name:
            attrs["name"] = model.key(k).name
        attrs["time"] = repr(float(model.key_time[k]))
        attrs["qpos"] = _fmt(model.key_qpos[k][qpos_idx])
        attrs["qvel"] = _fmt(model.key_qvel[k][dof_idx])
        if act_idx:
            attrs["act"] = _fmt(model.key_act[k][act_idx])
        if actuators:
            attrs["ctrl"] = _fmt(model.key_ctrl[k][actuators])
        if model.nmocap:
            rep.warn("keyframe mocap poses dropped", f"keyframe {k}")
        ET.SubElement(section, "key", attrs)
    return section


def _select_robot(
    model: mujoco.MjModel, path: Path, opt: MJCFOptions, rep: Reporter
) -> tuple[list[int], list[int]]:
    """The root body ids and the body ids they hold (model order): the subtree of
    ``root_body`` when one is named, else every top-level body of the world (a scene:
    a robot and its objects, or several robots, each a root of the HRDF)."""
    top = [i for i in range(1, model.nbody) if model.body_parentid[i] == 0]
    if opt.root_body is not None:
        # By the name the refusal lists: an unnamed body is 'body_<id>'.
        ids = [i for i in top if body_name(model, i) == opt.root_body]
        if not ids:
            names = [body_name(model, i) for i in top]
            raise ConversionError(
                [Problem(str(path), f"root_body '{opt.root_body}' is not a top-level body {names}")]
            )
        roots = ids[:1]
    elif not top:
        raise ConversionError(
            [Problem(str(path), "the world holds no bodies: no robot to convert")]
        )
    else:
        roots = top
    for i in top:
        if i not in roots:
            rep.warn(
                f"top-level body '{body_name(model, i)}' and its subtree dropped (not the "
                "robot: root_body names another)"
            )
    chosen = set(roots)
    keep = [i for i in range(1, model.nbody) if int(model.body_rootid[i]) in chosen]
    return roots, keep


def _named_bodies(model: mujoco.MjModel) -> set[int]:
    """Bodies other elements refer to (sensors, actuators, equality, excludes)."""
    out: set[int] = set()
    # Plain ints: a numpy integer read from a model is never ``in`` a tuple of MuJoCo's
    # enum members (the members' own comparison refuses it).
    body_types = (int(mujoco.mjtObj.mjOBJ_BODY), int(mujoco.mjtObj.mjOBJ_XBODY))
    for s in range(model.nsensor):
        if int(model.sensor_objtype[s]) in body_types:
            out.add(int(model.sensor_objid[s]))
        if int(model.sensor_reftype[s]) in body_types:
            out.add(int(model.sensor_refid[s]))
    for a in range(actuator_count(model)):
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_BODY:
            out.add(int(model.actuator_trnid[a, 0]))
    for e in range(model.neq):
        if int(model.eq_type[e]) in (
            int(mujoco.mjtEq.mjEQ_CONNECT),
            int(mujoco.mjtEq.mjEQ_WELD),
        ) and (model.eq_objtype[e] != mujoco.mjtObj.mjOBJ_SITE):
            out.update((int(model.eq_obj1id[e]), int(model.eq_obj2id[e])))
    for sig in model.exclude_signature:
        out.update((int(sig) >> 16, int(sig) & 0xFFFF))
    return out


def _frames_as_sites(
    model: mujoco.MjModel, keep: list[int], roots: list[int], opt: MJCFOptions
) -> set[int]:
    """Bodies that become sites under ``massless_frames="site"``."""
    if opt.massless_frames != "site":
        return set()
    parents = {int(model.body_parentid[b]) for b in keep if b not in roots}
    named = _named_bodies(model)
    return {
        b
        for b in keep
        if b not in roots
        and model.body_mass[b] == 0
        and model.body_jntnum[b] == 0
        and b not in parents
        and b not in named
    }


def _bodies(
    model: mujoco.MjModel, keep: list[int], roots: list[int], frames: set[int], rep: Reporter
) -> list[Body]:
    """Body records, frames and inertias as compiled (``frames`` are left out)."""
    bodies_ids = [b for b in keep if b not in frames]
    index = {b: k for k, b in enumerate(bodies_ids)}
    bodies: list[Body] = []
    for b in bodies_ids:
        if model.body_mocapid[b] >= 0:
            rep.warn("mocap flag dropped", f'<body name="{body_name(model, b)}">')
        if not model.body(b).name:
            rep.warn(f"unnamed body named '{body_name(model, b)}'", f"body #{b}", cosmetic=True)
        bodies.append(
            Body(
                name=body_name(model, b),
                parent=-1 if b in roots else index[int(model.body_parentid[b])],
                pos=_t3(model.body_pos[b]),
                quat=_t4(model.body_quat[b]),
                mass=float(model.body_mass[b]),
                inertial_pos=_t3(model.body_ipos[b]),
                inertial_quat=_t4(model.body_iquat[b]),
                diag_inertia=_t3(model.body_inertia[b]),
                gravcomp=float(model.body_gravcomp[b]),
                user=_user(model.body_user[b]),
            )
        )

    return bodies


def _joints(
    model: mujoco.MjModel, kept: set[int], roots: list[int], path: Path, rep: Reporter
) -> list[Joint]:
    """Joint records; fields HRDF has no column for are reported once per field."""
    joints: list[Joint] = []
    unheld_joint: dict[str, list[str]] = {}
    for j in range(model.njnt):
        b = int(model.jnt_bodyid[j])
        if b not in kept:
            continue
        jt = _JOINT[int(model.jnt_type[j])]
        name = model.joint(j).name or None
        where = f'<joint name="{name}">' if name else f"joint #{j}"
        if jt == "free" and b not in roots:
            raise ConversionError(
                [
                    Problem(
                        str(path),
                        "free joint below a root: HRDF allows one on a root body only",
                        element=where,
                    )
                ]
            )
        if name is None:
            # The free joint too: our MJCF and URDF then name it alike (URDF needs a name).
            name = joint_name(model, j)
            rep.warn(f"unnamed joint named '{name}'", where, cosmetic=True)
        if not model.jnt_limited[j] and np.any(model.jnt_range[j]):
            # MuJoCo ignores the range of an unlimited joint (a free joint's always):
            # harmless, but said.
            rep.warn(
                f"range {model.jnt_range[j].tolist()} of an unlimited joint dropped "
                "(MuJoCo ignores it)",
                where,
            )
        dof = int(model.jnt_dofadr[j])
        qadr = int(model.jnt_qposadr[j])
        for attr, field_name, per_dof in _JOINT_UNHELD:
            if _differs(model, field_name, dof if per_dof else j):
                unheld_joint.setdefault(attr, []).append(name or joint_name(model, j))
        if jt in ("hinge", "slide"):
            springref = float(model.qpos_spring[qadr])
            ref = float(model.qpos0[qadr])
        else:
            springref = ref = 0.0
        joints.append(
            Joint(
                name=name,
                body=body_name(model, b),
                type=jt,
                pos=_t3(model.jnt_pos[j]) if jt != "free" else (0.0, 0.0, 0.0),
                axis=_t3(model.jnt_axis[j]),
                range=(float(model.jnt_range[j, 0]), float(model.jnt_range[j, 1]))
                if model.jnt_limited[j]
                else None,
                armature=float(model.dof_armature[dof]),
                dynamic_friction=float(model.dof_frictionloss[dof]),
                viscous_friction=float(model.dof_damping[dof]),
                stiffness=float(model.jnt_stiffness[j]),
                springref=springref,
                ref=ref,
                margin=float(model.jnt_margin[j]),
                actuatorfrcrange=_pair(model.jnt_actfrcrange[j])
                if model.jnt_actfrclimited[j]
                else None,
                actuatorgravcomp=bool(model.jnt_actgravcomp[j]),
                solreflimit=_pair(model.jnt_solref[j]),
                solimplimit=_five(model.jnt_solimp[j]),
                solreffriction=_pair(model.dof_solref[dof]),
                solimpfriction=_five(model.dof_solimp[dof]),
                user=_user(model.jnt_user[j]),
            )
        )

    for attr, jnames in unheld_joint.items():
        rep.warn(f"joint attribute '{attr}' dropped (no HRDF column) on joints {jnames}")
    return joints


def _routing_sites(model: mujoco.MjModel) -> set[int]:
    """Sites that tendons (path points, side sites) and actuators (site transmission,
    reference site) go through."""
    out: set[int] = set()
    for w in range(model.nwrap):
        if model.wrap_type[w] == mujoco.mjtWrap.mjWRAP_SITE:
            out.add(int(model.wrap_objid[w]))
        elif int(model.wrap_type[w]) in (
            int(mujoco.mjtWrap.mjWRAP_SPHERE),
            int(mujoco.mjtWrap.mjWRAP_CYLINDER),
        ):
            side = int(model.wrap_prm[w])
            if side >= 0:
                out.add(side)
    for a in range(actuator_count(model)):
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_SITE:
            out.update(int(x) for x in model.actuator_trnid[a] if x >= 0)
    return out


def _sites(
    model: mujoco.MjModel, kept: set[int], frames: set[int], roots: list[int], rep: Reporter
) -> list[Site]:
    """Sites of the robot's bodies, and one per frame body turned into a site. A site of
    the world (an IMU frame, a muscle origin) stays a site of the world (``body`` is
    ``"world"``), except one a tendon or actuator goes through when the root is fixed to
    the world: that one is kept on the root body (the same place, as it never moves)."""
    sites: list[Site] = []
    routing = _routing_sites(model) if model.site_bodyid.size else set()
    root_id = roots[0]
    fixed_root = int(model.body_jntnum[root_id]) == 0 and model.body_parentid[root_id] == 0
    for s in range(model.nsite):
        b = int(model.site_bodyid[s])
        sname = model.site(s).name or f"site_{s}"
        if b == 0 and s in routing and fixed_root:
            # World frame -> root frame: p' = R^T (p - p_root), q' = q_root^-1 q.
            rq = model.body_quat[root_id]
            inv = np.array([rq[0], -rq[1], -rq[2], -rq[3]])
            rot = inr.quat_to_mat(rq)
            pos = _t3(rot.T @ (model.site_pos[s] - model.body_pos[root_id]))
            quat = _t4(inr.mul_quat(inv, model.site_quat[s]))
            rep.warn(
                f"site of the world kept on the root body '{body_name(model, root_id)}' (a "
                "tendon or actuator goes through it; the root is fixed, so it is the same "
                "place)",
                f'<site name="{sname}">',
            )
            b, site_pos, site_quat = root_id, pos, quat
        elif b == 0:  # fixed in the world (an IMU frame, a muscle origin): carried so
            site_pos, site_quat = model.site_pos[s], model.site_quat[s]
        elif b not in kept:
            rep.warn("site outside the robot dropped", f'<site name="{sname}">')
            continue
        else:
            site_pos, site_quat = model.site_pos[s], model.site_quat[s]
        if not model.site(s).name:
            rep.warn(f"unnamed site named '{sname}'", f"site #{s}", cosmetic=True)
        owner, pos, quat = (
            (0, _t3(site_pos), _t4(site_quat))
            if b == 0
            else _reparent(model, b, site_pos, site_quat, frames)
        )
        sites.append(
            Site(
                name=sname,
                body=WORLD if owner == 0 else body_name(model, owner),
                pos=pos,
                quat=quat,
                type=_SITE.get(int(model.site_type[s]), "sphere"),
                size=_t3(model.site_size[s]),
                rgba=_t4(np.clip(model.site_rgba[s], 0.0, 1.0)),
                group=int(model.site_group[s]),
                user=_user(model.site_user[s]),
            )
        )

    for b in sorted(frames):
        rep.warn(
            "massless frame body turned into a site on its parent (massless_frames='site')",
            f'<body name="{body_name(model, b)}">',
        )
        sites.append(
            Site(
                name=body_name(model, b),
                body=body_name(model, int(model.body_parentid[b])),
                pos=_t3(model.body_pos[b]),
                quat=_t4(model.body_quat[b]),
            )
        )
    return sites


def _sensors(
    model: mujoco.MjModel,
    kept_names: dict[str, set[str]],
    rep: Reporter,
    in_extra: dict[str, set[str]] | None = None,
) -> tuple[list[Sensor], list[ET.Element]]:
    """Sensor records; from the first sensor naming the world body on, ``<sensor>``
    elements for ``mjcf_extra`` (order kept)."""
    sensors: list[Sensor] = []
    extra_sensors: list[ET.Element] = []
    for s in range(model.nsensor):
        sname = model.sensor(s).name or f"sensor_{s}"
        stype = mujoco.mjtSensor(int(model.sensor_type[s])).name[len("mjSENS_") :].lower()
        stype = _SENSOR_ELEMENT.get(stype, stype)
        objtype = _OBJ.get(int(model.sensor_objtype[s]))
        where = f'<{stype} name="{sname}">'
        if objtype is None or objtype not in SENSOR_OBJTYPES.get(stype, ()):
            rep.warn("sensor dropped (its type or object type has no HRDF equivalent)", where)
            continue
        if not model.sensor(s).name:
            rep.warn(f"unnamed sensor named '{sname}'", where, cosmetic=True)
        oname = mujoco.mj_id2name(model, int(model.sensor_objtype[s]), int(model.sensor_objid[s]))
        reftype = refname = None
        if model.sensor_refid[s] >= 0:
            reftype = _OBJ.get(int(model.sensor_reftype[s]))
            refname = mujoco.mj_id2name(
                model, int(model.sensor_reftype[s]), int(model.sensor_refid[s])
            )
        oname = oname or ""
        refs = [(objtype, oname)] + ([(reftype, refname)] if reftype else [])
        lost = [f"{t} '{n}'" for t, n in refs if t in kept_names and n not in kept_names[t]]
        # A sensor of an object carried in mjcf_extra (an actuatorfrc of a <general>
        # actuator) goes with it: the sensor table names table objects only.
        moved = [n for t, n in refs if n in (in_extra or {}).get(t or "", set())]
        if extra_sensors or lost or moved:
            if any("'world'" not in x for x in lost):
                rep.warn(f"sensor dropped: it reads {lost} outside the robot", where)
                continue
            # The sensor table cannot name MuJoCo's world body: carry this sensor (and,
            # to keep sensor order, every later one) in mjcf_extra.
            attrs = {"name": sname}
            if stype.startswith("frame"):
                attrs |= {"objtype": objtype, "objname": oname}
                if reftype:
                    attrs |= {"reftype": reftype, "refname": refname}
            else:
                attrs[objtype] = oname
            if model.sensor_noise[s]:
                attrs["noise"] = repr(float(model.sensor_noise[s]))
            if model.sensor_cutoff[s]:
                attrs["cutoff"] = repr(float(model.sensor_cutoff[s]))
            if _user(model.sensor_user[s]):
                attrs["user"] = _fmt(_user(model.sensor_user[s]))
            extra_sensors.append(ET.Element(stype, attrs))
            continue
        sensors.append(
            Sensor(
                name=sname,
                type=stype,
                objtype=objtype,
                objname=oname,
                reftype=reftype,
                refname=refname,
                noise=float(model.sensor_noise[s]),
                cutoff=float(model.sensor_cutoff[s]),
                user=_user(model.sensor_user[s]),
            )
        )

    return sensors, extra_sensors
