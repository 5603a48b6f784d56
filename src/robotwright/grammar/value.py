"""The value of partial designs, learned from evaluations (the learned search's network).

A partial design is described by :class:`FeatureMap`: for every component of the library,
how many times it has been chosen and the sum of each of its parameters, for every rule
how many times it was applied, plus the number of steps and links. :class:`ValueNet` is a
two-layer perceptron (tanh) fitted by Adam to the mean squared error, numpy only;
inputs are standardised by the training set's mean and spread. :class:`PrefixValue`
trains it on every prefix of the evaluated designs (see :mod:`robotwright.grammar.learned`
and ``guided=True`` of beam search and MCTS).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from robotwright.grammar.derive import Partial
from robotwright.grammar.design import Step
from robotwright.grammar.objectives import Evaluation
from robotwright.grammar.rules import Grammar

__all__ = ["FeatureMap", "PrefixValue", "ValueNet"]

#: Rows of training a :class:`PrefixValue` round passes at most (beyond 2 epochs): a
#: search of 1,000 designs (about 7,000 prefixes) still trains 20 epochs a round.
TRAIN_ROWS = 200_000


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
        #: The best raw score through each prefix, prefixes in the order first met.
        self._best: dict[tuple[Step, ...], float] = {}
        self._lo, self._hi = math.inf, -math.inf  # the range of feasible scores
        self._absorbed = 0
        self.trained = False

    def learn(self, evaluations: Sequence[Evaluation]) -> None:
        """Fit the network to every prefix of ``evaluations`` (nothing to learn while no
        design is feasible). ``evaluations`` is a search's evaluation order, which only
        grows: the designs already taken in are not walked again. Normalising is
        monotonic, so the best normalised score through a prefix is that of its best
        raw score."""
        for e in evaluations[self._absorbed :]:
            if math.isfinite(e.score):
                self._lo, self._hi = min(self._lo, e.score), max(self._hi, e.score)
            steps = e.design.steps
            for k in range(len(steps) + 1):
                key = steps[:k]
                if key not in self._best:
                    self._x[key] = self.features(key)
                    self._best[key] = e.score
                elif e.score > self._best[key]:
                    self._best[key] = e.score
        self._absorbed = len(evaluations)
        if self._hi < self._lo:
            return
        keys = list(self._best)
        targets = [_normalised(self._best[k], self._lo, self._hi) for k in keys]
        # 20 epochs while the prefixes are few; then a fixed number of rows a round, so
        # that a long search's training grows with its length, not with its square.
        epochs = max(2, min(20, TRAIN_ROWS // len(keys)))
        x = np.stack([self._x[k] for k in keys])
        self.net.fit(x, np.array(targets), epochs=epochs)
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
