"""One output gate (issue 19, item 3): writers never follow a symbolic link they did not
create, ``--overwrite`` replaces only an output of the same kind that robotwright wrote,
``demo -o`` refuses any folder but its own output (and ``.``, ``..``, the home folder),
``grammar sample`` writes all designs or none, and mesh copies are size-capped.

Every refusal is exit 2 with one ``error:`` line and leaves every file, inside the
output and outside it, byte-identical (links included: compared without following).
"""

from __future__ import annotations

import errno
import json
import os
import random
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
import trimesh

from robotwright._atomic import copy_mesh_file, mesh_size_limit
from robotwright._outputs import MARKER
from robotwright.cli import main
from robotwright.errors import InputFileError
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR

pytestmark = pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")

MESH_HEADER = (
    "contact_type,contact_affinity,static_friction,dynamic_friction,restitution,"
    "pos0,pos1,pos2,quat0,quat1,quat2,quat3,rgba0,rgba1,rgba2,rgba3,body_name,name"
)
MESH_ROW = "1,1,1.0,1.0,,0,0,0,1,0,0,0,0.5,0.5,0.5,1,base_link,a"


def snapshot(root: Path) -> dict[str, object]:
    """Everything under ``root`` (hidden entries too), links read, never followed."""
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


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def _run(argv: list[str], capsys) -> tuple[int, str]:
    code = main(argv)
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return code, err


def _refused(argv: list[str], capsys, *roots: Path) -> str:
    """Run ``argv``, expecting exit 2, one error line, and ``roots`` unchanged."""
    before = [snapshot(r) for r in roots]
    code, err = _run(argv, capsys)
    assert code == 2, (argv, err)
    assert err.startswith("error: "), err
    assert [snapshot(r) for r in roots] == before, argv
    return err


@pytest.fixture
def arm(tmp_path: Path) -> Path:
    """The bundled arm with one STL mesh (so every writer copies a mesh file)."""
    dest = tmp_path / "src" / "arm"
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", dest)
    (dest / "mesh.csv").write_text(f"{MESH_HEADER}\n{MESH_ROW}\n", encoding="utf-8")
    (dest / "meshes").mkdir()
    box = trimesh.creation.box(extents=(0.05, 0.05, 0.05))
    box.export(str(dest / "meshes" / "a.stl"), file_type="stl")
    return dest


@pytest.fixture
def outside(tmp_path: Path) -> Path:
    """A folder of the user's outside every output: it must never change."""
    folder = tmp_path / "outside"
    (folder / "deep").mkdir(parents=True)
    (folder / "victim.xml").write_text("<mine/>", encoding="utf-8")
    (folder / "deep" / "a.stl").write_bytes(b"precious")
    return folder


# ------------------------------------------------------------ symbolic links planted

#: Writers whose output file gets a folder of copies next to it: argv (``{src}``,
#: ``{out}``), the output file's name, and the folders they copy into.
FILE_WRITERS: dict[str, tuple[list[str], str, list[str]]] = {
    "export": (
        ["export", "{src}", "-o", "{out}/arm.xml", "--copy-meshes"],
        "arm.xml",
        ["meshes", "meshes/arm"],
    ),
    "compose": (
        ["compose", "{src}", "-o", "{out}/scene.xml", "--copy-meshes"],
        "scene.xml",
        ["meshes", "meshes/arm"],
    ),
    "convert": (["convert", "{src}", "-o", "{out}/arm.xml"], "arm.xml", ["meshes", "meshes/arm"]),
    "things": (["things", "{src}", "{out}/arm.xml"], "arm.xml", ["assets"]),
}


def _argv(template: list[str], src: Path, out: Path) -> list[str]:
    return [a.replace("{src}", str(src)).replace("{out}", str(out)) for a in template]


def _link_targets(outside: Path, link: Path) -> dict[str, str]:
    """Where a planted link may point: a folder outside (absolute or relative), a path
    that does not exist, or itself (a loop)."""
    return {
        "absolute": str(outside),
        "relative": os.path.relpath(outside, link.parent),
        "dangling": str(outside / "missing"),
        "loop": link.name,
    }


