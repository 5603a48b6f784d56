"""The URDF reader's tree: the links and joints as a tree (one root, no loops), each
joint's record (limits, dynamics, mimic) and each body's."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from robotwright._names import shown
from robotwright._xmlsafe import describe
from robotwright.errors import ConversionError, Problem
from robotwright.hrdf.model import (
    Actuator,
    Body,
    Joint,
)
from robotwright.parsers import inertia as inr
from robotwright.parsers.report import Reporter
from robotwright.parsers.urdf import actuators as acts
from robotwright.parsers.urdf.common import _JOINT_TYPES, URDFOptions, _floats, _num, _t


@dataclass
class _Tree:
    """The link tree of a URDF: elements by name, joints, and depth-first link order."""

    links: dict[str, ET.Element]
    joints: list[ET.Element]
    parent_of: dict[str, ET.Element]
    children: dict[str, list[ET.Element]]
    order: list[str]
    roots: list[str]


def _read_tree(root: ET.Element, path: Path) -> _Tree:
    """Links and joints checked (names, references, one parent each, one root, no cycle).

    Raises:
        ConversionError: listing every problem found.
    """
    errors: list[Problem] = []
    links: dict[str, ET.Element] = {}
    for link in root.findall("link"):
        name = link.get("name")
        if not name:
            errors.append(Problem(str(path), "link without a name", element="<link>"))
        elif name in links:
            errors.append(Problem(str(path), "duplicate link name", element=describe(link)))
        else:
            links[name] = link
    joints: list[ET.Element] = []
    parent_of: dict[str, ET.Element] = {}
    seen_joint: set[str] = set()
    for j in root.findall("joint"):
        where = describe(j)
        jname, jtype = j.get("name"), j.get("type")
        par = j.find("parent")
        chi = j.find("child")
        if not jname:
            errors.append(Problem(str(path), "joint without a name", element=where))
            continue
        if jname in seen_joint:
            errors.append(Problem(str(path), "duplicate joint name", element=where))
            continue
        seen_joint.add(jname)
        if jtype not in _JOINT_TYPES:
            errors.append(
                Problem(
                    str(path),
                    f"type {shown(jtype)}: expected one of {sorted(_JOINT_TYPES)}",
                    element=where,
                )
            )
            continue
        if par is None or chi is None:
            errors.append(
                Problem(str(path), "expected <parent link> and <child link>", element=where)
            )
            continue
        p, c = par.get("link"), chi.get("link")
        for role, ln in (("parent", p), ("child", c)):
            if ln not in links:
                errors.append(
                    Problem(str(path), f"{role} link {shown(ln)} is not defined", element=where)
                )
        if c in parent_of:
            errors.append(Problem(str(path), f"link '{c}' has two parent joints", element=where))
            continue
        if p in links and c in links:
            parent_of[c] = j
            joints.append(j)
    roots = [n for n in links if n not in parent_of]
    if not errors and not links:
        errors.append(Problem(str(path), "the robot has no links"))
    elif not errors and len(roots) != 1:
        errors.append(
            Problem(str(path), f"expected exactly one root link, found {roots or 'none (cycle)'}")
        )
    if errors:
        raise ConversionError(errors, summary=f"invalid URDF {path}")

    children: dict[str, list[ET.Element]] = {n: [] for n in links}
    for j in joints:
        children[j.find("parent").get("link")].append(j)

    # Depth-first order from the root (document order of joints among siblings).
    order: list[str] = []
    stack = [roots[0]]
    while stack:
        n = stack.pop()
        order.append(n)
        stack.extend(reversed([j.find("child").get("link") for j in children[n]]))
    if len(order) != len(links):
        raise ConversionError([Problem(str(path), "the joints do not form a tree (cycle)")])

    return _Tree(links, joints, parent_of, children, order, roots)


def _joint_record(
    j: ET.Element, body: str, opt: URDFOptions, rep: Reporter
) -> tuple[Joint, Actuator | None, tuple[str, str, float, float] | None, bool]:
    """A moving URDF joint as an HRDF joint, its motor (``actuators="motor"``), its mimic
    ``(follower, leader, multiplier, offset)`` and whether effort/velocity were dropped."""
    where = describe(j)
    jtype = j.get("type")
    axis_el = j.find("axis")
    axis = _floats(
        axis_el.get("xyz") if axis_el is not None else None, 3, (1, 0, 0), where, "<axis xyz>", rep
    )
    if np.linalg.norm(axis) < 1e-12:
        raise ConversionError([Problem(rep.file, "axis is zero", element=where)])
    limit = j.find("limit")
    rng = None
    if jtype in ("revolute", "prismatic"):
        if limit is None or limit.get("lower") is None and limit.get("upper") is None:
            rep.warn(f"{jtype} joint without <limit lower upper>: kept unlimited", where)
        else:
            rng = (_num(limit, "lower", 0.0, where, rep), _num(limit, "upper", 0.0, where, rep))
            if rng[0] == rng[1]:
                rep.warn(
                    f"lower = upper = {rng[0]}: limit ignored, joint kept unlimited "
                    "(as MuJoCo's URDF importer does)",
                    where,
                )
                rng = None
    if jtype == "spherical" and limit is not None and limit.get("lower") is not None:
        rep.warn("<limit> of a spherical joint dropped (a ball joint, as MuJoCo imports it)", where)
    dyn = j.find("dynamics")
    joint = Joint(
        name=j.get("name"),
        body=body,
        type={"prismatic": "slide", "spherical": "ball"}.get(jtype, "hinge"),
        axis=_t(axis),
        range=rng,
        dynamic_friction=_num(dyn, "friction", 0.0, where, rep),
        viscous_friction=_num(dyn, "damping", 0.0, where, rep),
    )
    effort = _num(limit, "effort", 0.0, where, rep)
    velocity = _num(limit, "velocity", 0.0, where, rep)
    if effort and jtype != "spherical":
        # MuJoCo's URDF importer (3.11, 4.x) clamps the joint's actuator force to +-|effort|.
        joint = replace(joint, actuatorfrcrange=(-abs(effort), abs(effort)))
    actuator = None
    if opt.actuators == "motor" and effort > 0 and jtype != "spherical":
        actuator = Actuator(
            joint=joint.name,
            name=joint.name,
            type="motor",
            peak_torque=effort,
            peak_velocity=velocity if velocity > 0 else None,
            ctrl_range=(-effort, effort),
        )
        acts.LOG.info("%s: %s", rep.file, acts.describe([actuator])[0])
    for tag in ("safety_controller", "calibration"):
        if j.find(tag) is not None:
            rep.warn(f"<{tag}> dropped (no HRDF equivalent)", where)
    mimic_el = j.find("mimic")
    mimic = None
    if mimic_el is not None:
        mimic = (
            joint.name,
            mimic_el.get("joint"),
            _num(mimic_el, "multiplier", 1.0, where, rep),
            _num(mimic_el, "offset", 0.0, where, rep),
        )
    return joint, actuator, mimic, actuator is None and (effort > 0 or velocity > 0)


def _mimic_extra(
    mimics: list[tuple[str, str, float, float]], moving: set[str], rep: Reporter
) -> str | None:
    """``<equality>`` joint couplings ``q_follower = offset + multiplier * q_leader``."""
    lines = []
    for follower, leader, mult, off in mimics:
        if leader not in moving or follower not in moving:
            rep.warn(
                f"mimic of joint '{leader}' dropped: no moving joint of that name",
                f'<joint name="{follower}">',
            )
            continue
        lines.append(
            f'    <joint joint1="{follower}" joint2="{leader}" polycoef="{shown(off)} {shown(mult)} 0 0 0"/>'
        )
    if not lines:
        return None
    return "<mujoco>\n  <equality>\n" + "\n".join(lines) + "\n  </equality>\n</mujoco>\n"


def _body_record(
    name: str, b: dict, index: dict[str, int], opt: URDFOptions, rep: Reporter
) -> Body:
    """One body: its parts (link inertials, merged ones included) combined and
    diagonalised, with the repairs the options ask for (each reported)."""
    if len(b["parts"]) == 1:
        mass, com, tensor = b["parts"][0]
    elif b["parts"]:
        mass, com, tensor = inr.combine(b["parts"])
    else:
        mass, com, tensor = 0.0, np.zeros(3), np.zeros((3, 3))
    if len(b["parts"]) == 1 and b.get("principal") is not None:
        diag, iquat = b["principal"]  # MuJoCo's own, from the link's geoms
    else:
        diag, iquat = inr.diagonalize(tensor)
    where = f'<link name="{name}">'
    if mass > 0 and not inr.is_physical(diag):
        if opt.balance_inertia and min(diag) > 0:
            fixed = inr.balance(diag)
            rep.warn(f"principal moments {diag} violate A + B >= C: balanced to {fixed}", where)
            diag = fixed
        else:
            rep.warn(
                f"non-physical inertia: principal moments {diag} (negative or A + B < C)", where
            )
    if opt.bound_mass is not None and mass < opt.bound_mass:
        rep.warn(f"mass {mass} raised to bound_mass {opt.bound_mass}", where)
        mass = opt.bound_mass
    if opt.bound_inertia is not None and min(diag) < opt.bound_inertia:
        new = tuple(max(v, opt.bound_inertia) for v in diag)
        rep.warn(f"principal moments {diag} raised to bound_inertia: {new}", where)
        diag = new
    pose = b["pose"]
    return Body(
        name=name,
        parent=-1 if b["parent"] is None else index[b["parent"]],
        pos=_t(pose.pos),
        quat=pose.quat,
        mass=float(mass),
        inertial_pos=_t(com),
        inertial_quat=iquat,
        diag_inertia=diag,
    )
