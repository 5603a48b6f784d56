"""Continuous parameters: a design's component parameters searched within their
physical ranges by CMA-ES (pycma, ``pip install 'robotwright[cma]'``).

The grammar's search picks structures and the discrete ``values`` each parameter lists;
:func:`refine` then moves every parameter of the chosen design whose domain ``range``
is wider than a point (link lengths, strokes, joint limits, ...) anywhere within that
range, keeping the structure. CMA-ES works on the parameters scaled to ``[0, 1]``
(bounds handled by pycma), starts at the design's values with step ``sigma``, and
maximises the same score the search used (an infeasible design scores worst). Seeded and
evaluated through an executor in submission order: the same seed gives the same result
on any executor.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

from robotwright.grammar.design import Choice, Design, Step
from robotwright.grammar.executors import die_with_parent, pool_size
from robotwright.grammar.objectives import Constraint, Evaluation, Objective, best_of, evaluate
from robotwright.grammar.rules import Grammar

__all__ = ["Parameter", "RefineResult", "parameters", "refine", "with_values"]


@dataclass(frozen=True)
class Parameter:
    """One continuous parameter of a design: step and choice index, name, domain."""

    step: int
    choice: int
    name: str
    low: float
    high: float
    value: float


@dataclass
class RefineResult:
    """The best evaluation found (the start design's when nothing beat it), every
    evaluation in order, and the parameters searched."""

    best: Evaluation
    start: Evaluation
    evaluations: list[Evaluation] = field(default_factory=list)
    parameters: list[Parameter] = field(default_factory=list)


def parameters(grammar: Grammar, design: Design) -> list[Parameter]:
    """The parameters of ``design`` whose domain is wider than a point, in step order."""
    out = []
    for si, step in enumerate(design.steps):
        for ci, choice in enumerate(step.choices):
            if choice.component is None:
                continue
            comp = grammar.library.components[choice.component]
            for name, value in choice.params:
                dom = comp.params[name]
                if dom.high > dom.low:
                    out.append(Parameter(si, ci, name, dom.low, dom.high, float(value)))
    return out


#: Significant digits a refined parameter keeps: 0.1 % steps, values a designer reads
#: and builds (0.33 m, not 0.3299542718072217 m); the design evaluated is the one written.
REFINED_DIGITS = 4


def with_values(design: Design, params: Sequence[Parameter], values: Sequence[float]) -> Design:
    """``design`` with parameter ``params[k]`` set to ``values[k]``, rounded to
    :data:`REFINED_DIGITS` significant digits and clipped to its domain."""
    steps = [list(s.choices) for s in design.steps]
    for p, v in zip(params, values, strict=True):
        ch: Choice = steps[p.step][p.choice]
        new = min(max(float(f"{float(v):.{REFINED_DIGITS}g}"), p.low), p.high)
        steps[p.step][p.choice] = replace(
            ch, params=tuple((k, new if k == p.name else x) for k, x in ch.params)
        )
    return Design(
        design.grammar,
        tuple(Step(s.rule, s.at, tuple(c)) for s, c in zip(design.steps, steps, strict=True)),
    )


def _cma():  # noqa: ANN202 - the pycma module
    try:
        import cma
    except ImportError as exc:
        raise ImportError(
            "refining continuous parameters needs pycma: install robotwright[cma] "
            "(pip install 'robotwright[cma]')"
        ) from exc
    return cma


def refine(
    grammar: Grammar,
    design: Design,
    objectives: Sequence[Objective],
    constraints: Sequence[Constraint] = (),
    *,
    budget: int = 60,
    seed: int = 0,
    sigma: float = 0.2,
    executor: Executor | None = None,
    workers: int | None = 0,
) -> RefineResult:
    """Search the continuous parameters of ``design`` with CMA-ES for ``budget``
    evaluations (see the module docstring). ``sigma``: initial step, as a share of each
    parameter's range. Evaluations run on ``executor`` when given; else on a pool of
    ``workers`` processes that die with this one (``None``: one per core; the default
    0: in this process).

    Raises:
        ValueError: a budget below 1 or a ``sigma`` outside (0, 1].
        ImportError: pycma is not installed (the message says how to install it).
    """
    if not isinstance(budget, int) or budget < 1:
        raise ValueError(f"refine: budget must be a whole number >= 1, got {budget!r}")
    if not (isinstance(sigma, (int, float)) and 0 < sigma <= 1):
        raise ValueError(f"refine: sigma must be in (0, 1], got {sigma!r}")
    objectives, constraints = tuple(objectives), tuple(constraints)
    run = partial(evaluate, grammar, objectives=objectives, constraints=constraints)
    start = run(design)
    params = parameters(grammar, design)
    result = RefineResult(start, start, [start], params)
    if not params or budget <= 1:
        return result
    cma = _cma()
    if executor is None and workers != 0:
        with ProcessPoolExecutor(
            max_workers=pool_size(workers, budget),
            initializer=die_with_parent,
            initargs=(os.getpid(),),
        ) as pool:
            return _search(cma, result, design, params, run, budget, seed, sigma, pool)
    return _search(cma, result, design, params, run, budget, seed, sigma, executor)


def _search(
    cma: Any,
    result: RefineResult,
    design: Design,
    params: list[Parameter],
    run: Callable[[Design], Evaluation],
    budget: int,
    seed: int,
    sigma: float,
    executor: Executor | None,
) -> RefineResult:
    """The CMA-ES loop of :func:`refine` (``executor`` ``None``: in this process)."""
    span = [p.high - p.low for p in params]
    x0 = [(p.value - p.low) / s for p, s in zip(params, span, strict=True)]
    options = {
        "bounds": [0.0, 1.0],
        "seed": seed + 1,  # pycma takes 0 as "from the clock"
        "verbose": -9,
        "maxfevals": budget - 1,
    }
    if len(params) == 1:  # pycma needs two dimensions at least: a dummy one
        x0 = [*x0, 0.5]
    es = cma.CMAEvolutionStrategy(x0, sigma, options)
    spent = 1
    while not es.stop() and spent < budget:
        xs = es.ask()
        xs = xs[: budget - spent]
        designs = [
            with_values(
                design, params, [p.low + x * s for p, x, s in zip(params, xi, span, strict=False)]
            )
            for xi in xs
        ]
        evals = (
            list(executor.map(run, designs)) if executor is not None else list(map(run, designs))
        )
        spent += len(evals)
        result.evaluations.extend(evals)
        worst = min((e.score for e in result.evaluations if math.isfinite(e.score)), default=0.0)
        # pycma minimises; an infeasible design scores below every feasible one seen
        fitness = [-e.score if math.isfinite(e.score) else -worst + 1e6 for e in evals]
        if len(xs) < es.popsize:
            break  # the budget ended inside a generation: the last one is not told
        es.tell(xs, fitness)
    result.best = best_of(result.evaluations) or result.start
    return result
