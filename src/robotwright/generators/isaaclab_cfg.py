"""An Isaac Lab ``ArticulationCfg`` for a robot, written as a Python module.

``write_articulation_cfg(hrdf, "robot_cfg.py")`` exports the robot to USD beside the
module (:func:`~robotwright.generators.usd.to_usd`) and writes::

    ROBOT_CFG = ArticulationCfg(
        spawn=sim_utils.UsdFileCfg(usd_path=USD_PATH),
        init_state=ArticulationCfg.InitialStateCfg(pos=..., joint_pos={...}),
        actuators={"group_0": ImplicitActuatorCfg(joint_names_expr=[...], stiffness=...,
                   damping=..., joint_effort_limit=..., joint_velocity_limit=...), ...},
    )

one ``ImplicitActuatorCfg`` per set of equal values (stiffness and damping from
``p_gain``/``d_gain`` [N m/rad, N m s/rad], effort from ``peak_torque`` or the force
range, velocity from ``peak_velocity``; a gain the HRDF lacks is ``None``, which Isaac
Lab reads as "the USD drive's", a limit it lacks is left out; Isaac Lab 3's
``joint_effort_limit``/``joint_velocity_limit``, of which ``effort_limit_sim`` and
``velocity_limit_sim`` are deprecated aliases). Every name is written as a Python string literal (``repr``) and, in a
joint expression, as an escaped regular expression matching exactly that joint; every
number as a float literal. The module imports only Isaac Lab and ``pathlib``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from pathlib import Path

import mujoco

from robotwright._atomic import write_text_atomic
from robotwright._names import shown
from robotwright._notes import name_list
from robotwright._outputs import check_overwrite
from robotwright.errors import GeneratorError
from robotwright.generators.standing import fixed_walker, initial_state, walking_bodies
from robotwright.hrdf.model import HRDF

__all__ = [
    "articulation_cfg_source",
    "cfg_number",
    "docstring_literal",
    "module_docstring",
    "initial_state",
    "module_outputs",
    "setup_warnings",
    "write_articulation_cfg",
    "write_module_beside",
]


def cfg_number(value: float) -> str:
    """``value`` as a Python float literal for a generated config module."""
    value = float(value)
    if not math.isfinite(value):
        raise GeneratorError(f"cannot write a non-finite value {value!r} into a config module")
    return repr(value)


def actuator_groups(hrdf: HRDF) -> list[tuple[dict[str, float], list[str]]]:
    """Actuated joints grouped by equal drive values (in first-seen order)."""
    groups: dict[tuple, tuple[dict[str, float], list[str]]] = {}
    for act in hrdf.actuators:
        values: dict[str, float] = {}
        if act.p_gain is not None:
            values["stiffness"] = float(act.p_gain)
        if act.d_gain is not None:
            values["damping"] = float(act.d_gain)
        if act.peak_torque is not None:
            values["joint_effort_limit"] = float(act.peak_torque)
        elif act.force_range is not None:
            values["joint_effort_limit"] = float(max(abs(v) for v in act.force_range))
        if act.peak_velocity is not None:
            values["joint_velocity_limit"] = float(act.peak_velocity)
        key = tuple(sorted(values.items()))
        groups.setdefault(key, (values, []))[1].append(act.joint)
    return list(groups.values())


def setup_warnings(hrdf: HRDF) -> list[str]:
    """What would surprise a user training this robot: no drives at all, a fixed base on
    a robot whose bodies say it walks, a position drive without damping. One line each,
    naming the robot, the joints and the option that changes it."""
    out = []
    name = shown(hrdf.name)
    if not hrdf.actuators:
        out.append(
            f"robot {name} has no actuators: its USD has no joint drives and the config "
            "actuators={}; give --actuators position --actuator-gain 'PATTERN=KP,KV' (URDF "
            "sources) or a robot file with actuators"
        )
    feet = walking_bodies(hrdf)
    if not hrdf.floating_base and feet:
        out.append(fixed_walker(hrdf.name, feet))
    undamped = [
        a.joint
        for a in hrdf.actuators
        if (a.type or "motor") == "position" and (a.p_gain or 0.0) > 0 and not (a.d_gain or 0.0)
    ]
    if undamped:
        out.append(
            f"robot {name}: position drives without damping (kv = 0) on "
            f"{name_list(undamped, 4)}: they oscillate; give --actuator-gain 'PATTERN=KP,KV'"
        )
    return out


def module_docstring(lines: list[str], clamped: list[str]) -> str:
    """A generated module's docstring: ``lines``, then the joints whose reference
    position was clamped into its range (the frameworks check ranges), one each."""
    if clamped:
        lines = [
            *lines,
            "",
            "Joint positions clamped into their ranges:",
            *(f"  {c}" for c in clamped),
        ]
    return docstring_literal("\n".join(lines) + "\n")


def docstring_literal(text: str) -> str:
    """``text`` as a module docstring. It holds names from the robot file, so it is a
    plain triple-quoted block only when no character could end or escape it (printable
    characters and newlines, no quote or backslash); otherwise one escaped literal."""
    plain = all(c == "\n" or (c.isprintable() and c not in '"\\') for c in text)
    return f'"""{text}"""' if plain else repr(text)


def articulation_cfg_source(
    hrdf: HRDF,
    model: mujoco.MjModel,
    usd_name: str,
    joint_pos: Sequence[tuple[str, float]] = (),
) -> tuple[str, list[str]]:
    """The module's text and the notes (joints whose reference pose was clamped);
    ``joint_pos``: ``(fnmatch pattern, position)`` pairs, first match wins (see
    :func:`initial_state`)."""
    pos, joint_pos_by_name, clamped = initial_state(model, joint_pos)
    doc = [
        f"Isaac Lab ArticulationCfg of the robot {hrdf.name!r}, written by robotwright.",
        "",
        "The USD beside this file holds the robot with its joint drives; the actuator",
        "groups below repeat the drive values (stiffness N m/rad, damping N m s/rad,",
        "effort N m, velocity rad/s) so that Isaac Lab applies them.",
    ]
    lines = [
        module_docstring(doc, clamped),
        "",
        "from pathlib import Path",
        "",
        "import isaaclab.sim as sim_utils",
        "from isaaclab.actuators import ImplicitActuatorCfg",
        "from isaaclab.assets import ArticulationCfg",
        "",
        f"USD_PATH = str(Path(__file__).with_name({usd_name!r}))",
        "",
        "ROBOT_CFG = ArticulationCfg(",
        "    spawn=sim_utils.UsdFileCfg(usd_path=USD_PATH),",
        "    init_state=ArticulationCfg.InitialStateCfg(",
        f"        pos=({', '.join(cfg_number(v) for v in pos)}),",
        "        joint_pos={",
    ]
    lines += [
        f"            {re.escape(name)!r}: {cfg_number(q)},"
        for name, q in joint_pos_by_name.items()
    ]
    lines += ["        },", "    ),", "    actuators={"]
    for k, (values, joints) in enumerate(actuator_groups(hrdf)):
        exprs = ", ".join(repr(re.escape(j)) for j in joints)
        lines.append(f"        {f'group_{k}'!r}: ImplicitActuatorCfg(")
        lines.append(f"            joint_names_expr=[{exprs}],")
        for key in ("stiffness", "damping"):  # None: Isaac Lab takes the USD drive's
            lines.append(f"            {key}={cfg_number(values[key]) if key in values else None},")
        for key in ("joint_effort_limit", "joint_velocity_limit"):
            if key in values:
                lines.append(f"            {key}={cfg_number(values[key])},")
        lines.append("        ),")
    lines += ["    },", ")", ""]
    return "\n".join(lines), clamped


def write_articulation_cfg(
    hrdf: HRDF,
    output: str | Path,
    *,
    overwrite: bool = False,
    strict: bool = False,
    layout: str = "flat",
    joint_pos: Sequence[tuple[str, float]] = (),
) -> tuple[Path, Path]:
    """Write ``<output>`` (the module) and the robot's USD beside it, named after the
    module (``robots/go2_cfg.py`` and ``robots/go2_cfg.usd``: the robot file's own name
    never chooses a file name). Both go through the output gate (a temporary of their
    own, then a rename).

    Args:
        layout: ``"flat"`` (the default: every body a child of the robot's prim, so that
            ``{ENV_REGEX_NS}/Robot/<body>`` names a body, as the LiDAR's ``prim_path``
            and Isaac Lab's contact sensors need) or ``"nested"``; see
            :func:`~robotwright.generators.usd.to_usd`.
        joint_pos: the initial joint positions, ``(fnmatch pattern, value)`` pairs
            (rad or m; first match wins): a legged robot's standing pose.

    Each :func:`setup_warnings` line is a :class:`~robotwright.errors.RobotSetupWarning`.

    Returns:
        (module path, USD path).
    """
    import warnings

    from robotwright.errors import RobotSetupWarning
    from robotwright.generators.usd import to_usd

    out, usd = module_outputs(output, ".usd", overwrite)
    done = to_usd(
        hrdf,
        usd,
        overwrite=overwrite,
        strict=strict,
        layout=layout,
        root_at_origin=True,
        geometry=True,  # the standing height comes from the collision geometry
    )
    # The initial state comes from the MJCF the USD was made from.
    write_module_beside(
        out, usd, lambda: articulation_cfg_source(hrdf, done.mjcf_model, usd.name, joint_pos)[0]
    )
    for line in setup_warnings(hrdf):
        warnings.warn(line, RobotSetupWarning, stacklevel=2)
    return out, usd


def module_outputs(output: str | Path, side_suffix: str, overwrite: bool) -> tuple[Path, Path]:
    """A generated module's path and the path of the file written beside it (named after
    the module, ``side_suffix``), once checked: a ``.py`` name, and neither in the way
    without ``overwrite``."""
    out = Path(output)
    if out.suffix != ".py":
        raise GeneratorError(f"{out}: expected a Python module file name ending in .py")
    side = out.with_suffix(side_suffix)
    check_overwrite([out, side], overwrite)
    return out, side


def write_module_beside(out: Path, side: Path, text: Callable[[], str]) -> None:
    """Write the module ``out`` (its ``text()``) through the output gate once the file
    ``side`` it loads is written; on any failure ``side`` is removed again (no half of
    the pair without the other)."""
    try:
        write_text_atomic(out, text())
    except BaseException:
        side.unlink(missing_ok=True)
        raise
