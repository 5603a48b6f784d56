"""``robotwright export`` and ``robotwright compose``."""

from __future__ import annotations

import argparse
import re
import sys
import warnings
from pathlib import Path

from robotwright._bounds import Bound
from robotwright._names import shown
from robotwright._outputs import check_overwrite
from robotwright._usd_format import USD_SUFFIXES
from robotwright.cli.options import ROBOT_SOURCE_HELP, add_overwrite_flag, add_strict_flags
from robotwright.errors import ConversionWarning, GeneratorError, RobotSetupWarning
from robotwright.generators.placement import Placement

#: Meshes that exist only while a source is read are always copied.
_STAGED_MESHES = (
    "meshes made while reading a source, such as a URDF's DAE converted to STL, are "
    "copied, as they last only as long as the command"
)
_FORMAT_HELP = "mjcf or urdf (default: from the -o file name: .urdf is URDF, .xml or .mjcf is MJCF)"
_EXPORT_FORMAT_HELP = (
    "mjcf, urdf or usd (default: from the -o file name: .urdf is URDF, .xml or .mjcf is "
    "MJCF, .usd, .usda or .usdc is OpenUSD for Isaac Lab and Newton)"
)


def _add_usd_layout(p: argparse.ArgumentParser, default: str = "nested") -> None:
    p.add_argument(
        "--usd-layout",
        choices=("nested", "flat"),
        default=default,
        help=f"USD: bodies nested as the kinematic tree (the converter's) or flat, each a "
        "child of the robot's prim as Isaac Lab's importers write them (its body "
        f"expressions, sensor prim paths and PhysX contact sensors expect that); default "
        f"{default}",
    )


#: An initial joint position [rad or m] given on the command line.
JOINT_POS_BOUND = Bound(-1e3, 1e3)


def _add_joint_pos(p: argparse.ArgumentParser, lead: str = "") -> None:
    p.add_argument(
        "--joint-pos",
        action="append",
        type=_joint_pos,
        default=[],
        metavar="PATTERN=VALUE",
        help=f"{lead}initial position [rad or m] of the joints whose name matches PATTERN "
        "(fnmatch; first match wins; repeatable): a legged robot's standing pose; other "
        "joints keep their reference position",
    )


