"""``robotwright convert SRC -o DST`` and ``robotwright roundtrip SOURCE``."""

from __future__ import annotations

import argparse
import functools
import logging
import sys
import warnings
from collections.abc import Callable
from pathlib import Path

from robotwright._outputs import check_overwrite
from robotwright.cli.options import (
    ROBOT_SOURCE_HELP,
    actuator_gain,
    add_overwrite_flag,
    add_strict_flags,
    parse_xacro_arg,
)
from robotwright.errors import ConversionWarning


def _options(args: argparse.Namespace) -> dict:
    opts: dict = {}
    if getattr(args, "fixed_joints", None):
        opts["fixed_joints"] = args.fixed_joints
    if getattr(args, "root_body", None):
        opts["root_body"] = args.root_body
    if getattr(args, "massless_frames", None):
        opts["massless_frames"] = args.massless_frames
    for name in ("bound_mass", "bound_inertia", "density"):
        if getattr(args, name, None) is not None:
            opts[name] = getattr(args, name)
    for name in ("balance_inertia", "join_obj_objects"):
        if getattr(args, name, False):
            opts[name] = True
    if getattr(args, "actuators", None):
        opts["actuators"] = args.actuators
    if getattr(args, "floating_base", None):
        opts["floating_base"] = True
    if getattr(args, "inertia_from_geoms", None):
        opts["inertia_from_geoms"] = args.inertia_from_geoms
    if getattr(args, "xacro_arg", None):
        opts["xacro_args"] = dict(args.xacro_arg)
    if getattr(args, "actuator_gain", None):
        opts["actuator_gains"] = dict(args.actuator_gain)
    if getattr(args, "collision_max_faces", None) is not None:
        opts["collision_max_faces"] = args.collision_max_faces
    if getattr(args, "convex_decomposition", False):
        opts["convex_decomposition"] = True
    return opts


def _density(text: str) -> float:
    """``--density``: a finite number > 0 (kg/m^3)."""
    from robotwright.parsers.urdf.inertia_from_geoms import check_density

    try:
        return check_density(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a finite number > 0") from None


def _source_args(p: argparse.ArgumentParser) -> None:
    """Options of the parsers (URDF/MJCF source -> HRDF), shared by convert and roundtrip."""
    p.add_argument(
        "--fixed-joints",
        choices=("keep", "merge", "site"),
        help="URDF sources: a link on a fixed joint stays a body (keep, the default), is "
        "merged into its parent (merge), or becomes a site when massless (site)",
    )
    p.add_argument(
        "--actuators",
        choices=("none", "motor", "position", "velocity", "auto"),
        help="URDF sources: none (default; URDF has no actuators), one torque motor per "
        "moving joint with an effort limit (motor), PD or velocity servos with "
        "--actuator-gain (position, velocity), or the type each <transmission> / "
        "ros2_control command_interface declares (auto)",
    )
    p.add_argument(
        "--actuator-gain",
        action="append",
        type=actuator_gain,
        metavar="PATTERN=KP,KV",
        help="URDF --actuators position/velocity/auto: servo gains for the joints whose "
        "name matches PATTERN (fnmatch; first match wins; repeat for several)",
    )
    p.add_argument(
        "--xacro-arg",
        action="append",
        type=parse_xacro_arg,
        metavar="NAME:=VALUE",
        help=".xacro sources: value of $(arg NAME) (repeat for several)",
    )
    p.add_argument(
        "--root-body",
        metavar="NAME",
        help="MJCF sources: the top-level body that is the robot (when the world holds several)",
    )


def _repair_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--massless-frames",
        choices=("keep", "site"),
        help="MJCF: turn massless leaf frame bodies into sites",
    )
    p.add_argument(
        "--balance-inertia",
        action="store_true",
        help="URDF: repair principal moments that break A + B >= C, as MuJoCo's balanceinertia",
    )
    p.add_argument(
        "--bound-mass", type=float, metavar="KG", help="URDF: raise masses below KG to KG"
    )
    p.add_argument(
        "--bound-inertia",
        type=float,
        metavar="KG_M2",
        help="URDF: raise principal moments below KG_M2 [kg m^2] to it",
    )
    p.add_argument(
        "--inertia-from-geoms",
        choices=("auto", "never"),
        help="URDF: a link without <inertial> gets the mass and inertia of its collision "
        "geoms, computed by MuJoCo as its URDF import does (auto, the default; one note "
        "per link), or none (never: such a link is massless, a moving one refused)",
    )
    p.add_argument(
        "--density",
        type=_density,
        metavar="KG_M3",
        help="URDF, --inertia-from-geoms auto: density of the collision geoms of links "
        "without <inertial> (default 1000, MuJoCo's)",
    )
    p.add_argument(
        "--join-obj-objects",
        action="store_true",
        help="join the objects of a multi-object OBJ mesh into one (MuJoCo reads the first only)",
    )


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "convert",
        help="convert a robot between MJCF, URDF and HRDF",
        description="Convert SRC to DST; the type comes from the extension (.urdf, .xml = "
        "MJCF) or is an HRDF folder. Every dropped or approximated element is printed.",
    )
    p.add_argument("src", help=ROBOT_SOURCE_HELP)
    p.add_argument(
        "-o",
        "--output",
        required=True,
        help="output .urdf (URDF), .xml (MJCF) or folder (HRDF); meshes are copied next to it",
    )
    _source_args(p)
    add_strict_flags(
        p,
        strict_help="fail, writing nothing, when the output would simulate differently from "
        "the source (a note that changes the physics, or a difference the proof finds)",
        all_help="as --strict, and also on cosmetic notes (names given, materials reduced to "
        "colours, lights or cameras dropped, elements carried in another exact form)",
    )
    p.add_argument(
        "--scene",
        action="store_true",
        help="MJCF output: add a floor, a light and a sky (default: the robot alone, as read)",
    )
    p.add_argument(
        "--simulate",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="the proof also steps source and output side by side for 200 steps (zero and "
        "a fixed pseudo-random control, contacts on, the robot alone) and reports a "
        "divergence neither the source's own sensitivity nor its round-off explains (MJCF "
        "sources; on by default, --no-simulate compares the compiled models only)",
    )
    add_overwrite_flag(p)
    _repair_args(p)
    p.add_argument(
        "--collision-max-faces",
        type=int,
        metavar="N",
        help="decimate collision meshes with more than N triangles to N (visual meshes "
        "untouched; needs the meshfix extra)",
    )
    p.add_argument(
        "--convex-decomposition",
        action="store_true",
        help="split each collision mesh into convex parts with CoACD (needs the meshfix extra)",
    )
    p.set_defaults(func=_convert)

    p = sub.add_parser(
        "roundtrip",
        help="fidelity table: source -> HRDF -> our MJCF/URDF vs the source",
        description="Parse SOURCE (.urdf or MJCF .xml), write it back as MJCF and URDF, and "
        "compare the compiled models with the source compiled by MuJoCo (or yourdfpy): "
        "masses, inertias, joints, actuators, sites, sensors and forward kinematics.",
    )
    p.add_argument("source", help="robot file to check: .urdf or MJCF .xml")
    p.add_argument(
        "--configs",
        type=int,
        default=50,
        help="random joint configurations compared in forward kinematics (default 50)",
    )
    p.add_argument(
        "--simulate",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="the row of the source and our MJCF stepped side by side for 200 steps "
        "(zero and pseudo-random control, contacts on), flagging joint positions that "
        "differ by more than 1e-6 and more than the source's own sensitivity and "
        "round-off (on by default; --no-simulate leaves it out)",
    )
    _source_args(p)
    p.add_argument(
        "--show-warnings", action="store_true", help="list the parse warnings (as -v does)"
    )
    p.add_argument(
        "--reference",
        choices=("auto", "mujoco", "yourdfpy"),
        default="auto",
        help="URDF: what to compare with (auto: MuJoCo's import, yourdfpy if MuJoCo refuses)",
    )
    _repair_args(p)
    p.set_defaults(func=_roundtrip)


