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

import functools
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from pathlib import Path

import mujoco
import numpy as np

from robotwright._limits import keyframes_problem
from robotwright._mjmodel import actuator_count
from robotwright._paths import check_mjcf_includes, check_mjcf_spec, trusted_roots
from robotwright._xmlsafe import parse_xml
from robotwright.errors import ConversionError, InputFileError, Problem, UnsafePathError
from robotwright.hrdf.model import (
    HRDF,
    SENSOR_OBJTYPES,
    WORLD,
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
from robotwright.hrdf.options import nuser_from_model, options_from_model
from robotwright.parsers import inertia as inr
from robotwright.parsers import mjcf_extra
from robotwright.parsers.meshes import (
    MeshConversionError,
    MeshStore,
    conversion_is_cosmetic,
    conversion_note,
    mesh_store,
)
from robotwright.parsers.reference import body_name, joint_name
from robotwright.parsers.report import ParseResult, Reporter, warn_massless_moving

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
#: MJCF element names that differ from MuJoCo's sensor enum names (mjSENS_*).
_SENSOR_ELEMENT = {"jointactfrc": "jointactuatorfrc", "tendonactfrc": "tendonactuatorfrc"}


@dataclass(frozen=True)
class MJCFOptions:
    """How an MJCF is turned into HRDF.

    Attributes:
        root_body: name of the top-level body that is the robot, when the world holds
            several top-level bodies (the others are dropped with a warning). ``None``:
            the only top-level body.
        work_dir: folder where meshes are staged (default: a new temp folder).
        massless_frames: ``"keep"`` (default) or ``"site"``: a massless leaf body without
            joints that nothing else names (a camera or tool frame) becomes a site on its
            parent named after it, its sites and (massless) geoms moved to the parent.
            HRDF checks require mass > 0 on every body, so ``"keep"`` leaves such a robot
            invalid (reported).
        join_obj_objects: convert an OBJ mesh split into several objects (``o``/``g``
            lines), of which MuJoCo reads the first only, into one mesh holding every
            object's triangles unchanged (each such mesh is reported; the robot then
            differs from the source as MuJoCo compiles it). Without it the loss is
            reported.
        asset_roots: folders outside the MJCF's folder that its files (meshes,
            textures, includes) may point into. By default every file must lie inside
            the MJCF's folder (see :mod:`robotwright._paths`).
    """

    root_body: str | None = None
    work_dir: Path | None = None
    massless_frames: str = "keep"
    join_obj_objects: bool = False
    asset_roots: tuple[str | os.PathLike, ...] = ()

    def __post_init__(self) -> None:
        if self.massless_frames not in ("keep", "site"):
            raise ValueError(f"massless_frames={self.massless_frames!r}: expected 'keep' or 'site'")


_DEFAULT_MODEL = mujoco.MjModel.from_xml_string(
    '<mujoco><asset><material name="m"/></asset>'
    '<worldbody><body><joint/><geom size="1"/></body></worldbody></mujoco>'
)
#: Material fields beyond the colour (a material with defaults there is just a colour).
_MATERIAL_UNHELD = (
    "mat_texid", "mat_texuniform", "mat_texrepeat", "mat_emission", "mat_specular",
    "mat_shininess", "mat_reflectance", "mat_metallic", "mat_roughness",
)  # fmt: skip
#: Joint fields HRDF has no column for: (MJCF attribute, model array, per-dof?).
_JOINT_UNHELD = (
    ("group", "jnt_group", False),
    ("stiffnesspoly", "jnt_stiffnesspoly", False),
    ("springyield", "jnt_springyield", False),
    ("dampingpoly", "dof_dampingpoly", True),
)
#: Geom fields HRDF has no column for.
_GEOM_UNHELD = ("geom_fluid",)


def _differs(model: mujoco.MjModel, attr: str, i: int, j: int = 0) -> bool:
    if not hasattr(model, attr):  # fields of other MuJoCo versions
        return False
    return bool(np.any(getattr(model, attr)[i] != getattr(_DEFAULT_MODEL, attr)[j]))


def _user(values) -> tuple[float, ...]:
    """MuJoCo ``user`` data without its trailing zeros (``<size nuser_*>`` pads them)."""
    vals = [float(v) for v in values]
    while vals and vals[-1] == 0.0:
        vals.pop()
    return tuple(vals)


def _pair(v) -> tuple[float, float]:
    return (float(v[0]), float(v[1]))


def _five(v) -> tuple[float, float, float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]), float(v[3]), float(v[4]))


def _t3(v) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _t4(v) -> tuple[float, float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]), float(v[3]))


