"""The option groups every command shares, so that their help cannot drift: the robot
argument's description, the robot-source options (handed to the readers through
:func:`robotwright.sources.given_source_options`), ``--overwrite`` and
``--strict``/``--strict-all``."""

from __future__ import annotations

import argparse
from typing import Any

from robotwright._bounds import Bound
from robotwright._names import shown
from robotwright.sources import MJCF_OPTIONS, URDF_OPTIONS

__all__ = [
    "OVERWRITE_HELP",
    "ROBOT_SOURCE_HELP",
    "add_overwrite_flag",
    "add_source_options",
    "add_strict_flags",
    "parse_xacro_arg",
    "source_options",
]

#: What a robot argument of any command takes: the help text every command shows (a test
#: checks each one does, so that help cannot lag behind what the readers take).
ROBOT_SOURCE_HELP = (
    "a robot: a name ('robotwright robots' lists them), an HRDF folder, or a URDF (.urdf), "
    "xacro (.xacro), MJCF (.xml, .mjcf) or USD (.usd, .usda, .usdc) file"
)

OVERWRITE_HELP = "replace an existing output (without it an existing output is refused)"


def add_overwrite_flag(parser: argparse.ArgumentParser) -> None:
    """Add ``--overwrite`` (``args.overwrite``, default False) to a command's parser."""
    parser.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP)


def _float_arg(what: str, *, positive: bool) -> Any:
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        ok = value > 0 if positive else value >= 0
        if not ok or value == float("inf"):
            raise argparse.ArgumentTypeError(f"{text!r}: expected a finite {what}")
        return value

    return parse


def parse_xacro_arg(text: str) -> tuple[str, str]:
    """``NAME:=VALUE`` (xacro's own syntax) of ``--xacro-arg``, as ``(NAME, VALUE)``."""
    name, sep, value = text.partition(":=")
    if not sep or not name.strip():
        raise argparse.ArgumentTypeError(f"{text!r}: expected NAME:=VALUE")
    return name.strip(), value


#: A servo gain from the command line: kp [N m/rad or N/m], kv [N m s/rad or N s/m].
GAIN_BOUND = Bound(0.0, 1e9)


def actuator_gain(text: str) -> tuple[str, tuple[float, float]]:
    """``PATTERN=KP,KV`` (or ``PATTERN=KP``) of ``--actuator-gain``."""
    pattern, sep, values = text.rpartition("=")
    try:
        gains = tuple(float(v) for v in values.split(","))
    except ValueError:
        gains = ()
    if (
        not sep
        or not pattern
        or len(gains) not in (1, 2)
        or any(GAIN_BOUND.check(g) is None for g in gains)
    ):
        raise argparse.ArgumentTypeError(
            f"{shown(text)}: expected PATTERN=KP,KV, each {GAIN_BOUND.describe()}"
        )
    return pattern, (gains[0], gains[1] if len(gains) == 2 else 0.0)


def add_source_options(p: argparse.ArgumentParser) -> None:
    """The robot-source options (see the module docstring) on command parser ``p``; an
    option the command already has (``convert`` and ``roundtrip`` define their own,
    with the same meaning) is left as it is."""
    have = set(p._option_string_actions)
    group = p.add_argument_group("robot source (a name, HRDF folder, URDF, xacro or MJCF file)")

    def add(flag: str, **kw: Any) -> None:
        if flag not in have:
            group.add_argument(flag, **kw)

    add(
        "--root-body",
        metavar="NAME",
        help="MJCF: the top-level body that is the robot (when the world holds several)",
    )
    add(
        "--fixed-joints",
        choices=("keep", "merge", "site"),
        help="URDF: a link on a fixed joint stays a body (keep, the default), is merged "
        "into its parent (merge), or becomes a site when massless (site)",
    )
    add(
        "--bound-mass",
        type=_float_arg("mass >= 0 [kg]", positive=False),
        metavar="KG",
        help="URDF: raise masses below KG to KG",
    )
    add(
        "--bound-inertia",
        type=_float_arg("inertia >= 0 [kg m^2]", positive=False),
        metavar="KG_M2",
        help="URDF: raise principal moments below KG_M2 [kg m^2] to it",
    )
    add(
        "--inertia-from-geoms",
        choices=("auto", "never"),
        help="URDF: a link without <inertial> gets the mass and inertia of its collision "
        "geoms (auto, the default) or none (never)",
    )
    add(
        "--density",
        type=_float_arg("density > 0 [kg/m^3]", positive=True),
        metavar="KG_M3",
        help="URDF, --inertia-from-geoms auto: density of those collision geoms (default 1000)",
    )
    add(
        "--floating-base",
        action="store_const",
        const=True,
        default=None,
        help="URDF: give the root link a free joint (a legged robot's base; URDF has none); "
        "render, view and lidar then stand it on the floor",
    )
    add(
        "--actuators",
        choices=("none", "motor", "position", "velocity", "auto"),
        help="URDF: none (default; URDF has no actuators), one torque motor per moving joint "
        "(motor), PD or velocity servos with --actuator-gain (position, velocity), or what "
        "each <transmission> declares (auto)",
    )
    add(
        "--actuator-gain",
        action="append",
        type=actuator_gain,
        metavar="PATTERN=KP,KV",
        help="URDF --actuators position/velocity/auto: servo gains of the joints whose name "
        "matches PATTERN (fnmatch; first match wins; repeatable)",
    )
    add(
        "--xacro-arg",
        action="append",
        type=parse_xacro_arg,
        metavar="NAME:=VALUE",
        help=".xacro: value of $(arg NAME) (repeatable)",
    )


def source_options(args: argparse.Namespace) -> dict[str, Any]:
    """The readers' options given on the command line (only those given)."""
    opts: dict[str, Any] = {}
    for name in (*URDF_OPTIONS, *MJCF_OPTIONS):
        value = getattr(args, name, None)
        if value is not None:
            opts[name] = value
    if getattr(args, "xacro_arg", None):
        opts["xacro_args"] = dict(args.xacro_arg)
    if getattr(args, "actuator_gain", None):
        opts["actuator_gains"] = dict(args.actuator_gain)
    return opts


def add_strict_flags(p: argparse.ArgumentParser, *, strict_help: str, all_help: str) -> None:
    """``--strict`` (``args.strict`` True: fail on a note that changes the physics) and
    ``--strict-all`` (``"all"``: on every note, cosmetic ones too), one or the other
    (see :func:`robotwright.errors.strict_failures`)."""
    strictness = p.add_mutually_exclusive_group()
    strictness.add_argument(
        "--strict", action="store_const", const=True, default=False, help=strict_help
    )
    strictness.add_argument(
        "--strict-all", dest="strict", action="store_const", const="all", help=all_help
    )