def _joint_pos(text: str) -> tuple[str, float]:
    """``PATTERN=VALUE`` of ``--joint-pos``."""
    pattern, sep, value = text.rpartition("=")
    try:
        number = JOINT_POS_BOUND.check(float(value))
    except ValueError:
        number = None
    if not sep or not pattern or number is None:
        raise argparse.ArgumentTypeError(
            f"{shown(text)}: expected PATTERN=VALUE, VALUE {JOINT_POS_BOUND.describe()} (rad or m)"
        )
    return pattern, float(number)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export",
        help="write a robot as MJCF, URDF or USD",
        description="Write a robot (a name, HRDF folder, URDF, xacro, MJCF or USD file) as "
        "MJCF, URDF or OpenUSD. "
        "Mesh paths are written relative to the output file, so it loads as is. USD (for "
        "Isaac Lab and Newton) goes through mujoco-usd-converter with joint drives and "
        "velocity limits added, and is read back by Newton and compared with the robot "
        "(Isaac Lab's environment, Python 3.12).",
    )
    p.add_argument("robot", help=ROBOT_SOURCE_HELP)
    p.add_argument(
        "--format", choices=("mjcf", "urdf", "usd"), default=None, help=_EXPORT_FORMAT_HELP
    )
    p.add_argument(
        "--prefix",
        default=None,
        metavar="P",
        help="MJCF: prefix every name with P_ (default: none)",
    )
    p.add_argument("--no-scene", action="store_true", help="MJCF: no ground, light or sky")
    p.add_argument(
        "--no-mujoco-tag", action="store_true", help="URDF: leave out the <mujoco> block"
    )
    p.add_argument(
        "--copy-meshes",
        action="store_true",
        help="copy meshes into meshes/ next to the output file (default: point at the "
        f"robot's own files; {_STAGED_MESHES})",
    )
    add_strict_flags(
        p,
        strict_help="fail instead of writing when a value that changes the physics is lost",
        all_help="as --strict, and also when a cosmetic value (a name, a colour) is lost",
    )
    _add_usd_layout(p)
    _add_joint_pos(p, "MJCF: the pose of the 'home' keyframe; ")
    p.add_argument(
        "-o",
        "--output",
        required=True,
        help="output file (.xml, .mjcf, .urdf, .usd, .usda or .usdc)",
    )
    add_overwrite_flag(p)
    p.set_defaults(func=_export)

    p = sub.add_parser(
        "isaaclab-cfg",
        help="write an Isaac Lab ArticulationCfg module and the robot's USD",
        description="Write a Python module with an Isaac Lab ArticulationCfg (ROBOT_CFG: "
        "USD spawn, initial state, ImplicitActuatorCfg groups from the robot's actuators) "
        "and the robot's USD beside it, named after the module (robot_cfg.py: robot_cfg.usd; "
        "as `export -o robot_cfg.usd` writes it). A free base starts standing on z = 0 in "
        "its initial pose. Isaac Lab's environment (Python 3.12).",
        epilog="Example (a trainable Go2): robotwright isaaclab-cfg go2 --floating-base "
        "--actuators position --actuator-gain '*=25,0.5' --joint-pos '*thigh_joint=0.8' "
        "--joint-pos '*calf_joint=-1.5' -o robots/go2_cfg.py",
    )
    p.add_argument("robot", help=ROBOT_SOURCE_HELP)
    p.add_argument(
        "--strict", action="store_true", help="fail instead of writing when the USD's proof differs"
    )
    _add_joint_pos(p)
    _add_usd_layout(p, default="flat")
    p.add_argument("-o", "--output", required=True, help="the module to write (.py)")
    add_overwrite_flag(p)
    p.set_defaults(func=_isaaclab_cfg)
    p = sub.add_parser(
        "mjlab-cfg",
        help="write an mjlab EntityCfg module and the robot's MJCF",
        description="Write a Python module with an mjlab EntityCfg (ROBOT_CFG: the MJCF "
        "beside it, the initial state, the MJCF's actuators wrapped by XmlActuatorCfg) and "
        "the robot's MJCF (robot only, meshes copied), named after the module "
        "(robot_entity.py: robot_entity.xml). A free base starts standing on z = 0 in its "
        "initial pose. mjlab's environment (MuJoCo 3.11).",
        epilog="Example (a trainable Go2): robotwright mjlab-cfg go2 --floating-base "
        "--actuators position --actuator-gain '*=50,1' --joint-pos '*thigh_joint=0.9' "
        "--joint-pos '*calf_joint=-1.5' -o robots/go2_entity.py",
    )
    p.add_argument("robot", help=ROBOT_SOURCE_HELP)
    _add_joint_pos(p)
    p.add_argument("-o", "--output", required=True, help="the module to write (.py)")
    add_overwrite_flag(p)
    p.set_defaults(func=_mjlab_cfg)
    p = sub.add_parser(
        "compose",
        help="put several robots in one scene file",
        description="Compose robots into one MJCF (or URDF) scene. Each ROBOT is "
        "[KEY=]NAME_OR_PATH[@x,y,z[,yaw]] (metres, radians); names are prefixed with "
        "KEY (default: the robot name, numbered when repeated).",
        epilog="Example: robotwright compose h=mini_humanoid arm=arm6@1.2,0.8,0,3.1416 "
        "-o scene.xml",
    )
    p.add_argument(
        "robots",
        nargs="+",
        metavar="ROBOT",
        help=f"[KEY=]NAME_OR_PATH[@x,y,z[,yaw]]: {ROBOT_SOURCE_HELP}; optionally keyed "
        "and placed at x, y, z [m] turned by yaw [rad] about z (default: where its own "
        "description puts it)",
    )
    p.add_argument("--format", choices=("mjcf", "urdf"), default=None, help=_FORMAT_HELP)
    p.add_argument("--no-scene", action="store_true", help="MJCF: no ground, light or sky")
    p.add_argument(
        "--copy-meshes",
        action="store_true",
        help="copy meshes into meshes/ next to the output file (default: point at the "
        f"robots' own files; {_STAGED_MESHES})",
    )
    p.add_argument("-o", "--output", required=True, help="output scene file (.xml or .urdf)")
    add_overwrite_flag(p)
    p.set_defaults(func=_compose)


#: File name endings accepted per output format (URDF is often saved as .xml too).
_EXTENSIONS = {
    "mjcf": (".xml", ".mjcf"),
    "urdf": (".urdf", ".xml"),
    "usd": USD_SUFFIXES,
}


