"""``robotwright view SOURCE``: serve the browser viewer until Ctrl-C.

Registering the command imports nothing heavy: MuJoCo, numpy and viser are imported
when the command runs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from robotwright.cli.options import ROBOT_SOURCE_HELP

#: Geom groups accepted by ``--groups`` (MuJoCo has six).
_GROUPS = range(6)
#: The longest the serving thread sleeps between looks at a pending signal [s].
_SIGNAL_POLL_S = 0.5


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port number 0..65535, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port number 0..65535, got {value}")
    return value


def _origin(text: str) -> str:
    from robotwright.view.gate import parse_origin

    if parse_origin(text) is None:
        raise argparse.ArgumentTypeError(
            f"expected an origin scheme://host[:port] (http or https, no path), got {text!r}"
        )
    return text


def _groups(text: str) -> tuple[int, ...]:
    try:
        groups = tuple(int(g) for g in text.split(",") if g.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated geom groups 0..5, got {text!r}"
        ) from None
    if any(g not in _GROUPS for g in groups):
        raise argparse.ArgumentTypeError(f"expected geom groups 0..5, got {text!r}")
    return groups


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "view",
        help="show a robot, scene or scan in the browser (viser)",
        description="Serve a web page showing SOURCE: a bundled robot name, an HRDF "
        "folder, an MJCF, URDF or xacro file, a composed scene, a grammar design folder, or a "
        "scan .npz (with --scene). Meshes and primitives in MuJoCo's colours, body and site "
        "frames, joint sliders (MuJoCo forward kinematics), scan points by semantic class. "
        "Prints the URL and runs until Ctrl-C.",
    )
    p.add_argument(
        "source",
        help=f"{ROBOT_SOURCE_HELP}; a grammar design folder; or a scan (.npz, with --scene)",
    )
    p.add_argument("--scene", type=Path, help="MJCF scene a scan .npz was taken in")
    p.add_argument(
        "--port",
        type=_port,
        default=None,
        help="TCP port, an error when taken (default: 8080, or the next free one); 0 for any",
    )
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="address to listen on (default 127.0.0.1, this machine only; 0.0.0.0 for all, "
        "with a warning)",
    )
    p.add_argument(
        "--allow-origin",
        action="append",
        dest="allow_origins",
        type=_origin,
        default=[],
        metavar="ORIGIN",
        help="also let pages of ORIGIN (e.g. http://robot-pc.lan:8080) connect, and accept "
        "its host name in requests; for deliberate remote use; repeatable",
    )
    p.add_argument(
        "--groups",
        type=_groups,
        default=None,
        help="geom groups shown first, e.g. 0,1,2 (MuJoCo's default) or 3 for collision",
    )
    p.add_argument("--frames", action="store_true", help="show body and site frames first")
    p.add_argument(
        "--plain",
        action="store_true",
        help="simple lights, no environment map or shadows (faster without a GPU)",
    )
    p.add_argument(
        "--simulate",
        action="store_true",
        help="start the MuJoCo simulation playing (the page's Simulation folder has "
        "play/pause, step, actuator sliders, contacts and camera follow either way)",
    )
    p.set_defaults(func=_run, shows_only=True)


def _run(args: argparse.Namespace) -> int:
    from robotwright._notes import notes_of, summary_line
    from robotwright.scene.load import load_source
    from robotwright.view.server import Viewer, ViewerConfig

    # --asset-root (added by the main parser) is in force around this call.
    scene = load_source(args.source, scene=args.scene)
    # The page runs until Ctrl-C, so what the loaders could not carry is told now, in
    # the command line's usual form, rather than when the command ends.
    for line in scene.warnings:  # the model shown differs from the robot: always said
        print(f"warning: {line}", file=sys.stderr)
    # The viewer only shows the model, as render does: what a conversion would not keep
    # is listed with -v only.
    verbose = bool(getattr(args, "verbose", False))
    notes = [n for message in scene.notes for n in notes_of(message)]
    if notes and verbose:
        for n in notes:
            print(f"note: {n.text}", file=sys.stderr)
        print(summary_line(notes, "listed above"), file=sys.stderr)
    options = {} if args.groups is None else {"geom_groups": args.groups}
    config = ViewerConfig(
        host=args.host,
        port=args.port,
        body_frames=args.frames,
        site_frames=args.frames,
        plain=args.plain,
        simulate=args.simulate,
        allowed_origins=tuple(args.allow_origins),
        **options,
    )
    viewer = Viewer(scene, config)
    if viewer.exposure:
        print(f"warning: {viewer.exposure}", file=sys.stderr)
    m = scene.model
    print(
        f"{scene.title}: {m.nbody - 1} bodies, {m.njnt} joints, {viewer.geom_count} geoms shown"
        + (f", {len(scene.scan.points)} scan points" if scene.scan is not None else "")
    )
    for line in note_lines(viewer.notes, viewer.skipped, verbose):
        print(line, file=sys.stderr)
    _stop_on_signals()
    try:
        # Inside the try: a Ctrl-C right after the address is printed still stops cleanly.
        print(f"open {viewer.url} in a browser (Ctrl-C to stop)", flush=True)
        while True:
            # Short sleeps: a signal the kernel hands to another thread interrupts no
            # sleep of this one, and its handler runs only when this one wakes.
            time.sleep(_SIGNAL_POLL_S)
    except KeyboardInterrupt:
        _ignore_signals()  # a second Ctrl-C while the server stops does not cut it short
        print("stopped", flush=True)
    finally:
        viewer.stop()
    return 0


def _ignore_signals() -> None:
    """SIGINT and SIGTERM ignored from here on (the viewer is stopping: exit 0)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)


def note_lines(notes: list[str], skipped: list[str], verbose: bool) -> list[str]:
    """What the page cannot draw as MuJoCo would: every note with ``verbose``, else one
    line; a texture drawn as its colour (the scene's own floor has one) only with
    ``verbose``."""
    from robotwright.scene.geometry import TEXTURE_NOT_DRAWN

    lines = [*notes, *skipped]
    if verbose:
        return [f"note: {line}" for line in lines]
    lines = [line for line in lines if not line.endswith(TEXTURE_NOT_DRAWN)]
    if len(lines) <= 1:
        return [f"note: {line}" for line in lines]
    return [f"note: {lines[0]} (and {len(lines) - 1} more; -v lists each)"]


def _stop_on_signals() -> None:
    """Ctrl-C (SIGINT) and SIGTERM stop the viewer, also where SIGINT was inherited as
    ignored (a background job of a script starts with it ignored) or blocked."""
    import signal
    import threading

    def stop(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    if threading.current_thread() is not threading.main_thread():
        return  # a caller's thread: the caller's handlers and mask stay
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, stop)
    # A blocked signal is never delivered, and a process inherits its parent's mask.
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