def _fmt(values) -> str:
    return " ".join(repr(float(v)) for v in np.atleast_1d(values))


_TRN_ATTR = {
    int(mujoco.mjtTrn.mjTRN_JOINT): ("joint", mujoco.mjtObj.mjOBJ_JOINT),
    int(mujoco.mjtTrn.mjTRN_JOINTINPARENT): ("jointinparent", mujoco.mjtObj.mjOBJ_JOINT),
    int(mujoco.mjtTrn.mjTRN_TENDON): ("tendon", mujoco.mjtObj.mjOBJ_TENDON),
    int(mujoco.mjtTrn.mjTRN_SITE): ("site", mujoco.mjtObj.mjOBJ_SITE),
    int(mujoco.mjtTrn.mjTRN_BODY): ("body", mujoco.mjtObj.mjOBJ_BODY),
}


def _keywords(enum: type, prefix: str) -> dict[int, str]:
    """MJCF keywords of a MuJoCo enum (``mjDYN_FILTEREXACT`` -> ``filterexact``), from the
    installed MuJoCo: 4.x numbers them differently from 3.x (``dcmotor`` before ``user``)."""
    return {int(v): k[len(prefix) :].lower() for k, v in enum.__members__.items()}


_DYN = _keywords(mujoco.mjtDyn, "mjDYN_")
_GAIN = _keywords(mujoco.mjtGain, "mjGAIN_")
_BIAS = _keywords(mujoco.mjtBias, "mjBIAS_")
#: ``actuator_ctrlspec`` (3.11 has it too, but only for an so3 actuator's chart).
_HAS_CTRLSPEC = hasattr(mujoco.MjModel, "actuator_ctrlspec")
#: MuJoCo 4's declared control input (``actuator_ctrlspec``, ``mjtCtrlInput``) -> the
#: ``<general input>`` keyword; empty where the installed MuJoCo declares none (3.11's
#: ``input`` takes only an so3 chart). Other values (a DC motor's voltage) follow from
#: the gain type.
_INPUT = {
    int(v): k[len("mjINPUT_") :].lower()
    for k, v in getattr(getattr(mujoco, "mjtCtrlInput", None), "__members__", {}).items()
    if k in ("mjINPUT_POS", "mjINPUT_VEL", "mjINPUT_PRESSURE")
}


@functools.cache
def _table_ctrlspec() -> dict[str, int]:
    """The ``actuator_ctrlspec`` each HRDF actuator type compiles to once written back
    (``<motor>``, ``<position>``, ``<velocity>``), as the installed MuJoCo sets it."""
    xml = (
        "<mujoco><worldbody><body><joint name='j'/><geom size='1'/></body></worldbody>"
        "<actuator><motor joint='j'/><position joint='j' kp='1'/><velocity joint='j' kv='1'/>"
        "</actuator></mujoco>"
    )
    spec = mujoco.MjModel.from_xml_string(xml).actuator_ctrlspec
    return {"motor": int(spec[0]), "position": int(spec[1]), "velocity": int(spec[2])}


def _actuator_record(model: mujoco.MjModel, i: int) -> Actuator | None:
    """The actuator as an HRDF record when the table holds it exactly, else None."""
    if model.actuator_trntype[i] != mujoco.mjtTrn.mjTRN_JOINT:
        return None
    gain, bias = model.actuator_gainprm[i], model.actuator_biasprm[i]
    gt, bt = int(model.actuator_gaintype[i]), int(model.actuator_biastype[i])
    if (
        model.actuator_dyntype[i] != mujoco.mjtDyn.mjDYN_NONE
        or gt != 0
        or np.any(gain[3:] != 0)
        or np.any(bias[3:] != 0)
        or np.any(model.actuator_gear[i, 1:] != 0)
        or model.actuator_actlimited[i]
        or model.actuator_group[i] != 0
    ):
        return None
    kind, kp, kv = None, None, None
    if bt == 0 and gain[0] == 1.0 and not np.any(gain[1:3]) and not np.any(bias[:3]):
        kind = "motor"
    elif (
        bt == 1 and bias[0] == 0 and gain[0] == -bias[1] and gain[0] != 0 and not np.any(gain[1:3])
    ):
        kind, kp = "position", float(gain[0])
        kv = float(-bias[2]) if bias[2] != 0 else None
    elif (
        bt == 1
        and bias[0] == 0
        and bias[1] == 0
        and gain[0] == -bias[2]
        and gain[0] != 0
        and not np.any(gain[1:3])
    ):
        kind, kv = "velocity", float(gain[0])
    if kind is None:
        return None
    # MuJoCo 4 declares the input a <position>/<velocity> takes (pos/vel); a <general>
    # with the same gains declares none: the table's type would change it.
    if _HAS_CTRLSPEC and int(model.actuator_ctrlspec[i]) != _table_ctrlspec()[kind]:
        return None
    return Actuator(
        joint=joint_name(model, int(model.actuator_trnid[i, 0])),
        name=model.actuator(i).name or None,
        type=kind,
        p_gain=kp,
        d_gain=kv,
        gear=float(model.actuator_gear[i, 0]),
        ctrl_range=(float(model.actuator_ctrlrange[i, 0]), float(model.actuator_ctrlrange[i, 1]))
        if model.actuator_ctrllimited[i]
        else None,
        force_range=(
            float(model.actuator_forcerange[i, 0]),
            float(model.actuator_forcerange[i, 1]),
        )
        if model.actuator_forcelimited[i]
        else None,
        user=_user(model.actuator_user[i]),
    )