def output_format(output: str, fmt: str | None) -> str:
    """The output format: ``fmt`` when given (checked against the file name), else the
    one the file name's extension says (.urdf: URDF; .xml, .mjcf: MJCF)."""
    suffix = Path(output).suffix.lower()
    if fmt is None:
        if suffix == ".urdf":
            return "urdf"
        if suffix in (".xml", ".mjcf"):
            return "mjcf"
        if suffix in _EXTENSIONS["usd"]:
            return "usd"
        raise GeneratorError(
            f"{output}: cannot tell the format from '{suffix or '(no extension)'}': "
            "expected a file name ending in .xml or .mjcf (MJCF), .urdf (URDF) or "
            f"{', '.join(USD_SUFFIXES)} (OpenUSD), or --format"
        )
    if suffix not in _EXTENSIONS[fmt]:
        raise GeneratorError(
            f"{output}: expected a file name ending in {' or '.join(_EXTENSIONS[fmt])} "
            f"for --format {fmt}, got '{suffix or '(none)'}'"
        )
    return fmt


def _export(args: argparse.Namespace) -> int:
    from robotwright.generators.compiles import require_compiles
    from robotwright.generators.mjcf import MJCFHumanoidGenerator
    from robotwright.generators.urdf import URDFHumanoidGenerator
    from robotwright.tasks import load_robot

    args.format = output_format(args.output, args.format)
    if args.usd_layout != "nested" and args.format != "usd":
        raise GeneratorError(f"--usd-layout applies to USD output, not {args.format.upper()}")
    check_overwrite(args.output, args.overwrite)
    if args.joint_pos and args.format != "mjcf":
        raise GeneratorError(
            f"--joint-pos sets the home keyframe of MJCF output, not {args.format.upper()} "
            "(isaaclab-cfg and mjlab-cfg take it for a framework's initial state)"
        )
    hrdf = load_robot(args.robot)
    out = Path(args.output)
    # What MuJoCo refuses is not written (validate calls such a robot invalid); the robot
    # alone where the output has no scene, as the proof compiles it (one parse for both).
    require_compiles(hrdf, f"cannot write {out}", scene=args.format == "mjcf")
    if args.format == "urdf":
        _prove_urdf(hrdf, out, args.strict)
    if args.format == "usd":
        from robotwright.generators.usd import to_usd

        done = to_usd(
            hrdf, out, overwrite=args.overwrite, strict=args.strict, layout=args.usd_layout
        )
        proof = done.proof
        print(
            f"wrote {out} (usd, robot '{hrdf.name}', root {done.root}, {len(done.drives)} "
            f"drives); proof: {proof.bodies} bodies, {proof.joints} joints, {proof.drives} "
            f"drives, {proof.poses} poses compared (largest body offset "
            f"{proof.max_pose_error:.2g} m), {len(proof.differences)} difference(s)"
        )
        return 0
    if args.format == "mjcf":
        from robotwright.generators.standing import stand_on_floor

        hrdf, changes = stand_on_floor(hrdf, args.joint_pos)
        for line in changes:
            print(f"note: {line}", file=sys.stderr)
        MJCFHumanoidGenerator.from_hrdf(hrdf).export(
            out,
            copy_meshes=args.copy_meshes,
            prefix=args.prefix,
            add_scene=not args.no_scene,
            strict=args.strict,
        )
        if not args.no_scene:  # said, so that nobody takes the floor for the robot's
            warnings.warn(
                f"{out}: scene added: a floor plane 'floor', a light and a sky, not part of "
                "the robot (--no-scene leaves them out)",
                ConversionWarning,
                stacklevel=1,
            )
    else:
        if args.prefix:
            raise GeneratorError("--prefix applies to MJCF; URDF composites prefix by robot")
        URDFHumanoidGenerator.from_hrdf(hrdf).export(
            out,
            copy_meshes=args.copy_meshes,
            add_mujoco_tag=not args.no_mujoco_tag,
            strict=args.strict,
        )
    print(
        f"wrote {out} ({args.format}, robot {shown(hrdf.name)}, {len(hrdf.bodies)} bodies, "
        f"{sum(j.type in ('hinge', 'slide', 'ball') for j in hrdf.joints)} joints, "
        f"{'free' if hrdf.floating_base else 'fixed'} base, {len(hrdf.actuators)} actuators)"
    )
    for line in _export_warnings(hrdf):
        warnings.warn(line, RobotSetupWarning, stacklevel=1)
    return 0


def _export_warnings(hrdf) -> list[str]:
    """What a user of the written file would trip on: joints that nothing drives, a
    walking robot with its base fixed (its legs through the floor)."""
    from robotwright.generators.standing import fixed_walker, walking_bodies

    out = []
    moving = [j for j in hrdf.joints if j.type in ("hinge", "slide")]
    if moving and not hrdf.actuators:
        out.append(
            f"robot {shown(hrdf.name)} has no actuators: its {len(moving)} joints move "
            "freely; give --actuators position --actuator-gain 'PATTERN=KP,KV' (URDF "
            "sources) or a robot file with actuators"
        )
    feet = walking_bodies(hrdf)
    if feet and not hrdf.floating_base:
        out.append(fixed_walker(hrdf.name, feet))
    return out


