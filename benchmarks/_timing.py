"""Shared timing helpers for the benchmark scripts (medians over repeated runs)."""

from __future__ import annotations

import json
import statistics
import subprocess
import time
from collections.abc import Callable


def median_seconds(fn: Callable[[], object], *, repeat: int = 15, number: int = 5) -> float:
    """Median over ``repeat`` samples of the mean time of ``number`` calls (s)."""
    fn()  # warm-up: imports, caches, first-touch file reads
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        samples.append((time.perf_counter() - t0) / number)
    return statistics.median(samples)


def run_peer(python: str, code: str) -> dict:
    """Run ``code`` under another interpreter; it must print one JSON object last."""
    out = subprocess.run([python, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def report(rows: list[tuple[str, float, float | None]]) -> None:
    """Print ``(task, ours_s, peer_s)`` rows with the speed-up ratio."""
    print(f"{'task':40s} {'ours [ms]':>10s} {'peer [ms]':>10s} {'speed-up':>9s}")
    for task, ours, peer in rows:
        peer_txt = f"{peer * 1e3:10.3f}" if peer is not None else f"{'n/a':>10s}"
        ratio = f"{peer / ours:8.1f}x" if peer is not None else f"{'n/a':>9s}"
        print(f"{task:40s} {ours * 1e3:10.3f} {peer_txt} {ratio}")
