"""A search that learns: a value function over partial designs, trained online.

In the spirit of RoboGrammar's graph heuristic search. Every evaluated design teaches a
small neural network (:class:`ValueNet`, numpy only) the best normalised score reached
through each of its prefixes (the partial derivations on its way); each new design is
grown decision by decision, taking the child the network rates highest, or with
probability ``epsilon`` a uniform random one, so the search keeps exploring. The first
``warmup`` designs are drawn uniformly, to give the network something to learn from.

A partial design is described by :func:`features`: for every component of the library,
how many times it has been chosen and the sum of each of its parameters, for every rule
how many times it was applied, plus the number of steps and links. The network is a
two-layer perceptron (tanh, ``hidden`` units) fitted by Adam to the mean squared error;
inputs are standardised by the training set's mean and spread.

Everything is seeded: the same seed gives the same search on any executor.
"""

from __future__ import annotations

import math
import os
import random
from collections.abc import Callable, Sequence
from concurrent.futures import Executor

import numpy as np

from robotwright.grammar.derive import (
    Counter,
    Partial,
    choices_at,
    options,
    sample,
)
from robotwright.grammar.design import Design, Step
from robotwright.grammar.objectives import Constraint, Evaluation, Objective, best_of
from robotwright.grammar.rules import Grammar

__all__ = ["FeatureMap", "PrefixValue", "ValueNet", "learned_search"]

#: Designs drawn uniformly before the network steers.
WARMUP = 32
#: Designs grown per round between two trainings of the network.
LEARNED_BATCH = 16


class FeatureMap:
    """The feature vector of a partial design (a tuple of steps) in one grammar."""

    def __init__(self, grammar: Grammar) -> None:
        lib = grammar.library.components
        self.components = {name: i for i, name in enumerate(lib)}
        params = [(c, p) for c, comp in lib.items() for p in comp.params]
        self.params = {key: len(self.components) + i for i, key in enumerate(params)}
        start = len(self.components) + len(self.params)
        self.rules = {name: start + i for i, name in enumerate(grammar.rules)}
        self.links = set(grammar.link_symbols)
        self.size = start + len(self.rules) + 2

    def __call__(self, steps: Sequence[Step]) -> np.ndarray:
        x = np.zeros(self.size)
        links = 0
        for step in steps:
            x[self.rules[step.rule]] += 1
            for choice in step.choices:
                links += choice.symbol in self.links
                if choice.component is None:
                    continue
                x[self.components[choice.component]] += 1
                for name, value in choice.params:
                    x[self.params[(choice.component, name)]] += value
        x[-2] = len(steps)
        x[-1] = links
        return x


class ValueNet:
    """A two-layer perceptron ``x -> tanh(x W1 + b1) W2 + b2`` fitted by Adam.

    Inputs are standardised with the mean and spread of the last training set.
    """

    def __init__(self, size: int, hidden: int = 32, seed: int = 0) -> None:
        self.rng = np.random.default_rng(seed)
        self.w1 = self.rng.normal(0.0, 1.0 / math.sqrt(size), (size, hidden))
        self.b1 = np.zeros(hidden)
        self.w2 = self.rng.normal(0.0, 1.0 / math.sqrt(hidden), hidden)
        self.b2 = 0.0
        self.mean = np.zeros(size)
        self.scale = np.ones(size)
        # Adam's first moments, then its second moments, one array per parameter.
        self._adam = [np.zeros_like(p) for p in self._params() * 2]
        self._t = 0

    def _params(self) -> list[np.ndarray]:
        return [self.w1, self.b1, self.w2, np.array([self.b2])]

    def predict(self, x: np.ndarray) -> np.ndarray:
        h = np.tanh(((x - self.mean) / self.scale) @ self.w1 + self.b1)
        return h @ self.w2 + self.b2

    def fit(self, x: np.ndarray, y: np.ndarray, epochs: int = 20, lr: float = 0.01) -> float:
        """Minibatch Adam on the mean squared error; returns the last epoch's loss."""
        self.mean = x.mean(axis=0)
        self.scale = np.where(x.std(axis=0) > 1e-9, x.std(axis=0), 1.0)
        z = (x - self.mean) / self.scale
        n = len(y)
        loss = math.inf
        for _ in range(epochs):
            order = self.rng.permutation(n)
            total = 0.0
            for start in range(0, n, 64):
                idx = order[start : start + 64]
                zb, yb = z[idx], y[idx]
                h = np.tanh(zb @ self.w1 + self.b1)
                err = h @ self.w2 + self.b2 - yb
                total += float(err @ err)
                g_out = 2.0 * err / len(idx)
                g_w2 = h.T @ g_out
                g_b2 = g_out.sum()
                g_h = np.outer(g_out, self.w2) * (1.0 - h * h)
                grads = [zb.T @ g_h, g_h.sum(axis=0), g_w2, np.array([g_b2])]
                self._step(grads, lr)
            loss = total / n
        return loss

    def _step(self, grads: list[np.ndarray], lr: float) -> None:
        self._t += 1
        params = self._params()
        k = len(params)
        b1, b2, eps = 0.9, 0.999, 1e-8
        for i, (p, g) in enumerate(zip(params, grads)):
            m, v = self._adam[i], self._adam[k + i]
            m *= b1
            m += (1 - b1) * g
            v *= b2
            v += (1 - b2) * g * g
            upd = lr * (m / (1 - b1**self._t)) / (np.sqrt(v / (1 - b2**self._t)) + eps)
            if i == 3:
                self.b2 -= float(upd[0])
            else:
                p -= upd


