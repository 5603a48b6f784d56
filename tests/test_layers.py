"""The house's one way down: every import in ``src/robotwright`` (module level or inside a
function, ``TYPE_CHECKING`` blocks too) goes from a layer to a lower one, never up, so
no import cycle can form across packages. docs/architecture.md draws these layers; the
last test checks that the page names each package in the layer this test puts it in.
Inside the layers: readers and writers do not know each other, the readers are one
package per format, and no two modules import each other in a circle (the HRDF model's
delegation to its folder reader and writer excepted)."""

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
#: A unit imports its own modules, units of lower layers, and, in the gate and the
#: commands, units listed before it in its own layer (``sources`` reads the ``catalog``,
#: ``tasks`` reads robots through ``sources``; ``python -m robotwright`` runs ``cli``).
#: Elsewhere the units of one layer do not know each other: a reader imports no writer,
#: a sensor nothing of the grammar.
SIBLINGS_IMPORT = frozenset({"base", "gate", "commands"})

#: Names a package's face keeps for code written before they moved up a layer: the face
#: names them under ``if TYPE_CHECKING:`` and :func:`robotwright._lazy.attach` imports
#: them on first use, so importing the package imports nothing above it.
#: (face file, the package its names come from)
FORWARDS = frozenset({("parsers/__init__.py", "robotwright.proof")})
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("base", ("_*", "errors", "robotwright")),
    ("model", ("hrdf",)),
    ("readers and writers", ("parsers", "generators")),
    ("proof", ("proof",)),
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