@pytest.mark.parametrize("kind", ["absolute", "relative", "dangling", "loop"])
@pytest.mark.parametrize("writer", sorted(FILE_WRITERS))
def test_a_link_planted_as_a_copy_folder_is_never_written_through(
    writer: str, kind: str, arm: Path, outside: Path, tmp_path: Path, capsys
) -> None:
    template, _name, folders = FILE_WRITERS[writer]
    for depth, folder in enumerate(folders):
        out = tmp_path / f"out{depth}"
        link = out / folder
        link.parent.mkdir(parents=True)
        link.symlink_to(_link_targets(outside, link)[kind])
        err = _refused(_argv(template, arm, out), capsys, outside, out)
        assert f"{link}: is a symbolic link; not writing the output through it" in err


@pytest.mark.parametrize("overwrite", [False, True])
@pytest.mark.parametrize("kind", ["absolute", "relative", "dangling"])
@pytest.mark.parametrize("writer", sorted(FILE_WRITERS))
def test_a_link_at_the_output_file_is_replaced_never_followed(
    writer: str, kind: str, overwrite: bool, arm: Path, outside: Path, tmp_path: Path, capsys
) -> None:
    template, name, _ = FILE_WRITERS[writer]
    out = tmp_path / "out"
    out.mkdir()
    target = {"absolute": outside / "victim.xml", "dangling": outside / "gone.xml"}.get(kind)
    (out / name).symlink_to(target or os.path.relpath(outside / "victim.xml", out))
    argv = _argv(template, arm, out) + (["--overwrite"] if overwrite else [])
    before = snapshot(outside)
    if not overwrite:
        assert "give --overwrite" in _refused(argv, capsys, outside, out)
        return
    code, err = _run(argv, capsys)
    assert code == 0, err
    assert snapshot(outside) == before
    assert not (out / name).is_symlink() and (out / name).read_text().startswith("<")


@pytest.mark.parametrize("writer", sorted(FILE_WRITERS))
def test_links_named_like_temporaries_are_never_followed(
    writer: str, arm: Path, outside: Path, tmp_path: Path, capsys
) -> None:
    """Links named like the temporaries of a killed run (which the cleanup may remove:
    the link, not what it points at) or of a running writer (left alone)."""
    template, name, folders = FILE_WRITERS[writer]
    out = tmp_path / "out"
    out.mkdir()
    dead, alive = _dead_pid(), os.getpid()
    planted = {
        f".{name}.{dead}.abcdefgh.tmp": outside / "victim.xml",
        f".rw-stage.{dead}.abcdefgh": outside,
        f".meshes.{dead}.abcdefgh": outside,
        f".{name}.{alive}.zzzzzzzz.tmp": outside / "victim.xml",
        f".rw-stage.{alive}.zzzzzzzz": outside / "deep",
    }
    for link, target in planted.items():
        (out / link).symlink_to(target)
    before = snapshot(outside)
    code, err = _run(_argv(template, arm, out), capsys)
    assert code == 0, err
    assert snapshot(outside) == before
    for link, target in planted.items():  # removed, or the same link
        assert not os.path.lexists(out / link) or os.readlink(out / link) == str(target)
    assert (out / f".{name}.{alive}.zzzzzzzz.tmp").is_symlink()
    assert (out / f".rw-stage.{alive}.zzzzzzzz").is_symlink()
    assert (out / folders[-1]).is_dir() and not (out / folders[-1]).is_symlink()