def _actuator_target(model: mujoco.MjModel, i: int) -> tuple[str, str] | None:
    """(attribute, object name) of the actuator's transmission, or None (slider-crank)."""
    trn = _TRN_ATTR.get(int(model.actuator_trntype[i]))
    if trn is None:
        return None
    attr, obj = trn
    oid = int(model.actuator_trnid[i, 0])
    if obj == mujoco.mjtObj.mjOBJ_JOINT:
        return attr, joint_name(model, oid)
    if obj == mujoco.mjtObj.mjOBJ_BODY:
        return attr, body_name(model, oid)
    return attr, mujoco.mj_id2name(model, obj, oid) or ""


def _actuator_attrs(model: mujoco.MjModel, i: int) -> dict[str, str]:
    """The attributes every carried actuator element has: name, transmission, group,
    gear and the three ranges, each explicit."""
    attrs: dict[str, str] = {}
    if model.actuator(i).name:
        attrs["name"] = model.actuator(i).name
    attr, target = _actuator_target(model, i)
    attrs[attr] = target
    if model.actuator_trntype[i] == mujoco.mjtTrn.mjTRN_SITE and model.actuator_trnid[i, 1] >= 0:
        attrs["refsite"] = model.site(int(model.actuator_trnid[i, 1])).name
    if model.actuator_group[i]:
        attrs["group"] = str(int(model.actuator_group[i]))
    attrs["gear"] = _fmt(model.actuator_gear[i])
    for flag, rng in (("ctrl", "ctrlrange"), ("force", "forcerange"), ("act", "actrange")):
        limited = bool(getattr(model, f"actuator_{flag}limited")[i])
        attrs[f"{flag}limited"] = "true" if limited else "false"
        if limited:
            attrs[rng] = _fmt(getattr(model, f"actuator_{rng}")[i])
    return attrs


def _general_elem(model: mujoco.MjModel, i: int) -> ET.Element:
    """The compiled actuator as a ``<general>`` element, every parameter explicit."""
    attrs = _actuator_attrs(model, i)
    attrs["dyntype"] = _DYN[int(model.actuator_dyntype[i])]
    attrs["gaintype"] = _GAIN[int(model.actuator_gaintype[i])]
    attrs["biastype"] = _BIAS[int(model.actuator_biastype[i])]
    if _HAS_CTRLSPEC and int(model.actuator_ctrlspec[i]) in _INPUT:
        attrs["input"] = _INPUT[int(model.actuator_ctrlspec[i])]
    attrs["dynprm"] = _fmt(model.actuator_dynprm[i])
    attrs["gainprm"] = _fmt(model.actuator_gainprm[i])
    attrs["biasprm"] = _fmt(model.actuator_biasprm[i])
    if model.actuator_actearly[i]:
        attrs["actearly"] = "true"
    if np.any(model.actuator_lengthrange[i] != 0):
        attrs["lengthrange"] = _fmt(model.actuator_lengthrange[i])
    if _user(model.actuator_user[i]):
        attrs["user"] = _fmt(_user(model.actuator_user[i]))
    return ET.Element("general", attrs)


def _plugin_elem(model: mujoco.MjModel, spec: mujoco.MjSpec, i: int) -> ET.Element:
    """A plugin actuator (``mujoco.pid``, ...) as its ``<plugin>`` element: the plugin,
    its instance (or its own ``<config>`` lines), the transmission, ranges and the
    activation count the plugin keeps."""
    attrs = _actuator_attrs(model, i)
    plugin = spec.actuators[i].plugin
    attrs["plugin"] = plugin.plugin_name
    if plugin.name:
        attrs["instance"] = plugin.name
    attrs["actdim"] = str(int(model.actuator_actnum[i]))
    elem = ET.Element("plugin", attrs)
    if not plugin.name:
        for key, value in sorted(plugin.config.items()):
            ET.SubElement(elem, "config", {"key": key, "value": value})
    return elem


