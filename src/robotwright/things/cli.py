"""``robotwright things``: read MJCF into Things and write it back, or to/from HRDF."""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "things",
        help="read an MJCF or HRDF robot into Things and write MJCF or HRDF",
        description="Read a robot (MJCF file or HRDF folder) into the Things object model "
        "and write it as a self-contained MJCF (defaults resolved, radians, meshes copied "
        "next to it) or as an HRDF folder. Anything that cannot be represented is named in "
        "a warning (an error with --strict).",
    )
    p.add_argument("source", help="MJCF file (.xml) or HRDF folder")
    p.add_argument("output", help="output .xml file (MJCF) or folder (HRDF)")
    p.add_argument("--strict", action="store_true", help="fail instead of warning on losses")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from robotwright._atomic import check_output_path
    from robotwright.errors import OutputPathError
    from robotwright.hrdf import HRDF
    from robotwright.things import World, hrdf_to_world, things_to_hrdf

    source, output = Path(args.source), Path(args.output)
    to_xml = output.suffix.lower() == ".xml"
    if not to_xml and output.suffix and not output.is_dir():
        raise OutputPathError(
            f"{output}: expected a .xml file (MJCF) or a folder name without extension (HRDF)"
        )
    check_output_path(output, folder=not to_xml)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if source.is_dir():
            world = hrdf_to_world(HRDF.from_dir(source), strict=args.strict)
        else:
            world = World.from_xml_path(source, strict=args.strict)
        if to_xml:
            written = world.export(output)
        else:
            written = things_to_hrdf(world, strict=args.strict).save(output)
    for w in caught:
        print(f"warning: {w.message}")
    model = world.model
    print(
        f"{source} -> {written}: {model.nbody - 1} bodies, {model.njnt} joints, "
        f"{model.nu} actuators, {model.nsensor} sensors, mass {model.body_mass.sum():.4g} kg"
    )
    return 0
