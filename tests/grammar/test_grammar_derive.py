"""Exact counting, enumeration, uniform sampling, replay of designs."""

from __future__ import annotations

import collections
import dataclasses
import random

import pytest

from robotwright.errors import GrammarError
from robotwright.grammar import derive
from robotwright.grammar.derive import Partial
from robotwright.grammar.design import Design
from robotwright.grammar.loader import default_grammar

from .helpers import default_data, load_variant, one_choice_library

# Choices in the bundled library, counted by hand from srl_library.yaml:
N_BASE = 2 * 2  # diameter x thickness
N_CONN = 2 + 1 + 1  # revolute (2 limits), universal (1), prismatic (1)
N_LINK = 2 * 1 * 3  # length x diameter x rotation
N_END = 1 + 1  # gripper, tool


def _links(tree) -> int:
    return sum(n.symbol == "L" for n in tree.walk())


def test_count_matches_hand_formula():
    g = default_grammar()
    per = N_CONN * N_LINK
    expected = [0] + [N_BASE * N_END * per**n for n in range(1, 4)]
    assert derive.count_by_links(g, 3) == expected
    assert derive.count(g, 3) == sum(expected)


def test_enumeration_equals_count_and_designs_are_distinct_and_valid():
    g = default_grammar()
    designs = list(derive.enumerate_designs(g, 2))
    assert len(designs) == derive.count(g, 2) == 4800
    assert len({d.hash() for d in designs}) == len(designs)
    sizes = collections.Counter(_links(derive.replay(g, d)) for d in designs[::7])
    assert set(sizes) <= {1, 2}


def _branching_grammar(tmp_path):
    g, _ = default_data()
    g["rules"]["r5"] = {"lhs": "-L", "rhs": "-L -> C -> L*", "branching": True}
    return load_variant(tmp_path, g, one_choice_library())


def test_branching_grammar_counts_by_hand(tmp_path):
    g = _branching_grammar(tmp_path)
    # One choice per symbol. With 2 links: extend the open end (r3, r4); close it and
    # branch from the closed link (r4, r5, r4); or branch from the open end (r5, r4).
    assert derive.count_by_links(g, 2) == [0, 1, 3]
    designs = list(derive.enumerate_designs(g, 2))
    assert len(designs) == 4 == len({d.hash() for d in designs})
    trees = {derive.replay(g, d).walk().__next__().label() for d in designs}
    assert trees  # every design replays


def test_non_branching_one_choice_grammar_has_one_design_per_size(tmp_path):
    g, _ = default_data()
    g = load_variant(tmp_path, g, one_choice_library())
    assert derive.count_by_links(g, 5) == [0, 1, 1, 1, 1, 1]


def test_sampling_is_uniform_on_a_small_space(tmp_path):
    g = _branching_grammar(tmp_path)
    rng = random.Random(7)
    counts = collections.Counter(derive.sample(g, 2, rng).hash() for _ in range(4000))
    assert len(counts) == 4
    assert all(850 <= c <= 1150 for c in counts.values()), counts  # 1000 +- 5 sigma


def test_sampling_weights_sizes_by_their_counts():
    g = default_grammar()
    rng = random.Random(0)
    counter = derive.Counter(g)
    n = 4000
    small = sum(_links(derive.replay(g, derive.sample(g, 2, rng, counter))) == 1 for _ in range(n))
    # P(1 link) = 192 / 4800 = 0.04 -> 160 expected, sigma ~ 12.4
    assert 100 <= small <= 220


def test_same_seed_same_design_and_seeds_differ():
    g = default_grammar()
    a = [derive.sample(g, 4, random.Random(s)) for s in range(10)]
    b = [derive.sample(g, 4, random.Random(s)) for s in range(10)]
    assert a == b
    assert len({d.hash() for d in a}) == 10


def test_open_node_cannot_stop():
    p = Partial.start(default_grammar())
    assert not p.can_stop()
    with pytest.raises(ValueError, match="open"):
        p.stop()


def _edit(design: Design, i: int, **changes) -> Design:
    steps = list(design.steps)
    steps[i] = dataclasses.replace(steps[i], **changes)
    return Design(design.grammar, tuple(steps))


def test_replay_rejects_bad_designs_with_step_and_field():
    g = default_grammar()
    d = derive.sample(g, 2, random.Random(1))
    link = d.steps[1].choices[1]
    assert link.component == "link"
    bad = dataclasses.replace(
        link, params=tuple((k, 5.0 if k == "length" else v) for k, v in link.params)
    )
    with pytest.raises(GrammarError, match="step 1.*out of the domain") as exc:
        derive.replay(g, _edit(d, 1, choices=(d.steps[1].choices[0], bad)))
    assert exc.value.problems[0].column == "choices"
    with pytest.raises(GrammarError, match="unknown component 'wheel'"):
        derive.replay(
            g,
            _edit(
                d, 1, choices=(dataclasses.replace(d.steps[1].choices[0], component="wheel"), link)
            ),
        )
    with pytest.raises(GrammarError, match="not the next node to grow"):
        derive.replay(g, _edit(d, 1, at=1))
    with pytest.raises(GrammarError, match="unknown rule"):
        derive.replay(g, _edit(d, 1, rule="r9"))
    with pytest.raises(GrammarError, match="incomplete"):
        derive.replay(g, Design(d.grammar, d.steps[:-1]))
    with pytest.raises(GrammarError, match="grammar 'other'"):
        derive.replay(g, Design("other", d.steps))


def test_sample_with_impossible_budget_errors():
    with pytest.raises(GrammarError, match="at most 0 link"):
        derive.sample(default_grammar(), 0, random.Random(0))


def test_feasibility_cache_does_not_depend_on_the_first_limit():
    g = default_grammar()
    c = derive.Counter(g)
    p = Partial.start(g)
    assert not c.feasible(p, 0)  # every design needs a link
    assert c.feasible(p, 3)
    assert c.min_links(g.start_state, 0) is None and c.min_links(g.start_state, 5) == 1


def test_sampling_is_the_same_when_the_counters_memo_is_emptied(monkeypatch) -> None:
    g = default_grammar()
    rng, counter = random.Random(5), derive.Counter(g)
    kept = [derive.sample(g, 4, rng, counter) for _ in range(30)]
    assert len(counter._conv) > 3
    monkeypatch.setattr(derive, "CONV_MEMO", 3)  # emptied over and over
    rng, small = random.Random(5), derive.Counter(g)
    assert [derive.sample(g, 4, rng, small) for _ in range(30)] == kept
    assert len(small._conv) <= 3
    assert derive.count(g, 4) == derive.Counter(g).completions(Partial.start(g), 4)
