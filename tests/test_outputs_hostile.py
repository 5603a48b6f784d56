"""Outputs all or nothing (issue 11): a failure, a full disk or ``kill -9`` half-way
leaves the old output as it was and no partial file, temporary or new empty folder; the
next run cleans what a killed run left; outputs get the user's normal permissions."""

from __future__ import annotations

import errno
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import mujoco
import pytest
import trimesh

import robotwright._inputs as inputs
from robotwright._atomic import atomic_dir, atomic_files, copy_file_atomic, write_text_atomic
from robotwright.errors import OutputPathError
from robotwright.generators import MJCFHumanoidGenerator
from robotwright.hrdf import HRDF
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR
from robotwright.things import Body, Hinge, World
from robotwright.things.world import ThingBuildError

MESH_HEADER = (
    "contact_type,contact_affinity,static_friction,dynamic_friction,restitution,"
    "pos0,pos1,pos2,quat0,quat1,quat2,quat3,rgba0,rgba1,rgba2,rgba3,body_name,name"
)
MESH_ROW = "1,1,1.0,1.0,,0,0,0,1,0,0,0,0.5,0.5,0.5,1,{body},{name}"


def _tree(root: Path) -> dict[str, bytes]:
    """Every file under ``root`` (hidden ones too) with its content."""
    return {
        str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()
    }


@pytest.fixture
def arm(tmp_path: Path) -> Path:
    """The bundled arm with two mesh rows (two files in meshes/)."""
    dest = tmp_path / "arm"
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", dest)
    rows = [MESH_ROW.format(body="base_link", name="a"), MESH_ROW.format(body="tool", name="b")]
    rows[1] = rows[1].replace("tool", "wrist_3_link")
    (dest / "mesh.csv").write_text("\n".join([MESH_HEADER, *rows]) + "\n")
    (dest / "meshes").mkdir()
    for name, size in (("a", 0.05), ("b", 0.03)):
        box = trimesh.creation.box(extents=(size, size, size))
        box.export(str(dest / "meshes" / f"{name}.stl"), file_type="stl")
    return dest


def _enospc_after(monkeypatch, calls: int) -> None:
    """Make the ``calls``-th file copy and later ones fail with a full disk."""
    real = inputs.shutil.copyfileobj
    seen = {"n": 0}

    def copy(fin, fout, length=0):
        seen["n"] += 1
        if seen["n"] >= calls:
            fout.write(b"partial")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(fin, fout, length)

    monkeypatch.setattr(inputs.shutil, "copyfileobj", copy)


# ---------------------------------------------------------------- permissions


@pytest.mark.parametrize("mask", [0o022, 0o077])
def test_outputs_follow_the_umask(tmp_path: Path, mask: int) -> None:
    src = tmp_path / "src.bin"
    src.write_bytes(b"mesh")
    old = os.umask(mask)
    try:
        write_text_atomic(tmp_path / "out" / "a.xml", "x")
        copy_file_atomic(src, tmp_path / "out" / "m.bin")
        with atomic_dir(tmp_path / "folder") as tmp:
            (tmp / "f.txt").write_text("y")
        with atomic_files(tmp_path / "many") as staged:
            staged.copy(src, "meshes/m.bin")
            staged.write_text("t.xml", "z")
    finally:
        os.umask(old)
    for f in ("out/a.xml", "out/m.bin", "folder/f.txt", "many/meshes/m.bin", "many/t.xml"):
        assert (tmp_path / f).stat().st_mode & 0o777 == 0o666 & ~mask, f
    for d in ("out", "folder", "many", "many/meshes"):
        assert (tmp_path / d).stat().st_mode & 0o777 == 0o777 & ~mask, d


# ---------------------------------------------------------------- disk full


def test_disk_full_names_the_output_and_leaves_no_folder(tmp_path: Path, monkeypatch) -> None:
    src = tmp_path / "src.bin"
    src.write_bytes(b"mesh" * 100)
    _enospc_after(monkeypatch, 1)
    dst = tmp_path / "new" / "deep" / "m.bin"
    with pytest.raises(OutputPathError) as info:
        copy_file_atomic(src, dst)
    assert str(dst) in str(info.value) and "No space left" in str(info.value)
    assert sorted(os.listdir(tmp_path)) == ["src.bin"]  # no empty new/deep folders


