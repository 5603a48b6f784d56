"""``robotwright render``: a PNG picture of a robot or scene, no display needed."""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Callable
from pathlib import Path

from robotwright.cli.options import ROBOT_SOURCE_HELP, add_overwrite_flag

__all__ = ["register", "run"]

_SIZE = re.compile(r"^\s*(\d+)\s*[xX]\s*(\d+)\s*$")


def _size(text: str) -> tuple[int, int]:
    m = _SIZE.match(text)
    if not m:
        raise argparse.ArgumentTypeError(f"'{text}': expected WIDTHxHEIGHT in pixels, e.g. 800x600")
    return int(m[1]), int(m[2])


#: MuJoCo's geom groups.
_GROUPS = range(6)
#: Suffixes of a source file left out of the default output name.
_SOURCE_SUFFIXES = (".urdf.xacro", ".xacro", ".urdf", ".xml", ".mjcf", ".npz")


def _groups(text: str) -> tuple[int, ...]:
    parts = [p.strip() for p in text.split(",")]
    if not parts or any(not p.isdigit() or int(p) not in _GROUPS for p in parts):
        raise argparse.ArgumentTypeError(
            f"'{text}': expected comma-separated geom groups 0..5, e.g. 0,1,2"
        )
    return tuple(sorted({int(p) for p in parts}))


