"""Continuous parameters searched within their ranges (``grammar search --refine``)."""

from __future__ import annotations

import re
import sys
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import pytest

from robotwright.cli import main
from robotwright.grammar import default_grammar
from robotwright.grammar.design import Design
from robotwright.grammar.objectives import Mass, NoSelfCollision, Reach
from robotwright.grammar.refine import parameters, refine, with_values

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
    # The search's and the refine's evaluations counted apart (the refine's first is
    # the search's best, evaluated again).
    assert "10 designs evaluated + 11 by the refine (CMA-ES)" in out
    # Refined values are written as a designer reads them: 4 significant digits.
    numbers = re.findall(r"=(-?\d+\.\d+)", out.split("# robotwright-design/1")[1])
    assert numbers and all(len(n.lstrip("-0.").replace(".", "")) <= 4 for n in numbers)
    assert main([*args, "--objective", "mass", "--pareto", "--refine", "12"]) == 2
    assert "--refine" in capsys.readouterr().err
