"""How the cost of converting and exporting grows with the robot: chains and trees of
100, 300, 1,000 and 3,000 links, each step with its proof, as the command line runs it.

Robots (URDF, built here): link i hangs from link i-1 (a chain) or from link (i-1)//4 (a
tree), each with a box visual and collision geom, on revolute joints. Steps, timed in
this process (CPU seconds, median of --repeat runs):

  convert     robotwright convert ROBOT.urdf -o HRDF       (URDF -> HRDF, with its proof)
  export-mjcf robotwright export HRDF --format mjcf        (with its proof; a chain deeper
                                                            than MuJoCo's MJCF reader takes
                                                            has no MJCF: skipped)
  export-urdf robotwright export HRDF --format urdf        (with its proof)
  export-usd  robotwright export HRDF --format usd         (only where mujoco-usd-converter
                                                            is installed: Isaac Lab's
                                                            environment; --usd; through
                                                            our MJCF, so not a chain
                                                            too deep for it either)

  converter   mujoco-usd-converter alone on our MJCF of the robot (no scene; --usd):
              what the USD export hands it, the reference its time is set against

CPU time counts this process and the reader processes it starts. One conversion of a
small robot and its exports run first, untimed (imports, caches, warp's kernels).

  keys        a one-joint MJCF robot with as many keyframes as the sizes say (unnamed:
              the proof matches them by order): convert to HRDF and export MJCF, each with
              its proof (--max-keyframes raised to fit)

  mujoco      mujoco.MjModel.from_xml_path(ROBOT.urdf): MuJoCo's own import of the source,
              the reference every proof compiles at least once

Prints each time and, per step and shape, the growth exponent k of time ~ links^k fitted
over the sizes (least squares on the logs; the goal is k <= 1.2) and the exponent between
the two largest sizes (where a step that grows faster than the links shows first).

    python benchmarks/scaling.py [--sizes 100 300 1000 3000] [--repeat 1] [--usd]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import math
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _machine import measured

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "parsers"))
from test_roundtrip_scale import tree_urdf  # noqa: E402

from robotwright._inputs import MJCF_MAX_BODY_DEPTH  # noqa: E402
from robotwright._mjspec_cache import forget  # noqa: E402
from robotwright.cli import main as cli  # noqa: E402

SHAPES = {"chain": 1, "tree": 4}


def _depth(n: int, branching: int) -> int:
    """Bodies from the root to the deepest link of a robot of ``n`` links."""
    depth, i = 1, n - 1
    while i > 0:
        i = (i - 1) // branching
        depth += 1
    return depth


def _cpu() -> float:
    """CPU seconds of this process and of its finished children (the confined readers
    run in child processes)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def _run(args: list[str]) -> float:
    """CPU seconds of one command (its output swallowed), as its own process would spend
    them (no MuJoCo parse kept from the command before); exit code 0 required."""
    out, err = io.StringIO(), io.StringIO()
    forget()
    c0 = _cpu()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli(args)
    spent = _cpu() - c0
    if code != 0:
        raise SystemExit(f"robotwright {' '.join(args)} exited {code}:\n{err.getvalue()}")
    return spent


#: MuJoCo's import of one file, timed in its own process: MuJoCo 3.12, having refused a
#: chain deeper than its compiler takes, spun for minutes on the next import in the same
#: process. Prints the CPU seconds of the import, or "refused".
_IMPORT = """
import sys, time
import mujoco
start = time.process_time()
try:
    mujoco.MjModel.from_xml_path(sys.argv[1])
except (ValueError, RuntimeError):  # its depth limit (3.12 raises a RuntimeError)
    print("refused")
else:
    print(time.process_time() - start)
"""


def _mujoco_import(source: Path) -> float | None:
    """CPU seconds of MuJoCo's own import of ``source`` (None: MuJoCo refuses it)."""
    done = subprocess.run(
        [sys.executable, "-c", _IMPORT, str(source)], capture_output=True, text=True, check=True
    )
    answer = done.stdout.strip().splitlines()[-1]
    return None if answer == "refused" else float(answer)


def _converter_alone(hrdf: Path, folder: Path) -> float:
    """CPU seconds of mujoco-usd-converter alone on our MJCF of ``hrdf`` (the robot alone,
    written untimed into ``folder``)."""
    import mujoco_usd_converter

    from robotwright._library_output import captured_library_output

    mjcf = folder / "robot.xml"
    _run(["export", str(hrdf), "--format", "mjcf", "--no-scene", "-o", str(mjcf), "--overwrite"])
    c0 = _cpu()
    with captured_library_output():
        mujoco_usd_converter.Converter().convert(str(mjcf), str(folder / "usd"))
    return _cpu() - c0


