#!/usr/bin/env python
"""Search throughput: designs evaluated per second for each objective, on 1 and 2 local
processes and on a local Ray cluster, side by side; with ``--quality``, the best value
each search method reaches per evaluation budget instead.

    python benchmarks/grammar_search.py [--seconds 3] [--max-links 3] [--ray-cpus 2 8]
    python benchmarks/grammar_search.py --quality [--seeds 0 1 2] [--budget 1000]

Quality: random, beam, MCTS (each also guided by the value network: ``+value``) and
the learned search run on the same task (``reach`` and
``payload`` with the command line's default constraints, designs of at most 4 links)
with the same seeds; the table gives the best value found after 50, 100, 200, 300, 500
and 1,000 evaluations, averaged over the seeds, and the last line the mean number of
evaluations the learned search needs to reach the best value random search finds in
1,000 (``--budget``); a seed where it never does counts as the budget plus one.

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
from functools import partial

from _machine import measured

from robotwright.grammar import default_grammar
from robotwright.grammar.derive import Counter, sample
from robotwright.grammar.executors import usable_cores
from robotwright.grammar.learned import learned_search
from robotwright.grammar.objectives import (
    OBJECTIVES,
    NoCarrierCollision,
    NoOverlap,
    NoSelfCollision,
    evaluate,
)
from robotwright.grammar.search import beam_search, mcts_search, random_search

#: The methods compared by ``--quality``, in the order of the table.
METHODS = {
    "random": random_search,
    "beam": beam_search,
    "beam+value": partial(beam_search, guided=True),
    "mcts": mcts_search,
    "mcts+value": partial(mcts_search, guided=True),
    "learned": learned_search,
}
CHECKPOINTS = (50, 100, 200, 300, 500, 1000)


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
    ap.add_argument(
        "--quality", action="store_true", help="best value per budget of each search method"
    )
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2], help="--quality's seeds")
    ap.add_argument("--budget", type=int, default=1000, help="--quality's evaluations")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    g = default_grammar()
    if args.quality:
        return quality(g, args.seeds, args.budget)
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


def best_so_far(res) -> list[float]:  # noqa: ANN001 - a SearchResult
    """The best score after each evaluation, in evaluation order (-inf before any
    feasible design)."""
    best, out = float("-inf"), []
    for e in res.evaluations:
        best = max(best, e.score)
        out.append(best)
    return out


def quality(g, seeds: list[int], budget: int, max_links: int = 4) -> int:
    """Print the best value per budget of each method, and the learned search's
    evaluations to random's best (see the module docstring)."""
    tasks = {
        "reach": ([OBJECTIVES["reach"]()], [NoSelfCollision(), NoOverlap()]),
        "payload": (
            [OBJECTIVES["payload"]()],
            [NoSelfCollision(), NoOverlap(), NoCarrierCollision()],
        ),
    }
    marks = [c for c in CHECKPOINTS if c < budget] + [budget]
    needed: dict[str, list[int]] = {}
    print(f"best value per evaluation budget, designs of at most {max_links} links, seeds {seeds}")
    with ProcessPoolExecutor(max_workers=min(2, usable_cores())) as pool:
        for name, (objs, cons) in tasks.items():
            curves: dict[str, list[list[float]]] = {m: [] for m in METHODS}
            for seed in seeds:
                for method, search in METHODS.items():
                    t0 = time.perf_counter()
                    res = search(
                        g, objs, cons, budget=budget, max_links=max_links, seed=seed, executor=pool
                    )
                    curve = best_so_far(res)
                    curve += [curve[-1]] * (budget - len(curve))  # stopped early: stays
                    curves[method].append(curve)
                    print(
                        f"  {name} seed {seed} {method}: best {curve[-1]:.4f} after "
                        f"{res.n_evaluated} evaluations ({time.perf_counter() - t0:.0f} s)",
                        file=sys.stderr,
                    )
                target = curves["random"][-1][-1]
                hit = next(
                    (i + 1 for i, v in enumerate(curves["learned"][-1]) if v >= target), None
                )
                needed.setdefault(name, []).append(hit if hit is not None else budget + 1)
            unit = "m" if name == "reach" else "kg"
            print(f"{name} [{unit}], mean over seeds of the best value after N evaluations")
            print(f"  {'method':10s}" + "".join(f" {m:>8d}" for m in marks))
            for method, runs in curves.items():
                means = [sum(run[m - 1] for run in runs) / len(runs) for m in marks]
                print(f"  {method:10s}" + "".join(f" {v:8.4f}" for v in means))
            print(f"  learned search reached random's best at {needed[name]} evaluations")
    n1, n2 = (sum(v) / len(v) for v in needed.values())
    print(
        f"learned search: evaluations to random's best at {budget}: reach {n1:.0f}, "
        f"payload {n2:.0f}"
    )
    return 0


if __name__ == "__main__":
    with measured(("ray",)):
        sys.exit(main())
