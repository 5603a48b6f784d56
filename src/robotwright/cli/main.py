"""The ``robotwright`` command line: one entry point, one subcommand per job.

Each subsystem keeps its subcommands in its own module that exposes
``register(subparsers)``; this file only lists those modules, so adding a
command never touches another subsystem's code.
"""

from __future__ import annotations

import argparse
import importlib
import os
import platform
import sys
from collections.abc import Iterator, Sequence
from contextlib import nullcontext
from typing import Any

from robotwright import __version__
from robotwright._atomic import mesh_size_limit
from robotwright._limits import keyframe_limit
from robotwright._names import PrintableStream
from robotwright._notes import CaughtNotes, Note, collect_notes, summary_line
from robotwright._npz import npz_limit
from robotwright._outputs import copies_replace
from robotwright._paths import trusted_asset_roots
from robotwright._progress import shown as progress_shown
from robotwright._reader_budget import reader_budget
from robotwright._suggest import did_you_mean
from robotwright._temporaries import Terminated, sweep_stale, terminate_like_interrupt
from robotwright.cli.options import source_options
from robotwright.errors import ProblemsError, RobotwrightError
from robotwright.parsers.packages import given_packages
from robotwright.sources import given_source_options

# Modules that expose ``register(subparsers: argparse._SubParsersAction) -> None``.
_COMMAND_MODULES: tuple[str, ...] = (
    "robotwright.cli.hrdf",
    "robotwright.cli.demo",
    "robotwright.cli.convert",
    "robotwright.cli.lidar",
    "robotwright.cli.grammar",
    "robotwright.cli.export",
    "robotwright.cli.things",
    "robotwright.cli.view",
    "robotwright.cli.render",
    "robotwright.cli.robots",
    "robotwright.cli.train",
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
    "view",
    "render",
    "lidar",
    "isaaclab-cfg",
    "mjlab-cfg",
)

#: Commands that read URDF/xacro files (every command that reads a robot: any takes a
#: URDF): they take ``--package NAME=DIR`` (see :mod:`robotwright.parsers.packages`)
#: and the robot-source options (see :mod:`robotwright.sources`).
_PACKAGE_COMMANDS: tuple[str, ...] = _ASSET_COMMANDS

#: Every command that reads a robot takes ``--max-mesh-mb MB``: the largest mesh, height
#: field or texture file a model may make MuJoCo read, or copy into an output (see
#: :func:`robotwright._atomic.mesh_size_limit` and :mod:`robotwright._assets`).
_MESH_COMMANDS: tuple[str, ...] = _ASSET_COMMANDS

#: Commands that read scan ``.npz`` files: they take ``--max-scan-mb MB`` (see
#: :func:`robotwright._npz.npz_limit`).
_SCAN_COMMANDS: tuple[str, ...] = ("view", "render")


class _Parser(argparse.ArgumentParser):
    """argparse with a close-name suggestion when a choice (a command, ``--format``,
    ``--objective``, ...) is misspelt; subcommand parsers are of this class too."""

    def _check_value(self, action: argparse.Action, value: Any) -> None:
        if action.choices is not None and value not in action.choices:
            choices = ", ".join(map(repr, action.choices))
            hint = did_you_mean(str(value), map(str, action.choices))
            raise argparse.ArgumentError(
                action, f"invalid choice: {value!r} (choose from {choices}){hint}"
            )


class _VersionAction(argparse.Action):
    """``--version``: robotwright's, MuJoCo's and Python's versions (read when asked:
    importlib.metadata costs start-up time every other command would pay)."""

    def __init__(self, option_strings: list[str], dest: str = argparse.SUPPRESS, **kw: Any):
        kw.setdefault("help", "print the versions of robotwright, MuJoCo and Python and exit")
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kw)

    def __call__(self, parser: argparse.ArgumentParser, *args: Any) -> None:
        from importlib import metadata

        try:
            mujoco = metadata.version("mujoco")
        except metadata.PackageNotFoundError:
            mujoco = "not installed"
        version = f"robotwright {__version__} (MuJoCo {mujoco}, Python {platform.python_version()})"
        print(version)
        parser.exit()


def _all_parsers(parser: argparse.ArgumentParser) -> Iterator[argparse.ArgumentParser]:
    """``parser`` and every subcommand parser below it (grammar's actions included)."""
    yield parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in dict.fromkeys(action.choices.values()):
                yield from _all_parsers(child)