def _plugin_instances(spec: mujoco.MjSpec, used: set[str]) -> ET.Element | None:
    """``<extension>`` declaring the plugin instances the carried actuators name, with
    their configuration."""
    by_type: dict[str, ET.Element] = {}
    for instance in spec.plugins:
        if instance.name not in used:
            continue
        kind = by_type.get(instance.plugin_name)
        if kind is None:
            kind = by_type[instance.plugin_name] = ET.Element(
                "plugin", {"plugin": instance.plugin_name}
            )
        elem = ET.SubElement(kind, "instance", {"name": instance.name})
        for key, value in sorted(instance.config.items()):
            ET.SubElement(elem, "config", {"key": key, "value": value})
    if not by_type:
        return None
    section = ET.Element("extension")
    section.extend(by_type.values())
    return section


def _actuators(
    model: mujoco.MjModel, spec: mujoco.MjSpec, names: dict[str, set[str]], rep: Reporter
) -> tuple[list[Actuator], list[ET.Element], list[int]]:
    """Table actuators, and the rest as exact ``<general>`` elements for ``mjcf_extra``
    (a plugin actuator as its ``<plugin>`` element).

    From the first actuator the table cannot hold exactly (tendon or site transmission,
    activation dynamics, general gains, a plugin, ...), every later actuator goes to
    ``mjcf_extra`` too, so that actuator order (and ``ctrl`` layout) is kept."""
    table: list[Actuator] = []
    carried: list[ET.Element] = []
    kept: list[int] = []
    for i in range(actuator_count(model)):
        name = model.actuator(i).name
        where = f'<actuator name="{name}">' if name else f"actuator #{i}"
        target = _actuator_target(model, i)
        kind = {"jointinparent": "joint"}.get(target[0], target[0]) if target else None
        if target is None or target[1] not in names.get(kind, set()):
            rep.warn(f"actuator dropped: its transmission {target} is not part of the robot", where)
            continue
        kept.append(i)
        plugin = int(model.actuator_plugin[i]) >= 0
        record = None if carried or plugin else _actuator_record(model, i)
        if record is not None:
            table.append(record)
            continue
        if not carried:
            rep.warn(
                "actuator not expressible as an HRDF motor/position/velocity record: it and "
                "every later actuator are carried exactly as <general> (a plugin actuator "
                "as <plugin>) in mjcf_extra",
                where,
                cosmetic=True,
            )
        carried.append(_plugin_elem(model, spec, i) if plugin else _general_elem(model, i))
    return table, carried, kept


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
) -> tuple[int, list[int]]:
    """The robot's root body id and its subtree's body ids (model order)."""
    top = [i for i in range(1, model.nbody) if model.body_parentid[i] == 0]
    if opt.root_body is not None:
        # By the name the refusal lists: an unnamed body is 'body_<id>'.
        ids = [i for i in top if body_name(model, i) == opt.root_body]
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
                    "robot; choose one with root_body=<name> (command line: --root-body NAME)",
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
    return root_id, keep


def _named_bodies(model: mujoco.MjModel) -> set[int]:
    """Bodies other elements refer to (sensors, actuators, equality, excludes)."""
    out: set[int] = set()
    body_types = (mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_XBODY)
    for s in range(model.nsensor):
        if model.sensor_objtype[s] in body_types:
            out.add(int(model.sensor_objid[s]))
        if model.sensor_reftype[s] in body_types:
            out.add(int(model.sensor_refid[s]))
    for a in range(actuator_count(model)):
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_BODY:
            out.add(int(model.actuator_trnid[a, 0]))
    for e in range(model.neq):
        if model.eq_type[e] in (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD) and (
            model.eq_objtype[e] != mujoco.mjtObj.mjOBJ_SITE
        ):
            out.update((int(model.eq_obj1id[e]), int(model.eq_obj2id[e])))
    for sig in model.exclude_signature:
        out.update((int(sig) >> 16, int(sig) & 0xFFFF))
    return out


def _frames_as_sites(
    model: mujoco.MjModel, keep: list[int], root_id: int, opt: MJCFOptions
) -> set[int]:
    """Bodies that become sites under ``massless_frames="site"``."""
    if opt.massless_frames != "site":
        return set()
    parents = {int(model.body_parentid[b]) for b in keep if b != root_id}
    named = _named_bodies(model)
    return {
        b
        for b in keep
        if b != root_id
        and model.body_mass[b] == 0
        and model.body_jntnum[b] == 0
        and b not in parents
        and b not in named
    }


