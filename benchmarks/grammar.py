#!/usr/bin/env python
"""Grammar throughput: designs sampled, built and compiled per second; enumeration rate;
exact counting; search evaluations with a process pool vs one process.

    python benchmarks/grammar.py [--designs 200] [--max-links 4]

No peer runs here: RoboGrammar (the reference robot graph grammar) is a C++/Python
research build that is not on PyPI and has no MJCF/URDF export, and hurodes has no
grammar. The numbers are ours alone; each line is a median over repeats.
"""

from __future__ import annotations

import argparse
import os
import random
import statistics
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

from _machine import measured

sys.path.insert(0, str(Path(__file__).resolve().parent))

import mujoco  # noqa: E402

from robotwright.generators import MJCFHumanoidGenerator  # noqa: E402
from robotwright.grammar import build_hrdf, count, default_grammar, enumerate_designs  # noqa: E402
from robotwright.grammar.build import build  # noqa: E402
from robotwright.grammar.derive import Counter, sample  # noqa: E402
from robotwright.grammar.objectives import NoSelfCollision, Reach, evaluate  # noqa: E402
from robotwright.grammar.search import random_search  # noqa: E402


def rates(fn, n: int, repeat: int) -> tuple[float, float]:
    """Median items per second of ``fn()`` (which handles ``n`` items) over ``repeat``
    runs, by the wall clock and per second of this process's CPU time (what one core
    does when other work shares the machine), both taken on the same runs."""
    fn()
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(n / (time.perf_counter() - t0))
        cpu.append(n / (time.process_time() - c0))
    return statistics.median(wall), statistics.median(cpu)


def rate(fn, n: int, repeat: int) -> float:
    """Median items per second of ``fn()`` by the wall clock (see :func:`rates`)."""
    return rates(fn, n, repeat)[0]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=200)
    ap.add_argument("--max-links", type=int, default=4)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument(
        "--search-pairs",
        type=int,
        default=9,
        help="alternating runs of the 1-process and the 2-worker search",
    )
    ap.add_argument("--only-search", action="store_true", help="time the search alone")
    ap.add_argument(
        "--compare-search",
        action="store_true",
        help="also compare best values of beam, MCTS and random search (seeds 0-2)",
    )
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    g = default_grammar()
    if not args.only_search:
        time_building(g, args.designs, args.max_links, args.repeat)
    search_speedup(g, args.max_links, args.search_pairs)
    if args.compare_search:
        compare_search(g, args.max_links)
    return 0


def time_building(g, n: int, L: int, repeat: int) -> None:
    """Designs per second of each step of the search's path (wall and CPU clocks)."""
    counter = Counter(g)

    def sampled():
        rng = random.Random(0)
        return [sample(g, L, rng, counter) for _ in range(n)]

    designs = sampled()

    def built():
        return [build_hrdf(g, d) for d in designs]

    hrdfs = built()

    def compiled():
        for d in designs:
            # no scene: the default skybox texture alone costs ~13 ms to compile
            xml = MJCFHumanoidGenerator.from_hrdf(build_hrdf(g, d)).generate(add_scene=False)
            mujoco.MjModel.from_xml_string(ET_tostring(xml))

    from xml.etree.ElementTree import tostring as ET_tostring  # noqa: N812

    def specced():
        # what search evaluations compile: the limb built straight into an MjSpec
        # (motors limited to the peak torques), no XML text
        for d in designs:
            build(g, d).to_spec(motors=True).compile()

    def specced_xml():
        for d in designs:
            spec = build(g, d).to_spec(motors=True)
            spec.compile()
            spec.to_xml()  # the MJCF text of that spec

    tasks = [
        (f"sample (uniform, <= {L} links)", sampled),
        ("build HRDF (incl. MuJoCo mass props)", built),
        ("build + MJCF generate + MuJoCo compile", compiled),
        ("build + MjSpec + MuJoCo compile", specced),
        ("build + MjSpec + compile + MJCF text", specced_xml),
    ]
    mean_dof = statistics.mean(h.dof for h in hrdfs)
    print(f"grammar {g.name}: {n} designs, <= {L} links, mean {mean_dof:.1f} DoF")
    print(
        f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; "
        "designs/s by the wall clock and per CPU-second of this process"
    )
    print(f"{'task':42s} {'designs/s':>12s} {'per CPU-s':>12s}")
    for task, fn in tasks:
        wall, cpu = rates(fn, n, repeat)
        print(f"{task:42s} {wall:12.1f} {cpu:12.1f}")

    total = count(g, 3)
    t = rate(lambda: sum(1 for _ in enumerate_designs(g, 3)), total, 1)
    print(f"{'enumerate all designs <= 3 links':42s} {t:12.1f}   ({total} designs)")
    t0 = time.perf_counter()
    big = count(g, 12)
    print(
        f"exact count <= 12 links: {big:.4e} designs in {(time.perf_counter() - t0) * 1e3:.1f} ms"
    )