def _module_name(path: Path, src: Path | None = None) -> str:
    parts = list(path.relative_to((src or SRC).parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _face_lines(tree: ast.Module) -> set[int]:
    """Lines of a package face's ``if TYPE_CHECKING:`` block (its lazy names)."""
    return {
        n.lineno
        for s in tree.body
        if isinstance(s, ast.If) and ast.unparse(s.test).endswith("TYPE_CHECKING")
        for n in ast.walk(s)
        if hasattr(n, "lineno")
    }


def _imports(path: Path, lazy_names: bool = True, src: Path | None = None) -> list[tuple[int, str]]:
    """(line, module) of every ``robotwright`` import in the file, relative ones resolved.
    ``lazy_names=False``: a package face's lazy names (imported on first use) left out."""
    module = _module_name(path, src)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skip = _face_lines(tree) if path.name == "__init__.py" and not lazy_names else set()
    found = []
    for node in ast.walk(tree):
        if getattr(node, "lineno", None) in skip:
            continue
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            # ``from robotwright import x`` imports the unit x, ``from pkg import x`` the
            # module ``pkg.x`` or a name of ``pkg``: both are below ``pkg``'s unit
            found += [(node.lineno, f"{target}.{a.name}") for a in node.names]
    return [(line, t) for line, t in found if t == "robotwright" or t.startswith("robotwright.")]


def _forwarded(path: Path, line: int, target: str) -> bool:
    """Whether the import is one of a face's :data:`FORWARDS`."""
    face = str(path.relative_to(SRC))
    return any(
        face == f
        and (target == t or target.startswith(t + "."))
        and line in _face_lines(ast.parse(path.read_text(encoding="utf-8")))
        for f, t in FORWARDS
    )


def _upward_imports() -> list[str]:
    rank = _rank()
    wrong = []
    for path in sorted(SRC.rglob("*.py")):
        here = _unit(_module_name(path))
        for line, target in _imports(path):
            there = _unit(target)
            if there == here or (rank.get(there, (1,))[0] == rank[here][0] == 0):
                continue
            if _forwarded(path, line, target):
                continue
            if there not in rank:
                wrong.append(
                    f"{path.relative_to(SRC)}:{line}: {target}: unit {there!r} in no layer"
                )
            elif rank[there] >= rank[here] or (
                rank[there][0] == rank[here][0] and LAYERS[rank[here][0]][0] not in SIBLINGS_IMPORT
            ):
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


#: What a top-level file of ``parsers/`` may not be named after: a format (it belongs in
#: that format's package) or the proof (it belongs in ``robotwright.proof``).
_PACKAGE_PREFIXES = ("mjcf", "urdf", "xacro", "usd", "proof", "roundtrip")


def test_the_readers_are_one_package_per_format() -> None:
    """``parsers/`` holds the formats' packages and the helpers they share; no file at its
    top level is named after a format or the proof, and each format package's face
    names its entry points."""
    top = SRC / "parsers"
    prefixed = [p.name for p in top.glob("*.py") if p.stem.startswith(_PACKAGE_PREFIXES)]
    assert prefixed == []
    for fmt in ("mjcf", "urdf", "xacro", "usd"):
        face = top / fmt / "__init__.py"
        tree = ast.parse(face.read_text(encoding="utf-8"))
        assert ast.get_docstring(tree), fmt
        assert _face_lines(tree), f"{fmt}: its face names no entry point"


def test_the_proof_is_outside_the_readers() -> None:
    """The proof and the round trip live in ``robotwright.proof``; no reader module is
    the proof's, and no reader imports a writer (the proof does, the readers need not)."""
    readers = sorted((SRC / "parsers").rglob("*.py"))
    assert [p.name for p in readers if "proof" in p.stem or "roundtrip" in p.stem] == []
    assert (SRC / "proof" / "__init__.py").exists()
    writers = [
        f"{p.relative_to(SRC)}:{line}: {target}"
        for p in readers
        for line, target in _imports(p, lazy_names=False)
        if _unit(target) == "generators"
    ]
    assert writers == []


#: Modules that may import each other, each circle with its reason (docs/architecture.md
#: says the same). Every other circle fails the test.
ALLOWED_CIRCLES: dict[str, frozenset[str]] = {
    # The model delegates HRDF.load / save / validate to its folder reader, writer and
    # checks, which build and read the model: one class with its persistence beside it.
    "hrdf": frozenset(
        f"robotwright.hrdf.{m}"
        for m in (
            "io",
            "layout",
            "model",
            "options",
            "read_meta",
            "read_tables",
            "tables",
            "validate",
            "validate_geoms",
            "validate_tree",
            "write",
        )  # fmt: skip
    ),
    # The same delegation for the object API: World.from_xml / from_string read a file.
    "things": frozenset(
        {
            "robotwright.things.world",
            "robotwright.things.xml_reader",
            "robotwright.things.xml_world",
        }
    ),
    # mjlab's contract: a sensor config's build() returns its sensor, which reads its config.
    "mjlab": frozenset({"robotwright.sensors.mjlab.config", "robotwright.sensors.mjlab.sensor"}),
    # Isaac Lab's contract: a sensor config's class_type names (types, under
    # TYPE_CHECKING) the sensor class, which reads its config.
    "isaaclab": frozenset(
        {
            "robotwright.sensors.isaaclab.config",
            "robotwright.sensors.isaaclab.scene_shapes",
            "robotwright.sensors.isaaclab.sensor",
        }
    ),
}


def _allowed(circle: set[str]) -> bool:
    return any(circle <= allowed for allowed in ALLOWED_CIRCLES.values())


def _circles(src: Path) -> list[list[str]]:
    """Groups of modules that import one another (strongly connected, more than one
    module), from every import but a package face's lazy names."""
    modules = {_module_name(p, src): p for p in src.rglob("*.py")}
    graph = {}
    for name, path in modules.items():
        targets = set()
        for _, target in _imports(path, lazy_names=False, src=src):
            # ``from pkg import module`` names the module; ``from module import name``
            # the module itself
            while target and target not in modules:
                target = target.rpartition(".")[0]
            if target and target != name:
                targets.add(target)
        graph[name] = targets
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []

    def visit(v: str) -> None:  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_modules_import_each_other_in_a_circle() -> None:
    assert [c for c in _circles(SRC) if not _allowed(set(c))] == []


def test_the_circle_check_finds_a_circle(tmp_path) -> None:
    fake = tmp_path / "robotwright"
    (fake / "things").mkdir(parents=True)
    (fake / "__init__.py").write_text("")
    (fake / "things" / "__init__.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
        "    from robotwright.things.a import f\n"
    )
    (fake / "things" / "a.py").write_text("def f():\n    from robotwright.things import b\n")
    (fake / "things" / "b.py").write_text("from robotwright.things.a import f\n")
    (fake / "things" / "c.py").write_text("import robotwright.things\n")
    assert _circles(fake) == [["robotwright.things.a", "robotwright.things.b"]]
