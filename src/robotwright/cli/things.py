"""``robotwright things``: read MJCF into Things and write it back, or to/from HRDF."""

from __future__ import annotations

import argparse
from pathlib import Path

from robotwright._outputs import check_overwrite
from robotwright.cli.options import add_overwrite_flag


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "things",
        help="read a robot into Things and write MJCF or HRDF",
        description="Read a robot (robot name, HRDF folder, URDF, xacro or MJCF file) into "
        "the Things object model "
        "and write it as a self-contained MJCF (defaults resolved, radians, meshes copied "
        "next to it) or as an HRDF folder. Anything that cannot be represented is named in "
        "a warning (an error with --strict).",
    )
    p.add_argument(
        "source", help="robot name, HRDF folder, or URDF (.urdf), xacro or MJCF (.xml) file"
    )
    p.add_argument("output", help="output .xml file (MJCF) or folder (HRDF)")
    p.add_argument(
        "--strict", action="store_true", help="fail instead of writing when a value is lost"
    )
    add_overwrite_flag(p)
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from robotwright._atomic import check_output_path
    from robotwright.errors import OutputPathError
    from robotwright.sources import load_robot, resolve_source, wants_parse
    from robotwright.things import World, hrdf_to_world, things_to_hrdf

    source, output = Path(args.source), Path(args.output)
    to_xml = output.suffix.lower() == ".xml"
    if not to_xml and output.suffix and not output.is_dir():
        raise OutputPathError(
            f"{output}: expected a .xml file (MJCF) or a folder name without extension (HRDF)"
        )
    check_output_path(output, folder=not to_xml)
    check_overwrite(output, args.overwrite, kind=None if to_xml else "hrdf")
    resolved = resolve_source(args.source)
    if resolved.kind == "mjcf" and not wants_parse():
        # Things read MJCF themselves: every element they model is kept.
        world = World.from_xml_path(resolved.path, strict=args.strict)
    else:  # a robot name, an HRDF folder, a URDF or xacro: through HRDF
        # Held until the output is written: a parsed URDF's meshes live in a staging
        # folder that goes away with the robot (its temp_assets).
        robot = load_robot(args.source, strict=args.strict)
        world = hrdf_to_world(robot, strict=args.strict)
    if to_xml:
        written = world.export(output)
    else:
        # check_overwrite allowed it: an empty folder, or --overwrite.
        written = things_to_hrdf(world, strict=args.strict).save(output, overwrite=True)
    model = world.model
    print(
        f"{source} -> {written}: {model.nbody - 1} bodies, {model.njnt} joints, "
        f"{model.nu} actuators, {model.nsensor} sensors, mass {model.body_mass.sum():.4g} kg"
    )
    return 0
