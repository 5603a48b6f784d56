"""``robotwright things``: read MJCF into Things and write it back, or to/from HRDF."""

from __future__ import annotations

import argparse
from pathlib import Path

from robotwright._outputs import add_overwrite_flag, check_overwrite


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "things",
        help="read an MJCF or HRDF robot into Things and write MJCF or HRDF",
        description="Read a robot (MJCF file or HRDF folder) into the Things object model "
        "and write it as a self-contained MJCF (defaults resolved, radians, meshes copied "
        "next to it) or as an HRDF folder. Anything that cannot be represented is named in "
        "a warning (an error with --strict).",
    )
    p.add_argument(
        "source", help="MJCF file (.xml), HRDF folder or bundled robot name (arm6, mini_humanoid)"
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
    from robotwright.hrdf import HRDF
    from robotwright.hrdf.assets import resolve_robot
    from robotwright.things import World, hrdf_to_world, things_to_hrdf

    source, output = Path(args.source), Path(args.output)
    to_xml = output.suffix.lower() == ".xml"
    if not to_xml and output.suffix and not output.is_dir():
        raise OutputPathError(
            f"{output}: expected a .xml file (MJCF) or a folder name without extension (HRDF)"
        )
    check_output_path(output, folder=not to_xml)
    check_overwrite(output, args.overwrite, kind=None if to_xml else "hrdf")
    if source.is_file() or source.suffix.lower() == ".xml":
        world = World.from_xml_path(source, strict=args.strict)
    else:  # an HRDF folder, or a robot name (bundled or under $HURODES_ASSETS_PATH)
        world = hrdf_to_world(HRDF.from_dir(resolve_robot(args.source)), strict=args.strict)
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
