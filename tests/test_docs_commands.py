"""Every command shown in README.md and docs/*.md runs as written, all of them in order.

A user runs them from the project folder after the first set-up command
(``python -m pip install . && robotwright demo``), README first, then each page of
``docs/``: the test runs every command of every document in that order in one fresh
folder holding a copy of the project's ``src/`` and the demo's output, and checks each
one succeeds. So a command never collides with an earlier one's output (each writes its
own output names, all under ``out/``, which ``.gitignore`` holds), prints at most one
line on stderr (the notes' summary), and the commands leave nothing else behind (no
stray file in the checkout, no ``MUJOCO_LOG.TXT``). Commands are the ``$ `` lines of
``console`` blocks and the lines of ``bash`` blocks (the set-up commands themselves
excepted); syntax synopses with placeholders live in ``text`` blocks. Output lines a
document shows under a command must be what the command prints (timings and ``...``
excepted).
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import re
import shlex
import shutil
from pathlib import Path

import pytest

from robotwright.cli import build_parser, demo, main

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: Commands that serve until stopped (a browser viewer): their arguments are parsed only.
INTERACTIVE = {"view"}
#: A shown output line with a time in it ("in 0.25 s", "19200 designs/s") varies per run.
_TIMING = re.compile(r"\d s\b|/s\b")
#: What a command prints on stderr only when a step runs long on this machine (progress
#: lines, the announcement of long work): not counted in the one-line rule.
#: Progress lines of slow work: ``  12/60 links read (4 s, ...)`` and ``  WHAT (4 s)``.
_SLOW_WORK = re.compile(
    r"^  \d+/\d+ .+ \(\d.*\)$|^  \S.* \(\d[^()]*\)$|\(estimated\); progress follows"
)


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


#: What the documented commands may add to the folder they run in: their outputs, all
#: under ``out/`` (the set-up's ``robotwright_demo/`` is there before them).
OUTPUTS = {"out"}


def _snapshot(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (relative path -> SHA-256 of its bytes)."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and "__pycache__" not in p.parts
    }


@pytest.fixture(scope="module")
def fresh_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh folder as a new user has it after the set-up: a copy of the project's
    ``src/`` and the output of ``robotwright demo`` (without its pictures step: rendering
    is slow and no documented command reads its output)."""
    folder = tmp_path_factory.mktemp("fresh")
    shutil.copytree(
        ROOT / "src", folder / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info")
    )
    steps = [s for s in demo.STEPS if s[1].__name__ != "step_pictures"]
    original, demo.STEPS = demo.STEPS, steps
    try:
        demo.run_demo(folder / "robotwright_demo")
    finally:
        demo.STEPS = original
    return folder


def test_documents_show_commands() -> None:
    shown = {d.name: len(commands(d)) for d in DOCUMENTS}
    assert shown["README.md"] >= 8 and sum(shown.values()) >= 25, shown


def _run_command(document: Path, command: str, shown: list[str], capsys) -> list[str]:
    """Run one documented command; the problems found (empty when it ran as written)."""
    where = f"{document.name}: `{command}`"
    words = shlex.split(command, comments=True)
    if words[0] != "robotwright":
        return [f"{where}: not a robotwright command"]
    redirect = None
    if ">" in words:
        words, redirect = words[: words.index(">")], words[words.index(">") + 1]
    if words[1] in INTERACTIVE:
        try:
            build_parser().parse_args(words[1:])
        except SystemExit:
            return [f"{where}: its arguments do not parse:\n{capsys.readouterr().err}"]
        return []
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        code = main(words[1:])
    err = capsys.readouterr().err
    if code != 0:
        return [f"{where} exited {code}:\n{err}"]
    problems = []
    if len([line for line in err.splitlines() if not _SLOW_WORK.search(line)]) > 1:
        problems.append(f"{where} printed more than one line on stderr:\n{err}")
    if redirect:
        Path(redirect).write_text(stdout.getvalue(), encoding="utf-8")
        if Path(redirect).stat().st_size == 0:
            problems.append(f"{where} printed nothing into {redirect}")
    printed = stdout.getvalue().splitlines()
    problems += [
        f"{where} did not print: {line}"
        for line in shown
        if not _TIMING.search(line) and line not in printed
    ]
    return problems


def test_every_command_runs_in_order_in_one_fresh_folder(
    fresh_folder: Path, monkeypatch, capsys
) -> None:
    """README's commands, then each page's, in one folder: every one exits 0 (none
    refuses to replace an earlier one's output), and only ``out/`` is added."""
    monkeypatch.chdir(fresh_folder)
    before = _snapshot(fresh_folder)
    entries = {p.name for p in fresh_folder.iterdir()}
    problems: list[str] = []
    for document in DOCUMENTS:
        for command, shown in commands(document):
            problems += _run_command(document, command, shown, capsys)
    assert not problems, "\n".join(problems)
    added = {p.name for p in fresh_folder.iterdir()} - entries
    assert added <= OUTPUTS, f"the commands left files outside out/: {sorted(added - OUTPUTS)}"
    after = _snapshot(fresh_folder)
    changed = [name for name, digest in before.items() if after.get(name) != digest]
    assert not changed, f"the commands changed the project's or the demo's files: {changed}"