def build_parser() -> argparse.ArgumentParser:
    """The ``robotwright`` parser. Registering a command imports its ``cli`` module only:
    MuJoCo, numpy and the like are imported when a command runs, so ``--help`` is quick."""
    parser = _Parser(
        prog="robotwright",
        description="Describe, generate, compose and sense robots for simulation.",
        epilog="Run 'robotwright COMMAND --help' for a command's options.",
    )
    parser.add_argument("--version", action=_VersionAction)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module_name in _COMMAND_MODULES:
        importlib.import_module(module_name).register(sub)
    for p in _all_parsers(parser):
        p.add_argument(
            "-v",
            "--verbose",
            action="store_true",
            # Unset on subcommands unless given, so `robotwright -v export ...` and
            # `robotwright export ... -v` both work.
            default=False if p is parser else argparse.SUPPRESS,
            help="list every conversion note (value or element not kept), not only the "
            "summary line",
        )
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
    from robotwright.cli.options import add_source_options

    for name in _PACKAGE_COMMANDS:
        add_source_options(sub.choices[name])
        sub.choices[name].add_argument(
            "--package",
            action="append",
            dest="packages",
            type=_package_arg,
            metavar="NAME=DIR",
            default=[],
            help="URDF/xacro: package://NAME/... and $(find NAME) name folder DIR (by default "
            "only packages inside the robot's own folder or ROS package are found); repeatable",
        )
    limits = (
        (_MESH_COMMANDS, "--max-mesh-mb", _positive_mb, "MB",
         "largest mesh, height field or texture a model may read or copy into an output, "
         "in MB (default 512; counted as the file's size, or the data a height field or "
         "image declares): a larger one is refused before it is read"),
        (_ASSET_COMMANDS, "--max-keyframes", _count_arg, "N",
         "most keyframes a model read may hold (default 10,000): MuJoCo allocates a full "
         "state per keyframe"),
        (_ASSET_COMMANDS, "--max-reader-mb", _positive_mb, "MB",
         "memory the confined reader of an input may allocate, in MB (default 2000): "
         "MuJoCo allocates what a file declares as it reads it"),
        (_SCAN_COMMANDS, "--max-scan-mb", _positive_mb, "MB",
         "largest size of a scan's arrays once loaded, in MB (default 1000): a scan .npz "
         "declaring more is refused before it is loaded"),
    )  # fmt: skip
    for commands, flag, kind, metavar, text in limits:
        for name in commands:
            sub.choices[name].add_argument(
                flag, type=kind, default=None, metavar=metavar, help=text
            )
    return parser


def _count_arg(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}")
    return value


def _positive_mb(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value > 0 and value != float("inf")):
        raise argparse.ArgumentTypeError(f"expected a positive number of MB, got {text!r}")
    return value


def _package_arg(value: str) -> tuple[str, str]:
    """``--package NAME=DIR`` as ``(NAME, DIR)`` (argparse reports a malformed value)."""
    from robotwright.parsers.packages import check_package_name

    name, sep, folder = value.partition("=")
    if not sep or not folder:
        raise argparse.ArgumentTypeError(f"{value!r}: expected NAME=DIR (a package and its folder)")
    try:
        return check_package_name(name), folder
    except RobotwrightError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _report_notes(caught: CaughtNotes, verbose: bool) -> None:
    """One summary line of the conversion notes on stderr (each note with ``-v``); other
    libraries' warnings are shown once each."""
    for message in dict.fromkeys(str(w.message) for w in caught.others):
        print(f"warning: {message}", file=sys.stderr)
    if not caught.notes:
        return
    if verbose:
        for note in caught.notes:
            print(f"note: {note.text}", file=sys.stderr)
        print(summary_line(caught.notes, "listed above"), file=sys.stderr)
    else:
        print(summary_line(caught.notes, "-v lists each"), file=sys.stderr)


def _say_confinement() -> None:
    """With ``-v``, where untrusted files were read without a confined reader (no
    Landlock here): the path checks alone held them (see docs/security.md)."""
    from robotwright._confine import confinement

    how = confinement()
    if not how.startswith("landlock"):
        print(f"note: input files were read without confinement ({how})", file=sys.stderr)


def _mujoco_warnings(command: str) -> Any:
    """MuJoCo's warnings gathered while a command that reads models runs (see
    :mod:`robotwright._mujoco_log`); other commands do not import MuJoCo for it."""
    if command not in _ASSET_COMMANDS and command not in ("demo", "grammar"):
        return nullcontext([])
    from robotwright._mujoco_log import gathered

    return gathered()


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; returns its exit code (2 for bad input, with a one-line error)."""
    out, err = sys.stdout, sys.stderr
    try:
        parser = build_parser()
        try:
            args = parser.parse_args(argv)
        finally:
            out.flush()  # --help and --version print, then exit here
        # Text read from input files (names, CSV cells, paths) reaches the terminal in
        # messages and listings: control and bidirectional characters are shown escaped
        # (``\x1b``), never sent raw to the terminal.
        sys.stdout, sys.stderr = PrintableStream(out), PrintableStream(err)
        sweep_stale()  # what commands killed with SIGKILL left in the temporary folder
        with terminate_like_interrupt():  # SIGTERM unwinds: temporaries go, readers stop
            code = _run(args)
        # Flushed here, not at exit: a reader that closed the pipe ends it quietly.
        out.flush()
        return code
    except BrokenPipeError:
        return _closed_pipe(out)
    finally:
        sys.stdout, sys.stderr = out, err


def _closed_pipe(out: Any) -> int:
    """The reader of stdout went away (``robotwright info ... | head -5``): end quietly
    with exit 0 as ``git`` and ``ls`` do. stdout is pointed at the null device so that
    Python's own flush at exit does not fail on the closed pipe."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, out.fileno())
    except (OSError, ValueError, AttributeError):
        pass  # not a real file (a test's StringIO): nothing is flushed at exit
    return 0