def _up_to_60(what: str) -> Callable[[str], float]:
    """An option's type: a number in (0, 60], named ``what`` in the error."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not (0 < value <= 60):  # NaN fails too
            raise argparse.ArgumentTypeError(f"'{text}': expected {what} in (0, 60]")
        return value

    return parse


_seconds = _up_to_60("seconds")
_fps = _up_to_60("frames per second")


def default_output(source: str, suffix: str) -> Path:
    """The file written when ``-o`` is not given: the source's name (a robot name, a
    folder's or file's name without its model suffix) with ``suffix``, in the working
    folder. Characters other than letters, digits, ``.``, ``-`` and ``_`` become ``_``."""
    name = Path(source.rstrip("/\\")).name or "picture"
    lower = name.lower()
    for end in _SOURCE_SUFFIXES:
        if lower.endswith(end) and len(name) > len(end):
            name = name[: -len(end)]
            break
    safe = "".join(c if c.isalnum() and c.isascii() or c in ".-_" else "_" for c in name)
    safe = safe.lstrip(".") or "picture"
    return Path(safe + suffix)


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "render",
        help="draw a robot or scene to a PNG picture (no display needed)",
        description=(
            "Draw a bundled robot, an HRDF folder, an MJCF file (robot or composed scene), "
            "a URDF file or a grammar design folder in its first keyframe (else its "
            "reference pose) to a PNG; or a LiDAR scan's points in its scene. "
            "MuJoCo's OpenGL renderer draws when an off-screen GL platform starts (EGL, "
            "OSMesa; MUJOCO_GL picks one), otherwise a built-in software renderer does; "
            "the command says which."
        ),
    )
    p.add_argument(
        "source",
        help=f"{ROBOT_SOURCE_HELP}; a grammar design folder; or a scan (.npz, with --scene)",
    )
    p.add_argument(
        "-o",
        "--output",
        type=Path,
        help="PNG, or GIF/MP4 with --sweep or --simulate (default: the source's name with "
        ".png, or .gif for an animation, in the working folder)",
    )
    p.add_argument(
        "--camera",
        default="iso",
        help="a camera of the model by name; a view: iso (default), front, back, left, "
        "right, top; or AZIMUTH,ELEVATION[,DISTANCE] in degrees and metres (elevation < 0 "
        "looks down)",
    )
    p.add_argument(
        "--size",
        type=_size,
        default=None,
        metavar="WxH",
        help="picture size [px] (800x600; 400x300 for an animation)",
    )
    shown = p.add_mutually_exclusive_group()
    shown.add_argument(
        "--groups",
        type=_groups,
        metavar="G,G",
        help="geom groups drawn (default 0,1,2, as MuJoCo's viewer); e.g. 3 for collision geoms",
    )
    shown.add_argument(
        "--hide-groups",
        type=_groups,
        metavar="G,G",
        help="draw every geom group 0..5 except these, e.g. 3 to hide collision geoms",
    )
    motion = p.add_mutually_exclusive_group()
    motion.add_argument(
        "--sweep",
        type=_seconds,
        nargs="?",
        const=2.0,
        metavar="SECONDS",
        help="animate a joint sweep (every limited joint to its limits and back; 2 s) to "
        "a .gif or .mp4",
    )
    motion.add_argument(
        "--simulate",
        type=_seconds,
        metavar="SECONDS",
        help="animate SECONDS of MuJoCo simulation from the first pose to a .gif or .mp4",
    )
    p.add_argument("--fps", type=_fps, default=20.0, help="frames per second of an animation (20)")
    p.add_argument(
        "--backend",
        choices=("auto", "gl", "software"),
        default="auto",
        help="auto: OpenGL when it starts, else software (default); gl: OpenGL or fail",
    )
    p.add_argument("--title", help="a line of text drawn at the top of the picture")
    p.add_argument(
        "--scene",
        help="the MJCF scene a scan .npz was taken in (its points are drawn in it)",
    )
    add_overwrite_flag(p)
    p.set_defaults(func=run, shows_only=True)


def run(args: argparse.Namespace) -> int:
    from robotwright._atomic import check_output_path
    from robotwright._outputs import check_overwrite
    from robotwright.errors import OutputPathError
    from robotwright.render.api import render, render_animation
    from robotwright.render.core import DEFAULT_GEOM_GROUPS, RenderError, RenderOptions

    moving = args.sweep is not None or args.simulate is not None
    out: Path = args.output or default_output(args.source, ".gif" if moving else ".png")
    suffix = out.suffix.lower()
    if moving and suffix not in (".gif", ".mp4"):
        raise OutputPathError(f"{out}: expected a .gif or .mp4 output file for an animation")
    if not moving and suffix in (".gif", ".mp4"):
        raise OutputPathError(f"{out}: an animation needs --sweep or --simulate SECONDS")
    if not moving and suffix != ".png":
        raise OutputPathError(f"{out}: expected a .png output file")
    check_output_path(out)
    check_overwrite(out, args.overwrite)
    if moving:
        from robotwright.render.anim import require_writer

        require_writer(out)  # a missing extra fails before anything is drawn
    width, height = args.size or ((400, 300) if moving else (800, 600))
    if args.groups is not None:
        groups = args.groups
    elif args.hide_groups is not None:
        groups = tuple(g for g in _GROUPS if g not in args.hide_groups)
    else:
        groups = DEFAULT_GEOM_GROUPS
    # Options are checked before the model is loaded: a typo fails at once.
    options = RenderOptions(
        width=width,
        height=height,
        camera=args.camera,
        backend=args.backend,
        geom_groups=groups,
    )
    roots = tuple(getattr(args, "asset_roots", ()) or ())
    if moving:
        if args.scene is not None:
            raise RenderError("--scene draws a scan's points in a .png: a scan does not move")
        animation = render_animation(
            args.source,
            out,
            options,
            sweep=args.sweep,
            simulate=args.simulate,
            fps=args.fps,
            asset_roots=roots,
        )
        for note in animation.notes:
            print(f"note: {note}", file=sys.stderr)
        what = "sweep" if args.sweep is not None else "simulation"
        print(
            f"wrote {out} ({len(animation.frames)} frames of a {what}, {width}x{height}, "
            f"{args.fps:g} frames/s, {animation.backend} renderer, camera {args.camera})"
        )
        return 0
    from robotwright._progress import working

    with working(f"drawing {out}"):
        picture = render(
            args.source,
            out,
            options,
            scene=args.scene,
            title=args.title,
            asset_roots=roots,
        )
    for note in picture.notes:
        print(f"note: {note}", file=sys.stderr)
    print(f"wrote {out} ({width}x{height}, {picture.backend} renderer, camera {picture.camera})")
    return 0
