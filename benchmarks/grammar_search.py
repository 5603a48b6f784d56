#!/usr/bin/env python
"""Search throughput: designs evaluated per second for each objective, on 1 and 2 local
processes and on a local Ray cluster, side by side.

    python benchmarks/grammar_search.py [--seconds 3] [--max-links 3] [--ray-cpus 2 8]

Each column runs the same random search (same seed, so the same designs) through one
executor, started and warmed up before the clock starts; the rate is the budget over
the wall time of the search. Budgets are set per objective from a calibration in this
process so that one process takes about ``--seconds``. A Ray cluster of more CPUs than
the machine has cores runs that many worker processes on fewer cores (a simulated
larger cluster: it shows the overhead of the scheduling, not a faster machine).
Needs ``robotwright[ray]`` for the Ray columns (skipped without it).
"""

from __future__ import annotations

import argparse
import os
import random
import sys
import time
import warnings
from concurrent.futures import Executor, ProcessPoolExecutor

from _machine import measured

from robotwright.grammar import default_grammar
from robotwright.grammar.derive import Counter, sample
from robotwright.grammar.executors import usable_cores
from robotwright.grammar.objectives import OBJECTIVES, NoSelfCollision, evaluate
from robotwright.grammar.search import random_search


def ms_per_design(g, objective, max_links: int, n: int = 4) -> float:
    rng = random.Random(123)
    counter = Counter(g)
    designs = [sample(g, max_links, rng, counter) for _ in range(n)]
    evaluate(g, designs[0], (objective,), (NoSelfCollision(),))  # warm-up
    t0 = time.perf_counter()
    for d in designs:
        evaluate(g, d, (objective,), (NoSelfCollision(),))
    return (time.perf_counter() - t0) / n * 1e3


def rate(g, objective, budget: int, max_links: int, executor: Executor, workers: int) -> float:
    kw = dict(max_links=max_links, executor=executor, workers=workers)
    random_search(g, [objective], [NoSelfCollision()], budget=2 * workers, seed=99, **kw)
    t0 = time.perf_counter()
    res = random_search(g, [objective], [NoSelfCollision()], budget=budget, seed=0, **kw)
    return res.n_evaluated / (time.perf_counter() - t0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3.0, help="time per search on 1 process")
    ap.add_argument("--max-links", type=int, default=3)
    ap.add_argument("--objectives", nargs="+", default=list(OBJECTIVES), choices=list(OBJECTIVES))
    ap.add_argument("--ray-cpus", type=int, nargs="*", default=[2, 8], help="local Ray clusters")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    g = default_grammar()
    objectives = {name: OBJECTIVES[name]() for name in args.objectives}
    budgets = {}
    for name, obj in objectives.items():
        ms = ms_per_design(g, obj, args.max_links)
        budgets[name] = max(16, min(2000, int(args.seconds * 1e3 / ms)))
    columns: dict[str, dict[str, float]] = {}
    for procs in (1, 2):
        label = f"{procs} process{'es' if procs > 1 else ''}"
        with ProcessPoolExecutor(max_workers=procs) as pool:
            columns[label] = {
                n: rate(g, o, budgets[n], args.max_links, pool, procs)
                for n, o in objectives.items()
            }
    try:
        from robotwright.grammar.executors import RayExecutor

        for cpus in args.ray_cpus:
            label = f"Ray {cpus} CPUs" + (" (sim.)" if cpus > usable_cores() else "")
            with RayExecutor(num_cpus=cpus) as ray_ex:
                columns[label] = {
                    n: rate(g, o, budgets[n], args.max_links, ray_ex, cpus)
                    for n, o in objectives.items()
                }
    except ImportError as exc:
        print(f"(Ray columns skipped: {exc})", file=sys.stderr)
    print(
        f"designs/s of random search, designs of at most {args.max_links} links, "
        f"{os.cpu_count()} cores ({usable_cores()} usable), load average "
        f"{os.getloadavg()[0]:.1f}; (sim.): more Ray workers than cores"
    )
    head = f"{'objective':10s} {'budget':>6s}" + "".join(f" {c:>18s}" for c in columns)
    print(head)
    for name in objectives:
        cells = "".join(f" {columns[c][name]:18.1f}" for c in columns)
        print(f"{name:10s} {budgets[name]:6d}{cells}")
    return 0


if __name__ == "__main__":
    with measured(("ray",)):
        sys.exit(main())
