"""Hostile input to ``grammar search`` with the physics objectives and ``-o`` winners:
constraint strings, ``--top`` and ``--objective`` values, objective settings through the
API, and output folders that must not be replaced. Every case: exit 2 (or ValueError
from the API), one ``error`` line, no traceback, nothing written."""

from __future__ import annotations

import os
import random
import string
from pathlib import Path

import pytest

from robotwright.cli import main
from robotwright.grammar.objectives import (
    Energy,
    NoCarrierCollision,
    Payload,
    Track,
    make_constraint,
)


def snapshot(root: Path) -> dict[str, object]:
    """Everything under ``root``, links read, never followed."""
    found: dict[str, object] = {}
    for dirpath, dirs, files in os.walk(root, followlinks=False):
        for name in dirs + files:
            p = Path(dirpath, name)
            rel = str(p.relative_to(root))
            if p.is_symlink():
                found[rel] = ("link", os.readlink(p))
            elif p.is_dir():
                found[rel] = ("dir",)
            else:
                found[rel] = ("file", p.read_bytes())
    return found


def refused(argv: list[str], capsys, root: Path) -> str:
    """Exit 2, no traceback, ``root`` unchanged; returns the error line (the command's
    own ``error: ...`` first line, or argparse's usage error, its last line)."""
    before = snapshot(root)
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse refuses usage errors this way
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2, (argv, err)
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    line = lines[0] if lines[0].startswith("error: ") else lines[-1]
    assert "error:" in line, err
    assert snapshot(root) == before, argv
    return line


FLAGS = ["no-self-collision", "no-carrier-collision", "joint-limits"]
NUMERIC = ["max-mass", "max-dof", "min-dof"]
BAD_NUMBERS = ["", "x", "nan", "NaN", "inf", "-inf", "-1", "1e999", "2kg", "0x10", " ", "1,5"]
BAD_WHOLE = ["1.5", "-3", "1e3"]

CONSTRAINTS = (
    [f"{f}={v}" for f in FLAGS for v in ("", "1", "yes")]
    + [f"{n}={v}" for n in NUMERIC for v in BAD_NUMBERS]
    + [f"{n}={v}" for n in ("max-dof", "min-dof") for v in BAD_WHOLE]
    + [f"{n}" for n in NUMERIC]
    + ["", "=", "=1", "no-self-collision ", "NO-SELF-COLLISION", "max_mass=1", "max-mass==1"]
    + ["max-mass=1\x00", "no-carrier-collision\n", "\u202emax-mass=1", "a" * 5000]
)


def _junk(n: int, seed: int = 23) -> list[str]:
    rng = random.Random(seed)
    alphabet = string.printable + "\u00e9\u4e2d\U0001f600"
    return ["".join(rng.choice(alphabet) for _ in range(rng.randint(1, 40))) for _ in range(n)]


@pytest.mark.parametrize("text", CONSTRAINTS + _junk(40))
def test_bad_constraints_refused(text, tmp_path, capsys):
    out = tmp_path / "win"
    argv = ["grammar", "search", "--objective", "payload", "--budget", "2"]
    last = refused([*argv, f"--constraint={text}", "-o", str(out)], capsys, tmp_path)
    assert "constraint" in last
    assert not out.exists()
    with pytest.raises(ValueError):
        make_constraint(text)


@pytest.mark.parametrize("value", ["0", "-1", "x", "1.5", "", "1e9", "nan", "\x00"])
def test_bad_top_refused(value, tmp_path, capsys):
    last = refused(
        ["grammar", "search", "--budget", "2", "-o", str(tmp_path / "w"), f"--top={value}"],
        capsys,
        tmp_path,
    )
    assert "--top" in last


@pytest.mark.parametrize("value", ["Payload", "tracking", "energy ", "", "power", "reach,track"])
def test_unknown_objective_refused(value, tmp_path, capsys):
    last = refused(["grammar", "search", f"--objective={value}"], capsys, tmp_path)
    assert "--objective" in last


@pytest.mark.parametrize(
    ("cls", "kwargs"),
    [
        (Payload, {"samples": -1}),
        (Payload, {"samples": 1.5}),
        (Payload, {"samples": float("nan")}),
        (Payload, {"seed": -2}),
        (Payload, {"samples": True}),
        (NoCarrierCollision, {"samples": -5}),
        (NoCarrierCollision, {"seed": "0"}),
        *[(c, {"duration": v}) for c in (Track, Energy) for v in (0, -1.0, float("inf"), "2")],
        *[(c, {"scale": v}) for c in (Track, Energy) for v in (-0.1, float("nan"), None)],
    ],
)
def test_bad_objective_settings_refused(cls, kwargs):
    with pytest.raises(ValueError, match=next(iter(kwargs))):
        cls(**kwargs)


def _winners(tmp_path: Path, capsys) -> Path:
    out = tmp_path / "win"
    argv = ["grammar", "search", "--objective", "payload", "--budget", "3", "--max-links", "2"]
    argv += ["--workers", "1", "--method", "random", "--no-picture", "-o", str(out)]
    assert main(argv) == 0
    capsys.readouterr()
    return out


def _search_to(out: Path, *extra: str) -> list[str]:
    return [
        "grammar",
        "search",
        "--objective",
        "payload",
        "--budget",
        "2",
        "--max-links",
        "2",
        "--workers",
        "1",
        "--no-picture",
        # designs touching the carrier stay feasible: this checks the output folder
        "--constraint",
        "no-self-collision",
        "-o",
        str(out),
        *extra,
    ]


def test_winners_never_replace_what_they_did_not_write(tmp_path, capsys):
    keep = tmp_path / "keep"
    keep.mkdir()
    # a file, a foreign folder, a folder of another kind, a link to a folder
    (keep / "notes.txt").write_text("mine", encoding="utf-8")
    foreign = keep / "photos"
    foreign.mkdir()
    (foreign / "a.jpg").write_bytes(b"x")
    design = keep / "design"
    assert main(["grammar", "sample", "-n", "1", "-o", str(keep / "s"), "--no-picture"]) == 0
    one = next((keep / "s").glob("*/design.txt"))
    assert main(["grammar", "export", str(one), "-o", str(design)]) == 0
    link = keep / "link"
    link.symlink_to(foreign, target_is_directory=True)
    capsys.readouterr()
    for target in (keep / "notes.txt", foreign, design, link):
        for extra in ((), ("--overwrite",)):
            refused(_search_to(target, *extra), capsys, keep)
    # an earlier winners folder: only with --overwrite, and then wholly replaced
    out = _winners(tmp_path, capsys)
    refused(_search_to(out), capsys, tmp_path)
    (out / "best_1" / "mine.txt").write_text("added", encoding="utf-8")
    refused(_search_to(out, "--overwrite"), capsys, tmp_path)
    (out / "best_1" / "mine.txt").unlink()
    assert main(_search_to(out, "--overwrite", "--top", "1")) == 0
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "best_1",
        "winners.txt",
    ]
