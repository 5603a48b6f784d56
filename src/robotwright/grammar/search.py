"""Design search: beam search over partial derivations (scored by random completions)
and uniform random search, with evaluations run through an executor.

Reproducible: all randomness comes from one ``random.Random(seed)``; evaluation order
does not depend on the executor, because results are gathered in submission order. The
executor is a local process pool, a Ray cluster (:class:`RayExecutor`), or any
:class:`concurrent.futures.Executor` given. Evaluations may stream to a JSON-lines log
and a stopped search resume from it (:mod:`robotwright.grammar.searchlog`).
"""

from __future__ import annotations

import os
import random
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence, Sized
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import dataclass, field
from functools import partial as bind
from itertools import chain
from pathlib import Path
from typing import Any

import numpy as np

from robotwright.grammar.derive import Counter, Partial, choices_at, options, random_step, sample
from robotwright.grammar.design import Design
from robotwright.grammar.executors import RayExecutor, die_with_parent, pool_size, usable_cores
from robotwright.grammar.objectives import Constraint, Evaluation, Objective, best_of, evaluate
from robotwright.grammar.rules import Grammar, Rule
from robotwright.grammar.searchlog import SearchLog, read_log
from robotwright.grammar.value import PrefixValue

__all__ = [
    "RayExecutor",
    "SearchResult",
    "beam_search",
    "check_workers",
    "mcts_search",
    "random_search",
    "usable_cores",
]


def check_workers(
    workers: int | None, force: bool = False, how_to_force: str = "force_workers=True"
) -> None:
    """Refuse a worker count the machine cannot run at once.

    Each worker is a process: a count far above the cores only costs memory and start-up
    time (5,000 requested started 5,000 processes). At most :func:`usable_cores` workers
    are accepted unless ``force`` is true (``how_to_force`` says how, in the message).

    Raises:
        ValueError: ``workers`` is below 1, or above the cores without ``force``.
    """
    if workers is None:
        return
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    cores = usable_cores()
    if workers > cores and not force:
        raise ValueError(
            f"{workers} worker processes requested, but this machine has {cores} core(s): "
            f"expected at most {cores} ({how_to_force} starts more)"
        )


#: Leaves MCTS picks per round by default. A fixed number, not one that follows the
#: workers: the same seed then gives the same search on any machine, pool or Ray cluster.
MCTS_BATCH = 8
#: A guided beam search rolls out this many times ``beam_width`` expansions per step:
#: those its value network rates highest.
GUIDED_KEEP = 3

#: Designs random search draws per round: the pool starts, the log fills and progress
#: is reported from the first round, not after all ``budget`` draws. The result does not
#: depend on it: every round takes the next distinct designs of the same stream.
RANDOM_BATCH = 256


@dataclass
class SearchResult:
    """Best design found, every evaluation made (in order), and why the search stopped
    (``"budget reached"``, or what ended it before)."""

    best: Evaluation | None
    evaluations: list[Evaluation] = field(default_factory=list)
    stopped: str = "budget reached"

    @property
    def n_evaluated(self) -> int:
        return len(self.evaluations)


