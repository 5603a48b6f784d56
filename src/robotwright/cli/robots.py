"""``robotwright robots``: every robot loadable by name, with its source, format and path."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "robots",
        help="list every robot that can be loaded by name (bundled, installed packages)",
        description="List the robots every command takes by name: $HURODES_ASSETS_PATH, "
        "the bundled robots, and the robots of installed description packages "
        "(example-robot-data, *_description packages, share/ folders, robot_descriptions' "
        "downloaded repositories). A name held by several sources is the first's; the "
        "others are SOURCE:NAME.",
    )
    p.add_argument("--json", action="store_true", help="a JSON list, one object per robot")
    p.add_argument("--source", metavar="SOURCE", help="only the robots of this source")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    import json

    from robotwright._suggest import did_you_mean
    from robotwright.catalog import list_robots, not_downloaded
    from robotwright.errors import RobotwrightError

    every = list_robots()
    sources = sorted({r.source for r in every})
    if args.source is not None and args.source not in sources:
        raise RobotwrightError(
            f"--source {args.source!r}: no robot comes from it; the sources here: "
            f"{', '.join(sources) or 'none'}{did_you_mean(args.source, sources)}"
        )
    robots = [r for r in every if args.source in (None, r.source)]
    if args.json:
        rows = [
            {
                "name": r.ref,
                "qualified": r.qualified,
                "source": r.source,
                "format": r.format,
                "path": str(r.path),
                "on_disk": not_downloaded(r) is None,
            }
            for r in robots
        ]
        print(json.dumps(rows, indent=1))
        return 0
    width = max((len(r.ref) for r in robots), default=4)
    swidth = max((len(r.source) for r in robots), default=6)
    print(f"{'name'.ljust(width)}  {'source'.ljust(swidth)}  format  path")
    for r in robots:
        where = "(not downloaded)" if not_downloaded(r) else r.path
        print(f"{r.ref.ljust(width)}  {r.source.ljust(swidth)}  {r.format.ljust(6)}  {where}")
    print(f"{len(robots)} robot(s); any name works in every command (robotwright info NAME)")
    return 0
