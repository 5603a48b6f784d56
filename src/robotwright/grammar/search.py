"""Design search: beam search over partial derivations (scored by random completions)
and uniform random search, with evaluations run through an executor.

Reproducible: all randomness comes from one ``random.Random(seed)``; evaluation order
does not depend on the executor, because results are gathered in submission order.
"""

from __future__ import annotations

import os
import random
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import dataclass, field
from functools import partial as bind

from robotwright.grammar.derive import Counter, Partial, choices_at, options, random_step, sample
from robotwright.grammar.design import Design
from robotwright.grammar.objectives import Constraint, Evaluation, Objective, evaluate
from robotwright.grammar.rules import Grammar


@dataclass
class SearchResult:
    """Best design found and every evaluation made (in order)."""

    best: Evaluation | None
    evaluations: list[Evaluation] = field(default_factory=list)

    @property
    def n_evaluated(self) -> int:
        return len(self.evaluations)


class _Evaluator:
    """Evaluates batches of designs once each (by hash) through an executor."""

    def __init__(
        self,
        grammar: Grammar,
        objectives,
        constraints,
        budget: int,
        executor: Executor | None,
        workers: int | None,
    ) -> None:
        self.fn = bind(
            evaluate, grammar, objectives=tuple(objectives), constraints=tuple(constraints)
        )
        self.budget = budget
        self.cache: dict[str, Evaluation] = {}
        self.order: list[Evaluation] = []
        self._own = executor is None
        self.executor = executor
        self.workers = workers

    def __enter__(self) -> _Evaluator:
        if self.executor is None:
            self.executor = ProcessPoolExecutor(max_workers=self.workers or os.cpu_count() or 1)
        return self

    def __exit__(self, *exc) -> None:
        if self._own and self.executor is not None:
            self.executor.shutdown()

    @property
    def left(self) -> int:
        return self.budget - len(self.cache)

    def run(self, designs: Sequence[Design]) -> list[Evaluation | None]:
        """Evaluations of ``designs`` (``None`` for those past the budget)."""
        todo: list[Design] = []
        seen = set(self.cache)
        for d in designs:
            h = d.hash()
            if h not in seen and len(todo) < self.left:
                todo.append(d)
                seen.add(h)
        assert self.executor is not None
        # A few chunks per worker: fewer pickles of the grammar, still balanced.
        chunk = max(1, len(todo) // (4 * (self.workers or os.cpu_count() or 1)))
        for d, ev in zip(todo, self.executor.map(self.fn, todo, chunksize=chunk)):
            self.cache[d.hash()] = ev
            self.order.append(ev)
        return [self.cache.get(d.hash()) for d in designs]


def _best(evals: list[Evaluation]) -> Evaluation | None:
    feasible = [e for e in evals if e.feasible]
    return max(feasible, key=lambda e: e.score) if feasible else None


def random_search(
    grammar: Grammar,
    objectives: Sequence[Objective],
    constraints: Sequence[Constraint] = (),
    *,
    budget: int = 100,
    max_links: int = 4,
    seed: int = 0,
    executor: Executor | None = None,
    workers: int | None = None,
) -> SearchResult:
    """Evaluate ``budget`` distinct designs drawn uniformly (baseline for beam search)."""
    rng = random.Random(seed)
    counter = Counter(grammar)
    with _Evaluator(grammar, objectives, constraints, budget, executor, workers) as ev:
        tries = 0
        while ev.left > 0 and tries < 20 * budget:
            batch = [sample(grammar, max_links, rng, counter) for _ in range(ev.left)]
            tries += len(batch)
            ev.run(batch)
        return SearchResult(_best(ev.order), ev.order)


def beam_search(
    grammar: Grammar,
    objectives: Sequence[Objective],
    constraints: Sequence[Constraint] = (),
    *,
    budget: int = 100,
    max_links: int = 4,
    beam_width: int = 4,
    rollouts: int = 1,
    seed: int = 0,
    executor: Executor | None = None,
    workers: int | None = None,
    progress: Callable[[int, Evaluation | None], None] | None = None,
) -> SearchResult:
    """Beam search over partial derivations in canonical order.

    Each expansion of a partial derivation (one decision at its current node) is scored
    by evaluating ``rollouts`` uniform random completions of it; the ``beam_width``
    best partial derivations are kept. Stops when ``budget`` distinct designs have been
    evaluated or the beam empties. The first objective is optimised.
    """
    if budget < 1 or beam_width < 1 or rollouts < 1:
        raise ValueError("budget, beam_width and rollouts must be >= 1")
    rng = random.Random(seed)
    counter = Counter(grammar)
    beam = [Partial.start(grammar)]
    with _Evaluator(grammar, objectives, constraints, budget, executor, workers) as ev:
        while beam and ev.left > 0:
            children: list[Partial] = []
            for p in beam:
                for rule, n in options(p):
                    if rule is None:
                        children.append(p.stop())
                    else:
                        children += [p.apply(rule, choices_at(grammar, rule, i)) for i in range(n)]
            children = [c for c in children if counter.completions(c, max_links) > 0]
            rng.shuffle(children)  # ties and the budget cut are broken at random, seeded
            designs: list[list[Design]] = []
            for c in children:
                if c.complete:
                    designs.append([c.design()])
                else:
                    ds = []
                    for _ in range(rollouts):
                        q = c
                        while not q.complete:
                            q = random_step(q, max_links, rng, counter)
                        ds.append(q.design())
                    designs.append(ds)
            flat = [d for ds in designs for d in ds]
            results = ev.run(flat)
            k = 0
            scored: list[tuple[float, int, Partial]] = []
            for i, (c, ds) in enumerate(zip(children, designs)):
                rs = [r for r in results[k : k + len(ds)] if r is not None]
                k += len(ds)
                if not rs:
                    continue
                if not c.complete:
                    scored.append((max(r.score for r in rs), i, c))
            scored.sort(key=lambda t: (-t[0], t[1]))
            beam = [c for _, _, c in scored[:beam_width]]
            if progress is not None:
                progress(len(ev.order), _best(ev.order))
        return SearchResult(_best(ev.order), ev.order)
