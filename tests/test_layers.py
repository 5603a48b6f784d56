"""The house's one way down: every import in ``src/robotwright`` (module level or inside a
function, ``TYPE_CHECKING`` blocks too) goes from a layer to a lower one, never up, so
no import cycle can form across packages. docs/architecture.md draws these layers; the
last test checks that the page names each package in the layer this test puts it in."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "robotwright"
DOC = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"

#: Lowest first. A unit is a subpackage or a top-level module of ``robotwright``; ``_*``
#: stands for every private helper module. The base layer's units (the helpers, the
#: errors and the package's own ``__init__``) may use one another.
#: A unit imports its own modules, units of lower layers, and units listed before it in
#: its own layer (the gate: ``sources`` reads the ``catalog``, ``tasks`` reads robots
#: through ``sources``).
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("base", ("_*", "errors", "robotwright")),
    ("model", ("hrdf",)),
    ("sinks", ("generators",)),
    ("sources", ("parsers",)),
    ("gate", ("catalog", "sources", "tasks")),
    ("systems", ("sensors", "things", "grammar")),
    ("scene loading", ("scene",)),
    ("drawing", ("render", "view")),
    ("commands", ("cli", "__main__")),
)


def _unit(module: str) -> str:
    parts = module.split(".")
    if len(parts) == 1:
        return "robotwright"
    return "_*" if parts[1].startswith("_") and parts[1] != "__main__" else parts[1]


def _rank() -> dict[str, tuple[int, int]]:
    return {u: (i, j) for i, (_, units) in enumerate(LAYERS) for j, u in enumerate(units)}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> list[tuple[int, str]]:
    """(line, module) of every ``robotwright`` import in the file, relative ones resolved."""
    module = _module_name(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            # ``from robotwright import x`` imports the unit x
            names = [f"{target}.{a.name}" for a in node.names] if target == "robotwright" else []
            found += [(node.lineno, t) for t in names or [target]]
    return [(line, t) for line, t in found if t == "robotwright" or t.startswith("robotwright.")]


def _upward_imports() -> list[str]:
    rank = _rank()
    wrong = []
    for path in sorted(SRC.rglob("*.py")):
        here = _unit(_module_name(path))
        for line, target in _imports(path):
            there = _unit(target)
            if there == here or (rank.get(there, (1,))[0] == rank[here][0] == 0):
                continue
            if there not in rank:
                wrong.append(
                    f"{path.relative_to(SRC)}:{line}: {target}: unit {there!r} in no layer"
                )
            elif rank[there] >= rank[here]:
                wrong.append(
                    f"{path.relative_to(SRC)}:{line}: {here} ({LAYERS[rank[here][0]][0]}) "
                    f"imports {target} ({LAYERS[rank[there][0]][0]})"
                )
    return wrong


def test_every_unit_is_in_a_layer() -> None:
    rank = _rank()
    units = {_unit(_module_name(p)) for p in SRC.rglob("*.py")}
    assert sorted(units - set(rank)) == []
    assert sorted(set(rank) - units) == []


def test_imports_only_go_down() -> None:
    assert _upward_imports() == []


def test_only_the_commands_parse_arguments() -> None:
    """argparse belongs to the commands layer: a system takes typed arguments."""
    users = [
        str(p.relative_to(SRC))
        for p in SRC.rglob("*.py")
        if _unit(_module_name(p)) not in ("cli", "__main__")
        and re.search(r"^\s*(import argparse|from argparse import)", p.read_text(), re.M)
    ]
    assert users == []


@pytest.mark.parametrize(
    "source, expected",
    [
        ("from robotwright.cli import main\n", "imports robotwright.cli"),
        ("def f():\n    from robotwright.view.server import Viewer\n", "imports robotwright.view"),
    ],
)
def test_the_walk_finds_an_upward_import(tmp_path, monkeypatch, source, expected) -> None:
    """The check itself can fail: a model module importing a command, or (lazily, inside
    a function) the viewer, is reported with its file and line."""
    fake = tmp_path / "robotwright"
    (fake / "hrdf").mkdir(parents=True)
    (fake / "__init__.py").write_text("")
    (fake / "hrdf" / "__init__.py").write_text("")
    (fake / "hrdf" / "bad.py").write_text(source)
    for unit in ("cli", "view"):
        (fake / unit).mkdir()
        (fake / unit / "__init__.py").write_text("")
    monkeypatch.setitem(globals(), "SRC", fake)
    wrong = _upward_imports()
    assert len(wrong) == 1 and wrong[0].startswith("hrdf/bad.py:") and expected in wrong[0]


def test_architecture_page_matches_the_layers() -> None:
    """docs/architecture.md has one table row per layer, naming exactly its units."""
    text = DOC.read_text(encoding="utf-8")
    rows = re.findall(r"^\| *\d+ *\| *([^|]+?) *\| *([^|]+?) *\|", text, re.M)
    documented = {name: set(re.findall(r"`([\w*.]+)`", units)) for name, units in rows}
    for name, units in LAYERS:
        assert documented.get(name) == set(units), name
    assert list(documented) == [name for name, _ in LAYERS]
