"""Actuators for a URDF, which has none of its own (``URDFOptions.actuators``).

Modes (``actuators=``; ``"none"`` and ``"motor"`` are handled by the URDF parser):

- ``"position"``: a position servo (PD) per actuated joint: ``kp``/``kv`` from
  ``actuator_gains`` (the first ``fnmatch`` pattern matching the joint name), force
  range ``+-effort`` from ``<limit effort>``, control range = the joint range (a target
  position; unlimited joints get no control range).
- ``"velocity"``: a velocity servo per actuated joint: gain ``kv`` from
  ``actuator_gains``, force range ``+-effort``, control range ``+-velocity`` from
  ``<limit velocity>``.
- ``"auto"``: the type each joint's interface declares: ros2_control
  ``<command_interface name="position|velocity|effort">`` (the first one listed; its
  ``min``/``max`` params become the control range), else a ``<transmission>`` joint's
  ``hardwareInterface`` (``PositionJointInterface`` ...); ``effort`` makes a torque motor
  with control range ``+-effort``.

Actuated joints: those the URDF declares in ``<transmission>``/``<ros2_control>`` when
it declares any, else every moving joint. No value is invented: a position/velocity
servo without a matching gain pattern is an error naming the joint and the option, and
a joint that gets no actuator is reported. ``<mechanicalReduction>`` is reported, not
applied (URDF ``<limit>`` values are joint-side already). Each actuator made is logged
at INFO level on the ``robotwright.parsers`` logger; :func:`describe` gives the same
lines for an HRDF.
"""

from __future__ import annotations

import fnmatch
import logging
import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from robotwright._names import shown
from robotwright._notes import name_list
from robotwright.errors import ConversionError, Problem
from robotwright.hrdf.model import Actuator, Joint
from robotwright.parsers.report import Reporter

LOG = logging.getLogger("robotwright.parsers")

#: Every value of ``URDFOptions.actuators``.
ACTUATOR_MODES = ("none", "motor", "position", "velocity", "auto")
#: The modes this module builds (``"motor"`` is built by the URDF parser itself).
MODES = ("position", "velocity", "auto")
#: Top-level URDF elements this module reads.
INTERFACE_TAGS = ("transmission", "ros2_control")

_INTERFACE_TYPES = {"position": "position", "velocity": "velocity", "effort": "motor"}
_HARDWARE_TYPES = {
    "PositionJointInterface": "position",
    "VelocityJointInterface": "velocity",
    "EffortJointInterface": "motor",
}


def parse_gains(gains: Mapping[str, Any] | None) -> dict[str, tuple[float, float]] | None:
    """``{pattern: (kp, kv)}`` validated (finite, kp >= 0, kv >= 0); a bare number is
    ``kp`` with ``kv = 0``.

    Raises:
        ValueError: a gain that is not two non-negative finite numbers.
    """
    if gains is None:
        return None
    out: dict[str, tuple[float, float]] = {}
    for pattern, value in gains.items():
        values = [value] if isinstance(value, (int, float)) else list(value)
        if len(values) == 1:
            values.append(0.0)
        try:
            kp, kv = (float(v) for v in values)
        except (TypeError, ValueError):
            raise ValueError(
                f"actuator_gains[{shown(pattern)}] = {shown(value)}: expected (kp, kv), two numbers"
            ) from None
        if not (math.isfinite(kp) and math.isfinite(kv) and kp >= 0 and kv >= 0):
            raise ValueError(
                f"actuator_gains[{shown(pattern)}] = {shown(value)}: expected finite kp >= 0, kv >= 0"
            )
        out[str(pattern)] = (kp, kv)
    return out


def _float(text: str | None) -> float | None:
    try:
        value = float(text) if text is not None else None
    except ValueError:
        return None
    return value if value is not None and math.isfinite(value) else None


def declared_interfaces(root: ET.Element, rep: Reporter) -> dict[str, dict[str, Any]]:
    """Joint name -> {"type", "ctrl_range", "source"} from ``<ros2_control>`` (first)
    and ``<transmission>`` elements."""
    found: dict[str, dict[str, Any]] = {}
    for block in root.findall("ros2_control"):
        for joint in block.findall("joint"):
            name = joint.get("name")
            commands = joint.findall("command_interface")
            if not name or not commands:
                continue
            first = commands[0]
            kind = _INTERFACE_TYPES.get(first.get("name", ""))
            if kind is None:
                rep.warn(
                    f"command_interface '{first.get('name')}' has no MuJoCo actuator type: "
                    "joint gets none",
                    f'<ros2_control> <joint name="{name}">',
                )
                found[name] = {"type": None, "source": "ros2_control"}
                continue
            params = {p.get("name"): _float(p.text) for p in first.findall("param")}
            lo, hi = params.get("min"), params.get("max")
            found[name] = {
                "type": kind,
                "ctrl_range": (lo, hi) if lo is not None and hi is not None else None,
                "source": f"ros2_control command_interface '{first.get('name')}'",
            }
            if len(commands) > 1:
                rep.warn(
                    f"{len(commands)} command interfaces: the first ('{first.get('name')}') "
                    "makes the actuator, the others are not kept",
                    f'<ros2_control> <joint name="{name}">',
                )
    for tr in root.findall("transmission"):
        where = f'<transmission name="{tr.get("name")}">'
        for joint in tr.findall("joint"):
            name = joint.get("name")
            if not name or name in found:
                continue
            hw = joint.findtext("hardwareInterface") or ""
            kind = _HARDWARE_TYPES.get(hw.strip().rsplit("/", 1)[-1])
            found[name] = {"type": kind, "ctrl_range": None, "source": f"transmission {hw}"}
            if kind is None:
                rep.warn(f"hardwareInterface '{hw}' has no MuJoCo actuator type", where)
        for actuator in tr.findall("actuator"):
            reduction = _float(actuator.findtext("mechanicalReduction"))
            if reduction is not None and reduction != 1.0:
                rep.warn(
                    f"mechanicalReduction {reduction:g} not applied (the joint's <limit> "
                    "values are joint-side; gear stays 1)",
                    where,
                )
    return found