class PrefixValue:
    """The value of partial designs, learned from evaluations: for each prefix of an
    evaluated design's steps (the partial derivations on its way), the best normalised
    score of any evaluated design through it (:func:`_normalised`), fitted by a
    :class:`ValueNet` over :class:`FeatureMap` features. Guides the learned search, and
    beam search and MCTS when asked (``guided=True``)."""

    def __init__(self, grammar: Grammar, hidden: int = 32, seed: int = 0) -> None:
        self.features = FeatureMap(grammar)
        self.net = ValueNet(self.features.size, hidden=hidden, seed=seed)
        self._x: dict[tuple[Step, ...], np.ndarray] = {}
        self.trained = False

    def learn(self, evaluations: Sequence[Evaluation]) -> None:
        """Fit the network to every prefix of ``evaluations`` (nothing to learn while no
        design is feasible)."""
        finite = [e.score for e in evaluations if math.isfinite(e.score)]
        if not finite:
            return
        lo, hi = min(finite), max(finite)
        targets: dict[tuple[Step, ...], float] = {}
        for e in evaluations:
            value = _normalised(e.score, lo, hi)
            steps = e.design.steps
            for k in range(len(steps) + 1):
                key = steps[:k]
                if key not in self._x:
                    self._x[key] = self.features(key)
                targets[key] = max(targets.get(key, 0.0), value)
        keys = list(targets)
        self.net.fit(np.stack([self._x[k] for k in keys]), np.array([targets[k] for k in keys]))
        self.trained = True

    def rate(self, partials: Sequence[Partial]) -> np.ndarray:
        """The network's value of each partial derivation (about 0-1, larger better)."""
        return self.net.predict(np.stack([self.features(p.steps) for p in partials]))


def _normalised(score: float, lo: float, hi: float) -> float:
    """A score as a training target: feasible ones in [0.1, 1] by the range ``lo``-``hi``
    seen, an infeasible one (-inf) 0."""
    if not math.isfinite(score):
        return 0.0
    return 1.0 if hi <= lo else 0.1 + 0.9 * (score - lo) / (hi - lo)


def _pick(weights: np.ndarray, rng: random.Random) -> int:
    """An index drawn with probability proportional to ``weights`` (seeded)."""
    r = rng.random() * float(weights.sum())
    return min(int(np.searchsorted(np.cumsum(weights), r, side="right")), len(weights) - 1)


def _children(p: Partial, grammar: Grammar, counter: Counter, max_links: int) -> list[Partial]:
    """Every next partial derivation of ``p`` that can still complete within
    ``max_links``."""
    out = []
    for rule, n in options(p):
        if rule is None:
            out.append(p.stop())
        else:
            out += [p.apply(rule, choices_at(grammar, rule, i)) for i in range(n)]
    return [c for c in out if counter.completions(c, max_links) > 0]


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
    from robotwright.grammar.search import SearchResult, _Evaluator

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
            kids = _children(p, grammar, counter, max_links)
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
            seen = {e.design.hash() for e in ev.order}
            designs: list[Design] = []
            for _ in range(size):
                d = grow()
                tries = 0
                while (d.hash() in seen or d in designs) and tries < 20:
                    d = grow() if tries < 5 else sample(grammar, max_links, rng, counter)
                    tries += 1
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
