"""MJCF -> HRDF through MuJoCo itself.

The file is loaded with ``mujoco.MjSpec`` and compiled, so defaults and classes,
``fromto``, euler angles, includes, frames and compiler options are resolved by MuJoCo.
Numbers are then read from the compiled ``MjModel`` (what MuJoCo simulates): body frames,
inertias (as compiled, also when MuJoCo computed them from geoms), joints, actuators,
geoms, sites and sensors. Mesh files and scales come from the spec's mesh assets; a mesh
geom's pose is the authored one (MuJoCo's mesh re-centring is undone), so that our MJCF,
compiled again, gives the same model.

What the tables cannot hold goes to ``HRDF.mjcf_extra`` (tendons, equality constraints,
contact pairs and excludes, keyframes) or is reported as a warning naming it.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from robotwright.errors import ConversionError, Problem
from robotwright.hrdf.model import (
    HRDF,
    Actuator,
    Body,
    Joint,
    MeshGeom,
    Meta,
    Sensor,
    SimpleGeom,
    SimulatorConfig,
    Site,
)
from robotwright.parsers import inertia as inr
from robotwright.parsers.meshes import MeshConversionError, MeshStore, conversion_note
from robotwright.parsers.reference import body_name, joint_name
from robotwright.parsers.report import ParseResult, Reporter
from robotwright.parsers.xmlsafe import parse_xml

_JOINT = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}
_GEOM = {2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box", 7: "mesh"}
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
_INTEGRATORS = {0: "Euler", 1: "RK4", 2: "implicit", 3: "implicitfast"}
#: Sections of the source carried verbatim (as MuJoCo writes them) into ``mjcf_extra``.
EXTRA_SECTIONS = ("tendon", "equality", "contact")


@dataclass(frozen=True)
class MJCFOptions:
    """How an MJCF is turned into HRDF.

    Attributes:
        root_body: name of the top-level body that is the robot, when the world holds
            several top-level bodies (the others are dropped with a warning). ``None``:
            the only top-level body.
        work_dir: folder where meshes are staged (default: a new temp folder).
    """

    root_body: str | None = None
    work_dir: Path | None = None


def _t3(v) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _t4(v) -> tuple[float, float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]), float(v[3]))


def _fmt(values) -> str:
    return " ".join(repr(float(v)) for v in np.atleast_1d(values))


def _actuator(model: mujoco.MjModel, i: int, rep: Reporter) -> Actuator | None:
    name = model.actuator(i).name or None
    where = f'<actuator name="{name}">' if name else f"actuator #{i}"
    if model.actuator_trntype[i] != mujoco.mjtTrn.mjTRN_JOINT:
        rep.warn("actuator with a non-joint transmission dropped (HRDF drives joints only)", where)
        return None
    joint = joint_name(model, int(model.actuator_trnid[i, 0]))
    gain, bias = model.actuator_gainprm[i], model.actuator_biasprm[i]
    gt, bt = int(model.actuator_gaintype[i]), int(model.actuator_biastype[i])
    if model.actuator_dyntype[i] != mujoco.mjtDyn.mjDYN_NONE:
        rep.warn("actuator activation dynamics dropped (HRDF actuators have none)", where)
    if gt != 0 or np.any(gain[3:] != 0) or np.any(bias[3:] != 0):
        rep.warn("general actuator gain/bias beyond kp/kv dropped", where)
    kind, kp, kv = None, None, None
    if bt == 0 and gain[0] == 1.0 and not np.any(bias[:3]):
        kind = "motor"
    elif bt == 1 and bias[0] == 0 and gain[0] == -bias[1] and gain[0] != 0:
        kind, kp = "position", float(gain[0])
        kv = float(-bias[2]) if bias[2] != 0 else None
    elif bt == 1 and bias[0] == 0 and bias[1] == 0 and gain[0] == -bias[2] and gain[0] != 0:
        kind, kv = "velocity", float(gain[0])
    if kind is None:
        rep.warn(
            f"actuator gain {gain[:3].tolist()} / bias {bias[:3].tolist()} is not a motor, "
            "position or velocity servo: dropped",
            where,
        )
        return None
    gear = model.actuator_gear[i]
    if np.any(gear[1:] != 0):
        rep.warn("actuator gear beyond its first component dropped", where)
    return Actuator(
        joint=joint,
        name=name,
        type=kind,
        p_gain=kp,
        d_gain=kv,
        gear=float(gear[0]),
        ctrl_range=(float(model.actuator_ctrlrange[i, 0]), float(model.actuator_ctrlrange[i, 1]))
        if model.actuator_ctrllimited[i]
        else None,
        force_range=(
            float(model.actuator_forcerange[i, 0]),
            float(model.actuator_forcerange[i, 1]),
        )
        if model.actuator_forcelimited[i]
        else None,
    )


def _excludes(model: mujoco.MjModel, kept: set[int], rep: Reporter) -> list[ET.Element]:
    """``<contact><exclude>`` rebuilt from the compiled model (signature = b1 << 16 | b2)."""
    section = ET.Element("contact")
    for e in range(model.nexclude):
        sig = int(model.exclude_signature[e])
        b1, b2 = sig >> 16, sig & 0xFFFF
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_EXCLUDE, e)
        if b1 not in kept and b1 != 0 or b2 not in kept and b2 != 0:
            rep.warn("contact exclude with a body outside the robot dropped", f"exclude #{e}")
            continue
        attrs = {"name": name} if name else {}
        attrs |= {"body1": body_name(model, b1), "body2": body_name(model, b2)}
        ET.SubElement(section, "exclude", attrs)
    return [section] if len(section) else []


def _carried_sections(
    spec: mujoco.MjSpec, model: mujoco.MjModel, kept: set[int], rep: Reporter
) -> list[ET.Element]:
    """Tendon, equality and contact sections.

    Contact excludes alone are rebuilt from the compiled model (exact and fast); otherwise
    the sections are taken as MuJoCo writes them (``spec.to_xml``), with ``class``
    references removed (reported: values inherited from a class are not carried)."""
    if not any(len(getattr(spec, a)) for a in ("tendons", "equalities", "pairs")):
        return _excludes(model, kept, rep)
    root = ET.fromstring(spec.to_xml())  # MuJoCo's own output: trusted text
    out = []
    for tag in EXTRA_SECTIONS:
        for section in root.findall(tag):
            for el in section.iter():
                if "class" in el.attrib:
                    rep.warn(
                        f"<{el.tag}> in <{tag}>: default class '{el.attrib['class']}' not "
                        "carried; attributes MuJoCo wrote are kept",
                        f'<{el.tag} name="{el.get("name", "")}">',
                    )
                    del el.attrib["class"]
            out.append(section)
    return out


def parse_mjcf(
    path: str | os.PathLike, options: MJCFOptions | None = None, *, strict: bool = False
) -> ParseResult:
    """Parse an MJCF file into an HRDF (see the module docstring and :class:`MJCFOptions`).

    Raises:
        ConversionError: unsafe XML, a model MuJoCo cannot compile (MuJoCo's message),
            a world with several robots and no ``root_body``, or, with ``strict=True``,
            any warning.
    """
    path = Path(path)
    opt = options or MJCFOptions()
    rep = Reporter(str(path))
    parse_xml(path)  # refuse entity tricks before MuJoCo's own (expanding) XML reader
    try:
        spec = mujoco.MjSpec.from_file(str(path))
        model = spec.compile()
    except ValueError as exc:
        raise ConversionError([Problem(str(path), f"MuJoCo cannot load it: {exc}")]) from exc

    top = [i for i in range(1, model.nbody) if model.body_parentid[i] == 0]
    if opt.root_body is not None:
        ids = [i for i in top if model.body(i).name == opt.root_body]
        if not ids:
            names = [body_name(model, i) for i in top]
            raise ConversionError(
                [Problem(str(path), f"root_body '{opt.root_body}' is not a top-level body {names}")]
            )
        root_id = ids[0]
    elif len(top) == 1:
        root_id = top[0]
    elif not top:
        raise ConversionError(
            [Problem(str(path), "the world holds no bodies: no robot to convert")]
        )
    else:
        names = [body_name(model, i) for i in top]
        raise ConversionError(
            [
                Problem(
                    str(path),
                    f"the world holds {len(top)} top-level bodies {names}: an HRDF is one "
                    "robot; pass root_body=<name>",
                )
            ]
        )
    for i in top:
        if i != root_id:
            rep.warn(
                f"top-level body '{body_name(model, i)}' and its subtree dropped (not the robot)"
            )
    keep = [root_id]
    for i in range(root_id + 1, model.nbody):
        if model.body_rootid[i] == root_id:
            keep.append(i)
    kept = set(keep)
    index = {b: k for k, b in enumerate(keep)}

    bodies: list[Body] = []
    for b in keep:
        if model.body_mocapid[b] >= 0:
            rep.warn("mocap flag dropped", f'<body name="{body_name(model, b)}">')
        if model.body_gravcomp[b] != 0:
            rep.warn("gravcomp dropped", f'<body name="{body_name(model, b)}">')
        if not model.body(b).name:
            rep.warn(f"unnamed body named '{body_name(model, b)}'", f"body #{b}")
        bodies.append(
            Body(
                name=body_name(model, b),
                parent=-1 if b == root_id else index[int(model.body_parentid[b])],
                pos=_t3(model.body_pos[b]),
                quat=_t4(model.body_quat[b]),
                mass=float(model.body_mass[b]),
                inertial_pos=_t3(model.body_ipos[b]),
                inertial_quat=_t4(model.body_iquat[b]),
                diag_inertia=_t3(model.body_inertia[b]),
            )
        )

    joints: list[Joint] = []
    for j in range(model.njnt):
        b = int(model.jnt_bodyid[j])
        if b not in kept:
            continue
        jt = _JOINT[int(model.jnt_type[j])]
        name = model.joint(j).name or None
        where = f'<joint name="{name}">' if name else f"joint #{j}"
        if jt == "free" and b != root_id:
            raise ConversionError(
                [
                    Problem(
                        str(path),
                        "free joint below the root: HRDF allows one on the root only",
                        element=where,
                    )
                ]
            )
        if name is None and jt != "free":
            name = joint_name(model, j)
            rep.warn(f"unnamed joint named '{name}'", where)
        dof = int(model.jnt_dofadr[j])
        qadr = int(model.jnt_qposadr[j])
        if model.jnt_actfrclimited[j]:
            rep.warn(
                f"actuatorfrcrange {model.jnt_actfrcrange[j].tolist()} dropped (HRDF joints "
                "have no actuator force range; use actuator force_range)",
                where,
            )
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
            )
        )

    actuators = [a for i in range(model.nu) if (a := _actuator(model, i, rep)) is not None]

    store = MeshStore(opt.work_dir) if opt.work_dir else MeshStore()
    meshdir = spec.compiler.meshdir or ""
    base_dir = path.resolve().parent
    mesh_files: dict[int, tuple[str, str]] = {}
    meshes: list[MeshGeom] = []
    simple: list[SimpleGeom] = []
    world_geoms = 0
    for g in range(model.ngeom):
        b = int(model.geom_bodyid[g])
        if b == 0:
            world_geoms += 1
            continue
        if b not in kept:
            continue
        gt = int(model.geom_type[g])
        gname = model.geom(g).name or None
        where = f'<geom name="{gname}">' if gname else f'geom #{g} of body "{body_name(model, b)}"'
        if gt not in _GEOM:
            rep.warn(f"geom type {mujoco.mjtGeom(gt).name} dropped (not a robot part shape)", where)
            continue
        rgba = model.geom_rgba[g]
        mat = int(model.geom_matid[g])
        if mat >= 0:
            rgba = model.mat_rgba[mat]
            if model.mat_texid[mat].max() >= 0:
                rep.warn(
                    f"material '{model.material(mat).name}' texture dropped (colour kept)", where
                )
        if (
            np.any(model.geom_solref[g] != [0.02, 1.0])
            or np.any(model.geom_solimp[g] != [0.9, 0.95, 0.001, 0.5, 2.0])
            or model.geom_margin[g]
            or model.geom_gap[g]
            or model.geom_priority[g]
        ):
            rep.warn("geom solref/solimp/margin/gap/priority dropped (HRDF has no field)", where)
        common = {
            "body": body_name(model, b),
            "rgba": _t4(np.clip(rgba, 0.0, 1.0)),
            "contact_type": int(model.geom_contype[g]),
            "contact_affinity": int(model.geom_conaffinity[g]),
            "static_friction": float(model.geom_friction[g, 0]),
            "dynamic_friction": float(model.geom_friction[g, 0]),
            "torsional_friction": float(model.geom_friction[g, 1]),
            "rolling_friction": float(model.geom_friction[g, 2]),
            "group": int(model.geom_group[g]),
            "condim": int(model.geom_condim[g]),
            "geom_name": gname,
        }
        if gt == 7:
            mid = int(model.geom_dataid[g])
            m_spec = spec.meshes[mid]
            if mid not in mesh_files:
                if not m_spec.file:
                    rep.warn("mesh without a file (inline vertices) dropped", where)
                    continue
                src = (base_dir / meshdir / m_spec.file).resolve()
                try:
                    staged = store.add(src)
                except (MeshConversionError, OSError) as exc:
                    raise ConversionError([Problem(str(path), str(exc), element=where)]) from exc
                note = conversion_note(staged)
                if note:
                    rep.warn(f"mesh '{m_spec.file}': {note}", where)
                mesh_files[mid] = (model.mesh(mid).name or Path(m_spec.file).stem, staged.rel)
            mname, rel = mesh_files[mid]
            # Undo MuJoCo's mesh re-centring: compiled = authored * mesh frame.
            mq = model.mesh_quat[mid]
            conj = np.array([mq[0], -mq[1], -mq[2], -mq[3]])
            quat = inr.mul_quat(model.geom_quat[g], conj)
            pos = model.geom_pos[g] - inr.quat_to_mat(quat) @ model.mesh_pos[mid]
            meshes.append(
                MeshGeom(
                    name=mname, file=rel, scale=_t3(m_spec.scale), pos=_t3(pos), quat=quat, **common
                )
            )
        else:
            simple.append(
                SimpleGeom(
                    name="",
                    type=_GEOM[gt],
                    size=_t3(model.geom_size[g]),
                    pos=_t3(model.geom_pos[g]),
                    quat=_t4(model.geom_quat[g]),
                    **common,
                )
            )
    # SimpleGeom.name is the table key; keep the geom's own name when it has one.
    used: set[str] = set()
    for k, sg in enumerate(simple):
        nm = sg.geom_name or f"geom_{k}"
        while nm in used:
            nm = f"{nm}_"
        used.add(nm)
        from dataclasses import replace

        simple[k] = replace(sg, name=nm)
    if world_geoms:
        rep.warn(f"{world_geoms} geom(s) of the worldbody dropped (scene, not robot)")

    sites: list[Site] = []
    for s in range(model.nsite):
        b = int(model.site_bodyid[s])
        sname = model.site(s).name or f"site_{s}"
        if b == 0 or b not in kept:
            rep.warn("site outside the robot dropped", f'<site name="{sname}">')
            continue
        if not model.site(s).name:
            rep.warn(f"unnamed site named '{sname}'", f"site #{s}")
        sites.append(
            Site(
                name=sname,
                body=body_name(model, b),
                pos=_t3(model.site_pos[s]),
                quat=_t4(model.site_quat[s]),
                type=_SITE.get(int(model.site_type[s]), "sphere"),
                size=_t3(model.site_size[s]),
                rgba=_t4(np.clip(model.site_rgba[s], 0.0, 1.0)),
                group=int(model.site_group[s]),
            )
        )

    sensors: list[Sensor] = []
    extra_sensors: list[ET.Element] = []
    kept_names = {
        "body": {body_name(model, b) for b in keep},
        "xbody": {body_name(model, b) for b in keep},
        "site": {x.name for x in sites},
        "joint": {x.name for x in joints},
        "actuator": {x.name for x in actuators},
        "geom": {x.geom_name for x in [*meshes, *simple] if x.geom_name},
    }
    for s in range(model.nsensor):
        sname = model.sensor(s).name or f"sensor_{s}"
        stype = mujoco.mjtSensor(int(model.sensor_type[s])).name[len("mjSENS_") :].lower()
        objtype = _OBJ.get(int(model.sensor_objtype[s]))
        where = f'<{stype} name="{sname}">'
        if objtype is None or stype in ("user", "plugin"):
            rep.warn("sensor dropped (its object type has no HRDF equivalent)", where)
            continue
        if not model.sensor(s).name:
            rep.warn(f"unnamed sensor named '{sname}'", where)
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
        if extra_sensors or lost:
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
            )
        )

    for what, count in (("camera", model.ncam), ("light", model.nlight)):
        if count:
            rep.warn(f"{count} {what}(s) dropped (HRDF has no {what}s)")
    if model.nhfield or model.ntex:
        rep.warn(f"{model.nhfield} height field(s) and {model.ntex} texture(s) dropped")

    extra_parts = _carried_sections(spec, model, kept, rep)
    if extra_sensors:
        section = ET.Element("sensor")
        section.extend(extra_sensors)
        extra_parts.append(section)
    if model.nkey:
        section = ET.Element("keyframe")
        for k in range(model.nkey):
            attrs = {}
            if model.key(k).name:
                attrs["name"] = model.key(k).name
            attrs["time"] = repr(float(model.key_time[k]))
            attrs["qpos"] = _fmt(model.key_qpos[k])
            attrs["qvel"] = _fmt(model.key_qvel[k])
            if model.na:
                attrs["act"] = _fmt(model.key_act[k])
            if model.nu:
                attrs["ctrl"] = _fmt(model.key_ctrl[k])
            if model.nmocap:
                rep.warn("keyframe mocap poses dropped", f"keyframe {k}")
            ET.SubElement(section, "key", attrs)
        extra_parts.append(section)
        if len(keep) != model.nbody - 1 or len(actuators) != model.nu:
            rep.warn("keyframes kept, but qpos/ctrl sizes no longer match the dropped parts")
    extra = None
    if extra_parts:
        root = ET.Element("mujoco")
        root.extend(extra_parts)
        ET.indent(root)
        extra = ET.tostring(root, encoding="unicode") + "\n"

    sim = SimulatorConfig(
        timestep=float(model.opt.timestep),
        gravity=_t3(model.opt.gravity),
        ground=None,
        integrator=_INTEGRATORS.get(int(model.opt.integrator)),
    )
    hrdf = HRDF(
        name=spec.modelname or path.stem,
        bodies=bodies,
        joints=joints,
        actuators=actuators,
        meshes=meshes,
        simple_geoms=simple,
        sites=sites,
        sensors=sensors,
        meta=Meta(simulator_config=sim, body_name_config=None),
        mjcf_extra=extra,
        root_dir=store.root,
    )
    warnings = rep.finish(strict)
    return ParseResult(hrdf, warnings, str(path))