def _limits(root: ET.Element) -> dict[str, tuple[float, float]]:
    out = {}
    for j in root.findall("joint"):
        limit = j.find("limit")
        if limit is not None and j.get("name"):
            effort = _float(limit.get("effort")) or 0.0
            velocity = _float(limit.get("velocity")) or 0.0
            out[j.get("name")] = (effort, velocity)
    return out


def _gain(
    gains: Mapping[str, tuple[float, float]] | None, joint: str
) -> tuple[str, tuple[float, float]] | None:
    for pattern, value in (gains or {}).items():
        if fnmatch.fnmatchcase(joint, pattern):
            return pattern, value
    return None


def make_actuators(
    root: ET.Element,
    joints: Sequence[Joint],
    mode: str,
    gains: Mapping[str, tuple[float, float]] | None,
    rep: Reporter,
) -> tuple[list[Actuator], set[str]]:
    """The actuators of ``mode`` for the moving ``joints`` of the URDF ``root``, and the
    names of the joints whose effort/velocity limits they keep.

    Raises:
        ConversionError: a position or velocity servo whose joint matches no pattern of
            ``actuator_gains`` (every such joint is listed).
    """
    declared = declared_interfaces(root, rep)
    limits = _limits(root)
    moving = [j for j in joints if j.type in ("hinge", "slide")]
    for name in sorted(set(declared) - {j.name for j in moving}):
        rep.warn(f"interface of joint '{name}', which is not a moving joint of the robot: ignored")
    if declared:
        actuated = [j for j in moving if j.name in declared]
        left = [j.name for j in moving if j.name not in declared]
        if left:
            rep.warn(
                f"{len(left)} moving joint(s) without a transmission/ros2_control interface "
                "get no actuator: " + name_list(left)
            )
    else:
        actuated = moving
    made: list[Actuator] = []
    missing: list[Problem] = []
    kept: set[str] = set()
    for joint in actuated:
        iface = declared.get(joint.name, {})
        kind = mode if mode != "auto" else iface.get("type")
        if mode == "auto" and not iface:
            rep.warn(f"joint '{joint.name}' declares no interface: no actuator (auto)")
            continue
        if kind is None:
            continue
        effort, velocity = limits.get(joint.name, (0.0, 0.0))
        act = Actuator(
            joint=joint.name,
            name=joint.name,
            type=kind,
            peak_torque=effort if effort > 0 else None,
            peak_velocity=velocity if velocity > 0 else None,
        )
        if effort > 0 or velocity > 0:
            kept.add(joint.name)
        ctrl = iface.get("ctrl_range")
        how = iface.get("source", f"actuators='{mode}'")
        if kind == "motor":
            if ctrl is None and effort <= 0:
                rep.warn(f"joint '{joint.name}': torque motor without <limit effort>: unlimited")
            act = replace(act, ctrl_range=ctrl or ((-effort, effort) if effort > 0 else None))
        else:
            found = _gain(gains, joint.name)
            if found is None:
                gain_name = "kp" if kind == "position" else "kv"
                missing.append(
                    Problem(
                        rep.file,
                        f"{kind} actuator needs {gain_name}: no pattern of actuator_gains "
                        f"(--actuator-gain PATTERN=KP,KV) matches joint '{joint.name}'",
                        element=f'<joint name="{joint.name}">',
                    )
                )
                continue
            pattern, (kp, kv) = found
            if kind == "position":
                act = replace(act, p_gain=kp, d_gain=kv, ctrl_range=ctrl or joint.range)
            else:
                vel = (-velocity, velocity) if velocity > 0 else None
                act = replace(act, d_gain=kv, ctrl_range=ctrl or vel)
            how += f", gains of '{pattern}'"
            if effort > 0:
                act = replace(act, force_range=(-effort, effort))
        made.append(act)
        LOG.info("%s: %s", rep.file, _line(act, how))
    if missing:
        raise ConversionError(missing, summary=f"actuators for {rep.file}: gains missing")
    return made, kept


def _line(act: Actuator, how: str) -> str:
    parts = [f"{act.type} actuator '{act.name}' on joint '{act.joint}'"]
    if act.p_gain is not None:
        parts.append(f"kp={act.p_gain:g}")
    if act.d_gain is not None:
        parts.append(f"kv={act.d_gain:g}")
    if act.ctrl_range is not None:
        parts.append(f"ctrlrange=[{act.ctrl_range[0]:g}, {act.ctrl_range[1]:g}]")
    if act.force_range is not None:
        parts.append(f"forcerange=[{act.force_range[0]:g}, {act.force_range[1]:g}]")
    return " ".join(parts) + f" ({how})"


def describe(actuators: Sequence[Actuator]) -> list[str]:
    """One line per actuator: type, joint, gains and ranges (for reports)."""
    return [_line(a, "from the URDF") for a in actuators]
