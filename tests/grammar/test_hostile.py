"""Hostile grammar, library and design files (issue 11): non-UTF-8, FIFOs, absurd
nesting, a library path leading out of the grammar's folder. Each is one located
GrammarError (exit 2), never a UnicodeDecodeError, RecursionError or a hang."""

from __future__ import annotations

import os
import shutil
import threading
from pathlib import Path

import pytest

from robotwright.cli import main
from robotwright.errors import GrammarError
from robotwright.grammar.design import Design
from robotwright.grammar.loader import default_grammar_path, default_library_path, load_grammar


@pytest.fixture
def grammar(tmp_path: Path) -> Path:
    folder = tmp_path / "g"
    folder.mkdir()
    shutil.copy(default_library_path(), folder / "lib.yaml")
    text = default_grammar_path().read_text()
    path = folder / "grammar.yaml"
    path.write_text(text + "\nlibrary: lib.yaml\n")
    load_grammar(path)  # valid as written
    return path


def _check_fails(path: Path, capsys, text: str) -> None:
    with pytest.raises(GrammarError) as exc:
        load_grammar(path)
    assert text in str(exc.value), str(exc.value)
    # 'grammar check' reports like 'validate': the problems on stdout, exit 1.
    assert main(["grammar", "check", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"error: {path}" in out and text in out, out


def test_non_utf8_grammar_is_a_located_error(grammar, capsys) -> None:
    grammar.write_bytes(b"name: \xff\xfe\n")
    _check_fails(grammar, capsys, "not UTF-8 text (byte 0xff at offset 6)")


def test_deeply_nested_grammar_is_refused(grammar, capsys) -> None:
    # Our depth check or PyYAML's own (6.0.4 and later refuse deep flow nesting while
    # scanning) may answer first: either way one GrammarError located at the file.
    grammar.write_text("name: [" + "[" * 50_000 + "]" * 50_000 + "]\n")
    _check_fails(grammar, capsys, str(grammar))


def test_fifo_grammar_does_not_hang(grammar, capsys) -> None:
    grammar.unlink()
    os.mkfifo(grammar)
    done: dict = {}
    thread = threading.Thread(
        target=lambda: done.update(code=main(["grammar", "check", str(grammar)]))
    )
    thread.daemon = True
    thread.start()
    thread.join(20)
    assert not thread.is_alive(), "hung on a FIFO"
    assert done["code"] == 1
    assert "FIFO" in capsys.readouterr().out


def test_library_path_leading_out_of_the_grammar_folder_is_refused(grammar, tmp_path, capsys):
    shutil.copy(default_library_path(), tmp_path / "outside.yaml")
    grammar.write_text(grammar.read_text().replace("library: lib.yaml", "library: ../outside.yaml"))
    _check_fails(grammar, capsys, "outside the grammar's folder")
    with pytest.raises(GrammarError) as exc:
        load_grammar(grammar)
    assert exc.value.problems[0].column == "library"


def test_deep_or_binary_design_file_is_a_grammar_error(tmp_path, capsys) -> None:
    with pytest.raises(GrammarError, match="nests lists/objects too deeply"):
        Design.from_json("[" * 100_000 + "]" * 100_000, "d.json")
    design = tmp_path / "design.json"
    design.write_text('{"steps": ' + "[" * 100_000 + "]" * 100_000 + "}")
    assert main(["grammar", "show", str(design)]) == 2
    assert "design.json: nests lists/objects too deeply" in capsys.readouterr().err
    design.write_bytes(b"{\xff}")
    assert main(["grammar", "show", str(design)]) == 2
    assert "not UTF-8" in capsys.readouterr().err


LIBRARY_EDITS = {
    "reversed DoF range": (
        "range: [0.0, stroke]",
        "range: [stroke, 0.0]",
        "component 'prismatic'",
        "dofs[0]",
        "lower > upper for {'stroke': 0.1}",
    ),
    "negative diameter": (
        "diameter: {range: [0.01, 0.2], values: [0.04]}",
        "diameter: {range: [-0.2, 0.2], values: [-0.04]}",
        "component 'link'",
        "params.diameter",
        "expected a domain above 0 m",
    ),
    "NaN twist": (
        "{type: hinge, twist: 1.5708, range: [-limit, limit]}",
        "{type: hinge, twist: .nan, range: [-limit, limit]}",
        "component 'universal'",
        "dofs[1]",
        "twist must be a number",
    ),
    "NaN density": (
        "density: 1200.0",
        "density: .nan",
        "component 'link'",
        "density",
        "density must be a number in (0, 100000]",
    ),
    "absurd density": (
        "density: 1200.0",
        "density: 1.0e+308",
        "component 'link'",
        "density",
        "density must be a number in (0, 100000]",
    ),
}


@pytest.mark.parametrize("case", sorted(LIBRARY_EDITS))
def test_library_that_sampling_would_crash_on_is_refused(grammar, capsys, case) -> None:
    """grammar check used to accept these; sample/search then crashed, or built a robot
    of mass 0 (density NaN) or 4.5e304 kg (density 1e308)."""
    old, new, element, column, text = LIBRARY_EDITS[case]
    library = grammar.parent / "lib.yaml"
    content = library.read_text()
    assert old in content
    library.write_text(content.replace(old, new, 1))
    with pytest.raises(GrammarError) as exc:
        load_grammar(grammar)
    hits = [p for p in exc.value.problems if p.element == element and p.column == column]
    assert hits and text in hits[0].message, exc.value.problems
    assert main(["grammar", "check", str(grammar)]) == 1
    assert text in capsys.readouterr().out
    out = grammar.parent / "designs"
    assert main(["grammar", "sample", "--grammar", str(grammar), "-o", str(out)]) == 2
    assert not out.exists()