def test_export_copy_meshes_disk_full_keeps_the_old_output(
    arm: Path, tmp_path: Path, monkeypatch
) -> None:
    out = tmp_path / "out" / "arm.xml"
    gen = MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(arm))
    gen.export(out, copy_meshes=True)
    before = _tree(out.parent)
    assert sorted(before) == ["arm.xml", "meshes/arm/a.stl", "meshes/arm/b.stl"]
    _enospc_after(monkeypatch, 2)  # the second mesh fails
    with pytest.raises(OutputPathError) as info:
        gen.export(out, copy_meshes=True)
    assert str(out.parent / "meshes" / "arm" / "b.stl") in str(info.value)
    assert _tree(out.parent) == before
    # a fresh output folder is not left behind empty
    with pytest.raises(OutputPathError):
        gen.export(tmp_path / "fresh" / "arm.xml", copy_meshes=True)
    assert not (tmp_path / "fresh").exists()


def test_export_refuses_a_folder_as_output_before_copying(arm: Path, tmp_path: Path) -> None:
    (tmp_path / "out" / "arm.xml").mkdir(parents=True)
    gen = MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(arm))
    with pytest.raises(OutputPathError, match="is a folder"):
        gen.export(tmp_path / "out" / "arm.xml", copy_meshes=True)
    assert _tree(tmp_path / "out") == {}


def test_things_export_disk_full_and_refused_model_leave_nothing(
    arm: Path, tmp_path: Path, monkeypatch
) -> None:
    xml = tmp_path / "src" / "arm.xml"
    MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(arm)).export(xml, copy_meshes=True)
    world = World.from_xml_path(xml)
    out = tmp_path / "things" / "t.xml"
    world.export(out)
    before = _tree(out.parent)
    assert sorted(before) == ["assets/a.stl", "assets/b.stl", "t.xml"]
    with monkeypatch.context() as m:
        _enospc_after(m, 2)
        with pytest.raises(OutputPathError, match="assets/b.stl"):
            world.export(out)
    assert _tree(out.parent) == before
    # A model MuJoCo refuses is refused before anything is written (a massless moving body).
    moving = Body(name="massless")
    moving.attach(Hinge())
    world.attach(moving)
    with pytest.raises(ThingBuildError, match="mass and inertia"):
        world.export(tmp_path / "bad_out" / "t.xml")
    assert not (tmp_path / "bad_out").exists()
    with pytest.raises(ThingBuildError):
        world.export(out)
    assert _tree(out.parent) == before


# ---------------------------------------------------------------- kill -9

_SLOW_COPY = textwrap.dedent(
    """
    import shutil, sys, time
    import robotwright._inputs as inputs
    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.hrdf import HRDF

    real = shutil.copyfileobj
    def slow(fin, fout, length=0):
        real(fin, fout, length)
        fout.flush()
        print("copied", flush=True)
        time.sleep(60)
    inputs.shutil.copyfileobj = slow
    gen = MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(sys.argv[1]))
    gen.export(sys.argv[2], copy_meshes=True)
    """
)


