"""``robotwright lidar``: scan a MuJoCo scene with a semantic LiDAR, save data and a picture."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from robotwright._atomic import check_output_path
from robotwright._outputs import check_overwrite
from robotwright.cli.options import add_overwrite_flag
from robotwright.errors import SensorError
from robotwright.sensors._names import PATTERN_NAMES

__all__ = ["register", "run"]


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "lidar",
        help="scan an MJCF scene with a semantic LiDAR (saves .npz, draws .png)",
        description=(
            "Cast one frame of a LiDAR pattern from a body or site of an MJCF scene and save "
            "distances [m], world-frame points [m], semantic labels and hit geom ids."
        ),
    )
    p.add_argument(
        "scene",
        type=Path,
        help="MJCF file of the scene, or any robot: name, HRDF folder, URDF or xacro file",
    )
    p.add_argument("--sensor", required=True, help="name of the body or site carrying the sensor")
    p.add_argument(
        "--pattern", default="mid360", choices=PATTERN_NAMES, help="scan pattern (default mid360)"
    )
    p.add_argument("-o", "--output", type=Path, help="output .npz file")
    p.add_argument("--png", type=Path, help="output picture (top and side views coloured by class)")
    p.add_argument(
        "--max-distance", type=float, default=40.0, help="maximum range [m] (default 40)"
    )
    p.add_argument(
        "--offset",
        type=float,
        nargs=3,
        default=(0.0, 0.0, 0.0),
        metavar=("X", "Y", "Z"),
        help="sensor position in the carrier's frame [m]",
    )
    p.add_argument(
        "--view-radius",
        type=float,
        help="picture only: draw points within this horizontal distance of the sensor [m]",
    )
    p.add_argument(
        "--mapping",
        type=Path,
        help="JSON file {class name: [keywords]} (default: terrain, dynamic_obstacle and "
        "valuable with their keywords, see docs/sensors.md); a robot is unknown unless a "
        "class names it",
    )
    p.add_argument(
        "--include-robot", action="store_true", help="let rays hit the robot carrying the sensor"
    )
    p.add_argument(
        "--engine", choices=("mujoco", "warp"), default="mujoco", help="ray engine (default mujoco)"
    )
    add_overwrite_flag(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import mujoco

    from robotwright.sensors.scan import scan_to_files

    if args.output is None and args.png is None:
        raise SensorError("nothing to write: give -o SCAN.npz and/or --png SCAN.png")
    scene_file = args.scene.suffix.lower() in (".xml", ".mjcf")
    if scene_file and not args.scene.exists():
        raise SensorError(f"{args.scene}: scene file not found")
    if args.view_radius is not None and not args.view_radius > 0:
        raise SensorError(
            f"--view-radius: expected a positive distance [m], got {args.view_radius}"
        )
    # Both outputs are checked before the scan, so a bad --png leaves no .npz behind.
    for out, ext, flag in ((args.output, ".npz", "-o"), (args.png, ".png", "--png")):
        if out is not None:
            if out.suffix.lower() != ext:
                raise SensorError(f"{flag} {out}: expected a file name ending in {ext}")
            check_output_path(out)
            if not out.parent.is_dir():
                raise SensorError(f"{out}: folder {out.parent} does not exist")
    check_overwrite([args.output, args.png], args.overwrite)
    from robotwright.scene.load import compile_mjcf
    from robotwright.sensors.config import read_class_mapping

    mapping = None if args.mapping is None else read_class_mapping(args.mapping)
    from robotwright.sources import wants_parse

    if scene_file and not wants_parse():
        model = compile_mjcf(args.scene, error=SensorError)
    else:  # a robot by name, HRDF folder, URDF or xacro: as view and render show it
        from robotwright.scene.load import load_source

        model = load_source(str(args.scene)).model
    _check_sensor_name(model, args.sensor, args.scene)
    data = mujoco.MjData(model)
    if model.nkey:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    summary = scan_to_files(
        model,
        data,
        args.sensor,
        args.pattern,
        args.output,
        args.png,
        semantic_class_mapping=mapping,
        max_distance=args.max_distance,
        offset_pos=tuple(args.offset),
        exclude_robot=not args.include_robot,
        engine=args.engine,
        view_radius=args.view_radius,
    )
    counts = ", ".join(f"{k}={v}" for k, v in summary["class_counts"].items())
    print(f"{summary['num_rays']} rays, {summary['num_hits']} hits ({counts})")
    for key in ("npz", "png"):
        if summary[key]:
            print(f"wrote {summary[key]}")
    return 0


def _check_sensor_name(model: Any, name: str, scene: object) -> None:
    """``--sensor`` names a body or a site of the model (said in the command's terms,
    with the close names)."""
    import mujoco

    from robotwright._suggest import did_you_mean

    for kind in (mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_SITE):
        if mujoco.mj_name2id(model, kind, name) >= 0:
            return
    names = [model.body(i).name for i in range(model.nbody)]
    names += [model.site(i).name for i in range(model.nsite)]
    raise SensorError(
        f"--sensor {name!r}: no body or site of that name in {scene}"
        f"{did_you_mean(name, [n for n in names if n])}"
    )
