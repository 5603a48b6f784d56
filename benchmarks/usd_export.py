"""USD export against mujoco-usd-converter alone, side by side on the same robots.

For each robot, rounds alternate between (in an order shuffled each round):

  converter   mujoco-usd-converter's ``Converter().convert`` on the robot's own MJCF
              (its default: a layered asset, several .usda files)
  one file    the same converter with ``layer_structure=False``: one flattened file (what
              ours writes), as Isaac Sim's MJCF importer calls the converter
  Isaac Sim   Isaac Sim's kit-less MJCF importer (``MJCFImporter``, default config: the
              converter, then Isaac's schemas, PhysX conversion and asset packaging):
              what an Isaac Lab 3 user runs to bring an MJCF robot in; only where
              isaacsim-asset-isolated is installed
  ours        ``robotwright.generators.to_usd(hrdf, path)``: our MJCF of the robot, the
              same converter, the drives and names authored, the flattened file, and
              the proof (Newton reads the file back; bodies, joints, drives and 20
              random poses compared)
  ours, no proof  the same with ``prove=False`` (what the proof adds)

and the median over rounds of ``ours`` over each of the first three is printed per
robot (the issue's goal: at most 1.5x the converter alone). The robots: mjlab's G1 (from
its wheel), OpenAI's Shadow hand and Gymnasium's humanoid (both fetched by
tools/fetch_test_data.py); each skipped with a reason where absent.

Needs Isaac Lab's environment (Python 3.12, mujoco-usd-converter, Newton)::

    python benchmarks/usd_export.py [--rounds 5]
"""

from __future__ import annotations

import argparse
import gc
import random
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _machine import measured  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / ".testdata"
HAND_ASSETS = DATA / "gymnasium-robotics" / "gymnasium_robotics" / "envs" / "assets"

#: name -> (MJCF file, options for load_robot)
ROBOTS: dict[str, tuple[Path, dict]] = {
    "G1 (mjlab)": (
        DATA / "mjlab" / "mjlab" / "asset_zoo" / "robots" / "unitree_g1" / "xmls" / "g1.xml",
        {},
    ),
    "Shadow hand (OpenAI)": (
        HAND_ASSETS / "hand" / "reach.xml",
        {"asset_roots": (HAND_ASSETS,), "root_body": "robot0:hand mount"},
    ),
    "humanoid (Gymnasium)": (
        DATA / "gymnasium" / "gymnasium" / "envs" / "mujoco" / "assets" / "humanoid.xml",
        {},
    ),
}


def _timed(fn) -> float:
    gc.collect()  # what the step before left is not collected on this step's time
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _convert_alone(mjcf: Path, out: Path, layer_structure: bool = True) -> None:
    import mujoco_usd_converter

    from robotwright._library_output import captured_library_output

    with captured_library_output():
        mujoco_usd_converter.Converter(layer_structure=layer_structure).convert(str(mjcf), str(out))


def _isaac_sim_importer():
    """Isaac Sim's kit-less MJCF importer's class and its config, or ``None``."""
    try:
        from isaacsim.asset.importer.mjcf.impl.converter import MJCFImporter, MJCFImporterConfig
    except ImportError:
        return None
    return MJCFImporter, MJCFImporterConfig


def _import_with_isaac_sim(importer, mjcf: Path, out: Path) -> None:
    from robotwright._library_output import captured_library_output

    cls, config = importer
    out.mkdir()
    with captured_library_output():
        cls(config(mjcf_path=str(mjcf), usd_path=str(out))).import_mjcf()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5, help="alternating rounds per robot")
    ap.add_argument(
        "--without-isaac-sim",
        action="store_true",
        help="leave out Isaac Sim's importer (its rounds take most of the run's time)",
    )
    ap.add_argument("--seed", type=int, default=0, help="seed of each round's order of steps")
    args = ap.parse_args()
    try:
        import mujoco_usd_converter  # noqa: F401
    except ImportError as exc:
        print(f"mujoco-usd-converter is not installed here ({exc}): run in Isaac Lab's env")
        return 2
    from robotwright.generators.usd import to_usd
    from robotwright.sources import load_robot

    warnings.simplefilter("ignore")  # the notes of each export are not what is timed
    shuffle = random.Random(args.seed)
    importer = None if args.without_isaac_sim else _isaac_sim_importer()
    if importer is None and not args.without_isaac_sim:
        print(
            "Isaac Sim's MJCF importer is not installed here (isaacsim-asset-isolated): not timed"
        )
    with measured(("mujoco-usd-converter", "newton", "usd-core", "isaacsim-asset-isolated")):
        print(f"{'robot':22s} {'converter':>9s} {'one file':>8s} {'Isaac Sim':>9s} {'ours':>5s} {'no proof':>8s}   ours / converter, / one file, / Isaac Sim")  # fmt: skip
        for name, (path, options) in ROBOTS.items():
            if not path.is_file():
                print(f"{name:22s} skipped: {path} absent (run tools/fetch_test_data.py)")
                continue
            hrdf = load_robot(str(path), **options)
            with tempfile.TemporaryDirectory() as tmp:
                folder = Path(tmp)
                steps = {
                    "converter": lambda k, path=path, folder=folder: _convert_alone(
                        path, folder / f"c{k}"
                    ),  # fmt: skip
                    "one file": lambda k, path=path, folder=folder: _convert_alone(
                        path, folder / f"f{k}", layer_structure=False
                    ),  # fmt: skip
                    "ours": lambda k, hrdf=hrdf, folder=folder: to_usd(hrdf, folder / f"o{k}.usdc"),
                    "no proof": lambda k, hrdf=hrdf, folder=folder: to_usd(
                        hrdf, folder / f"n{k}.usdc", prove=False
                    ),
                }
                if importer is not None:
                    steps["Isaac Sim"] = lambda k, path=path, folder=folder: _import_with_isaac_sim(
                        importer, path, folder / f"i{k}"
                    )
                times: dict[str, list[float]] = {key: [] for key in steps}
                for step in steps.values():  # warm-up: imports, kernels
                    step(-1)
                order = list(steps)
                for k in range(args.rounds):
                    shuffle.shuffle(order)  # no step always runs after the same one
                    for key in order:
                        step = steps[key]
                        times[key].append(_timed(lambda step=step, k=k: step(k)))
            med = {key: statistics.median(v) for key, v in times.items()}

            def ratio(base: str, times=times) -> str:
                if base not in times:
                    return "-"
                r = [o / c for o, c in zip(times["ours"], times[base], strict=True)]
                return f"{statistics.median(r):.2f}x ({min(r):.2f}-{max(r):.2f})"

            isaac = f"{med['Isaac Sim']:9.2f}" if "Isaac Sim" in med else f"{'-':>9s}"
            print(
                f"{name:22s} {med['converter']:9.2f} {med['one file']:8.2f} {isaac} "
                f"{med['ours']:5.2f} {med['no proof']:8.2f}   {ratio('converter')}, "
                f"{ratio('one file')}, {ratio('Isaac Sim')}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
