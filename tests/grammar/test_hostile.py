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
    grammar.write_text("name: [" + "[" * 50_000 + "]" * 50_000 + "]\n")
    _check_fails(grammar, capsys, "nests more than 100 levels")


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
