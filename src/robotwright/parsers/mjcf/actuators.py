"""The MJCF reader's actuators: each compiled actuator as an ``actuator.csv`` row where the
table holds it, else carried as its MJCF element in ``extra.xml`` (general dynamics,
gain and bias, plugin actuators with their ``<extension>`` instances)."""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ET

import mujoco
import numpy as np

from robotwright._mjmodel import actuator_count
from robotwright.hrdf.model import (
    Actuator,
)
from robotwright.parsers.mjcf.common import _fmt, _user
from robotwright.parsers.reference import body_name, joint_name
from robotwright.parsers.report import Reporter

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


def _carried_instances(carried: list[ET.Element]) -> int:
    """Plugin instances the carried actuators use (one per actuator configured inline)."""
    named = {e.get("instance") for e in carried if e.tag == "plugin" and e.get("instance")}
    inline = sum(1 for e in carried if e.tag == "plugin" and not e.get("instance"))
    return len(named) + inline
