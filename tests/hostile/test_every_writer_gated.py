"""Every file the program writes goes through the output gate (issue 38, item 2 of
"what to build"), and a link planted at a name the program writes is never followed.

The gate is :mod:`robotwright._atomic` (a temporary of the program's own, made with
``O_EXCL | O_NOFOLLOW``, renamed onto the output; or a staging folder made by
``atomic_dir``/``atomic_files``). The static test below lists every call in the source
that writes a file by name and requires each to be one of the reviewed places: the
gate itself, or a write into a folder the program has just made for itself (a staging
folder, a private temporary folder). A new ``write_text`` on a user's path fails it.
"""

from __future__ import annotations

import ast
import os
import re
from pathlib import Path

import pytest

import robotwright

ROOT = Path(robotwright.__file__).parent

#: Calls that write a file by name.
_WRITE_METHODS = {"write_text", "write_bytes", "savefig", "Export", "savez", "savez_compressed"}

#: (module, function) -> where it writes. Every entry was read: it writes into a folder
#: the program made for itself, or it is the gate.
REVIEWED = {
    ("_atomic.py", "copy_mesh_file"): "the gate: the temporary of _new_file",
    ("_atomic.py", "atomic_open"): "the gate: the temporary of _new_file",
    ("_atomic.py", "write_bytes_atomic"): "the gate: the temporary of _new_file",
    ("_atomic.py", "StagedFiles.write_text"): "the gate: its staging folder",
    ("_inputs.py", "copy_regular_file"): "the gate's copy: into the gate's temporary",
    ("_outputs.py", "write_marker"): "atomic_dir's staging folder",
    ("cli/demo.py", "step_hrdf"): "atomic_dir's staging folder (run_demo)",
    ("cli/demo.py", "step_roundtrip"): "atomic_dir's staging folder (run_demo)",
    ("cli/demo.py", "step_lidar"): "atomic_dir's staging folder (run_demo)",
    ("cli/demo.py", "run_demo"): "atomic_dir's staging folder",
    ("generators/base.py", "GeneratorBase.export"): "StagedFiles (atomic_files)",
    ("grammar/draw.py", "draw_limb"): "atomic_open's file object",
    ("grammar/export.py", "export_design"): "atomic_dir's staging folder",
    ("grammar/winners.py", "write_front.extra"): "atomic_dir's staging folder",
    ("grammar/winners.py", "_write_designs"): "atomic_dir's staging folder",
    ("grammar/winners.py", "plot_front"): "atomic_open's file object",
    ("grammar/winners.py", "plot_track"): "atomic_open's file object",
    ("hrdf/write.py", "write_hrdf_dir.fill"): "atomic_dir's staging folder",
    ("parsers/mujoco_probes.py", "mujoco_urdf_keeps_mesh_files_apart"): "a private temporary",
    ("render/png.py", "save_png"): "an in-memory buffer, then the gate",
    ("sensors/plot.py", "plot_scan"): "atomic_open's file object",
    ("sensors/scan.py", "save_npz"): "atomic_open's file object",
    ("generators/usd.py", "to_usd"): "the private temporary of the conversion, then the gate",
    ("things/world.py", "World.export"): "StagedFiles (atomic_files)",
}


def _mode(call: ast.Call) -> str | None:
    mode = call.args[1] if len(call.args) >= 2 else None
    for kw in call.keywords:
        if kw.arg == "mode":
            mode = kw.value
    if mode is None:
        return "r"
    return mode.value if isinstance(mode, ast.Constant) else None  # None: not a constant


class _WriteCalls(ast.NodeVisitor):
    """The calls of one module that write a file by name, by enclosing function."""

    def __init__(self, module: str, found: dict[tuple[str, str], list[int]]) -> None:
        self.module, self.found, self.stack = module, found, []

    def visit_FunctionDef(self, node: ast.AST) -> None:
        self.stack.append(node.name)  # type: ignore[attr-defined]
        self.generic_visit(node)
        self.stack.pop()

    visit_AsyncFunctionDef = visit_FunctionDef
    visit_ClassDef = visit_FunctionDef

    def visit_Call(self, node: ast.Call) -> None:
        func = node.func
        writes = isinstance(func, ast.Attribute) and func.attr in _WRITE_METHODS
        if isinstance(func, ast.Name) and func.id == "open":
            mode = _mode(node)
            writes = mode is None or any(c in mode for c in "wax+")
        if writes:
            key = (self.module, ".".join(self.stack))
            self.found.setdefault(key, []).append(node.lineno)
        self.generic_visit(node)


def _writers() -> dict[tuple[str, str], list[int]]:
    found: dict[tuple[str, str], list[int]] = {}
    for path in sorted(ROOT.rglob("*.py")):
        visitor = _WriteCalls(path.relative_to(ROOT).as_posix(), found)
        visitor.visit(ast.parse(path.read_text(encoding="utf-8")))
    return found


def test_every_file_write_is_a_reviewed_gated_one() -> None:
    found = _writers()
    unreviewed = {k: v for k, v in found.items() if k not in REVIEWED}
    assert unreviewed == {}, f"writes outside the output gate: {unreviewed}"
    stale = sorted(set(REVIEWED) - set(found))
    assert stale == [], f"reviewed places that no longer write (drop them): {stale}"


def test_the_gates_temporary_never_follows_a_planted_link(tmp_path) -> None:
    """Whatever temporary name a writer uses, a link there is not written through: the
    gate makes its temporaries with O_EXCL | O_NOFOLLOW under random names, and the old
    fixed ``.NAME.partial`` names are no longer used by anyone."""
    from robotwright._atomic import write_text_atomic

    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    out = tmp_path / "out"
    out.mkdir()
    for planted in (".robot_cfg.py.partial", ".robot.usda.partial.usda", "robot_cfg.py"):
        (out / planted).symlink_to(victim)
    write_text_atomic(out / "robot_cfg.py", "ROBOT_CFG = 1\n")
    assert victim.read_text() == "precious"
    assert not (out / "robot_cfg.py").is_symlink()
    assert (out / "robot_cfg.py").read_text() == "ROBOT_CFG = 1\n"


def test_no_source_names_a_fixed_partial_file() -> None:
    hits = [
        p.relative_to(ROOT).as_posix()
        for p in ROOT.rglob("*.py")
        if re.search(r"[\"'{]\.[^\"']*\.partial", p.read_text(encoding="utf-8"))
    ]
    assert hits == []


def test_a_search_log_is_never_written_through_a_link(tmp_path, capsys) -> None:
    from robotwright.cli import main

    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    log = tmp_path / "log.jsonl"
    log.symlink_to(victim)
    args = ["grammar", "search", "--budget", "2", "--workers", "1", "--method", "random"]
    code = main([*args, "--max-links", "1", "--log", str(log), "--overwrite"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error:") and "link" in err and "Traceback" not in err
    assert victim.read_text() == "precious"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
def test_the_gate_copies_only_regular_files(tmp_path) -> None:
    from robotwright._atomic import copy_file_atomic
    from robotwright.errors import InputFileError

    fifo = tmp_path / "pipe.stl"
    os.mkfifo(fifo)
    with pytest.raises(InputFileError, match="FIFO|regular"):
        copy_file_atomic(fifo, tmp_path / "out" / "x.stl")
    assert not (tmp_path / "out").exists()