def _reparent(
    model: mujoco.MjModel, b: int, pos, quat, frames: set[int]
) -> tuple[int, tuple[float, float, float], tuple[float, float, float, float]]:
    """(body id, pos, quat) of a pose on body ``b``, moved to its parent when ``b`` is a
    frame turned into a site."""
    if b not in frames:
        return b, _t3(pos), _t4(quat)
    rot = inr.quat_to_mat(model.body_quat[b])
    new_pos = model.body_pos[b] + rot @ np.asarray(pos, dtype=float)
    return int(model.body_parentid[b]), _t3(new_pos), inr.mul_quat(model.body_quat[b], quat)


def _bodies(
    model: mujoco.MjModel, keep: list[int], root_id: int, frames: set[int], rep: Reporter
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
                parent=-1 if b == root_id else index[int(model.body_parentid[b])],
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
    model: mujoco.MjModel, kept: set[int], root_id: int, path: Path, rep: Reporter
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


def _keep_interleaved_order(
    in_order: dict[str, list[tuple[str, int]]], meshes: list, simple: list
) -> None:
    """Give each geom of a body whose mesh and primitive geoms interleave its position
    (``order``): written meshes-first, such a body's contacts would come in another order."""
    for geoms in in_order.values():
        natural = sorted(geoms, key=lambda kind_row: kind_row[0] != "mesh")  # stable
        if natural == geoms:
            continue
        for position, (kind, row) in enumerate(geoms):
            table = meshes if kind == "mesh" else simple
            table[row] = replace(table[row], order=position)


def _mesh_source(
    m_spec: mujoco.MjsMesh, meshdir: str, base_dir: Path, sub_dirs: list[Path]
) -> Path:
    """The file of mesh ``m_spec`` as MuJoCo finds it: under its own model's mesh folder
    (a sub-model's meshes keep their ``<compiler meshdir>``), from the main file's folder
    or the sub-model's."""
    own = getattr(getattr(m_spec, "compiler", None), "meshdir", None)
    folder = meshdir if own is None else own
    for base in (base_dir, *sub_dirs):
        candidate = (base / folder / m_spec.file).resolve()
        if candidate.is_file():
            return candidate
    return (base_dir / folder / m_spec.file).resolve()


def _geoms(
    model: mujoco.MjModel,
    spec: mujoco.MjSpec,
    kept: set[int],
    path: Path,
    store: MeshStore,
    frames: set[int],
    rep: Reporter,
    sub_dirs: list[Path],
) -> tuple[list[MeshGeom], list[SimpleGeom]]:
    """Mesh geoms (files staged, authored poses restored) and primitive geoms;
    ``sub_dirs``: the folders of the sub-models, whose meshes are named from there."""
    # Relative to the main file's folder (MuJoCo folds <compiler assetdir> into meshdir).
    meshdir = spec.compiler.meshdir or ""
    base_dir = path.resolve().parent
    mesh_files: dict[int, tuple[str, str]] = {}
    meshes: list[MeshGeom] = []
    simple: list[SimpleGeom] = []
    world_geoms: list[str] = []
    materials: set[str] = set()
    unheld_geom: dict[str, list[str]] = {}
    in_order: dict[str, list[tuple[str, int]]] = {}  # body -> its geoms, in model order
    for g in range(model.ngeom):
        b = int(model.geom_bodyid[g])
        if b == 0:
            world_geoms.append(model.geom(g).name or f"geom #{g}")
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
        # MuJoCo draws the material colour unless the geom's own rgba is not the default.
        if mat >= 0:
            if any(_differs(model, attr, mat) for attr in _MATERIAL_UNHELD):
                materials.add(model.material(mat).name or f"material #{mat}")
            if not _differs(model, "geom_rgba", g):
                rgba = model.mat_rgba[mat]
        for attr in _GEOM_UNHELD:
            if _differs(model, attr, g):
                unheld_geom.setdefault(attr[len("geom_") :], []).append(gname or f"geom #{g}")
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
            "solref": _pair(model.geom_solref[g]),
            "solimp": _five(model.geom_solimp[g]),
            "margin": float(model.geom_margin[g]),
            "gap": float(model.geom_gap[g]),
            "priority": int(model.geom_priority[g]),
            "solmix": float(model.geom_solmix[g]),
            "user": _user(model.geom_user[g]),
        }
        if gt == 7:
            mid = int(model.geom_dataid[g])
            m_spec = spec.meshes[mid]
            if mid not in mesh_files:
                if not m_spec.file:
                    rep.warn("mesh without a file (inline vertices) dropped", where)
                    continue
                unheld = [
                    attr
                    for attr, default in (
                        ("maxhullvert", -1),
                        ("smoothnormal", False),
                    )
                    if getattr(m_spec, attr) != default
                ]
                if unheld:
                    rep.warn(
                        f"mesh asset '{model.mesh(mid).name}': {unheld} dropped (no HRDF "
                        "column); MuJoCo may centre the mesh differently",
                        where,
                    )
                src = _mesh_source(m_spec, meshdir, base_dir, sub_dirs)
                signs = tuple(-1.0 if v < 0 else 1.0 for v in m_spec.scale)
                try:
                    if -1.0 in signs:
                        # HRDF scales are positive: the reflection goes into a mirrored copy.
                        staged = store.add_mirrored(src, signs)
                        rep.warn(
                            f"mesh '{m_spec.file}' with negative scale {tuple(m_spec.scale.tolist())}: "
                            f"mirrored copy written ({staged.rel}), scale made positive",
                            where,
                        )
                    else:
                        staged = store.add(src)
                except (MeshConversionError, OSError) as exc:
                    raise ConversionError([Problem(str(path), str(exc), element=where)]) from exc
                note = conversion_note(staged)
                if note:
                    cosmetic = conversion_is_cosmetic(staged)
                    rep.warn(f"mesh '{m_spec.file}': {note}", where, cosmetic=cosmetic)
                mesh_files[mid] = (model.mesh(mid).name or Path(m_spec.file).stem, staged.rel)
            mname, rel = mesh_files[mid]
            # Undo MuJoCo's mesh re-centring: compiled = authored * mesh frame.
            mq = model.mesh_quat[mid]
            conj = np.array([mq[0], -mq[1], -mq[2], -mq[3]])
            quat = inr.mul_quat(model.geom_quat[g], conj)
            pos = model.geom_pos[g] - inr.quat_to_mat(quat) @ model.mesh_pos[mid]
            # The mesh's refpos/refquat (the frame its file's vertices are given in)
            # folded into the geom's pose: HRDF meshes are their files as they are.
            ref_q = np.asarray(m_spec.refquat, dtype=float)
            ref_q = ref_q / np.linalg.norm(ref_q)
            ref_inv = np.array([ref_q[0], -ref_q[1], -ref_q[2], -ref_q[3]])
            pos = pos - inr.quat_to_mat(quat) @ (
                inr.quat_to_mat(ref_inv) @ np.asarray(m_spec.refpos)
            )
            quat = inr.mul_quat(quat, ref_inv)
            owner, pos, quat = _reparent(model, b, pos, quat, frames)
            common["body"] = body_name(model, owner)
            mode = m_spec.inertia.name.removeprefix("mjMESH_INERTIA_").lower()
            in_order.setdefault(common["body"], []).append(("mesh", len(meshes)))
            meshes.append(
                MeshGeom(
                    name=mname,
                    file=rel,
                    scale=_t3(np.abs(m_spec.scale)),
                    inertia=None if mode == "legacy" else mode,
                    pos=pos,
                    quat=quat,
                    **common,
                )
            )
        else:
            owner, pos, quat = _reparent(model, b, model.geom_pos[g], model.geom_quat[g], frames)
            common["body"] = body_name(model, owner)
            in_order.setdefault(common["body"], []).append(("simple", len(simple)))
            simple.append(
                SimpleGeom(
                    name="",
                    type=_GEOM[gt],
                    size=_t3(model.geom_size[g]),
                    pos=pos,
                    quat=quat,
                    **common,
                )
            )
    _keep_interleaved_order(in_order, meshes, simple)
    # SimpleGeom.name is the table key; keep the geom's own name when it has one.
    used: set[str] = set()
    for k, sg in enumerate(simple):
        nm = sg.geom_name or f"geom_{k}"
        while nm in used:
            nm = f"{nm}_"
        used.add(nm)
        simple[k] = replace(sg, name=nm)
    if materials:
        rep.warn(
            f"materials {sorted(materials)} replaced by their colour (their textures, "
            "specular, shininess, reflectance, emission dropped)",
            cosmetic=True,
        )
    for attr, gnames in unheld_geom.items():
        shown = gnames[:8] + ([f"... {len(gnames) - 8} more"] if len(gnames) > 8 else [])
        rep.warn(f"geom attribute '{attr}' dropped (no HRDF column) on geoms {shown}")
    if world_geoms:
        shown = ", ".join(world_geoms[:6]) + (", ..." if len(world_geoms) > 6 else "")
        rep.warn(f"{len(world_geoms)} geom(s) of the worldbody dropped (scene, not robot): {shown}")

    return meshes, simple


