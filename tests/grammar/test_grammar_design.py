"""Design text/JSON round trip, canonical hash, DOT output."""

from __future__ import annotations

import dataclasses
import random

import pytest

from robotwright.errors import GrammarError
from robotwright.grammar import derive
from robotwright.grammar.design import Design, to_dot
from robotwright.grammar.loader import default_grammar


def test_round_trips_and_hash_are_stable():
    g = default_grammar()
    rng = random.Random(3)
    for _ in range(30):
        d = derive.sample(g, 4, rng)
        assert Design.from_text(d.to_text()) == d
        assert Design.from_json(d.to_json()) == d
        assert Design.from_json(d.to_json()).hash() == d.hash()
        assert len(d.hash()) == 16 and int(d.hash(), 16) >= 0


def test_hash_changes_with_a_parameter():
    d = derive.sample(default_grammar(), 2, random.Random(0))
    c = d.steps[0].choices[0]
    changed = dataclasses.replace(c, params=tuple((k, v + 0.001) for k, v in c.params))
    steps = (
        dataclasses.replace(d.steps[0], choices=(changed, *d.steps[0].choices[1:])),
        *d.steps[1:],
    )
    assert Design(d.grammar, steps).hash() != d.hash()


def test_text_is_readable():
    d = derive.sample(default_grammar(), 1, random.Random(0))
    text = d.to_text()
    assert text.splitlines()[1].startswith("r1 @0: B=base(diameter=")
    # A design.txt read on its own says what "@0" means.
    assert "RULE @NODE: CHOICES, NODE = id of the node grown" in text.splitlines()[0]
    assert "P=pinned()" in text and "L=link(" in text


def test_text_parse_errors_name_the_row():
    with pytest.raises(GrammarError, match="row 1.*expected 'RULE @NODE"):
        Design.from_text("# grammar=srl\nr1 0 B=base()\n")
    with pytest.raises(GrammarError, match="NAME=NUMBER"):
        Design.from_text("# grammar=srl\nr1 @0: B=base(diameter=wide)\n")
    with pytest.raises(GrammarError, match="grammar=NAME"):
        Design.from_text("r1 @0: B=base()\n")
    with pytest.raises(GrammarError, match="invalid JSON"):
        Design.from_json("{")


def test_dot_has_one_edge_per_non_root_node():
    g = default_grammar()
    d = derive.sample(g, 3, random.Random(5))
    tree = derive.replay(g, d)
    dot = to_dot(tree)
    nodes = list(tree.walk())
    assert dot.startswith("digraph") and dot.count("->") == len(nodes) - 1
    assert 'label="r1"' in dot and "B:base(" in dot
