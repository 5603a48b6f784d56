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
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field, replace
from typing import Any

from robotwright.grammar.design import Choice, Design, Step
from robotwright.grammar.executors import InProcessExecutor
from robotwright.grammar.objectives import Constraint, Evaluation, Objective, best_of
from robotwright.grammar.rules import Grammar
from robotwright.grammar.search import _Evaluator

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
    #: why the refine ended (budget, CMA-ES's own stop, or restarts spent)
    stopped: str = ""
    #: restarts made after a generation with no feasible design
    restarts: int = 0


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
    force_workers: bool = False,
    log: str | os.PathLike[str] | None = None,
    resume: str | os.PathLike[str] | None = None,
    known: Mapping[str, Evaluation] | None = None,
    progress: Callable[[int, Evaluation | None], None] | None = None,
) -> RefineResult:
    """Search the continuous parameters of ``design`` with CMA-ES over ``budget``
    distinct designs, the start design included (see the module docstring). ``sigma``:
    initial step, as a share of each parameter's range. Evaluations run on ``executor``
    when given; else on a pool of ``workers`` processes that die with this one
    (``None``: one per core; the default 0: in this process).

    When a whole generation is infeasible (no score to rank them by), CMA-ES starts
    again from the best feasible design found (or the start) with twice the step, up to
    :data:`MAX_RESTARTS` times. :attr:`RefineResult.stopped` says why the refine ended.

    ``log``: every evaluation is appended to this search log (after a ``search`` line
    with ``"method": "refine"``); ``resume``: a log whose evaluations are taken instead
    of evaluated again, as a search's (:mod:`robotwright.grammar.searchlog`); ``known``:
    evaluations by design hash taken the same way (the search's own, so its best is not
    evaluated twice). ``progress(n, best)`` is called after each generation.

    Raises:
        ValueError: a budget below 1 or a ``sigma`` outside (0, 1].
        ImportError: pycma is not installed (the message says how to install it).
    """
    if not isinstance(budget, int) or budget < 1:
        raise ValueError(f"refine: budget must be a whole number >= 1, got {budget!r}")
    if not (isinstance(sigma, (int, float)) and 0 < sigma <= 1):
        raise ValueError(f"refine: sigma must be in (0, 1], got {sigma!r}")
    params = parameters(grammar, design)
    cma = _cma() if params and budget > 1 else None
    if executor is None and workers == 0:
        executor = InProcessExecutor()
    header = {"method": "refine", "seed": seed, "budget": budget, "sigma": sigma}
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
        known=known,
        append=True,
    ) as ev:
        (start,) = ev.run([design])
        assert start is not None  # the budget is at least 1
        result = RefineResult(start, start, ev.order, params)
        if cma is None:
            result.stopped = (
                "nothing to refine: no parameter with a range" if not params else "budget reached"
            )
            return result
        _search(cma, result, design, params, ev, seed, sigma)
    result.best = best_of(result.evaluations) or result.start
    return result


#: Restarts a refine makes when a generation is all infeasible (each with twice the step).
MAX_RESTARTS = 4


def _search(
    cma: Any,
    result: RefineResult,
    design: Design,
    params: list[Parameter],
    ev: _Evaluator,
    seed: int,
    sigma: float,
) -> None:
    """The CMA-ES loop of :func:`refine`, with its restarts; sets ``result.stopped``."""
    span = [p.high - p.low for p in params]

    def scaled(d: Design) -> list[float]:
        values = {(p.step, p.name): p.value for p in parameters(ev.grammar, d)}
        x = [(values[(p.step, p.name)] - p.low) / s for p, s in zip(params, span, strict=True)]
        return [*x, 0.5] if len(params) == 1 else x  # pycma needs two dimensions at least

    x0, step = scaled(design), sigma
    for restart in range(MAX_RESTARTS + 1):
        options = {
            "bounds": [0.0, 1.0],
            "seed": seed + 1 + 1000 * restart,  # pycma takes 0 as "from the clock"
            "verbose": -9,
        }
        es = cma.CMAEvolutionStrategy(x0, step, options)
        generations = 0
        while not es.stop():
            if ev.left <= 0:
                result.stopped = f"budget reached ({ev.budget} designs)"
                return
            xs = es.ask()
            designs = [
                with_values(
                    design,
                    params,
                    [p.low + x * s for p, x, s in zip(params, xi, span, strict=False)],
                )
                for xi in xs
            ]
            evals = ev.run(designs)
            generations += 1
            if any(e is None for e in evals):
                result.stopped = f"budget reached ({ev.budget} designs)"
                return  # the budget ended inside a generation: the last one is not told
            if not any(e.feasible for e in evals):
                break
            worst = min((e.score for e in ev.order if math.isfinite(e.score)), default=0.0)
            # pycma minimises; an infeasible design scores below every feasible one seen
            es.tell(xs, [-e.score if math.isfinite(e.score) else -worst + 1e6 for e in evals])
        else:
            why = ", ".join(
                f"{k} {v:g}" if isinstance(v, float) else k for k, v in es.stop().items()
            )
            result.stopped = f"CMA-ES converged ({why}) after {generations} generation(s)"
            return
        if restart == MAX_RESTARTS:
            break
        result.restarts += 1
        best = best_of(ev.order)
        x0 = scaled(best.design if best is not None else design)
        step = min(1.0, step * 2)
    result.stopped = (
        f"a generation with no feasible design after {MAX_RESTARTS} restarts, each with "
        "twice the step"
    )