#: Longest error line printed (characters) and most problem lines under a heading: a
#: file can make a message as long as it likes (a 10,000-body world named in one line).
MAX_ERROR_LINE = 1000
MAX_ERROR_LINES = 20


def _one_line(text: str) -> str:
    """``text`` on one line (MuJoCo's messages carry the element and line on a second),
    at most :data:`MAX_ERROR_LINE` characters."""
    line = " ".join(part.strip() for part in text.splitlines() if part.strip())
    if len(line) <= MAX_ERROR_LINE:
        return line
    cut = line[:MAX_ERROR_LINE].rsplit(" ", 1)[0] or line[:MAX_ERROR_LINE]
    return f"{cut} ... (and {len(line) - len(cut):,} more characters)"


def _error_text(exc: RobotwrightError) -> str:
    """The message of a refusal: one line, or for several problems one line each under
    a heading line (at most :data:`MAX_ERROR_LINES`, then how many more)."""
    if isinstance(exc, ProblemsError) and len(exc.problems) > 1:
        head, _, _ = str(exc).partition("\n")
        shown = [f"  - {_one_line(str(p))}" for p in exc.problems[:MAX_ERROR_LINES]]
        more = len(exc.problems) - MAX_ERROR_LINES
        if more > 0:
            shown.append(f"  - and {more:,} more")
        return "\n".join([_one_line(head), *shown])
    return _one_line(str(exc))


def _interrupt_behind(exc: BaseException) -> KeyboardInterrupt | None:
    """The Ctrl-C or SIGTERM among the causes of ``exc`` (an import it interrupted
    fails as an ``ImportError`` caused by an ``ImportError`` caused by it), if any."""
    seen = 0
    cause = exc.__cause__ or exc.__context__
    while cause is not None and seen < 16:
        if isinstance(cause, KeyboardInterrupt):
            return cause
        cause, seen = cause.__cause__ or cause.__context__, seen + 1
    return None


def _interrupted(exc: KeyboardInterrupt) -> int:
    """Exit status and line of a command stopped by Ctrl-C (130) or SIGTERM (143)."""
    if isinstance(exc, Terminated):
        print("terminated", file=sys.stderr)
        return 143
    print("interrupted", file=sys.stderr)
    return 130


def _run(args: argparse.Namespace) -> int:
    try:
        roots = getattr(args, "asset_roots", None) or []
        packages = given_packages(dict(getattr(args, "packages", None) or []))
        limit = mesh_size_limit(getattr(args, "max_mesh_mb", None))
        scans = npz_limit(getattr(args, "max_scan_mb", None))
        # Files copied next to a file output replace others only with --overwrite.
        copies = copies_replace(args.overwrite) if "overwrite" in args else nullcontext()
        keys = keyframe_limit(getattr(args, "max_keyframes", None))
        budget = reader_budget(getattr(args, "max_reader_mb", None))
        sources = given_source_options(source_options(args))
        with (
            trusted_asset_roots(roots),
            packages,
            limit,
            scans,
            keys,
            budget,
            sources,
            copies,
            collect_notes() as caught,
            _mujoco_warnings(args.command) as mujoco_warnings,
            progress_shown(),
        ):
            code = int(args.func(args) or 0)
        # MuJoCo's own warnings (a mesh's texture coordinates discarded, ...) are notes
        # of the same summary line.
        caught.notes += [
            Note("MuJoCo warning", f"MuJoCo: {m}") for m in dict.fromkeys(mujoco_warnings)
        ]
        # Commands that only show a model (view, render) write no conversion: the notes
        # of loading it say nothing about the picture, so they are listed with -v only.
        if not args.verbose and getattr(args, "shows_only", False):
            caught.notes = []
        _report_notes(caught, bool(args.verbose))
        if args.verbose and args.command in _ASSET_COMMANDS:
            _say_confinement()
        return code
    except RobotwrightError as exc:
        print(f"error: {_error_text(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        # Ctrl-C or SIGTERM on long work (grammar enumeration, search): a line, not a
        # traceback; every temporary was removed on the way out.
        return _interrupted(exc)
    except ImportError as exc:
        # The signal came while an extension module initialised (MuJoCo's, loaded
        # lazily): Python reports the interrupted import as a cause of the failure.
        cause = _interrupt_behind(exc)
        if cause is not None:
            return _interrupted(cause)
        raise
    except BrokenPipeError:
        raise  # main ends quietly: the reader of stdout closed the pipe
    except OSError as exc:
        # The file system refused a path the user gave (permissions, disk full, a file
        # where a folder is needed): name the path, no traceback.
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