@pytest.mark.parametrize("seed", range(6))
def test_random_link_positions_in_a_copy_tree(
    seed: int, arm: Path, outside: Path, tmp_path: Path, capsys
) -> None:
    """A link at a random depth of the copy folders (folder or file position) of a
    random writer: refused when it is a folder on the way; when it is the copied file
    itself, refused without --overwrite (as any other file there) and replaced with it;
    what it points at never changes."""
    rng = random.Random(seed)
    writer = rng.choice(sorted(FILE_WRITERS))
    template, _name, folders = FILE_WRITERS[writer]
    out = tmp_path / "out"
    path = folders[-1] + "/a.stl"
    parts = path.split("/")
    cut = rng.randrange(1, len(parts) + 1)
    link = out.joinpath(*parts[:cut])
    link.parent.mkdir(parents=True)
    link.symlink_to(outside / "deep" if cut < len(parts) else outside / "deep" / "a.stl")
    before = snapshot(outside)
    code, err = _run(_argv(template, arm, out), capsys)
    assert snapshot(outside) == before
    if cut < len(parts):
        assert code == 2 and "is a symbolic link" in err, err
    else:
        assert code == 2 and "--overwrite" in err and link.is_symlink(), err
        code, err = _run([*_argv(template, arm, out), "--overwrite"], capsys)
        assert snapshot(outside) == before
        assert code == 0, err
        assert not link.is_symlink() and link.read_bytes() == (arm / "meshes/a.stl").read_bytes()


def _scene(tmp_path: Path, capsys) -> Path:
    scene = tmp_path / "scene" / "scene.xml"
    assert main(["compose", "mini_humanoid", "-o", str(scene)]) == 0
    capsys.readouterr()
    return scene


@pytest.mark.parametrize("writer", ["lidar", "render"])
def test_single_file_writers_replace_a_planted_link_only_with_overwrite(
    writer: str, outside: Path, tmp_path: Path, capsys
) -> None:
    scene = _scene(tmp_path, capsys)
    out = tmp_path / "out"
    out.mkdir()
    name = "scan.npz" if writer == "lidar" else "picture.png"
    (out / name).symlink_to(outside / "victim.xml")
    argv = (
        ["lidar", str(scene), "--sensor", "mini_humanoid_head_lidar", "--pattern", "grid"]
        if writer == "lidar"
        else ["render", str(scene), "--size", "32x24"]
    ) + ["-o", str(out / name)]
    _refused(argv, capsys, outside, out)
    before = snapshot(outside)
    code, err = _run([*argv, "--overwrite"], capsys)
    assert code == 0, err
    assert snapshot(outside) == before and not (out / name).is_symlink()


# ------------------------------------------------------------ folder outputs

#: Commands writing a folder: argv with ``{out}`` (and ``{src}``, ``{design}``).
FOLDER_WRITERS: dict[str, list[str]] = {
    "convert": ["convert", "{src}", "-o", "{out}"],
    "things": ["things", "{src}", "{out}"],
    "grammar export": ["grammar", "export", "{design}", "-o", "{out}"],
    "grammar sample": [
        "grammar",
        "sample",
        "-n",
        "2",
        "--max-links",
        "2",
        "--no-picture",
        "-o",
        "{out}",
    ],
    "demo": ["demo", "-o", "{out}"],
}


@pytest.fixture
def quick_demo(monkeypatch) -> list[Path]:
    """``robotwright demo`` with one quick step (the gate runs before the steps); the
    list collects the folders the step ran in."""
    from robotwright.cli import demo

    ran: list[Path] = []

    def step(out: Path, ctx: dict) -> str:
        ran.append(out)
        (out / "robots").mkdir()
        (out / "robots" / "a.xml").write_text("<mujoco/>", encoding="utf-8")
        return "wrote robots/a.xml"

    monkeypatch.setattr(demo, "STEPS", [("quick", step)])
    return ran


@pytest.fixture
def design(tmp_path: Path) -> Path:
    path = tmp_path / "src" / "design.txt"
    path.parent.mkdir(parents=True, exist_ok=True)
    assert (
        main(
            [
                "grammar",
                "sample",
                "--seed",
                "1",
                "-n",
                "1",
                "--max-links",
                "2",
                "--no-picture",
                "-o",
                str(tmp_path / "s0"),
            ]
        )
        == 0
    )
    shutil.copy(next((tmp_path / "s0").glob("*/design.txt")), path)
    return path


