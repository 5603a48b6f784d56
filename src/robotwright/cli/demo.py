"""``robotwright demo``: one offline run that shows every system working together.

Writes a folder with the bundled robots' summaries, their MJCF and URDF exports, a
two-robot scene, a grammar-generated limb mounted on the humanoid, and a semantic LiDAR
scan of the scene (data and picture), then prints a short summary. Each step is a plain
function so that a failure names the step that failed.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robotwright._names import file_stem
from robotwright._notes import notes_of
from robotwright._progress import working

if TYPE_CHECKING:  # MuJoCo and Things load when the demo runs, not with `robotwright --help`
    from robotwright.things import World

DEFAULT_OUT = Path("robotwright_demo")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "demo",
        help="run the offline demo of every system (writes ./robotwright_demo)",
        description="Export the bundled robots, compose a scene, grow a limb with the "
        "grammar, scan the scene with a semantic LiDAR, and save it all in one folder.",
    )
    p.add_argument(
        "-o",
        "--out",
        type=Path,
        default=DEFAULT_OUT,
        help=f"output folder (default ./{DEFAULT_OUT}): a new or empty folder, or an earlier "
        "demo output, which is refreshed (any other folder is refused)",
    )
    p.set_defaults(func=_run)


def step_hrdf(out: Path, ctx: dict[str, Any]) -> str:
    from robotwright.cli.hrdf import format_info
    from robotwright.hrdf.io import HRDFWarning
    from robotwright.hrdf.model import HRDF

    lines = []
    for name in ("mini_humanoid", "arm6"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", HRDFWarning)
            hrdf = HRDF.from_robot_name(name)
        ctx[name] = hrdf
        text = format_info(hrdf)
        (out / f"{file_stem(name, 'robot')}_info.txt").write_text(text + "\n", encoding="utf-8")
        s = hrdf.summary()
        lines.append(f"{name}: {s['bodies']} bodies, {s['dof']} DoF, {s['total_mass']:.2f} kg")
    return "; ".join(lines)


def step_export(out: Path, ctx: dict[str, Any]) -> str:
    import mujoco

    from robotwright.tasks import export_robot

    written = []
    for name in ("mini_humanoid", "arm6"):
        paths = export_robot(ctx[name], out / "robots")
        model = mujoco.MjModel.from_xml_path(str(paths["mjcf"]))
        from_urdf = mujoco.MjModel.from_xml_path(str(paths["urdf"]))
        written.append(
            f"{name}.xml ({model.nbody - 1} bodies, {model.nu} actuators) + {name}.urdf "
            f"(MuJoCo mass {from_urdf.body_mass.sum():.2f} kg)"
        )
    return "; ".join(written)


def step_roundtrip(out: Path, ctx: dict[str, Any]) -> str:
    from robotwright.proof.roundtrip.run import roundtrip

    lines = []
    log = logging.getLogger("robotwright.parsers")
    level = log.level
    log.setLevel(logging.ERROR)  # the notes go into the report file instead
    try:
        reports = {
            s: roundtrip(out / "robots" / s, configs=20) for s in ("mini_humanoid.urdf", "arm6.xml")
        }
    finally:
        log.setLevel(level)
    for source, report in reports.items():
        notes = "".join(f"note: {w}\n" for w in report.warnings)
        # Paths relative to the demo folder: it is built under a temporary name.
        text = (report.table() + "\n" + notes).replace(f"{out}{os.sep}", "")
        (out / "robots" / f"roundtrip_{source.replace('.', '_')}.txt").write_text(
            text, encoding="utf-8"
        )
        if not report.ok:
            failed = "; ".join(f"{r.check}: {r.value}" for r in report.failures())
            raise RuntimeError(f"round trip of {source} failed: {report.error or failed}")
        passed = len(report.passed())
        empty = len(report.rows) - passed  # nothing to compare (e.g. no sensors): not a pass
        lines.append(
            f"{source} -> HRDF -> MJCF/URDF: {passed} checks pass"
            + (f" ({empty} n/a: nothing to compare)" if empty else "")
        )
    return "; ".join(lines)


def step_limb(out: Path, ctx: dict[str, Any]) -> str:
    from robotwright.grammar import default_grammar, demo_limb_design
    from robotwright.grammar.build import build_hrdf
    from robotwright.grammar.demo import BACKWARDS, write_mounted_limb
    from robotwright.grammar.mount import mount_on

    summary = write_mounted_limb(out / "srl", ctx["mini_humanoid"], seed=DEMO_SEED)
    limb = build_hrdf(default_grammar(), demo_limb_design(DEMO_SEED))
    ctx["wearer"] = mount_on(ctx["mini_humanoid"], limb, "back_mount", quat=BACKWARDS)
    return (
        f"design {summary['design_hash']}: {summary['limb_dof']} DoF, "
        f"{summary['limb_mass_kg']:.2f} kg limb on {summary['mounted_on']} "
        f"-> {summary['robot_dof']} DoF robot"
    )


def step_scene(out: Path, ctx: dict[str, Any]) -> str:
    import mujoco

    from robotwright.tasks import compose_scene
    from robotwright.things import World

    scene_dir = out / "scene"
    robots_xml = compose_scene(
        {"h": ctx["wearer"], "arm": ctx["arm6"]},
        scene_dir / "two_robots.xml",
        placements={"h": (0.0, 0.0, 0.0, 0.0), "arm": (1.2, 0.8, 0.0, math.pi)},
    )
    world = furnish(World.from_xml_path(robots_xml))
    scene = scene_dir / "semantic_scene.xml"
    world.export(scene)
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    ctx["scene_model"], ctx["scene_data"] = model, data
    return (
        f"two_robots.xml (humanoid wearing the limb + arm) and semantic_scene.xml "
        f"({model.nbody - 1} bodies, {model.ngeom} geoms, {model.nu} actuators, "
        f"{data.ncon} contacts at t=0: props resting on floor and table)"
    )


def step_lidar(out: Path, ctx: dict[str, Any]) -> str:
    from robotwright.sensors import scan_to_files

    (out / "lidar").mkdir(parents=True, exist_ok=True)
    # The mapping is saved so that `robotwright lidar ... --mapping classes.json` labels
    # the same scene exactly as the demo does (labels come from the mapping alone).
    (out / "lidar" / "classes.json").write_text(
        json.dumps(DEMO_CLASSES, indent=2) + "\n", encoding="utf-8"
    )
    summary = scan_to_files(
        ctx["scene_model"],
        ctx["scene_data"],
        "h_head_lidar",
        "mid360",
        out / "lidar" / "scan.npz",
        out / "lidar" / "scan.png",
        semantic_class_mapping=DEMO_CLASSES,
        title="Semantic LiDAR (Mid-360-like pattern) from the humanoid's head",
    )
    counts = ", ".join(f"{k} {v}" for k, v in summary["class_counts"].items() if v)
    return f"{summary['num_hits']} of {summary['num_rays']} rays hit: {counts}"


def step_pictures(out: Path, ctx: dict[str, Any]) -> str:
    """Shaded pictures of each robot, of the furnished scene, and of the scene with the
    LiDAR points drawn in it (robotwright.render; no display needed)."""
    from robotwright.render.demo import demo_pictures

    return demo_pictures(out / "pictures", ctx, out / "lidar" / "scan.npz", DEMO_CLASSES)


#: The default classes, plus the other robot in the scene (saved as lidar/classes.json).
DEMO_CLASSES: dict[str, list[str]] = {
    "terrain": ["ground", "wall", "floor", "plane"],
    "dynamic_obstacle": ["cracker_box", "sugar_box", "tomato_soup_can"],
    "valuable": ["sofa", "armchair", "table", "chair", "desk"],
    "robot": ["arm_"],
}
DEMO_SEED = 3


def furnish(world: World) -> World:
    """Add walls, boxes and furniture named so that each falls in one semantic class."""
    from robotwright.things import Body, Box, Cylinder, Free

    wood, fabric, card = (0.55, 0.38, 0.22, 1.0), (0.25, 0.35, 0.6, 1.0), (0.85, 0.2, 0.15, 1.0)
    grey = (0.8, 0.8, 0.78, 1.0)
    for name, pos, size in (
        ("wall_north", (0.5, 4.0, 1.0), (4.5, 0.05, 1.0)),
        ("wall_south", (0.5, -3.0, 1.0), (4.5, 0.05, 1.0)),
        ("wall_east", (5.0, 0.5, 1.0), (0.05, 3.5, 1.0)),
        ("wall_west", (-4.0, 0.5, 1.0), (0.05, 3.5, 1.0)),
    ):
        world.attach(Body(name, pos=pos).attach(Box(f"{name}_geom", size=size, rgba=grey)))
    table = Body("table", pos=(2.0, -1.2, 0.0))
    table.attach(Box("table_top", pos=(0, 0, 0.72), size=(0.6, 0.4, 0.02), rgba=wood))
    for i, (x, y) in enumerate(((0.55, 0.35), (0.55, -0.35), (-0.55, 0.35), (-0.55, -0.35))):
        table.attach(Box(f"table_leg_{i}", pos=(x, y, 0.35), size=(0.025, 0.025, 0.35), rgba=wood))
    sofa = Body("sofa", pos=(-2.2, 2.2, 0.0))
    sofa.attach(
        Box("sofa_seat", pos=(0, 0, 0.22), size=(0.9, 0.4, 0.22), rgba=fabric),
        Box("sofa_back", pos=(0, 0.33, 0.6), size=(0.9, 0.08, 0.3), rgba=fabric),
    )
    chair = Body("chair", pos=(2.6, 1.8, 0.0))
    chair.attach(
        Box("chair_seat", pos=(0, 0, 0.45), size=(0.22, 0.22, 0.02), rgba=wood),
        Box("chair_back", pos=(0, 0.2, 0.7), size=(0.22, 0.02, 0.25), rgba=wood),
        Box("chair_post", pos=(0, 0, 0.22), size=(0.03, 0.03, 0.22), rgba=wood),
    )
    world.attach(table, sofa, chair)
    for i, (x, y) in enumerate(((1.6, -0.3), (-1.5, -1.4), (0.6, 2.4))):
        box = Body(f"cracker_box_{i}", pos=(x, y, 0.15))
        box.attach(
            Free(f"cracker_box_{i}_free"),
            Box(f"cracker_box_{i}_geom", size=(0.08, 0.03, 0.15), rgba=card, mass=0.4),
        )
        world.attach(box)
    can = Body("tomato_soup_can_0", pos=(-1.0, 0.9, 0.05))
    can.attach(
        Free("tomato_soup_can_0_free"),
        Cylinder("tomato_soup_can_0_geom", size=(0.035, 0.05), rgba=card, mass=0.35),
    )
    sugar = Body("sugar_box_0", pos=(1.9, -1.1, 0.83))
    sugar.attach(
        Free("sugar_box_0_free"),
        Box("sugar_box_0_geom", size=(0.045, 0.02, 0.09), rgba=(0.95, 0.9, 0.3, 1.0), mass=0.5),
    )
    world.attach(can, sugar)
    return world


STEPS: list[tuple[str, Callable[[Path, dict[str, Any]], str]]] = [
    ("bundled robots (HRDF)", step_hrdf),
    ("export to MJCF and URDF (generators)", step_export),
    ("parse the exports back and compare in MuJoCo (parsers, proof)", step_roundtrip),
    ("grow a limb with the grammar and mount it", step_limb),
    ("compose a scene and furnish it (composite + Things)", step_scene),
    ("semantic LiDAR scan (sensors)", step_lidar),
    ("pictures of the robots and the scene (render)", step_pictures),
]


def run_demo(out: Path = DEFAULT_OUT) -> dict[str, str]:
    """Run every demo step into ``out``; return step name -> one-line result.

    The folder is built next to ``out`` and replaces it only when every step succeeded:
    a failed or interrupted run leaves the previous demo folder as it was. Only an
    earlier demo output holding nothing else is replaced: any other non-empty folder,
    and a folder holding the working or home folder, raise
    :class:`~robotwright.errors.OutputExistsError` before the first step."""
    from robotwright._atomic import atomic_dir

    ctx: dict[str, Any] = {}
    results: dict[str, str] = {}
    notes: list[str] = []
    with atomic_dir(out, kind="demo") as tmp:
        for i, (title, step) in enumerate(STEPS, 1):
            t0 = time.perf_counter()
            print(f"[{i}/{len(STEPS)}] {title} ...", flush=True)
            # Conversion notes (values a format cannot hold) go to a file, not the terminal.
            with (
                warnings.catch_warnings(record=True) as caught,
                working(f"[{i}/{len(STEPS)}] still at work"),
            ):
                warnings.simplefilter("always")
                results[title] = step(tmp, ctx)
            # One note per value or element, the unit the notes file lists (one per line).
            step_notes = [f"[{title}] {n.text}" for w in caught for n in notes_of(str(w.message))]
            notes += step_notes
            note = f", {len(step_notes)} conversion note(s)" if step_notes else ""
            print(f"      {results[title]} ({time.perf_counter() - t0:.1f} s{note})", flush=True)
        (tmp / "summary.json").write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
        (tmp / "conversion_notes.txt").write_text("\n".join(notes) + "\n", encoding="utf-8")
    return results


def _run(args: argparse.Namespace) -> int:
    from robotwright._atomic import check_output_path
    from robotwright._outputs import check_folder_output
    from robotwright.errors import OutputPathError

    # Checked before the first step, so a wrong -o fails at once and writes nothing.
    check_output_path(args.out, folder=True)
    if args.out.exists() and not args.out.is_dir():
        raise OutputPathError(f"{args.out}: is a file; expected a folder for the demo output")
    check_folder_output(args.out, "demo", overwrite=True)  # only its own output is replaced
    run_demo(args.out)
    print(f"demo written to {args.out.resolve()} (summary.json, conversion_notes.txt)")
    return 0