class _Evaluator:
    """Evaluates batches of designs once each (by hash) through an executor, taking
    those found in a resumed log from it and appending the others to the log."""

    def __init__(
        self,
        grammar: Grammar,
        objectives,
        constraints,
        budget: int,
        executor: Executor | None,
        workers: int | None,
        progress: Callable[[int, Evaluation | None], None] | None = None,
        force_workers: bool = False,
        *,
        log: str | os.PathLike[str] | None = None,
        resume: str | os.PathLike[str] | None = None,
        header: Mapping[str, Any] | None = None,
        known: Mapping[str, Evaluation] | None = None,
        append: bool = False,
    ) -> None:
        """``known``: evaluations by design hash taken instead of evaluated (beside the
        resumed log's); ``append``: add to the log (a later stage of the same run)."""
        if executor is None:  # the pool started here has ``workers`` processes
            check_workers(workers, force_workers)
        self.progress = progress
        objectives, constraints = tuple(objectives), tuple(constraints)
        self.fn = bind(evaluate, grammar, objectives=objectives, constraints=constraints)
        self.grammar = grammar
        self.budget = budget
        self.cache: dict[str, Evaluation] = {}
        self.order: list[Evaluation] = []
        self._own = executor is None
        self.executor = executor
        self.workers = workers
        # Read before the log is opened: resuming into the same file appends to it.
        self.known: dict[str, Evaluation] = (
            read_log(resume, grammar.name, objectives, constraints, header) if resume else {}
        )
        self.known.update(known or {})
        same = resume is not None and (log is None or _same_file(log, resume))
        # Appending to the resumed log: its own evaluations are in it already.
        self._log_known = not same
        path = resume if same else log
        self.log = (
            SearchLog(
                path, grammar.name, objectives, constraints, append=same or append, **(header or {})
            )
            if path is not None
            else None
        )

    def __enter__(self) -> _Evaluator:
        if self.executor is None:
            # Never more processes than evaluations: a forced count above the budget
            # would only start idle processes.
            self.executor = ProcessPoolExecutor(
                max_workers=pool_size(self.workers, self.budget),
                initializer=die_with_parent,
                initargs=(os.getpid(),),
            )
        return self

    def __exit__(self, *exc) -> None:
        try:
            if self._own and self.executor is not None:
                self.executor.shutdown()
        finally:
            if self.log is not None:
                self.log.close()

    @property
    def left(self) -> int:
        return self.budget - len(self.cache)

    def run(
        self, designs: Iterable[Design], expected: int | None = None
    ) -> list[Evaluation | None]:
        """Evaluations of ``designs`` (``None`` for those past the budget).

        ``designs`` may be a generator (random search draws them as it goes): each batch
        goes to the executor as soon as it is full, so the workers evaluate while the
        rest are drawn. ``expected``: how many designs it yields (it sizes the batches;
        default: its length, or the budget left).
        """
        assert self.executor is not None
        if expected is None:
            expected = len(designs) if isinstance(designs, Sized) else self.left
        # Many small batches per worker, so that the last ones end close together; each
        # batch's pickle of the grammar and objectives is a few kB.
        workers = getattr(self.executor, "workers", None) or self.workers or usable_cores()
        chunk = max(1, min(expected, self.left) // (16 * workers))
        given: list[Design] = []
        todo: list[Design] = []
        seen = set(self.cache)
        batch: list[Design] = []
        parts: list[Iterator[Evaluation]] = []
        for d in designs:
            given.append(d)
            h = d.hash()
            if h in seen or len(todo) >= self.left:
                continue
            todo.append(d)
            seen.add(h)
            if h not in self.known:
                batch.append(d)
                if len(batch) >= chunk:
                    parts.append(iter(self.executor.map(self.fn, batch, chunksize=chunk)))
                    batch = []
        if batch:
            parts.append(iter(self.executor.map(self.fn, batch, chunksize=chunk)))
        results = chain.from_iterable(parts)
        for d in todo:  # submission order: the same on every executor
            h = d.hash()
            known = self.known.get(h)
            ev = known if known is not None else next(results)
            self.cache[h] = ev
            self.order.append(ev)
            if self.log is not None and (known is None or self._log_known):
                self.log.write(ev, len(self.order) - 1)
        if self.progress is not None and todo:
            self.progress(len(self.order), best_of(self.order))
        return [self.cache.get(d.hash()) for d in given]


def _same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return Path(a).resolve() == Path(b).resolve()


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
    progress: Callable[[int, Evaluation | None], None] | None = None,
    force_workers: bool = False,
    log: str | os.PathLike[str] | None = None,
    resume: str | os.PathLike[str] | None = None,
) -> SearchResult:
    """Evaluate ``budget`` distinct designs drawn uniformly (baseline for beam search).

    Shared by the three searches: ``executor`` runs the evaluations (default: a pool of
    ``workers`` processes, at most the usable cores unless ``force_workers``; or a
    :class:`RayExecutor`); ``progress(n, best)`` is called after each batch; ``log``
    names a JSON-lines file that gets one line per evaluation as it comes, and
    ``resume`` a log whose evaluations are taken instead of evaluated again (appended
    to when ``log`` is not given or is the same file). Results do not depend on the
    executor, nor on a stop and a resume: the same seed gives the same result.
    """
    rng = random.Random(seed)
    counter = Counter(grammar)
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
        header=dict(method="random", seed=seed, budget=budget, max_links=max_links),
    ) as ev:
        tries = 0
        while ev.left > 0 and tries < 20 * budget:
            size = min(ev.left, RANDOM_BATCH)
            # Drawn as they are evaluated: the pool starts on the first designs.
            ev.run((sample(grammar, max_links, rng, counter) for _ in range(size)), size)
            tries += size
        stopped = (
            "budget reached"
            if ev.left <= 0
            else f"{tries} draws found only {len(ev.order)} distinct designs (the grammar "
            f"has few within max_links {max_links})"
        )
        return SearchResult(best_of(ev.order), ev.order, stopped)


