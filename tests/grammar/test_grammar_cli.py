"""``robotwright grammar ...`` commands."""

from __future__ import annotations

import mujoco
import pytest

from robotwright.cli import main
from robotwright.grammar.design import Design
from robotwright.grammar.loader import default_grammar_path

from .helpers import default_data, write


def test_check_valid_and_invalid(tmp_path, capsys):
    assert main(["grammar", "check", str(default_grammar_path())]) == 0
    assert "r3: -L* => -L -> C -> L*" in capsys.readouterr().out
    g, lib = default_data()
    g["rules"]["r4"]["lhs"] = "-L"
    gp, lp = write(tmp_path, g, lib)
    assert main(["grammar", "check", str(gp), "--library", str(lp)]) == 1
    out = capsys.readouterr().out
    assert "rule 'r4'" in out and "column 'lhs'" in out and "grammar.yaml" in out


def test_count_with_enumeration(capsys):
    assert main(["grammar", "count", "--max-links", "2", "--enumerate"]) == 0
    out = capsys.readouterr().out
    assert "designs with at most 2 link(s): 4800" in out and "equal to count: True" in out


@pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")
def test_sample_writes_every_file_and_they_load(tmp_path, capsys):
    assert (
        main(
            ["grammar", "sample", "--seed", "4", "-n", "2", "--max-links", "3", "-o", str(tmp_path)]
        )
        == 0
    )
    folders = sorted(p for p in tmp_path.iterdir() if p.is_dir())
    assert len(folders) == 2
    for f in folders:
        names = {p.name for p in f.iterdir()}
        assert {
            "srl.xml",
            "srl.urdf",
            "design.txt",
            "design.json",
            "tree.dot",
            "picture.png",
        } <= names
        d = Design.from_text((f / "design.txt").read_text())
        assert f.name.endswith(d.hash())
        m = mujoco.MjModel.from_xml_path(str(f / "srl.xml"))
        u = mujoco.MjModel.from_xml_path(str(f / "srl.urdf"))
        assert m.nq == u.nq >= 1
        assert (f / "picture.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    again = tmp_path / "again"
    assert (
        main(
            [
                "grammar",
                "sample",
                "--seed",
                "4",
                "-n",
                "2",
                "--max-links",
                "3",
                "-o",
                str(again),
                "--no-picture",
            ]
        )
        == 0
    )
    # The folder's hidden .robotwright marker is not a design.
    designs = sorted(p.name for p in again.iterdir() if not p.name.startswith("."))
    assert designs == [f.name for f in folders]


@pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")
def test_search_and_export(tmp_path, capsys):
    out = tmp_path / "best"
    rc = main(
        [
            "grammar",
            "search",
            "--objective",
            "reach",
            "--budget",
            "12",
            "--max-links",
            "2",
            "--workers",
            "1",
            "-o",
            str(out),
        ]
    )
    assert rc == 0
    text = capsys.readouterr().out
    assert "12 designs evaluated" in text and "best reach" in text
    again = tmp_path / "again"
    assert main(["grammar", "export", str(out / "best_1" / "design.json"), "-o", str(again)]) == 0
    assert (again / "srl.xml").read_text() == (out / "best_1" / "srl.xml").read_text()
    assert main(["grammar", "search", "--constraint", "shiny", "--budget", "2"]) == 2


def test_show_prints_tree_dh_and_dot(tmp_path, capsys):
    design = tmp_path / "d.txt"
    design.write_text(
        "# grammar=srl\n"
        "r1 @0: B=base(diameter=0.08, thickness=0.02) P=pinned()\n"
        "r2 @0: C=universal(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=0.0)\n"
        "r4 @3: E=tool(length=0.08)\n"
    )
    assert main(["grammar", "show", str(design)]) == 0
    out = capsys.readouterr().out
    assert (
        "2 DoF" in out and "  L:link(" in out and "joint2   hinge  a=0.0 alpha=1.5708 d=0.0" in out
    )
    assert main(["grammar", "show", str(design), "--dot"]) == 0
    assert capsys.readouterr().out.count("->") == 4
    design.write_text("# grammar=srl\nr2 @0: C=universal(limit=1.5708)\n")
    assert main(["grammar", "show", str(design)]) == 2
    assert "step 0" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["search", "--budget", "-5"], "--budget: expected an integer >= 1, got -5"),
        (["search", "--budget", "0"], "--budget: expected an integer >= 1, got 0"),
        (["search", "--beam-width", "0"], "--beam-width: expected an integer >= 1, got 0"),
        (["search", "--max-links", "-1"], "--max-links: expected an integer >= 0, got -1"),
        (["search", "--workers", "0"], "--workers: expected an integer >= 1, got 0"),
        (["sample", "-n", "0", "-o", "OUT"], "-n: expected an integer >= 1, got 0"),
        (["sample", "--max-links", "-2", "-o", "OUT"], "expected an integer >= 0, got -2"),
        (["count", "--max-links", "x"], "--max-links: expected an integer, got 'x'"),
        # A bound, named in the message, instead of minutes of counting (docs/grammar.md).
        (["count", "--max-links", "200"], "--max-links: expected at most 50"),
        (["sample", "--max-links", "51", "-o", "OUT"], "--max-links: expected at most 50"),
        (["search", "--max-links", "1000"], "--max-links: expected at most 50"),
    ],
)
def test_bad_numbers_are_usage_errors(tmp_path, capsys, argv, expected):
    argv = [str(tmp_path / "out") if a == "OUT" else a for a in argv]
    with pytest.raises(SystemExit) as exc:
        main(["grammar", *argv])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert expected in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_export_and_search_never_replace_a_file_or_a_foreign_folder(tmp_path, capsys):
    assert (
        main(["grammar", "sample", "--seed", "1", "-o", str(tmp_path / "s"), "--no-picture"]) == 0
    )
    design = next((tmp_path / "s").glob("*/design.txt"))
    capsys.readouterr()
    keep = tmp_path / "notes.txt"
    keep.write_text("mine", encoding="utf-8")
    foreign = tmp_path / "photos"
    foreign.mkdir()
    (foreign / "a.jpg").write_text("x", encoding="utf-8")
    assert main(["grammar", "export", str(design), "-o", str(keep)]) == 2
    assert "notes.txt: is a file; expected a folder for the design" in capsys.readouterr().err
    assert main(["grammar", "export", str(design), "-o", str(foreign)]) == 2
    assert "holds files robotwright did not write (a.jpg)" in capsys.readouterr().err
    assert main(["grammar", "search", "--budget", "2", "-o", str(keep)]) == 2
    assert main(["grammar", "sample", "-o", str(keep), "--no-picture"]) == 2
    assert "is a file; expected a folder" in capsys.readouterr().err
    assert keep.read_text(encoding="utf-8") == "mine"
    assert [p.name for p in foreign.iterdir()] == ["a.jpg"]
    # An earlier design folder is replaced in place with --overwrite only.
    assert main(["grammar", "export", str(design), "-o", str(design.parent)]) == 2
    assert "give --overwrite to replace it" in capsys.readouterr().err
    assert main(["grammar", "export", str(design), "-o", str(design.parent), "--overwrite"]) == 0