def test_kill_during_mesh_copy_keeps_old_output_and_next_run_cleans(
    arm: Path, tmp_path: Path
) -> None:
    out = tmp_path / "out" / "arm.xml"
    gen = MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(arm))
    gen.export(out, copy_meshes=True)
    before = _tree(out.parent)
    proc = subprocess.Popen(
        [sys.executable, "-c", _SLOW_COPY, str(arm), str(out)],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline().strip() == "copied"  # one mesh copied, then asleep
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    after = _tree(out.parent)
    # The old output is whole; only a hidden staging folder of the killed run is new.
    assert {k: v for k, v in after.items() if not k.startswith(".")} == before
    assert any(k.startswith(f".rw-stage.{proc.pid}.") for k in after)
    gen.export(out, copy_meshes=True)  # the next run removes it
    assert _tree(out.parent) == before
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nmesh == 2


def test_a_running_writers_temporaries_are_left_alone(tmp_path: Path) -> None:
    live = tmp_path / f".a.xml.{os.getppid()}.abcdefgh.tmp"
    dead_pid = _dead_pid()
    dead = tmp_path / f".a.xml.{dead_pid}.abcdefgh.tmp"
    other = tmp_path / f".b.xml.{dead_pid}.abcdefgh.tmp"
    for p in (live, dead, other):
        p.write_text("x")
    write_text_atomic(tmp_path / "a.xml", "new")
    assert live.exists() and other.exists() and not dead.exists()


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        try:
            os.kill(proc.pid, 0)
        except ProcessLookupError:
            return proc.pid
        time.sleep(0.01)
    pytest.skip("no dead process id to test with")


# ---------------------------------------------------------------- demo


def test_a_failed_demo_keeps_the_previous_demo_folder(tmp_path: Path, monkeypatch) -> None:
    from robotwright.cli import demo

    def writes(out: Path, ctx: dict) -> str:
        (out / "robots").mkdir()
        (out / "robots" / "a.xml").write_text("<mujoco/>")
        return "wrote robots/a.xml"

    def fails(out: Path, ctx: dict) -> str:
        raise RuntimeError("step failed")

    out = tmp_path / "demo"
    monkeypatch.setattr(demo, "STEPS", [("writes", writes)])
    assert demo.run_demo(out) == {"writes": "wrote robots/a.xml"}
    before = _tree(out)
    # .robotwright: the marker that lets a later demo run replace this folder.
    assert sorted(before) == [
        ".robotwright",
        "conversion_notes.txt",
        "robots/a.xml",
        "summary.json",
    ]
    monkeypatch.setattr(demo, "STEPS", [("writes", writes), ("fails", fails)])
    with pytest.raises(RuntimeError, match="step failed"):
        demo.run_demo(out)
    assert _tree(out) == before
    assert sorted(os.listdir(tmp_path)) == ["demo"]  # no partial folder beside it
    with pytest.raises(RuntimeError):
        demo.run_demo(tmp_path / "fresh")
    assert not (tmp_path / "fresh").exists()


def test_disk_full_in_any_writer_names_its_output(tmp_path: Path) -> None:
    """The writers behind lidar scans and pictures (atomic_open) and grammar designs
    (atomic_dir): a full disk names the output being written."""
    from robotwright._atomic import atomic_open

    def full(*_args) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    target = tmp_path / "scan.npz"
    with pytest.raises(OutputPathError, match=str(target)), atomic_open(target, "wb") as fh:
        fh.write(b"x")
        full()
    folder = tmp_path / "design"
    with pytest.raises(OutputPathError, match=str(folder)), atomic_dir(folder) as tmp:
        (tmp / "design.json").write_text("{}")
        full()
    assert os.listdir(tmp_path) == []


def test_an_old_folder_moved_aside_by_a_killed_run_is_put_back(tmp_path: Path) -> None:
    # A run killed between "move the old output aside" and "rename the new one in".
    aside = tmp_path / f".robot.{_dead_pid()}.abcdefgh"
    (aside / "x").mkdir(parents=True)
    (aside / "x" / "meta.yaml").write_text("old")
    with pytest.raises(RuntimeError), atomic_dir(tmp_path / "robot"):
        raise RuntimeError("this run fails too")
    assert _tree(tmp_path) == {"robot/meta.yaml": b"old"}


def test_cli_export_on_a_full_disk_is_exit_2_naming_the_output(
    arm: Path, tmp_path: Path, monkeypatch, capsys
) -> None:
    from robotwright.cli import main

    out = tmp_path / "out" / "arm.xml"
    _enospc_after(monkeypatch, 1)
    assert main(["export", str(arm), "-o", str(out), "--copy-meshes"]) == 2
    err = capsys.readouterr().err
    assert str(out.parent / "meshes" / "arm") in err and "No space left" in err
    assert "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_disk_full_inside_a_new_folder_names_the_final_path(tmp_path: Path, monkeypatch) -> None:
    src = tmp_path / "src.bin"
    src.write_bytes(b"mesh")
    _enospc_after(monkeypatch, 1)
    target = tmp_path / "robot"
    with pytest.raises(OutputPathError) as info, atomic_dir(target) as tmp:
        copy_file_atomic(src, tmp / "meshes" / "m.bin")
    assert str(target / "meshes" / "m.bin") in str(info.value)
    assert sorted(os.listdir(tmp_path)) == ["src.bin"]