def expansions(p: Partial, grammar: Grammar, counter: Counter, max_links: int) -> list[Partial]:
    """Every next partial derivation of ``p`` (one decision at its current node: a rule
    with each of its choices, or stopping) that can still complete within
    ``max_links``."""
    out = [
        decide(p, grammar, rule, i)
        for rule, n in options(p)
        for i in (range(n) if rule is not None else (0,))
    ]
    return [c for c in out if counter.completions(c, max_links) > 0]


def decide(p: Partial, grammar: Grammar, rule: Rule | None, i: int) -> Partial:
    """``p`` after one decision at its current node: ``rule`` with its ``i``-th choices,
    or stopping when ``rule`` is None."""
    return p.stop() if rule is None else p.apply(rule, choices_at(grammar, rule, i))


def beam_search(
    grammar: Grammar,
    objectives: Sequence[Objective],
    constraints: Sequence[Constraint] = (),
    *,
    budget: int = 100,
    max_links: int = 4,
    beam_width: int = 4,
    rollouts: int = 1,
    guided: bool = False,
    seed: int = 0,
    executor: Executor | None = None,
    workers: int | None = None,
    progress: Callable[[int, Evaluation | None], None] | None = None,
    force_workers: bool = False,
    log: str | os.PathLike[str] | None = None,
    resume: str | os.PathLike[str] | None = None,
) -> SearchResult:
    """Beam search over partial derivations in canonical order.

    Each expansion of a partial derivation (one decision at its current node) is scored
    by evaluating ``rollouts`` uniform random completions of it; the ``beam_width``
    best partial derivations are kept. Stops when ``budget`` distinct designs have been
    evaluated or the beam empties. The first objective is optimised.

    ``guided``: a value network over partial designs (:class:`~robotwright.grammar.
    value.PrefixValue`), trained on every evaluation so far, picks which expansions
    are rolled out: once it has learned, only the ``GUIDED_KEEP`` times ``beam_width``
    it rates highest are, so the budget goes to the promising ones.
    """
    if budget < 1 or beam_width < 1 or rollouts < 1:
        raise ValueError("budget, beam_width and rollouts must be >= 1")
    rng = random.Random(seed)
    counter = Counter(grammar)
    beam = [Partial.start(grammar)]
    value = PrefixValue(grammar, seed=seed) if guided else None
    header = dict(method="beam", seed=seed, budget=budget, max_links=max_links)
    if guided:  # a log of a guided search resumes only as one
        header["guided"] = True
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
        header=header,
    ) as ev:
        while beam and ev.left > 0:
            children = [c for p in beam for c in expansions(p, grammar, counter, max_links)]
            rng.shuffle(children)  # ties and the budget cut are broken at random, seeded
            if value is not None and value.trained and children:
                keep = GUIDED_KEEP * beam_width
                rated = value.rate(children)
                order = sorted(range(len(children)), key=lambda i: (-rated[i], i))
                children = [children[i] for i in order[:keep]]
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
            if value is not None:
                value.learn(ev.order)
        stopped = (
            "budget reached" if ev.left <= 0 else "the beam emptied: every design was complete"
        )
        return SearchResult(best_of(ev.order), ev.order, stopped)


class _Node:
    """A node of the MCTS decision tree: one partial derivation."""

    __slots__ = ("partial", "children", "untried", "visits", "total", "best")

    def __init__(self, partial: Partial, decisions: list[tuple]) -> None:
        self.partial = partial
        self.children: list[_Node] = []
        self.untried = decisions
        self.visits = 0
        self.total = 0.0
        self.best = 0.0


def _decisions(p: Partial, rng: random.Random) -> list[tuple]:
    out: list[tuple] = []
    for rule, n in options(p):
        out += [(None, 0)] if rule is None else [(rule, i) for i in range(n)]
    rng.shuffle(out)
    return out