def _folder_argv(writer: str, arm: Path, design: Path, out: Path, overwrite: bool) -> list[str]:
    argv = [
        a.replace("{src}", str(arm)).replace("{design}", str(design)).replace("{out}", str(out))
        for a in FOLDER_WRITERS[writer]
    ]
    return argv + (["--overwrite"] if overwrite and writer != "demo" else [])


def _plant_ours_then(
    extra: Callable[[Path], None],
) -> Callable[[Path, Callable[[Path], None]], None]:
    def plant(folder: Path, write_ours: Callable[[Path], None]) -> None:
        write_ours(folder)
        extra(folder)

    return plant


def _first_subfolder(folder: Path) -> Path:
    subs = sorted(p for p in folder.iterdir() if p.is_dir() and not p.is_symlink())
    return subs[0] if subs else folder


def _forged_marker(content: str | None, kind: str = "file") -> Callable[[Path], None]:
    def plant(folder: Path) -> None:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "notes.txt").write_text("mine", encoding="utf-8")
        marker = folder / MARKER
        if marker.exists():
            marker.unlink()
        if kind == "dir":
            marker.mkdir()
        elif kind == "link":
            marker.symlink_to(folder.parent / "outside" / "victim.xml")
        else:
            marker.write_text(content or "", encoding="utf-8")

    return plant


def _user(files: dict[str, str]) -> Callable[[Path], None]:
    def plant(folder: Path) -> None:
        for rel, text in files.items():
            (folder / rel).parent.mkdir(parents=True, exist_ok=True)
            (folder / rel).write_text(text, encoding="utf-8")

    return plant


#: A folder's content that no writer may replace. Each takes the folder and a function
#: writing this writer's own earlier output into a folder.
UNRELATED: dict[str, Callable[[Path, Callable[[Path], None]], None]] = {
    "one file": lambda f, _: _user({"notes.txt": "mine"})(f),
    "hidden file only": lambda f, _: _user({".DS_Store": "x"})(f),
    "hidden folder only": lambda f, _: _user({".git/config": "[core]"})(f),
    "nested": lambda f, _: _user({"a/b/c/d.txt": "deep"})(f),
    "empty subfolder": lambda f, _: (f / "photos").mkdir(parents=True),
    "a link only": lambda f, _: (f.mkdir(parents=True), (f / "l").symlink_to(f.parent))[0],
    "our output + a file added": _plant_ours_then(_user({"notes.txt": "mine"})),
    "our output + a hidden file added": _plant_ours_then(_user({".notes": "mine"})),
    "our output + a file in a subfolder": _plant_ours_then(
        lambda f: (_first_subfolder(f) / "mine.bin").write_bytes(b"\0mine")
    ),
    "our output + a link added": _plant_ours_then(
        lambda f: (f / "l").symlink_to(f.parent / "outside")
    ),
    "marker: not JSON": lambda f, _: _forged_marker("{not json")(f),
    "marker: kind unhashable": lambda f, _: _forged_marker('{"kind": [], "files": ["notes.txt"]}')(
        f
    ),
    "marker: files not a list": lambda f, _: _forged_marker('{"kind": "hrdf", "files": 3}')(f),
    "marker: a folder": lambda f, _: _forged_marker(None, "dir")(f),
    "marker: a link": lambda f, _: _forged_marker(None, "link")(f),
    "marker: other kind": lambda f, _: _forged_marker(
        json.dumps({"kind": "weather", "files": ["notes.txt"]})
    )(f),
}


def _random_tree(seed: int) -> Callable[[Path, Callable[[Path], None]], None]:
    rng = random.Random(seed)
    alphabet = "abcxyz_-.é 0123"
    files = {}
    for k in range(rng.randint(1, 6)):
        depth = rng.randint(1, 4)
        # Each entry its own prefix: no path is another's folder.
        parts = [
            f"u{k}_{i}" + "".join(rng.choice(alphabet) for _ in range(rng.randint(1, 8)))
            for i in range(depth)
        ]
        if rng.random() < 0.3:
            parts[-1] = "." + parts[-1]
        files["/".join(parts)] = "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 40)))
    return lambda f, _: _user(files)(f)


