"""USD export against mujoco-usd-converter alone, side by side on the same robots.

For each robot, rounds alternate between:

  converter   mujoco-usd-converter's ``Converter().convert`` on the robot's own MJCF
              (what a user runs without robotwright)
  ours        ``robotwright.generators.to_usd(hrdf, path)``: our MJCF of the robot, the
              same converter, the drives and names authored, the flattened file, and
              the proof (Newton reads the file back; bodies, joints, drives and 20
              random poses compared)
  ours, no proof  the same with ``prove=False`` (what the proof adds)

and the median ratio of ``ours`` over ``converter`` is printed per robot (the issue's
goal: at most 1.5x). The robots: mjlab's G1 (from its wheel), OpenAI's Shadow hand and Gymnasium's humanoid (both fetched by
tools/fetch_test_data.py); each skipped with a reason where absent.

Needs Isaac Lab's environment (Python 3.12, mujoco-usd-converter, Newton)::

    python benchmarks/usd_export.py [--rounds 5]
"""

from __future__ import annotations

import argparse
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
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _convert_alone(mjcf: Path, out: Path) -> None:
    import mujoco_usd_converter

    from robotwright._library_output import captured_library_output

    with captured_library_output():
        mujoco_usd_converter.Converter().convert(str(mjcf), str(out))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5, help="alternating rounds per robot")
    args = ap.parse_args()
    try:
        import mujoco_usd_converter  # noqa: F401
    except ImportError as exc:
        print(f"mujoco-usd-converter is not installed here ({exc}): run in Isaac Lab's env")
        return 2
    from robotwright.generators.usd import to_usd
    from robotwright.sources import load_robot

    warnings.simplefilter("ignore")  # the notes of each export are not what is timed
    with measured(("mujoco-usd-converter", "newton", "usd-core")):
        print(f"{'robot':24s} {'converter [s]':>13s} {'ours [s]':>9s} {'no proof [s]':>12s} {'ours / converter':>17s}")  # fmt: skip
        for name, (path, options) in ROBOTS.items():
            if not path.is_file():
                print(f"{name:24s} skipped: {path} absent (run tools/fetch_test_data.py)")
                continue
            hrdf = load_robot(str(path), **options)
            times: dict[str, list[float]] = {"converter": [], "ours": [], "no proof": []}
            with tempfile.TemporaryDirectory() as tmp:
                folder = Path(tmp)
                steps = {
                    "converter": lambda k, path=path, folder=folder: _convert_alone(
                        path, folder / f"c{k}"
                    ),  # fmt: skip
                    "ours": lambda k, hrdf=hrdf, folder=folder: to_usd(hrdf, folder / f"o{k}.usdc"),
                    "no proof": lambda k, hrdf=hrdf, folder=folder: to_usd(
                        hrdf, folder / f"n{k}.usdc", prove=False
                    ),
                }
                for step in steps.values():  # warm-up: imports, kernels
                    step(-1)
                for k in range(args.rounds):
                    for key, step in steps.items():
                        times[key].append(_timed(lambda step=step, k=k: step(k)))
            med = {key: statistics.median(v) for key, v in times.items()}
            ratios = [o / c for o, c in zip(times["ours"], times["converter"], strict=True)]
            print(
                f"{name:24s} {med['converter']:13.2f} {med['ours']:9.2f} {med['no proof']:12.2f} "
                f"{statistics.median(ratios):16.2f}x  (rounds {min(ratios):.2f}-{max(ratios):.2f}x)"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
