"""A search that learns: a value function over partial designs, trained online.

In the spirit of RoboGrammar's graph heuristic search. Every evaluated design teaches a
small neural network (:class:`~robotwright.grammar.value.PrefixValue`, numpy only) the
best normalised score reached through each of its prefixes (the partial derivations on
its way); each new design is grown decision by decision, mostly towards the children the
network rates highest, with probability ``epsilon`` a uniform random one, so the search
keeps exploring. The first ``warmup`` designs are drawn uniformly, to give the network
something to learn from. Everything is seeded: the same seed gives the same search on
any executor.
"""

from __future__ import annotations

import os
import random
from collections.abc import Callable, Sequence
from concurrent.futures import Executor

import numpy as np

from robotwright.grammar.derive import (
    Counter,
    Partial,
    sample,
)
from robotwright.grammar.design import Design
from robotwright.grammar.objectives import Constraint, Evaluation, Objective, best_of
from robotwright.grammar.rules import Grammar
from robotwright.grammar.search import SearchResult, _Evaluator, expansions
from robotwright.grammar.value import PrefixValue

__all__ = ["learned_search"]

#: Designs drawn uniformly before the network steers.
WARMUP = 32
#: Designs grown per round between two trainings of the network.
LEARNED_BATCH = 16


def _pick(weights: np.ndarray, rng: random.Random) -> int:
    """An index drawn with probability proportional to ``weights`` (seeded)."""
    r = rng.random() * float(weights.sum())
    return min(int(np.searchsorted(np.cumsum(weights), r, side="right")), len(weights) - 1)


def learned_search(
    grammar: Grammar,
    objectives: Sequence[Objective],
    constraints: Sequence[Constraint] = (),
    *,
    budget: int = 100,
    max_links: int = 4,
    epsilon: float = 0.05,
    temperature: float = 0.05,
    warmup: int = WARMUP,
    batch: int = LEARNED_BATCH,
    hidden: int = 32,
    seed: int = 0,
    executor: Executor | None = None,
    workers: int | None = None,
    progress: Callable[[int, Evaluation | None], None] | None = None,
    force_workers: bool = False,
    log: str | os.PathLike[str] | None = None,
    resume: str | os.PathLike[str] | None = None,
):
    """Grow designs guided by a value network trained on the evaluations so far.

    The first objective is optimised; scores are normalised to [0, 1] by the range of
    feasible scores seen, an infeasible design counts as 0. A prefix's training target
    is the best normalised score of any evaluated design through it. Each round grows
    ``batch`` designs: at every decision, with probability ``epsilon`` a uniform random
    child, else a child drawn with weight ``exp((v - v_best) / temperature)`` of its
    rating ``v`` (the best mostly, its close rivals sometimes); a design already
    evaluated is grown again, and after 5 tries replaced by a uniform one. Shares the
    executor, log and resume rules of :func:`robotwright.grammar.search.random_search`.
    """
    if budget < 1:
        raise ValueError("budget must be >= 1")
    for name, value, low, high in (
        ("epsilon", epsilon, 0.0, 1.0),
        ("temperature", temperature, 1e-6, 100.0),
        ("warmup", warmup, 0, 1_000_000),
        ("batch", batch, 1, 10_000),
        ("hidden", hidden, 1, 4096),
    ):
        if isinstance(value, bool) or not (low <= value <= high):
            raise ValueError(f"{name} must be in [{low}, {high}], got {value!r}")
    rng = random.Random(seed)
    counter = Counter(grammar)
    value = PrefixValue(grammar, hidden=hidden, seed=seed)

    def grow() -> Design:
        if not value.trained or rng.random() < epsilon / 4:
            return sample(grammar, max_links, rng, counter)
        p = Partial.start(grammar)
        while not p.complete:
            kids = expansions(p, grammar, counter, max_links)
            if not kids:  # cannot happen for a feasible partial; be safe
                return sample(grammar, max_links, rng, counter)
            if rng.random() < epsilon:
                p = kids[rng.randrange(len(kids))]
                continue
            rated = value.rate(kids)
            # Boltzmann choice: the best child mostly, its close rivals sometimes, so
            # that designs near the best are tried rather than the same one again.
            weights = np.exp((rated - rated.max()) / temperature)
            p = kids[_pick(weights, rng)]
        return p.design()

    with _Evaluator(
        grammar,
        objectives,
        constraints,
        budget,
        executor,
        workers,
        progress,
        force_workers,
        log=log,
        resume=resume,
        header=dict(method="learned", seed=seed, budget=budget, max_links=max_links),
    ) as ev:
        stalls = 0
        while ev.left > 0 and stalls < 50:
            size = min(ev.left, warmup if not value.trained else batch)
            seen = set(ev.cache)  # the hashes of the designs evaluated so far
            designs: list[Design] = []
            for _ in range(size):
                d = grow()
                tries = 0
                while d.hash() in seen and tries < 20:
                    d = grow() if tries < 5 else sample(grammar, max_links, rng, counter)
                    tries += 1
                seen.add(d.hash())
                designs.append(d)
            before = len(ev.order)
            ev.run(designs)
            stalls = stalls + 1 if len(ev.order) == before else 0
            value.learn(ev.order)
        stopped = (
            "budget reached"
            if ev.left <= 0
            else f"50 rounds in a row found no design not evaluated before ({len(ev.order)} "
            f"distinct designs within max_links {max_links})"
        )
        return SearchResult(best_of(ev.order), ev.order, stopped)