def test_long_work_is_announced_and_shows_progress_with_time_left(capsys, monkeypatch):
    from robotwright.cli import grammar as gcli

    progress = gcli.Progress(10, "designs done", every=0.0)
    progress.update(0)  # nothing done: no estimate yet
    progress.update(4, ", best reach 0.5")
    progress.update(10)  # the end is reported by the command itself
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and err[1].startswith("  4/10 designs done, best reach 0.5 (")
    assert "left)" in err[1] and "left" not in err[0]
    # Work estimated over a minute is announced before it runs; short work is not.
    gcli._warn_long(gcli.LONG_WORK_S + 1, "enumerating 7 designs")
    gcli._warn_long(gcli.LONG_WORK_S - 1, "enumerating 3 designs")
    err = capsys.readouterr().err
    assert (
        err.startswith("warning: enumerating 7 designs will take about 61 s")
        and "3 designs" not in err
    )
    assert gcli._duration(3 * 3600) == "3 h" and gcli._duration(90) == "90 s"
    # The command: every design passes through the progress; a slow rate makes the warning.
    monkeypatch.setattr(gcli, "LONG_WORK_S", 0.0)
    assert main(["grammar", "count", "--max-links", "2", "--enumerate"]) == 0
    captured = capsys.readouterr()
    assert "equal to count: True" in captured.out
    assert captured.err.startswith("warning: enumerating 4800 designs will take about")


def test_show_and_export_take_the_folder_sample_writes(tmp_path, capsys):
    assert main(["grammar", "sample", "-n", "1", "--seed", "3", "-o", str(tmp_path / "s"),
                 "--no-picture"]) == 0  # fmt: skip
    (folder,) = [p for p in (tmp_path / "s").iterdir() if p.is_dir()]
    capsys.readouterr()
    assert main(["grammar", "show", str(folder)]) == 0
    shown = capsys.readouterr().out
    assert shown.startswith((folder / "design.txt").read_text().splitlines()[0])
    assert main(["grammar", "export", str(folder), "-o", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "design.txt").read_text() == (folder / "design.txt").read_text()
    assert main(["grammar", "show", str(tmp_path / "s")]) == 2  # no design.txt: refused


def test_sample_piped_into_a_reader_that_stops_early_still_writes_every_design(tmp_path):
    import subprocess
    import sys

    run = subprocess.run(
        f'"{sys.executable}" -m robotwright grammar sample -n 3 --seed 1 --no-picture '
        f'-o "{tmp_path / "out"}" | head -1',
        shell=True,
        capture_output=True,
        text=True,
    )
    assert len(run.stdout.splitlines()) == 1
    designs = [p for p in (tmp_path / "out").iterdir() if (p / "design.txt").is_file()]
    assert len(designs) == 3
    assert run.stdout.split(":")[0] == str(tmp_path / "out" / sorted(p.name for p in designs)[0])