def _routing_sites(model: mujoco.MjModel) -> set[int]:
    """Sites that tendons (path points, side sites) and actuators (site transmission,
    reference site) go through."""
    out: set[int] = set()
    for w in range(model.nwrap):
        if model.wrap_type[w] == mujoco.mjtWrap.mjWRAP_SITE:
            out.add(int(model.wrap_objid[w]))
        elif model.wrap_type[w] in (mujoco.mjtWrap.mjWRAP_SPHERE, mujoco.mjtWrap.mjWRAP_CYLINDER):
            side = int(model.wrap_prm[w])
            if side >= 0:
                out.add(side)
    for a in range(actuator_count(model)):
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_SITE:
            out.update(int(x) for x in model.actuator_trnid[a] if x >= 0)
    return out


def _sites(
    model: mujoco.MjModel, kept: set[int], frames: set[int], root_id: int, rep: Reporter
) -> list[Site]:
    """Sites of the robot's bodies, and one per frame body turned into a site. A site of
    the world (an IMU frame, a muscle origin) stays a site of the world (``body`` is
    ``"world"``), except one a tendon or actuator goes through when the root is fixed to
    the world: that one is kept on the root body (the same place, as it never moves)."""
    sites: list[Site] = []
    routing = _routing_sites(model) if model.site_bodyid.size else set()
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


