"""The ``robotwright`` command line: one entry point, one subcommand per job.

Each subsystem keeps its subcommands in its own module that exposes
``register(subparsers)``; this file only lists those modules, so adding a
command never touches another subsystem's code.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from robotwright._paths import trusted_asset_roots
from robotwright.errors import RobotwrightError

# Modules that expose ``register(subparsers: argparse._SubParsersAction) -> None``.
_COMMAND_MODULES: tuple[str, ...] = (
    "robotwright.hrdf.cli",
    "robotwright.demo",
    "robotwright.parsers.cli",
    "robotwright.sensors.cli",
    "robotwright.grammar.cli",
    "robotwright.generators.cli",
    "robotwright.things.cli",
)

#: Commands that read robots from files: they take ``--asset-root DIR`` (see
#: :mod:`robotwright._paths`).
_ASSET_COMMANDS: tuple[str, ...] = (
    "validate",
    "info",
    "export",
    "compose",
    "convert",
    "roundtrip",
    "things",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="robotwright",
        description="Describe, generate, compose and sense robots for simulation.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module_name in _COMMAND_MODULES:
        importlib.import_module(module_name).register(sub)
    for name in _ASSET_COMMANDS:
        sub.choices[name].add_argument(
            "--asset-root",
            action="append",
            dest="asset_roots",
            metavar="DIR",
            default=[],
            help="trust folder DIR: mesh/asset paths of the input may point into it "
            "(by default they must stay inside the robot's own folder); repeatable",
        )
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with trusted_asset_roots(getattr(args, "asset_roots", None) or []):
            return int(args.func(args) or 0)
    except RobotwrightError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        # The file system refused a path the user gave (permissions, disk full, a file
        # where a folder is needed): name the path, no traceback.
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
