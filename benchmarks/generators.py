"""Time robotwright's generators against hurodes on the same HRDF, in one run.

Tasks (same robot folder for both tools, output written to a temporary folder):

1. ``load+mjcf``: read the HRDF folder and export MJCF to a file.
2. ``urdf``: export URDF (robot already loaded).
3. ``composite``: build a two-robot MJCF composite and export it (robots already loaded).

hurodes runs in its own interpreter (``--hurodes-python``); its robot folder is copied
under a temporary ``$HURODES_ASSETS_PATH/robots`` because hurodes only reads robots there.

Usage::

    python benchmarks/generators.py --hurodes-python .testdata/hurodes-venv/bin/python
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path

from _machine import measured, print_peer

HERE = Path(__file__).resolve().parent
#: The hurodes-written G1 that tools/fetch_test_data.py makes.
DEFAULT_ROBOT = HERE.parent / ".testdata" / "hurodes-fixtures" / "g1_29"

HURODES_WORKER = r"""
import contextlib, io, sys, time
from collections.abc import Callable
from pathlib import Path
from hurodes import ROBOTS_PATH
from hurodes.hrdf.hrdf import HRDF
from hurodes.generators.mjcf_generator.mjcf_humanoid_generator import MJCFHumanoidGenerator
from hurodes.generators.mjcf_generator.mjcf_generator_composite import MJCFGeneratorComposite
from hurodes.generators.urdf_generator.urdf_humanoid_generator import URDFHumanoidGenerator

name, out = sys.argv[1], Path(sys.argv[2])
path = ROBOTS_PATH / name
hrdf = HRDF.from_dir(path)
sink = io.StringIO()

def load_mjcf():
    MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(path)).export(out / "h.xml")

urdf_gen = URDFHumanoidGenerator.from_hrdf(hrdf)
def urdf():
    urdf_gen.export(out / "h.urdf")

def composite():
    gens = {"a": MJCFHumanoidGenerator.from_hrdf(hrdf), "b": MJCFHumanoidGenerator.from_hrdf(hrdf)}
    MJCFGeneratorComposite(gens).export(out / "hc.xml")

tasks = {"load+mjcf": load_mjcf, "urdf": urdf, "composite": composite}
print("ready", flush=True)
for line in sys.stdin:
    task, count = line.split()
    results = []
    try:
        for _ in range(int(count)):
            with contextlib.redirect_stdout(sink):
                c = time.process_time()
                t = time.perf_counter()
                tasks[task]()
                dt = time.perf_counter() - t
                dc = time.process_time() - c
            results.append(f"{dt!r},{dc!r}")
    except Exception as exc:  # a feature hurodes lacks (e.g. capsules in URDF)
        print("error " + " ".join(f"{type(exc).__name__}: {exc}".split()), flush=True)
        continue
    print(" ".join(results), flush=True)