def _carried_instances(carried: list[ET.Element]) -> int:
    """Plugin instances the carried actuators use (one per actuator configured inline)."""
    named = {e.get("instance") for e in carried if e.tag == "plugin" and e.get("instance")}
    inline = sum(1 for e in carried if e.tag == "plugin" and not e.get("instance"))
    return len(named) + inline


def _report_scene(model: mujoco.MjModel, rep: Reporter, carried_plugins: int = 0) -> None:
    """Warnings for the model parts HRDF has no place for (``carried_plugins``: plugin
    instances that travel with their actuators)."""
    for what, count in (("camera", model.ncam), ("light", model.nlight)):
        if count:
            rep.warn(f"{count} {what}(s) dropped (HRDF has no {what}s)", cosmetic=True)
    for what, count in (
        ("flex", model.nflex),
        ("skin", model.nskin),
        ("plugin instance (of a sensor or passive force)", model.nplugin - carried_plugins),
        ("custom numeric", model.nnumeric),
        ("custom text", model.ntext),
        ("custom tuple", model.ntuple),
    ):
        if count:
            rep.warn(f"{count} {what} element(s) dropped (no HRDF equivalent)")
    for what, count in (("height field", model.nhfield), ("texture", model.ntex)):
        if count:
            rep.warn(
                f"{count} {what}(s) dropped (HRDF geoms carry a colour only)",
                cosmetic=what == "texture",
            )


def parse_mjcf(
    path: str | os.PathLike, options: MJCFOptions | None = None, *, strict: bool = False
) -> ParseResult:
    """Parse an MJCF file into an HRDF (see the module docstring and :class:`MJCFOptions`).

    Raises:
        ConversionError: unsafe XML, a file path leaving the MJCF's folder (an include,
            mesh or texture: ``..``, an absolute path or ``meshdir``, a symbolic link; see
            ``asset_roots``), a model MuJoCo cannot compile (MuJoCo's message), a world
            with several robots and no ``root_body``, or, with ``strict=True``, any
            warning.
    """
    path = Path(path)
    opt = options or MJCFOptions()
    rep = Reporter(str(path))
    # Refuse entity tricks before MuJoCo's own (expanding) XML reader, and any file the
    # model would make MuJoCo read (include, mesh, texture) outside the MJCF's folder.
    tree = parse_xml(path)
    where = {"source": str(path), "model_dir": path.resolve().parent}
    try:
        trusted = trusted_roots(opt.asset_roots)
        sub_dirs = check_mjcf_includes(tree, **where, root=path.resolve().parent, trusted=trusted)
        spec = mujoco.MjSpec.from_file(str(path))
        check_mjcf_spec(spec, **where, root=path.resolve().parent, trusted=trusted)
        # Keyframes are allocated when the model compiles: refuse a flood of them first.
        too_many = keyframes_problem(max(len(spec.keys), spec.nkey))
        if too_many is not None:
            raise InputFileError(path, too_many)
        model = spec.compile()
        # The proof of the conversion compares with this compile (one compile saved).
        from robotwright.parsers.proof_models import remember_parsed

        remember_parsed(path, spec, model)
    except UnsafePathError as exc:
        problem = Problem(exc.file or str(path), exc.reason, element=exc.element)
        raise ConversionError([problem]) from exc
    except InputFileError:
        raise  # a file over the size limit: refused before MuJoCo read it
    except ValueError as exc:
        raise ConversionError([Problem(str(path), f"MuJoCo cannot load it: {exc}")]) from exc
    return _from_compiled(spec, model, path, opt, rep, strict, sub_dirs)


