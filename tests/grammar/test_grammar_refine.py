"""Continuous parameters searched within their ranges (``grammar search --refine``)."""

from __future__ import annotations

import json
import re
import sys
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

from robotwright.cli import main
from robotwright.grammar import default_grammar
from robotwright.grammar.design import Design
from robotwright.grammar.objectives import Mass, NoSelfCollision, Reach
from robotwright.grammar.refine import MAX_RESTARTS, parameters, refine, with_values
from robotwright.grammar.searchlog import read_log

from .helpers import ARM

pytest.importorskip("cma", reason="pycma not installed (robotwright[cma]; the test extra has it)")


@pytest.fixture(scope="module")
def grammar():
    return default_grammar()


def test_parameters_are_the_ranged_ones_and_values_stay_in_their_domains(grammar) -> None:
    design = Design.from_text(ARM)
    params = parameters(grammar, design)
    names = [(p.step, p.name) for p in params]
    assert (1, "length") in names and (0, "diameter") in names and (1, "limit") in names
    for p in params:
        dom = grammar.library.components[design.steps[p.step].choices[p.choice].component]
        assert dom.params[p.name].low == p.low < p.high == dom.params[p.name].high
    moved = with_values(design, params, [p.high + 1.0 for p in params])
    assert [s.rule for s in moved.steps] == [s.rule for s in design.steps]
    assert [p.value for p in parameters(grammar, moved)] == [p.high for p in params]
    assert moved.hash() != design.hash()


def test_refine_improves_within_the_ranges_and_is_reproducible(grammar) -> None:
    design = Design.from_text(ARM)
    objs, cons = (Reach(), Mass()), (NoSelfCollision(),)
    with ThreadPoolExecutor(1) as one, ProcessPoolExecutor(2) as two:
        a = refine(grammar, design, objs, cons, budget=40, seed=3, executor=one)
        b = refine(grammar, design, objs, cons, budget=40, seed=3, executor=two)
    assert len(a.evaluations) == 40
    assert [e.design.hash() for e in a.evaluations] == [e.design.hash() for e in b.evaluations]
    assert a.best.values["reach"] > a.start.values["reach"]  # longer links reach further
    assert a.best.rank_key == max(e.rank_key for e in a.evaluations if e.feasible)
    for p in parameters(grammar, a.best.design):
        assert p.low <= p.value <= p.high
    own = refine(grammar, design, objs, cons, budget=40, seed=3, workers=2)  # its own pool
    assert [e.design.hash() for e in own.evaluations] == [e.design.hash() for e in a.evaluations]
    c = refine(grammar, design, objs, cons, budget=40, seed=4)
    assert [e.design.hash() for e in c.evaluations] != [e.design.hash() for e in a.evaluations]
    with pytest.raises(ValueError, match="budget"):
        refine(grammar, design, objs, budget=0)


def test_refine_says_how_to_install_pycma(grammar, monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "cma", None)
    with pytest.raises(ImportError, match=r"robotwright\[cma\]"):
        refine(grammar, Design.from_text(ARM), (Reach(),), budget=5)


def test_search_cli_refines_the_best_design(capsys) -> None:
    args = ["grammar", "search", "--objective", "reach", "--budget", "10", "--max-links", "2"]
    assert main([*args, "--workers", "1", "--refine", "12"]) == 0
    out = capsys.readouterr().out
    assert "continuous parameter(s)" in out and "(CMA-ES): reach = " in out
    assert "refine stopped: " in out
    # The search's and the refine's evaluations counted apart (the refine's first is
    # the search's best, evaluated again).
    assert "10 designs evaluated + 11 by the refine (CMA-ES)" in out
    # Refined values are written as a designer reads them: 4 significant digits.
    numbers = re.findall(r"=(-?\d+\.\d+)", out.split("# robotwright-design/1")[1])
    assert numbers and all(len(n.lstrip("-0.").replace(".", "")) <= 4 for n in numbers)
    assert main([*args, "--objective", "mass", "--pareto", "--refine", "12"]) == 2
    assert "--refine" in capsys.readouterr().err


