"""Loading and validating grammars and component libraries."""

from __future__ import annotations

import pytest

from robotwright.cli.grammar import register  # noqa: F401  (import check)
from robotwright.errors import GrammarError
from robotwright.grammar.loader import default_grammar, load_grammar, load_library
from robotwright.grammar.symbols import NodePattern

from .helpers import default_data, load_variant, write


def _problems(tmp_path, g, lib):
    with pytest.raises(GrammarError) as exc:
        load_variant(tmp_path, g, lib)
    return exc.value.problems


def test_default_grammar_is_the_seed_with_open_ends_marked():
    g = default_grammar()
    assert [str(r) for r in g.rules.values()] == [
        "r1: S => B* -> P",
        "r2: -B* => -B -> C -> L*",
        "r3: -L* => -L -> C -> L*",
        "r4: -L* => -L -> E",
    ]
    assert g.symbols["E"].kind == "terminal" and g.symbols["L"].kind == "nonterminal"
    assert {c.name for c in g.library.for_symbol("C")} == {"revolute", "universal", "prismatic"}
    assert len(g.library.components["universal"].dofs) == 2


def test_node_pattern_parse_and_errors():
    assert NodePattern.parse("-L*") == NodePattern("L", keep=True, open=True)
    assert NodePattern.parse("S") == NodePattern("S")
    with pytest.raises(ValueError, match="cannot parse node"):
        NodePattern.parse("L-*")


def test_unknown_symbol_names_rule_and_field(tmp_path):
    g, lib = default_data()
    g["rules"]["r3"]["rhs"] = "-L -> X -> L*"
    probs = _problems(tmp_path, g, lib)
    p = next(p for p in probs if "unknown symbol 'X'" in p.message)
    assert p.element == "rule 'r3'" and p.column == "rhs" and p.file.endswith("grammar.yaml")


def test_seed_defect_any_link_rule_is_rejected_unless_branching(tmp_path):
    g, lib = default_data()
    g["rules"]["r3"]["lhs"] = "-L"
    probs = _problems(tmp_path, g, lib)
    p = next(p for p in probs if p.element == "rule 'r3'")
    assert "branching" in p.message and "-L*" in p.message and p.column == "lhs"
    g["rules"]["r3"]["branching"] = True
    grammar = load_variant(tmp_path, g, lib)
    assert grammar.rules["r3"].branching


def test_left_side_that_cannot_match_and_unreachable_rule(tmp_path):
    g, lib = default_data()
    g["symbols"]["X"] = {"kind": "nonterminal"}
    g["symbols"]["Y"] = {"kind": "nonterminal"}
    g["rules"]["r5"] = {"lhs": "-X*", "rhs": "-X* -> Y*"}  # nothing creates X
    g["rules"]["r6"] = {"lhs": "-Y*", "rhs": "L*"}  # Y only from r5
    g["rules"]["r7"] = {"lhs": "L*", "rhs": "-L -> E"}  # L always has edges
    probs = _problems(tmp_path, g, lib)
    by_rule = {p.element: p.message for p in probs}
    assert "can never match" in by_rule["rule 'r5'"]
    assert "unreachable" in by_rule["rule 'r6'"]
    assert "can never match" in by_rule["rule 'r7'"]


def test_non_terminating_symbol(tmp_path):
    g, lib = default_data()
    del g["rules"]["r4"]
    probs = _problems(tmp_path, g, lib)
    p = next(p for p in probs if p.element == "symbol 'L'")
    assert "'-L*'" in p.message and "never be finished" in p.message


def test_parameter_out_of_domain_names_component_and_param(tmp_path):
    g, lib = default_data()
    lib["components"]["link"]["params"]["length"]["values"] = [0.15, 2.0]
    probs = _problems(tmp_path, g, lib)
    p = next(p for p in probs if "out of the domain" in p.message)
    assert p.file.endswith("library.yaml")
    assert p.element == "component 'link'" and p.column == "params.length" and "2.0" in p.message


def test_port_mismatch(tmp_path):
    g, lib = default_data()
    lib["components"]["link"]["offer"] = ["motor"]
    probs = _problems(tmp_path, g, lib)
    p = next(p for p in probs if "port mismatch" in p.message)
    assert p.element == "rule 'r4'" and "'link'" in p.message and "'tool'" in p.message


def test_terminal_on_left_side_and_missing_kind_param(tmp_path):
    g, lib = default_data()
    g["rules"]["r5"] = {"lhs": "-E", "rhs": "-E -> P"}
    del lib["components"]["link"]["params"]["rotation"]
    probs = _problems(tmp_path, g, lib)
    msgs = [str(p) for p in probs]
    assert any("rule 'r5'" in m and "terminal" in m for m in msgs)
    assert any("component 'link'" in m and "needs parameter 'rotation'" in m for m in msgs)


def test_yaml_syntax_error_names_file(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("rules: [unclosed\n")
    with pytest.raises(GrammarError, match="bad.yaml"):
        load_grammar(bad)
    with pytest.raises(GrammarError, match="invalid YAML"):
        load_library(bad)


def test_library_referenced_by_grammar_file(tmp_path):
    g, lib = default_data()
    g["library"] = "library.yaml"
    gp, _ = write(tmp_path, g, lib)
    assert load_grammar(gp).library.source.endswith("library.yaml")


def test_unknown_fields_and_bad_connector_ranges(tmp_path):
    g, lib = default_data()
    g["rules"]["r2"]["rsh"] = "typo"
    lib["components"]["revolute"]["dofs"][0]["range"] = ["-lim", "lim"]
    lib["components"]["link"]["colour"] = [1, 0, 0, 1]
    msgs = [str(p) for p in _problems(tmp_path, g, lib)]
    assert any("rule 'r2'" in m and "column 'rsh'" in m and "unknown field" in m for m in msgs)
    assert any("component 'revolute'" in m and "unknown parameter '-lim'" in m for m in msgs)
    assert any("component 'link'" in m and "column 'colour'" in m for m in msgs)


def test_symbol_never_produced_is_a_warning_not_an_error(tmp_path):
    from robotwright.grammar.loader import GrammarWarning

    g, lib = default_data()
    g["symbols"]["W"] = {"kind": "terminal", "description": "unused"}
    with pytest.warns(GrammarWarning, match="symbol 'W'"):
        grammar = load_variant(tmp_path, g, lib)
    assert "W" in grammar.symbols