def parse_mjcf_spec(
    spec: mujoco.MjSpec, path: Path, options: MJCFOptions | None = None, *, strict: bool = False
) -> ParseResult:
    """An HRDF from a spec built in memory by another reader (its values exactly: an
    MJCF text would keep 6 digits). ``path`` names the source in notes, and its folder
    holds the spec's mesh files (``spec.modelfiledir``)."""
    rep = Reporter(str(path))
    try:
        model = spec.compile()
    except ValueError as exc:
        raise ConversionError([Problem(str(path), f"MuJoCo cannot compile it: {exc}")]) from exc
    return _from_compiled(spec, model, Path(path), options or MJCFOptions(), rep, strict)


def _from_compiled(
    spec: mujoco.MjSpec,
    model: mujoco.MjModel,
    path: Path,
    opt: MJCFOptions,
    rep: Reporter,
    strict: bool,
    sub_dirs: list[Path] | None = None,
) -> ParseResult:
    """The HRDF of a compiled spec (the body of :func:`parse_mjcf`; ``sub_dirs``: the
    folders of its sub-models, from the containment check)."""
    root_id, keep = _select_robot(model, path, opt, rep)
    kept = set(keep)
    frames = _frames_as_sites(model, keep, root_id, opt)
    bodies = _bodies(model, keep, root_id, frames, rep)
    joints = _joints(model, kept, root_id, path, rep)
    store = mesh_store(opt.work_dir, opt.join_obj_objects)
    meshes, simple = _geoms(model, spec, kept, path, store, frames, rep, sub_dirs or [])
    sites = _sites(model, kept, frames, root_id, rep)
    names = {
        "joint": {j.name for j in joints if j.name},
        "tendon": {model.tendon(t).name for t in range(model.ntendon) if model.tendon(t).name},
        "site": {x.name for x in sites},
        "body": {body_name(model, b) for b in keep if b not in frames} | {"world"},
        "geom": {x.geom_name for x in [*meshes, *simple] if x.geom_name},
    }
    extra_parts: list[ET.Element] = []
    tendon_section, names["tendon"] = mjcf_extra.tendons(model, names, rep.warn)
    for section in (
        tendon_section,
        mjcf_extra.equalities(model, names, rep.warn, mjcf_extra.welds_with_relpose(spec, model)),
        mjcf_extra.contacts(model, names, rep.warn),
    ):
        if section is not None:
            extra_parts.append(section)
    actuators, carried_actuators, kept_actuators = _actuators(model, spec, names, rep)
    option, flag, option_unheld = options_from_model(model)
    if option_unheld:
        rep.warn(f"<option> fields {option_unheld} dropped (no HRDF key)")
    kept_names = {
        "body": {body_name(model, b) for b in keep if b not in frames},
        "xbody": {body_name(model, b) for b in keep if b not in frames},
        "site": {x.name for x in sites},
        "joint": {x.name for x in joints},
        "actuator": {x.name for x in actuators} | {e.get("name") for e in carried_actuators},
        "geom": {x.geom_name for x in [*meshes, *simple] if x.geom_name},
        "tendon": names["tendon"],
    }
    in_extra = {"actuator": {e.get("name") for e in carried_actuators if e.get("name")}}
    sensors, extra_sensors = _sensors(model, kept_names, rep, in_extra)
    _report_scene(model, rep, _carried_instances(carried_actuators))

    if carried_actuators:
        used = {e.get("instance") for e in carried_actuators if e.tag == "plugin"}
        instances = _plugin_instances(spec, used - {None})
        if instances is not None:
            extra_parts.insert(0, instances)
        section = ET.Element("actuator")
        section.extend(carried_actuators)
        extra_parts.append(section)
    if extra_sensors:
        section = ET.Element("sensor")
        section.extend(extra_sensors)
        extra_parts.append(section)
    if model.nkey:
        extra_parts.append(_keyframes(model, keep, kept_actuators, rep))
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
        option=option,
        flag=flag,
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
        meta=Meta(simulator_config=sim, body_name_config=None, mjcf_size=nuser_from_model(model)),
        mjcf_extra=extra,
        root_dir=store.root,
        temp_assets=store.lifetime,
    )
    warn_massless_moving(hrdf, rep, '<body name="{}">')
    warnings = rep.finish(strict)
    return ParseResult(hrdf, warnings, str(path))