def _isaaclab_cfg(args: argparse.Namespace) -> int:
    from robotwright.generators.isaaclab_cfg import module_outputs, write_articulation_cfg
    from robotwright.tasks import load_robot

    module_outputs(args.output, ".usd", args.overwrite)  # before the robot is read
    hrdf = load_robot(args.robot)
    module, usd = write_articulation_cfg(
        hrdf,
        args.output,
        overwrite=args.overwrite,
        strict=args.strict,
        layout=args.usd_layout,
        joint_pos=args.joint_pos,
    )
    print(f"wrote {module} (ROBOT_CFG) and {usd}")
    if args.usd_layout == "flat":
        # Where a sensor goes: a body of the robot prim spawned at {ENV_REGEX_NS}/Robot.
        print(
            f"bodies are {{ENV_REGEX_NS}}/Robot/<body>; the base: {{ENV_REGEX_NS}}/Robot/{hrdf.root_body.name}"
        )
    return 0


def _mjlab_cfg(args: argparse.Namespace) -> int:
    from robotwright.generators.isaaclab_cfg import module_outputs
    from robotwright.generators.mjlab_cfg import write_entity_cfg
    from robotwright.tasks import load_robot

    module_outputs(args.output, ".xml", args.overwrite)  # before the robot is read
    hrdf = load_robot(args.robot)
    module, xml = write_entity_cfg(
        hrdf, args.output, overwrite=args.overwrite, joint_pos=args.joint_pos
    )
    print(f"wrote {module} (ROBOT_CFG) and {xml}")
    return 0


def _prove_urdf(hrdf, out: Path, strict: bool) -> None:
    """The proof of a URDF output: MuJoCo's import of it against our MJCF of the robot
    (:mod:`robotwright.proof.urdf_output`); each difference the writer does not report
    is a warning, under ``strict`` an error before anything is written."""
    import warnings

    from robotwright.errors import ConversionError, ConversionWarning
    from robotwright.proof.urdf_output import prove_urdf_output

    found = prove_urdf_output(hrdf, str(out))
    if strict and found:
        raise ConversionError(
            found,
            summary=f"strict export of {out}: {len(found)} value(s) differ between our MJCF "
            "and MuJoCo's import of the URDF",
        )
    for p in found:
        warnings.warn(str(p), ConversionWarning, stacklevel=2)


def parse_robot_spec(spec: str) -> tuple[str | None, str, Placement | None]:
    """``[KEY=]ROBOT[@x,y,z[,yaw]]`` -> (key or None, robot, placement or None)."""
    key = None
    m = re.match(r"^([A-Za-z_][A-Za-z0-9_]*)=(.+)$", spec)
    if m:
        key, spec = m.group(1), m.group(2)
    placement = None
    if "@" in spec:
        spec, _, pose = spec.rpartition("@")
        placement = Placement.parse(pose)
    if not spec:
        raise GeneratorError(f"robot spec '{spec}': empty robot name")
    return key, spec, placement


def _compose(args: argparse.Namespace) -> int:
    from robotwright.tasks import compose_scene, load_robot

    args.format = output_format(args.output, args.format)
    if args.format == "usd":
        raise GeneratorError(
            f"{args.output}: compose writes MJCF or URDF; export one robot to USD with "
            "`robotwright export ROBOT -o robot.usd`"
        )
    check_overwrite(args.output, args.overwrite)
    robots: list[tuple[str, object]] = []
    placements: dict[str, Placement] = {}
    used: dict[str, int] = {}
    for spec in args.robots:
        key, robot, placement = parse_robot_spec(spec)
        hrdf = load_robot(robot)
        if key is None:
            base = re.sub(r"[^A-Za-z0-9_]", "_", hrdf.name)
            n = used.get(base, 0)
            used[base] = n + 1
            key = base if n == 0 else f"{base}{n + 1}"
        robots.append((key, hrdf))
        if placement is not None:
            placements[key] = placement
    out = compose_scene(
        robots,  # type: ignore[arg-type]
        args.output,
        placements,
        fmt=args.format,
        add_scene=not args.no_scene,
        copy_meshes=args.copy_meshes,
    )
    print(f"wrote {out} ({args.format}, robots: {', '.join(k for k, _ in robots)})")
    return 0
