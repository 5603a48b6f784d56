"""``robotwright validate`` and ``robotwright info``."""

from __future__ import annotations

import argparse
import warnings
from typing import TYPE_CHECKING

from robotwright.cli.options import ROBOT_SOURCE_HELP

if TYPE_CHECKING:  # the readers load when a command runs, not with `robotwright --help`
    from robotwright.hrdf.model import HRDF


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "validate",
        help="check a robot and report every problem",
        description="Check a robot (HRDF folder, URDF, xacro or MJCF file, or a robot name); "
        "print every problem (file, row or element, column, what was expected); exit 1 "
        "when any is an error. A URDF or MJCF is checked as read into HRDF, with the same "
        "checks and MuJoCo compile as a folder.",
    )
    p.add_argument("path", help=ROBOT_SOURCE_HELP)
    p.set_defaults(func=_validate)

    p = sub.add_parser(
        "info",
        help="summarise a robot (bodies, joints, actuators, mass, DoF)",
        description="Print a readable summary of a robot given by name, HRDF folder, or "
        "URDF, xacro or MJCF file.",
    )
    p.add_argument("robot", help=ROBOT_SOURCE_HELP)
    p.set_defaults(func=_info)


def _validate(args: argparse.Namespace) -> int:
    from robotwright.sources import resolve_source

    resolved = resolve_source(args.path)
    path = resolved.path
    problems = _problems(str(path) if resolved.entry is None else args.path, resolved.kind)
    errors = [p for p in problems if p.severity == "error"]
    for p in problems:
        print(f"{p.severity}: {p}")
    if errors:
        print(f"{path}: {len(errors)} error(s), {len(problems) - len(errors)} warning(s)")
        return 1
    print(f"{path}: valid ({len(problems)} warning(s))")
    return 0


def _problems(source: str, kind: str) -> list:
    """Every problem of a robot: an HRDF folder as read and compiled; a URDF or MJCF as
    read into HRDF (a refusal of the reader is its problems), then the same checks."""
    from robotwright.errors import ProblemsError
    from robotwright.generators.compiles import check_compiles, validate_dir
    from robotwright.hrdf.validate import check_model
    from robotwright.sources import load_robot, resolve_source

    if kind == "hrdf":
        return validate_dir(resolve_source(source).path)

    try:
        hrdf = load_robot(source)
    except ProblemsError as exc:
        return list(exc.problems)
    problems = check_model(hrdf, check_files=True)
    if not any(p.severity == "error" for p in problems):
        problems += check_compiles(hrdf)
    return problems


def _table(headers: list[str], rows: list[list[str]]) -> str:
    widths = [
        max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(headers)
    ]
    line = "  ".join(h.ljust(w) for h, w in zip(headers, widths, strict=True)).rstrip()
    out = [line, "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    return "\n".join(out)


def format_info(hrdf: HRDF) -> str:
    """A readable multi-table summary of a robot: masses in kg (3 decimals everywhere),
    joint ranges in rad (hinge, ball) or m (slide), actuator limits with their units."""
    s = hrdf.summary()
    head = (
        f"robot {s['name']}: {s['bodies']} bodies, {s['joints']} joints, "
        f"{s['actuators']} actuators, {s['dof']} DoF, total mass {s['total_mass']:.3f} kg, "
        f"{'floating' if s['floating_base'] else 'fixed'} base"
    )
    roots = hrdf.root_indices
    if len(roots) > 1:
        free = {j.body for j in hrdf.joints if j.type == "free"}
        listed = ", ".join(
            f"{hrdf.bodies[i].name} ({'free' if hrdf.bodies[i].name in free else 'fixed'})"
            for i in roots
        )
        head += f"; a scene of {len(roots)} roots: {listed}"
    bodies = [
        [
            b.name,
            hrdf.bodies[b.parent].name if b.parent >= 0 else "-",
            f"{b.mass:.3f}",
            ", ".join(f"{j.name or '(free)'}:{j.type}" for j in hrdf.joints_of(b.name)) or "-",
        ]
        for b in hrdf.bodies
    ]
    joint_types = {j.name: j.type for j in hrdf.joints}

    def unit(j_type: str | None) -> str:
        return "m" if j_type == "slide" else "rad"

    joints = [
        [
            j.name or "(free)",
            j.type,
            j.body,
            "-" if j.range is None else f"[{j.range[0]:.4g}, {j.range[1]:.4g}] {unit(j.type)}",
        ]
        for j in hrdf.joints
    ]

    def limit(value: float | None, joint: str, per: str) -> str:
        if value is None:
            return "-"
        j_type = joint_types.get(joint)
        if per == "force":
            return f"{value:g} {'N' if j_type == 'slide' else 'N m'}"
        return f"{value:g} {unit(j_type)}/s"

    acts = [
        [
            # hurodes writes unnamed actuators; they stay unnamed in the MJCF we write.
            a.name or "(unnamed)",
            a.type,
            a.joint,
            limit(a.peak_torque, a.joint, "force"),
            limit(a.peak_velocity, a.joint, "speed"),
        ]
        for a in hrdf.actuators
    ]
    parts = [
        head,
        "",
        _table(["body", "parent", "mass [kg]", "joints"], bodies),
        "",
        _table(["joint", "type", "body", "range"], joints),
    ]
    if acts:
        parts += [
            "",
            _table(["actuator", "type", "joint", "peak torque/force", "peak velocity"], acts),
        ]
    return "\n".join(parts)


def _info(args: argparse.Namespace) -> int:
    from robotwright.hrdf.io import HRDFWarning
    from robotwright.sources import load_robot_with_notes

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HRDFWarning)
        hrdf, _ = load_robot_with_notes(args.robot)  # a summary: what was not kept is not
    print(format_info(hrdf))
    return 0
