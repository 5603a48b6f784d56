"""``robotwright convert SRC -o DST`` and ``robotwright roundtrip SOURCE``."""

from __future__ import annotations

import argparse
import logging


def _options(args: argparse.Namespace) -> dict:
    opts: dict = {}
    if getattr(args, "fixed_joints", None):
        opts["fixed_joints"] = args.fixed_joints
    if getattr(args, "root_body", None):
        opts["root_body"] = args.root_body
    if getattr(args, "massless_frames", None):
        opts["massless_frames"] = args.massless_frames
    for name in ("bound_mass", "bound_inertia"):
        if getattr(args, name, None) is not None:
            opts[name] = getattr(args, name)
    for name in ("balance_inertia", "join_obj_objects"):
        if getattr(args, name, False):
            opts[name] = True
    return opts


def _repair_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--massless-frames",
        choices=("keep", "site"),
        help="MJCF: turn massless leaf frame bodies into sites",
    )
    p.add_argument("--balance-inertia", action="store_true", help="URDF: MuJoCo's balanceinertia")
    p.add_argument("--bound-mass", type=float, help="URDF: raise masses below this (kg)")
    p.add_argument("--bound-inertia", type=float, help="URDF: raise moments below this (kg m^2)")
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
    p.add_argument("src", help="source .urdf, .xml (MJCF) or HRDF folder")
    p.add_argument("-o", "--output", required=True, help="output .urdf, .xml or folder")
    p.add_argument("--fixed-joints", choices=("keep", "merge", "site"), help="URDF sources")
    p.add_argument("--root-body", help="MJCF sources: the top-level body that is the robot")
    p.add_argument("--strict", action="store_true", help="fail instead of dropping anything")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output")
    _repair_args(p)
    p.set_defaults(func=_convert)

    p = sub.add_parser(
        "roundtrip",
        help="fidelity table: source -> HRDF -> our MJCF/URDF vs the source",
        description="Parse SOURCE (.urdf or MJCF .xml), write it back as MJCF and URDF, and "
        "compare the compiled models with the source compiled by MuJoCo (or yourdfpy): "
        "masses, inertias, joints, actuators, sites, sensors and forward kinematics.",
    )
    p.add_argument("source")
    p.add_argument("--configs", type=int, default=50, help="random configurations for FK")
    p.add_argument("--fixed-joints", choices=("keep", "merge", "site"), help="URDF sources")
    p.add_argument("--root-body", help="MJCF sources: the top-level body that is the robot")
    p.add_argument("--show-warnings", action="store_true", help="list the parse warnings")
    p.add_argument(
        "--reference",
        choices=("auto", "mujoco", "yourdfpy"),
        default="auto",
        help="URDF: what to compare with (auto: MuJoCo's import, yourdfpy if MuJoCo refuses)",
    )
    _repair_args(p)
    p.set_defaults(func=_roundtrip)


def _convert(args: argparse.Namespace) -> int:
    from robotwright.parsers.convert import convert

    logging.getLogger("robotwright.parsers").setLevel(logging.ERROR)
    messages = convert(
        args.src, args.output, strict=args.strict, overwrite=args.overwrite, **_options(args)
    )
    for m in messages:
        print(f"warning: {m}")
    print(f"wrote {args.output} ({len(messages)} warning(s))")
    return 0


def _roundtrip(args: argparse.Namespace) -> int:
    from robotwright.parsers.roundtrip import roundtrip

    logging.getLogger("robotwright.parsers").setLevel(logging.ERROR)
    report = roundtrip(
        args.source, configs=args.configs, reference=args.reference, **_options(args)
    )
    print(report.table())
    if args.show_warnings:
        for w in report.warnings:
            print(f"warning: {w}")
    return 0 if report.ok else 1