def mcts_search(
    grammar: Grammar,
    objectives: Sequence[Objective],
    constraints: Sequence[Constraint] = (),
    *,
    budget: int = 100,
    max_links: int = 4,
    exploration: float = 0.5,
    batch: int = MCTS_BATCH,
    guided: bool = False,
    seed: int = 0,
    executor: Executor | None = None,
    workers: int | None = None,
    progress: Callable[[int, Evaluation | None], None] | None = None,
    force_workers: bool = False,
    log: str | os.PathLike[str] | None = None,
    resume: str | os.PathLike[str] | None = None,
) -> SearchResult:
    """Monte Carlo tree search (UCT) over the decisions of canonical derivations.

    Each iteration walks down by UCT (value = mix of the mean and best normalised score
    below a node), expands one untried decision, completes it uniformly at random and
    evaluates the design. ``batch`` leaves are chosen per round (with a virtual visit
    so they differ) and evaluated together through the executor; the batch is a
    parameter of the search (recorded in its log, checked on resume), not the number of
    workers, so the same seed gives the same search with any executor. Scores are
    normalised to [0, 1] by the range seen so far; infeasible designs count as 0.

    ``guided``: a value network over partial designs (:class:`~robotwright.grammar.
    value.PrefixValue`), trained after every batch, picks which untried decision a
    node expands first (the one whose partial design it rates highest) instead of a
    seeded random one.
    """
    import math

    if budget < 1:
        raise ValueError("budget must be >= 1")
    if isinstance(batch, bool) or not isinstance(batch, int) or batch < 1:
        raise ValueError(f"batch must be an integer >= 1, got {batch!r}")
    rng = random.Random(seed)
    counter = Counter(grammar)
    start = Partial.start(grammar)
    root = _Node(start, _decisions(start, rng))
    lo, hi = math.inf, -math.inf
    prior = PrefixValue(grammar, seed=seed) if guided else None
    header = dict(method="mcts", seed=seed, budget=budget, max_links=max_links, batch=batch)
    if guided:
        header["guided"] = True

    def next_decision(node: _Node) -> tuple:
        if prior is None or not prior.trained or len(node.untried) == 1:
            return node.untried.pop()
        rated = prior.rate([decide(node.partial, grammar, r, i) for r, i in node.untried])
        return node.untried.pop(int(np.argmax(rated)))

    def norm(score: float) -> float:
        if not math.isfinite(score) or hi <= lo:
            return 0.0 if not math.isfinite(score) else 0.5
        return (score - lo) / (hi - lo)

    def value(n: _Node) -> float:
        return 0.5 * (n.total / n.visits) + 0.5 * n.best if n.visits else 0.0

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
        header=header,
    ) as ev:
        stalls = 0
        while ev.left > 0 and stalls < 50 and (root.untried or root.children):
            paths: list[list[_Node]] = []
            designs: list[Design] = []
            for _ in range(min(batch, ev.left)):
                node, path = root, [root]
                while not node.untried and node.children:
                    ln = math.log(node.visits + 1)
                    node = max(
                        node.children,
                        key=lambda c: value(c) + exploration * math.sqrt(ln / (c.visits + 1)),
                    )
                    path.append(node)
                while node.untried:
                    rule, i = next_decision(node)
                    child_p = decide(node.partial, grammar, rule, i)
                    if counter.feasible(child_p, max_links):
                        child = _Node(child_p, _decisions(child_p, rng))
                        node.children.append(child)
                        node, path = child, path + [child]
                        break
                for n in path:
                    n.visits += 1  # virtual visit: spreads a batch over different leaves
                q = node.partial
                if q.complete:
                    designs.append(q.design())
                elif counter.feasible(q, max_links):
                    while not q.complete:
                        q = random_step(q, max_links, rng, counter)
                    designs.append(q.design())
                else:
                    designs.append(None)  # type: ignore[arg-type]
                paths.append(path)
            before = len(ev.order)
            results = ev.run([d for d in designs if d is not None])
            stalls = stalls + 1 if len(ev.order) == before else 0
            it = iter(results)
            scores = [(next(it) if d is not None else None) for d in designs]
            for r in scores:
                if r is not None and math.isfinite(r.score):
                    lo, hi = min(lo, r.score), max(hi, r.score)
            for path, r in zip(paths, scores):
                s = norm(r.score) if r is not None else 0.0
                for n in path:
                    n.total += s
                    n.best = max(n.best, s)
            if prior is not None:
                prior.learn(ev.order)
        if ev.left <= 0:
            stopped = "budget reached"
        elif stalls >= 50:
            stopped = (
                f"50 rounds in a row found no design not evaluated before ({len(ev.order)} "
                f"distinct designs within max_links {max_links})"
            )
        else:
            stopped = f"every derivation within max_links {max_links} was explored"
        return SearchResult(best_of(ev.order), ev.order, stopped)