for _seed in range(8):
    UNRELATED[f"random tree {_seed}"] = _random_tree(_seed)


@pytest.mark.parametrize("content", sorted(UNRELATED))
@pytest.mark.parametrize("writer", sorted(FOLDER_WRITERS))
def test_overwrite_never_replaces_a_folder_robotwright_did_not_write(
    writer: str,
    content: str,
    arm: Path,
    design: Path,
    outside: Path,
    tmp_path: Path,
    quick_demo: list[Path],
    capsys,
) -> None:
    def write_ours(folder: Path) -> None:
        code, err = _run(_folder_argv(writer, arm, design, folder, False), capsys)
        assert code == 0, err

    out = tmp_path / "out"
    UNRELATED[content](out, write_ours)
    ran = len(quick_demo)
    for overwrite in (False, True):
        _refused(_folder_argv(writer, arm, design, out, overwrite), capsys, out, outside)
    assert len(quick_demo) == ran  # refused before any work
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["out", "outside", "src", "s0"])


@pytest.mark.parametrize("writer", sorted(FOLDER_WRITERS))
def test_overwrite_replaces_the_writers_own_earlier_output(
    writer: str, arm: Path, design: Path, tmp_path: Path, quick_demo: list[Path], capsys
) -> None:
    """The control: the same command's own output (marked) is replaced with --overwrite
    (demo: always), refused without it, and an empty folder is written into."""
    out = tmp_path / "out"
    out.mkdir()
    code, err = _run(_folder_argv(writer, arm, design, out, False), capsys)
    assert code == 0, err
    marker = json.loads((out / MARKER).read_text(encoding="utf-8"))
    assert marker["written_by"] == "robotwright" and marker["files"]
    if writer != "demo":
        assert "give --overwrite" in _refused(
            _folder_argv(writer, arm, design, out, False), capsys, out
        )
    # A file of its own the user removed: still its own output.
    (out / next(f for f in marker["files"] if not f.endswith("/"))).unlink()
    code, err = _run(_folder_argv(writer, arm, design, out, True), capsys)
    assert code == 0, err
    assert (out / MARKER).is_file()


@pytest.mark.parametrize(
    "mine,theirs",
    [
        ("convert", "grammar export"),
        ("grammar export", "convert"),
        ("grammar sample", "demo"),
        ("demo", "grammar sample"),
        ("convert", "grammar sample"),
    ],
)
def test_an_output_of_another_kind_is_not_replaced(
    mine: str, theirs: str, arm: Path, design: Path, tmp_path: Path, quick_demo: list[Path], capsys
) -> None:
    out = tmp_path / "out"
    code, err = _run(_folder_argv(theirs, arm, design, out, False), capsys)
    assert code == 0, err
    err = _refused(_folder_argv(mine, arm, design, out, True), capsys, out)
    assert "robotwright wrote it as" in err


