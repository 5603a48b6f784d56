"""Shared helpers for grammar tests: write variants of the bundled grammar/library."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from robotwright.grammar.loader import default_grammar_path, default_library_path, load_grammar


def default_data() -> tuple[dict[str, Any], dict[str, Any]]:
    g = yaml.safe_load(default_grammar_path().read_text())
    lib = yaml.safe_load(default_library_path().read_text())
    return g, lib


def write(tmp: Path, grammar: dict[str, Any], library: dict[str, Any]) -> tuple[Path, Path]:
    gp, lp = tmp / "grammar.yaml", tmp / "library.yaml"
    gp.write_text(yaml.safe_dump(grammar, sort_keys=False))
    lp.write_text(yaml.safe_dump(library, sort_keys=False))
    return gp, lp


def load_variant(tmp: Path, grammar: dict[str, Any], library: dict[str, Any]):
    gp, lp = write(tmp, grammar, library)
    return load_grammar(gp, lp)


def one_choice_library() -> dict[str, Any]:
    """The default library cut to one component and one value per symbol."""
    _, lib = default_data()
    comps = lib["components"]
    for name in ("universal", "prismatic", "tool"):
        del comps[name]
    for comp in comps.values():
        for p in (comp.get("params") or {}).values():
            p["values"] = p["values"][:1]
    return lib


#: A 3-DoF arm of the bundled grammar (universal + revolute joints, a tool).
ARM = """# grammar=srl
r1 @0: B=base(diameter=0.08, thickness=0.02) P=pinned()
r2 @0: C=universal(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=0.0)
r3 @3: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=0.0)
r4 @5: E=tool(length=0.08)
"""
