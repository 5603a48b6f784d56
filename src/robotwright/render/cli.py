"""``robotwright render``: a PNG picture of a robot or scene, no display needed."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from robotwright._outputs import add_overwrite_flag

__all__ = ["register", "run"]

_SIZE = re.compile(r"^\s*(\d+)\s*[xX]\s*(\d+)\s*$")


def _size(text: str) -> tuple[int, int]:
    m = _SIZE.match(text)
    if not m:
        raise argparse.ArgumentTypeError(f"'{text}': expected WIDTHxHEIGHT in pixels, e.g. 800x600")
    return int(m[1]), int(m[2])


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
        help="robot name, HRDF folder, MJCF (.xml) or URDF (.urdf) file, grammar design "
        "folder, or scan (.npz, with --scene)",
    )
    p.add_argument("-o", "--output", type=Path, required=True, help="PNG file to write")
    p.add_argument(
        "--camera",
        default="iso",
        help="a camera of the model by name; a view: iso (default), front, back, left, "
        "right, top; or AZIMUTH,ELEVATION[,DISTANCE] in degrees and metres (elevation < 0 "
        "looks down)",
    )
    p.add_argument(
        "--size", type=_size, default=(800, 600), metavar="WxH", help="picture size [px] (800x600)"
    )
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
    from robotwright.render.api import render
    from robotwright.render.core import RenderOptions

    out: Path = args.output
    if out.suffix.lower() != ".png":
        raise OutputPathError(f"{out}: expected a .png output file")
    check_output_path(out)
    check_overwrite(out, args.overwrite)
    width, height = args.size
    # Options are checked before the model is loaded: a typo fails at once.
    options = RenderOptions(width=width, height=height, camera=args.camera, backend=args.backend)
    picture = render(
        args.source,
        out,
        options,
        scene=args.scene,
        title=args.title,
        asset_roots=tuple(getattr(args, "asset_roots", ()) or ()),
    )
    for note in picture.notes:
        print(f"note: {note}", file=sys.stderr)
    print(f"wrote {out} ({width}x{height}, {picture.backend} renderer, camera {picture.camera})")
    return 0