class _Counting(ThreadPoolExecutor):
    """One thread; counts the designs it evaluates."""

    def __init__(self) -> None:
        super().__init__(1)
        self.evaluated = 0

    def map(self, fn, *iterables, **kw):  # noqa: ANN001, ANN201
        items = list(iterables[0])
        self.evaluated += len(items)
        return super().map(fn, items, **kw)


def test_refine_logs_every_evaluation_and_resumes_without_evaluating_again(
    grammar, tmp_path
) -> None:
    """Each refine evaluation is a line of the log, after a ``refine`` search line; a
    refine resumed from that log evaluates nothing and ends where the first did."""
    design = Design.from_text(ARM)
    objs, cons = (Reach(),), (NoSelfCollision(),)
    log = tmp_path / "search.jsonl"
    with _Counting() as first:
        a = refine(grammar, design, objs, cons, budget=25, seed=2, executor=first, log=log)
    assert first.evaluated == len(a.evaluations) == 25
    lines = [json.loads(x) for x in log.read_text().splitlines()]
    assert lines[0]["kind"] == "search" and lines[0]["method"] == "refine"
    assert lines[0]["budget"] == 25 and lines[0]["sigma"] == 0.2
    logged = [x["hash"] for x in lines[1:]]
    assert logged == [e.design.hash() for e in a.evaluations]
    assert set(read_log(log, grammar.name, objs, cons)) == set(logged)
    assert a.stopped.startswith("budget reached")
    with _Counting() as second:
        b = refine(grammar, design, objs, cons, budget=25, seed=2, executor=second, resume=log)
    assert second.evaluated == 0
    assert [e.design.hash() for e in b.evaluations] == logged
    assert b.best.values == a.best.values
    # Known evaluations (a search's) are taken too: the start is not evaluated again.
    with _Counting() as third:
        refine(grammar, design, objs, cons, budget=3, seed=2, executor=third,
               known={design.hash(): a.start})  # fmt: skip
    assert third.evaluated == 2


class _OnlyThe:
    """A constraint only one design meets: every generation of a refine is infeasible."""

    name = "only-the-start"

    def __init__(self, design: Design) -> None:
        self.hash = design.hash()

    def __call__(self, ctx) -> str | None:  # noqa: ANN001
        return None if ctx.design.hash() == self.hash else "not the start design"


def test_refine_restarts_with_a_wider_step_when_a_generation_is_all_infeasible(grammar) -> None:
    design = Design.from_text(ARM)
    out = refine(grammar, design, (Reach(),), (_OnlyThe(design),), budget=400, seed=1, sigma=0.02)
    assert out.restarts == MAX_RESTARTS
    assert "no feasible design after 4 restarts" in out.stopped
    assert out.best is out.start and out.start.feasible
    params = parameters(grammar, design)
    span = np.array([p.high - p.low for p in params])

    def spread(evals) -> float:  # mean spread of the scaled parameters
        xs = np.array([[p.value for p in parameters(grammar, e.design)] for e in evals]) / span
        return float(xs.std(axis=0).mean())

    first, last = out.evaluations[1:9], out.evaluations[-8:]
    assert spread(last) > 4 * spread(first)  # the step doubled at each of 4 restarts


def test_search_cli_logs_the_refine_and_resumes_it(tmp_path, capsys) -> None:
    log = tmp_path / "run.jsonl"
    args = ["grammar", "search", "--objective", "reach", "--budget", "8", "--max-links", "2"]
    assert main([*args, "--workers", "1", "--refine", "10", "--log", str(log)]) == 0
    first = capsys.readouterr().out
    lines = [json.loads(x) for x in log.read_text().splitlines()]
    heads = [i for i, x in enumerate(lines) if x["kind"] == "search"]
    assert [lines[i]["method"] for i in heads] == ["beam", "refine"]  # the default method
    assert len(lines) - heads[1] - 1 == 10  # the refine's designs, its start first
    assert "8 designs evaluated + 9 by the refine" in first
    assert main([*args, "--workers", "1", "--refine", "10", "--resume", str(log)]) == 0
    again = capsys.readouterr().out
    best = [x for x in first.splitlines() if x.startswith("best ")]
    assert best and best == [x for x in again.splitlines() if x.startswith("best ")]