class _InfoRecords(logging.Handler):
    """Keeps the INFO records of the parsers (the actuators an option made)."""

    def __init__(self) -> None:
        super().__init__(logging.INFO)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        if record.levelno == logging.INFO:
            self.lines.append(record.getMessage())


def _quiet_parser_log(func: Callable[[argparse.Namespace], int]) -> Callable:
    """Run a command with the parsers' log kept from the console (their warnings reach the
    user as the command's notes), restoring it after, so that a program calling
    ``main()`` keeps its own logging. What an option made (``--actuators``) is part of
    what was written: one line on stdout after ``wrote ...`` (stderr keeps one line, the
    notes' summary), each on stderr with ``-v``."""

    @functools.wraps(func)
    def wrapper(args: argparse.Namespace) -> int:
        log = logging.getLogger("robotwright.parsers")
        old_level, old_propagate = log.level, log.propagate
        made = _InfoRecords()
        log.setLevel(logging.INFO)
        log.propagate = False
        log.addHandler(made)
        try:
            return func(args)
        finally:
            log.removeHandler(made)
            log.setLevel(old_level)
            log.propagate = old_propagate
            if made.lines:
                if getattr(args, "verbose", False):
                    for line in made.lines:
                        print(f"made: {line}", file=sys.stderr)
                print(
                    f"{len(made.lines)} actuator(s) made by --actuators"
                    + ("" if getattr(args, "verbose", False) else " (-v lists each)")
                )

    return wrapper


@_quiet_parser_log
def _convert(args: argparse.Namespace) -> int:
    from robotwright.proof.convert import convert, file_kind

    # What cannot be written at all is said before whether it may be overwritten.
    file_kind(Path(args.output), existing=False)
    # A name without extension is an HRDF folder: --overwrite replaces only one we wrote.
    folder = Path(args.output).suffix == ""
    check_overwrite(args.output, args.overwrite, kind="hrdf" if folder else None)
    source = Path(args.src)
    if not source.exists() and source.suffix.lower() not in (".urdf", ".xml", ".xacro"):
        # Not a file: a robot name (see robotwright.sources), as every command takes.
        from robotwright.sources import resolve_source

        source = resolve_source(args.src).path
    # An existing empty folder holds nothing to lose: the rule lets it be written into.
    overwrite = args.overwrite or Path(args.output).is_dir()
    messages = convert(
        source,
        args.output,
        strict=args.strict,
        overwrite=overwrite,
        scene=args.scene,
        simulate=args.simulate,
        **_options(args),
    )
    # Reported like every command's losses: one summary line, each with -v.
    for m in messages:
        warnings.warn(m, ConversionWarning, stacklevel=1)
    print(f"wrote {args.output}")
    return 0


@_quiet_parser_log
def _roundtrip(args: argparse.Namespace) -> int:
    from robotwright.proof.roundtrip.run import roundtrip
    from robotwright.sources import resolve_source

    source = Path(args.source)
    if not source.exists() and source.suffix.lower() not in (".urdf", ".xml", ".xacro"):
        source = resolve_source(args.source).path  # a robot name
    report = roundtrip(
        source,
        configs=args.configs,
        reference=args.reference,
        simulate=args.simulate,
        **_options(args),
    )
    if report.input_error is not None:
        raise report.input_error  # bad input: exit 2 on stderr, no table
    print(report.table())
    if args.show_warnings or args.verbose:
        for w in report.warnings:
            print(f"warning: {w}")
    return 0 if report.ok else 1