def _keyframes(tmp: Path, n: int) -> dict[str, float]:
    """CPU seconds of converting a one-joint robot with ``n`` keyframes to HRDF and of
    exporting that HRDF as MJCF, each with its proof."""
    folder = tmp / f"keys{n}"
    folder.mkdir()
    source = folder / "robot.xml"
    keys = "".join(f'<key qpos="{i / n:.6f}"/>' for i in range(n))
    body = '<body name="arm"><joint name="hinge"/><geom size="0.1" mass="1"/></body>'
    source.write_text(
        f"<mujoco><worldbody>{body}</worldbody><keyframe>{keys}</keyframe></mujoco>",
        encoding="utf-8",
    )
    limit = ["--max-keyframes", str(max(n, 1))]
    hrdf = folder / "hrdf"
    out = folder / "out.xml"
    return {
        "convert": _run(["convert", str(source), "-o", str(hrdf), *limit]),
        "export-mjcf": _run(["export", str(hrdf), "--format", "mjcf", "-o", str(out), *limit]),
    }


def _record(
    growth: dict[tuple[str, str], tuple[list[int], list[float]]],
    key: tuple[str, str],
    n: int,
    spent: float,
) -> str:
    """Adds ``spent`` at size ``n`` to the growth series ``key`` (shape, step); its cell."""
    sizes, times = growth.setdefault(key, ([], []))
    sizes.append(n)
    times.append(spent)
    return f"{spent:12.2f}"


def exponent(sizes: list[int], times: list[float]) -> float:
    """k of ``time ~ size^k``, least squares on the logs."""
    xs = [math.log(s) for s in sizes]
    ys = [math.log(max(t, 1e-9)) for t in times]
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--sizes", type=int, nargs="+", default=[100, 300, 1000, 3000])
    ap.add_argument("--repeat", type=int, default=1, help="runs per step (median)")
    ap.add_argument("--usd", action="store_true", help="also export USD (Isaac Lab's env)")
    args = ap.parse_args()
    steps = ["convert", "export-mjcf", "export-urdf"]
    steps += ["export-usd", "converter"] if args.usd else []
    steps.append("mujoco")
    print(f"{'shape':6} {'links':>6} " + " ".join(f"{s:>12}" for s in steps) + "   (CPU s)")
    growth: dict[tuple[str, str], tuple[list[int], list[float]]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        warm = Path(tmp) / "warm.urdf"
        warm.write_text(tree_urdf(10), encoding="utf-8")
        _run(["convert", str(warm), "-o", str(Path(tmp) / "warm"), "--overwrite"])
        for step in steps:  # the first USD export loads Newton and builds warp's kernels
            if step.startswith("export-"):
                kind = step.split("-")[1]
                out = Path(tmp) / f"warm-out.{'xml' if kind == 'mjcf' else kind}"
                _run(["export", str(Path(tmp) / "warm"), "--format", kind, "-o", str(out)])
        for shape, branching in SHAPES.items():
            for n in args.sizes:
                folder = Path(tmp) / f"{shape}{n}"
                folder.mkdir()
                source = folder / "robot.urdf"
                source.write_text(tree_urdf(n, branching=branching), encoding="utf-8")
                hrdf = folder / "hrdf"
                cells = []
                # USD goes out through our MJCF: neither holds a chain that deep
                too_deep = _depth(n, branching) > MJCF_MAX_BODY_DEPTH
                for step in steps:
                    if step in ("export-mjcf", "export-usd", "converter") and too_deep:
                        cells.append(f"{'(too deep)':>12}")
                        continue
                    if step == "mujoco":
                        runs = [_mujoco_import(source) for _ in range(args.repeat)]
                        if None in runs:
                            cells.append(f"{'(refused)':>12}")
                            continue
                        spent = statistics.median(runs)  # type: ignore[type-var]
                        cells.append(_record(growth, (shape, step), n, spent))
                        continue
                    if step == "converter":
                        runs = [
                            _converter_alone(hrdf, folder / "alone") for _ in range(args.repeat)
                        ]
                        cells.append(_record(growth, (shape, step), n, statistics.median(runs)))
                        continue
                    if step == "convert":
                        cmd = ["convert", str(source), "-o", str(hrdf), "--overwrite"]
                    else:
                        kind = step.split("-")[1]
                        out = folder / f"out.{'xml' if kind == 'mjcf' else kind}"
                        cmd = ["export", str(hrdf), "--format", kind, "-o", str(out)]
                        cmd.append("--overwrite")
                    spent = statistics.median(_run(cmd) for _ in range(args.repeat))
                    cells.append(_record(growth, (shape, step), n, spent))
                print(f"{shape:6} {n:>6} " + " ".join(cells), flush=True)
        for n in args.sizes:
            cells = [
                _record(growth, ("keys", step), n, spent)
                for step, spent in _keyframes(Path(tmp), n).items()
            ]
            print(f"{'keys':6} {n:>6} " + " ".join(cells), flush=True)
    print("growth exponent k (time ~ links^k, or keyframes^k; goal <= 1.2):")
    for (shape, step), (sizes, times) in growth.items():
        if len(sizes) >= 2:
            k = exponent(sizes, times)
            last = exponent(sizes[-2:], times[-2:])
            unit = "keyframes" if shape == "keys" else "links"
            print(
                f"  {shape:6} {step:12} k = {k:.2f} over {sizes[0]}-{sizes[-1]} {unit}, "
                f"{last:.2f} from {sizes[-2]} to {sizes[-1]}"
            )


if __name__ == "__main__":
    with measured(("trimesh",)):
        main()
