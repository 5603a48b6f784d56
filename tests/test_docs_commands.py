"""Every command shown in README.md and docs/*.md runs as written.

A user runs them from the project folder after the first set-up command
(``python -m pip install . && robotwright demo``), so each document's commands run in
order in a fresh folder holding the project's ``src/`` and the demo's output. Commands
are the ``$ `` lines of ``console`` blocks and the lines of ``bash`` blocks (the set-up
commands themselves excepted); syntax synopses with placeholders live in ``text``
blocks. Output lines a document shows under a command must be what the command prints
(timings and ``...`` excepted).
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
import shutil
from pathlib import Path

import pytest

from robotwright import demo
from robotwright.cli import main

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: Commands that serve until stopped (a browser viewer): their arguments are parsed only.
INTERACTIVE = {"view"}
#: A shown output line with a time in it ("in 0.25 s", "19200 designs/s") varies per run.
_TIMING = re.compile(r"\d s\b|/s\b")


def commands(document: Path) -> list[tuple[str, list[str]]]:
    """``(command, output lines shown under it)`` in document order."""
    found: list[tuple[str, list[str]]] = []
    lang = None
    for line in document.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            lang = line[3:].strip() if lang is None else None
            continue
        if lang == "console":
            if line.startswith("$ "):
                found.append((line[2:], []))
            elif found and line.strip() and line.strip() != "...":
                found[-1][1].append(line)
        elif (
            lang in ("bash", "sh")
            and line.strip()
            and not line.lstrip().startswith("#")
            and "pip install" not in line  # the set-up commands themselves
        ):
            found.append((line, []))
    return found


@pytest.fixture(scope="module")
def demo_output(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The folder the first set-up command leaves (``robotwright demo``), without the
    pictures step (rendering is slow and no documented command reads its output)."""
    out = tmp_path_factory.mktemp("setup") / "robotwright_demo"
    steps = [s for s in demo.STEPS if s[1].__name__ != "step_pictures"]
    original, demo.STEPS = demo.STEPS, steps
    try:
        demo.run_demo(out)
    finally:
        demo.STEPS = original
    return out


def test_documents_show_commands() -> None:
    shown = {d.name: len(commands(d)) for d in DOCUMENTS}
    assert shown["README.md"] >= 8 and sum(shown.values()) >= 25, shown


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda d: d.name)
def test_every_command_runs_as_written(
    document: Path, demo_output: Path, tmp_path: Path, monkeypatch, capsys
) -> None:
    listed = commands(document)
    if not listed:
        pytest.skip(f"{document.name} shows no command")
    (tmp_path / "src").symlink_to(ROOT / "src", target_is_directory=True)
    shutil.copytree(demo_output, tmp_path / "robotwright_demo")
    monkeypatch.chdir(tmp_path)
    for command, shown in listed:
        words = shlex.split(command, comments=True)
        assert words[0] == "robotwright", f"{document.name}: not a robotwright command: {command}"
        redirect = None
        if ">" in words:
            words, redirect = words[: words.index(">")], words[words.index(">") + 1]
        if words[1] in INTERACTIVE:
            continue
        stdout = io.StringIO()
        with contextlib.redirect_stdout(stdout):
            code = main(words[1:])
        err = capsys.readouterr().err
        assert code == 0, f"{document.name}: `{command}` exited {code}:\n{err}"
        if redirect:
            Path(redirect).write_text(stdout.getvalue(), encoding="utf-8")
            assert Path(redirect).stat().st_size > 0
        printed = stdout.getvalue().splitlines()
        for line in shown:
            if not _TIMING.search(line):
                assert line in printed, f"{document.name}: `{command}` did not print: {line}"