def _evaluate_all(g, designs) -> float:
    """Seconds to evaluate ``designs`` one after another in this process."""
    objs, cons = (Reach(),), (NoSelfCollision(),)
    t0 = time.perf_counter()
    for d in designs:
        evaluate(g, d, objs, cons)
    return time.perf_counter() - t0


def machine_ceiling(ex: ProcessPoolExecutor, g, designs) -> float:
    """What two processes give on this machine for these evaluations, with nothing
    shared: a warm worker evaluates them all alone, then each of two evaluates them all
    at once; twice the first wall time over the second (2.0 where the two cores do not
    slow each other)."""
    t0 = time.perf_counter()
    ex.submit(_evaluate_all, g, designs).result()
    alone = time.perf_counter() - t0
    t0 = time.perf_counter()
    list(ex.map(_evaluate_all, [g, g], [designs, designs]))
    return 2 * alone / (time.perf_counter() - t0)


def search_speedup(g, L: int, pairs: int, budget: int = 256) -> None:
    """A random search on one process against the same search on a 2-worker pool, and
    against what two processes give on this machine at all.

    The three run in turn, ``pairs`` times, so that a change of the machine's speed
    touches each alike; each round gives a ratio, and the medians are printed with their
    range. The pool's start is inside its timing, as in a user's search. The ceiling
    (:func:`machine_ceiling`) is measured because two busy processes on a shared virtual
    machine do not get two cores' work: a CPU-bound loop ran 1.1-2.7x alone's rate on two
    processes on the 2-core development machine, so the pool's speed-up is also given as
    a fraction of it.
    """
    print(f"load average before search: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    objs, cons = [Reach()], [NoSelfCollision()]
    makers = {
        "1 process (thread pool of 1)": lambda: ThreadPoolExecutor(1),
        "process pool, 2 workers": lambda: ProcessPoolExecutor(2),
    }
    rng, counter = random.Random(0), Counter(g)
    designs = [sample(g, L, rng, counter) for _ in range(budget)]
    times: dict[str, list[float]] = {label: [] for label in makers}
    ceilings: list[float] = []
    with ProcessPoolExecutor(2) as calibration:
        machine_ceiling(calibration, g, designs[:8])  # both workers started and warm
        for _ in range(pairs):
            for label, make in makers.items():
                with make() as ex:
                    t0 = time.perf_counter()
                    random_search(g, objs, cons, budget=budget, max_links=L, seed=0, executor=ex)
                    times[label].append(time.perf_counter() - t0)
            ceilings.append(machine_ceiling(calibration, g, designs))
    for label, values in times.items():
        print(
            f"search evaluations (reach + self-collision), {label:30s} "
            f"{budget / statistics.median(values):8.1f} designs/s"
        )
    one, pool = times.values()
    ratios = [a / b for a, b in zip(one, pool)]
    shares = [r / c for r, c in zip(ratios, ceilings)]

    def spread(v: list[float]) -> str:
        return f"{statistics.median(v):.2f} (range {min(v):.2f}-{max(v):.2f})"

    print(f"process pool speed-up with 2 workers: {spread(ratios)}x, {pairs} rounds")
    print(
        f"this machine's ceiling, two processes evaluating at once against one alone: "
        f"{spread(ceilings)}x"
    )
    print(f"pool speed-up as a share of the ceiling: {spread(shares)}")


def compare_search(g, max_links: int, budget: int = 300) -> None:
    """Best value found by each method at the same budget (quality, not speed)."""
    from robotwright.grammar.objectives import WorkspaceVolume
    from robotwright.grammar.search import beam_search, mcts_search

    print(f"best value at {budget} evaluations, <= {max_links} links, no self-collision")
    for obj in (Reach(), WorkspaceVolume(samples=512)):
        for seed in (0, 1, 2):
            vals = {}
            for name, fn in (
                ("beam", beam_search),
                ("mcts", mcts_search),
                ("random", random_search),
            ):
                with ThreadPoolExecutor(1) as ex:
                    res = fn(
                        g,
                        [obj],
                        [NoSelfCollision()],
                        budget=budget,
                        max_links=max_links,
                        seed=seed,
                        executor=ex,
                    )
                vals[name] = res.best.score
            ratio = {k: v / vals["random"] for k, v in vals.items()}
            print(
                f"  {obj.name:9s} seed {seed}: beam {vals['beam']:.4f} ({ratio['beam']:.2f}x random), "
                f"mcts {vals['mcts']:.4f} ({ratio['mcts']:.2f}x), random {vals['random']:.4f}"
            )


if __name__ == "__main__":
    with measured(("cma", "ray")):
        sys.exit(main())