"""


def our_tasks(robot: Path, out: Path) -> dict[str, Callable[[], object]]:
    """The three tasks on our side, as callables."""
    from robotwright.generators import (
        MJCFGeneratorComposite,
        MJCFHumanoidGenerator,
        Placement,
        URDFHumanoidGenerator,
    )
    from robotwright.hrdf import HRDF

    hrdf = HRDF.from_dir(robot)
    urdf_gen = URDFHumanoidGenerator.from_hrdf(hrdf)

    def composite() -> object:
        gens = {
            "a": MJCFHumanoidGenerator.from_hrdf(hrdf),
            "b": MJCFHumanoidGenerator.from_hrdf(hrdf),
        }
        return MJCFGeneratorComposite(gens, {"b": Placement((1.5, 0.0, 0.0))}).export(
            out / "rc.xml"
        )

    return {
        "load+mjcf": lambda: MJCFHumanoidGenerator.from_hrdf_path(robot).export(out / "r.xml"),
        "urdf": lambda: urdf_gen.export(out / "r.urdf"),
        "composite": composite,
    }


def prepare_robot(robot: Path, assets: Path, peak_velocity: float) -> tuple[Path, int]:
    """Copy ``robot`` to ``assets/robots/<name>`` (where hurodes looks) and fill empty
    ``peak_velocity`` cells, which hurodes' URDF export cannot do without. Both tools
    then read this same copy. Returns the copy and the number of cells filled."""
    import csv

    dst = assets / "robots" / robot.name
    shutil.copytree(robot, dst, ignore=shutil.ignore_patterns("exported"))
    table = dst / "actuator.csv"
    filled = 0
    if table.is_file():
        with table.open(newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
            fields = list(rows[0].keys()) if rows else []
        for row in rows:
            if "peak_velocity" in row and not row["peak_velocity"]:
                row["peak_velocity"] = repr(peak_velocity)
                filled += 1
        with table.open("w", newline="", encoding="utf-8") as fh:
            writer = csv.DictWriter(fh, fieldnames=fields, lineterminator="\n")
            writer.writeheader()
            writer.writerows(rows)
    return dst, filled


def _block_runs(timed: list[tuple[float, float]], seconds: float) -> int:
    """Runs in the next block so that it lasts about ``seconds`` of wall time, judged by
    the median run so far (one run, to measure, when there is none yet)."""
    if not timed:
        return 1
    per_run = statistics.median(wall for wall, _ in timed)
    return max(1, min(10_000, round(seconds / max(per_run, 1e-9))))


class HurodesWorker:
    """hurodes in its own interpreter, timing one task per request (same process
    throughout, so imports and caches are warm as on our side)."""

    def __init__(self, python: str, robot: Path, assets: Path, out: Path) -> None:
        env = dict(os.environ, HURODES_ASSETS_PATH=str(assets))
        self.proc = subprocess.Popen(
            [python, "-c", HURODES_WORKER, robot.name, str(out)],
            env=env,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert self.proc.stdout is not None and self.proc.stdin is not None
        if self.proc.stdout.readline().strip() != "ready":
            raise SystemExit(
                f"hurodes worker failed:\n{self.proc.stderr.read() if self.proc.stderr else ''}"
            )

    def time(self, task: str, count: int) -> list[tuple[float, float]] | str:
        """Run ``task`` ``count`` times back to back; (wall, cpu) seconds of each run,
        or hurodes' error message where it cannot do the task on this robot."""
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(f"{task} {count}\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line:
            raise SystemExit(
                f"hurodes worker died:\n{self.proc.stderr.read() if self.proc.stderr else ''}"
            )
        if line.startswith("error "):
            return line[len("error ") :].strip()
        out = []
        for item in line.split():
            wall, cpu = item.split(",")
            out.append((float(wall), float(cpu)))
        return out

    def close(self) -> None:
        if self.proc.stdin is not None:
            self.proc.stdin.close()
        self.proc.wait(timeout=30)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", type=Path, default=DEFAULT_ROBOT, help="HRDF folder")
    parser.add_argument("--hurodes-python", default=None, help="python of a hurodes venv")
    parser.add_argument("--repeat", type=int, default=30, help="runs of each task per tool")
    parser.add_argument(
        "--block-seconds",
        type=float,
        default=0.25,
        help="wall time [s] of each tool's block of runs of one task, the tools alternating",
    )
    parser.add_argument(
        "--peak-velocity",
        type=float,
        default=30.0,
        help="rad/s written into empty peak_velocity cells of the benchmark copy",
    )
    parser.add_argument(
        "--out-dir",
        type=Path,
        default=Path("/dev/shm") if Path("/dev/shm").is_dir() else None,
        help="where both tools write their files (default: /dev/shm when present, so the "
        "disk's write latency, the same for both, does not hide the generators' time)",
    )
    args = parser.parse_args(argv)
    print_peer(args.hurodes_python, "hurodes")
    robot = args.robot.resolve()
    if not (robot / "meta.yaml").is_file():
        raise SystemExit(f"{robot}: not an HRDF folder (run python tools/fetch_test_data.py)")
    ours: dict[str, list[tuple[float, float]]] = {}
    theirs: dict[str, list[tuple[float, float]]] | None = {} if args.hurodes_python else None
    failed: dict[str, str] = {}  # task -> hurodes' error on this robot
    with tempfile.TemporaryDirectory(dir=args.out_dir) as tmp:
        out = Path(tmp)
        copy, filled = prepare_robot(robot, out / "assets", args.peak_velocity)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            tasks = our_tasks(copy, out)
            worker = (
                HurodesWorker(args.hurodes_python, copy, out / "assets", out)
                if args.hurodes_python
                else None
            )
            try:
                # Alternate the two tools in blocks of equal wall time (--block-seconds)
                # per task, until each tool has --repeat runs: both see the same machine
                # load over the same span of time, and each block runs warm. Blocks of
                # equal run counts would not: the first few runs after the other process
                # ran are up to 1.6x slower (its work evicted our caches), which for the
                # tool whose runs are shorter spreads over most of its block.
                pending = True
                while pending:
                    pending = False
                    for task, fn in tasks.items():
                        mine = ours.setdefault(task, [])
                        for _ in range(_block_runs(mine, args.block_seconds)):
                            c = time.process_time()
                            t = time.perf_counter()
                            fn()
                            dt = time.perf_counter() - t
                            mine.append((dt, time.process_time() - c))
                        pending |= len(mine) < args.repeat
                        if worker is None or theirs is None or task in failed:
                            continue
                        done = theirs.setdefault(task, [])
                        timed = worker.time(task, _block_runs(done, args.block_seconds))
                        if isinstance(timed, str):
                            failed[task] = timed
                            continue
                        done.extend(timed)
                        pending |= len(done) < args.repeat
            finally:
                if worker is not None:
                    worker.close()
    print(f"robot: {robot}  repeats: {args.repeat}  python: {sys.version.split()[0]}")
    print(
        f"output folder: {tmp} (medians of wall time per task; blocks of "
        f"{args.block_seconds} s per tool, alternating)"
    )
    if filled:
        print(
            f"note: {filled} empty peak_velocity cell(s) set to {args.peak_velocity} rad/s "
            "in the copy both tools read (hurodes' URDF export needs them)"
        )
    header = (
        f"{'task':<12} {'ours wall':>10} {'hurodes wall':>13} {'ratio':>6}"
        f" {'ours cpu':>9} {'hurodes cpu':>12} {'ratio':>6}   (ms, medians)"
    )
    print(header)
    print("-" * len(header))
    for task, values in ours.items():
        wall = statistics.median(v[0] for v in values) * 1e3
        cpu = statistics.median(v[1] for v in values) * 1e3
        if theirs is None or task in failed:
            print(f"{task:<12} {wall:>10.2f} {'-':>13} {'-':>6} {cpu:>9.2f} {'-':>12} {'-':>6}")
            continue
        hw = statistics.median(v[0] for v in theirs[task]) * 1e3
        hc = statistics.median(v[1] for v in theirs[task]) * 1e3
        print(
            f"{task:<12} {wall:>10.2f} {hw:>13.2f} {hw / wall:>5.1f}x"
            f" {cpu:>9.2f} {hc:>12.2f} {hc / cpu:>5.1f}x"
        )
    for task, error in failed.items():
        print(f"note: hurodes cannot do {task!r} on this robot: {error}")
    if os.getloadavg()[0] > (os.cpu_count() or 1):
        print(
            f"note: load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores: wall "
            "times include waiting for the CPU; the CPU-time columns do not"
        )
    return 0


if __name__ == "__main__":
    with measured():
        sys.exit(main())