def test_things_and_convert_share_the_hrdf_kind(arm: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "robot"
    assert _run(["convert", str(arm), "-o", str(out)], capsys)[0] == 0
    assert _run(["things", str(arm), str(out), "--overwrite"], capsys)[0] == 0


def test_a_link_at_a_folder_output_is_never_replaced(
    arm: Path, design: Path, outside: Path, tmp_path: Path, quick_demo: list[Path], capsys
) -> None:
    """Even a link to a folder robotwright wrote: the link is the user's."""
    ours = outside / "robot"
    assert _run(["convert", str(arm), "-o", str(ours)], capsys)[0] == 0
    for writer in FOLDER_WRITERS:
        link = tmp_path / "link"
        link.symlink_to(ours)
        for overwrite in (False, True):
            err = _refused(_folder_argv(writer, arm, design, link, overwrite), capsys, outside)
            assert "is a symbolic link" in err or "is a file" in err, err
        assert link.is_symlink()
        link.unlink()


@pytest.mark.parametrize("writer", sorted(FILE_WRITERS) + ["lidar", "render"])
@pytest.mark.parametrize("filled", [False, True])
def test_overwrite_of_a_file_output_never_replaces_a_folder(
    writer: str, filled: bool, arm: Path, tmp_path: Path, capsys
) -> None:
    out = tmp_path / "out"
    if writer in FILE_WRITERS:
        template, name, _ = FILE_WRITERS[writer]
        argv = _argv(template, arm, out)
    else:
        name = "scan.npz" if writer == "lidar" else "p.png"
        scene = tmp_path / "scene.xml"
        scene.write_text("<mujoco/>", encoding="utf-8")
        argv = (
            ["lidar", str(scene), "--sensor", "s", "-o", str(out / name)]
            if writer == "lidar"
            else ["render", str(arm), "-o", str(out / name)]
        )
    (out / name).mkdir(parents=True)
    if filled:
        (out / name / "notes.txt").write_text("mine", encoding="utf-8")
    for flags in ([], ["--overwrite"]):
        _refused([*argv, *flags], capsys, out)


# ------------------------------------------------------------ demo -o


@pytest.fixture
def home_and_work(tmp_path: Path, monkeypatch) -> tuple[Path, Path]:
    """A home folder and a working folder two levels inside it (a project's subfolder)."""
    home = tmp_path / "home"
    work = home / "project" / "sub"
    work.mkdir(parents=True)
    (home / "project" / "pyproject.toml").write_text("[project]\n", encoding="utf-8")
    (work / "notes.txt").write_text("mine", encoding="utf-8")
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir(work)
    return home, work


DEMO_REFUSED = {
    ".": lambda home, work: ".",
    "./": lambda home, work: "./",
    "..": lambda home, work: "..",
    "../..": lambda home, work: "../..",
    "../sub": lambda home, work: "../sub",
    "cwd absolute": lambda home, work: str(work),
    "home": lambda home, work: str(home),
    "home/": lambda home, work: str(home) + "/",
    "parent of home": lambda home, work: str(home.parent),
    "project": lambda home, work: str(home / "project"),
    "root": lambda home, work: "/",
}


@pytest.mark.parametrize("case", sorted(DEMO_REFUSED))
def test_demo_refuses_folders_holding_the_working_or_home_folder(
    case: str, home_and_work: tuple[Path, Path], quick_demo: list[Path], tmp_path: Path, capsys
) -> None:
    home, work = home_and_work
    root_listing = sorted(os.listdir("/"))
    err = _refused(["demo", "-o", DEMO_REFUSED[case](home, work)], capsys, tmp_path)
    assert "not replacing it" in err, err
    assert quick_demo == []  # no step ran
    assert sorted(os.listdir("/")) == root_listing


def test_demo_refuses_a_cwd_reached_through_a_link(
    home_and_work: tuple[Path, Path], quick_demo: list[Path], tmp_path: Path, capsys
) -> None:
    home, work = home_and_work
    (tmp_path / "alias").symlink_to(work)
    for target in (tmp_path / "alias", tmp_path / "alias" / ".."):
        _refused(["demo", "-o", str(target)], capsys, tmp_path)
    assert quick_demo == []


def test_demo_refreshes_its_own_output_and_nothing_else(
    home_and_work: tuple[Path, Path], quick_demo: list[Path], tmp_path: Path, capsys
) -> None:
    home, work = home_and_work
    code, err = _run(["demo", "-o", "robotwright_demo"], capsys)
    assert code == 0, err
    first = snapshot(work / "robotwright_demo")
    assert {"summary.json", "robots/a.xml", MARKER} <= set(first)
    # Its own output, unchanged or with a file of its own removed: refreshed.
    (work / "robotwright_demo" / "robots" / "a.xml").unlink()
    code, err = _run(["demo", "-o", "robotwright_demo"], capsys)
    assert code == 0, err
    assert set(snapshot(work / "robotwright_demo")) == set(first)
    # With a file of the user's in it: refused, nothing changed, no temporary left.
    (work / "robotwright_demo" / "robots" / "mine.txt").write_text("mine", encoding="utf-8")
    err = _refused(["demo", "-o", "robotwright_demo"], capsys, tmp_path)
    assert "robots/mine.txt" in err
    assert sorted(os.listdir(work)) == ["notes.txt", "robotwright_demo"]
    # An empty folder and a new one are written.
    (work / "empty").mkdir()
    assert _run(["demo", "-o", "empty"], capsys)[0] == 0
    assert _run(["demo", "-o", "new/deeper"], capsys)[0] == 0
    assert (work / "new" / "deeper" / "summary.json").is_file()


def test_an_old_unmarked_demo_output_is_still_refreshed(
    home_and_work: tuple[Path, Path], quick_demo: list[Path], capsys
) -> None:
    """A demo folder written before output folders were marked is recognised by what it
    holds (summary.json and the demo's own names only)."""
    home, work = home_and_work
    old = work / "robotwright_demo"
    (old / "robots").mkdir(parents=True)
    (old / "summary.json").write_text("{}", encoding="utf-8")
    (old / "arm6_info.txt").write_text("x", encoding="utf-8")
    assert _run(["demo", "-o", str(old)], capsys)[0] == 0
    assert (old / MARKER).is_file()


# ------------------------------------------------------------ grammar sample


@pytest.mark.parametrize("fail_at", [1, 2, 3])
@pytest.mark.parametrize("failure", ["ctrl-c", "disk full"])
@pytest.mark.parametrize("earlier", [False, True])
def test_grammar_sample_writes_all_designs_or_none(
    fail_at: int, failure: str, earlier: bool, tmp_path: Path, monkeypatch, capsys
) -> None:
    import robotwright.grammar.export as gexport

    out = tmp_path / "designs"
    argv = ["grammar", "sample", "-n", "4", "--max-links", "2", "--no-picture", "-o", str(out)]
    if earlier:
        assert _run(argv, capsys)[0] == 0
    before = snapshot(tmp_path)
    real, calls = gexport.export_design, []

    def export(*args, **kw):
        calls.append(1)
        if len(calls) > fail_at:
            if failure == "ctrl-c":
                raise KeyboardInterrupt
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(*args, **kw)

    monkeypatch.setattr(gexport, "export_design", export)
    code, err = _run([*argv, "--overwrite"], capsys)
    assert code == (130 if failure == "ctrl-c" else 2), err
    assert snapshot(tmp_path) == before  # the old designs, or no folder, and no temporary


# ------------------------------------------------------------ HRDF readers and the marker


def test_the_marker_is_not_an_unknown_file_to_the_hrdf_reader(
    arm: Path, tmp_path: Path, capsys
) -> None:
    from robotwright.hrdf import HRDF

    out = tmp_path / "robot"
    assert _run(["convert", str(arm), "-o", str(out)], capsys)[0] == 0
    assert (out / MARKER).is_file()
    code, err = _run(["validate", str(out)], capsys)
    assert code == 0 and MARKER not in err, err
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        HRDF.from_dir(out)
    assert not [w for w in caught if MARKER in str(w.message)]


# ------------------------------------------------------------ mesh size cap


def _sparse_mesh(arm: Path, size: int) -> Path:
    mesh = arm / "meshes" / "a.stl"
    os.truncate(mesh, size)  # a sparse file: no disk used
    return mesh


@pytest.mark.parametrize("writer", ["compose", "export-urdf"])
def test_a_600_mb_sparse_mesh_is_refused_by_default(
    writer: str, arm: Path, tmp_path: Path, capsys
) -> None:
    mesh = _sparse_mesh(arm, 600 * 10**6)
    out = tmp_path / "out"
    argv = (
        ["compose", str(arm), "-o", str(out / "s.xml"), "--copy-meshes"]
        if writer == "compose"
        else ["export", str(arm), "-o", str(out / "a.urdf"), "--copy-meshes", "--no-mujoco-tag"]
    )
    code, err = _run(argv, capsys)
    assert code == 2, err
    if "limit for a mesh" in err:
        assert f"{mesh}: is larger than the 512 MB limit" in err and "--max-mesh-mb" in err
    assert not out.exists()


CAP_WRITERS = {
    "export": ["export", "{src}", "-o", "{out}/arm.xml", "--copy-meshes"],
    "compose": ["compose", "{src}", "-o", "{out}/s.xml", "--copy-meshes"],
    "convert mjcf": ["convert", "{src}", "-o", "{out}/arm.xml"],
    "convert hrdf": ["convert", "{src}", "-o", "{out}/robot"],
    "things mjcf": ["things", "{src}", "{out}/arm.xml"],
    "things hrdf": ["things", "{src}", "{out}/robot"],
}


@pytest.mark.parametrize("writer", sorted(CAP_WRITERS))
def test_the_mesh_cap_names_the_file_and_the_override_lets_it_through(
    writer: str, arm: Path, tmp_path: Path, capsys
) -> None:
    mesh = arm / "meshes" / "a.stl"
    size = mesh.stat().st_size
    below, exact = f"{(size - 1) / 1e6:.6f}", f"{size / 1e6:.6f}"
    argv = _argv(CAP_WRITERS[writer], arm, tmp_path / "refused")
    err = _refused([*argv, "--max-mesh-mb", below], capsys, arm)
    assert f"{mesh}: is larger than the {float(below):g} MB limit" in err
    assert not (tmp_path / "refused").exists()
    ok = tmp_path / "ok"
    code, err = _run([*_argv(CAP_WRITERS[writer], arm, ok), "--max-mesh-mb", exact], capsys)
    assert code == 0, err
    copies = [p for p in ok.rglob("*.stl")]
    assert copies and all(p.read_bytes() == mesh.read_bytes() for p in copies)


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf", "abc", "", "1e400"])
def test_a_bad_mesh_cap_is_a_usage_error(value: str, arm: Path, tmp_path: Path, capsys) -> None:
    with pytest.raises(SystemExit) as info:
        main(["export", str(arm), "-o", str(tmp_path / "a.xml"), "--max-mesh-mb", value])
    assert info.value.code == 2
    assert "--max-mesh-mb: expected a positive number of MB" in capsys.readouterr().err


@pytest.mark.parametrize("seed", range(12))
def test_copy_mesh_file_refuses_exactly_what_is_over_the_cap(seed: int, tmp_path: Path) -> None:
    rng = random.Random(seed)
    cap = rng.randint(1, 64_000)
    size = max(0, cap + rng.choice([-2, -1, 0, 1, 2, rng.randint(-cap, 10**9)]))
    src = tmp_path / "m.stl"
    src.write_bytes(b"")
    if size <= cap:
        src.write_bytes(bytes(rng.getrandbits(8) for _ in range(size)))
    else:
        os.truncate(src, size)  # sparse
    dst = tmp_path / "copy.stl"
    with mesh_size_limit(cap / 10**6):
        if size > cap:
            with pytest.raises(InputFileError, match="limit for a mesh"):
                copy_mesh_file(src, dst)
            assert not dst.exists() or dst.stat().st_size == 0
        else:
            copy_mesh_file(src, dst)
            assert dst.read_bytes() == src.read_bytes()


def test_a_mesh_growing_past_the_cap_while_copied_is_refused(tmp_path: Path, monkeypatch) -> None:
    """The size is checked before copying and the bytes counted while copying: a file
    that reports a small size but reads on is stopped at the cap."""
    import robotwright._inputs as inputs

    src = tmp_path / "m.stl"
    src.write_bytes(b"x" * 5000)
    real = inputs._open_regular

    def small(path):
        fd, st = real(path)
        return fd, os.stat_result((st.st_mode, *st[1:6], 10, *st[7:]))

    monkeypatch.setattr(inputs, "_open_regular", small)
    with mesh_size_limit(0.001), pytest.raises(InputFileError, match="0.001 MB limit"):
        copy_mesh_file(src, tmp_path / "copy.stl")
