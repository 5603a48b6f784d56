"""tools/gpu_pack.py: wheels unpacked as pip places them, less what the GPU suite never
loads; robotwright's entry points declared; the archive cut into pieces no larger than a
device call carries and put back together byte for byte (a damaged or missing piece is
refused)."""

from __future__ import annotations

import importlib.metadata
import importlib.util
import os
import zipfile
from pathlib import Path

import pytest

_SPEC = importlib.util.spec_from_file_location(
    "gpu_pack", Path(__file__).resolve().parents[1] / "tools" / "gpu_pack.py"
)
gpu_pack = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(gpu_pack)


def _wheel(folder: Path, name: str, members: dict[str, bytes]) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(folder / name, "w") as archive:
        for member, data in members.items():
            archive.writestr(member, data)
    return folder / name


def _files(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in root.rglob("*") if p.is_file()}


def test_a_wheel_unpacks_as_pip_places_it_less_what_the_suite_never_loads(tmp_path) -> None:
    site = tmp_path / "site"
    demo = _wheel(
        tmp_path,
        "Demo_Pkg-1.0-py3-none-any.whl",
        {
            "demo_pkg/__init__.py": b"x = 1\n",
            "demo_pkg/__pycache__/__init__.cpython-312.pyc": b"\0",
            "Demo_Pkg-1.0.data/purelib/demo_extra.py": b"y = 2\n",
            "Demo_Pkg-1.0.data/scripts/demo-tool": b"#!/bin/sh\n",
            "Demo_Pkg-1.0.dist-info/METADATA": b"Name: Demo_Pkg\n",
        },
    )
    warp = _wheel(
        tmp_path,
        "warp_lang-1.19.0-py3-none-manylinux_2_28_x86_64.whl",
        {"warp/bin/warp.so": b"cuda", "warp/bin/warp-clang.so": b"llvm", "warp/examples/a.py": b""},
    )
    assert gpu_pack.distribution(demo.name) == "demo-pkg"
    assert gpu_pack.unpack_wheel(demo, site) == 3
    assert gpu_pack.unpack_wheel(warp, site) == 1
    assert _files(site) == {
        "demo_pkg/__init__.py": b"x = 1\n",
        "demo_extra.py": b"y = 2\n",
        "Demo_Pkg-1.0.dist-info/METADATA": b"Name: Demo_Pkg\n",
        "warp/bin/warp.so": b"cuda",
    }


def test_only_the_go2_is_taken_from_example_robot_data(tmp_path) -> None:
    robots = "cmeel.prefix/share/example-robot-data/robots"
    wheel = _wheel(
        tmp_path,
        "example_robot_data-6.0.0-0-py3-none-any.whl",
        {
            f"{robots}/go2_description/urdf/go2.urdf": b"<robot/>",
            f"{robots}/talos_data/robots/talos.urdf": b"<robot/>",
            "example_robot_data-6.0.0.dist-info/METADATA": b"",
        },
    )
    gpu_pack.unpack_wheel(wheel, tmp_path / "site")
    assert set(_files(tmp_path / "site")) == {
        f"{robots}/go2_description/urdf/go2.urdf",
        "example_robot_data-6.0.0.dist-info/METADATA",
    }


@pytest.mark.parametrize("member", ["../evil.py", "pkg/../../evil.py", "/etc/evil.py"])
def test_a_member_leaving_the_folder_is_refused(tmp_path, member) -> None:
    wheel = _wheel(tmp_path / "in", "pkg-1.0-py3-none-any.whl", {member: b"boom"})
    with pytest.raises(SystemExit, match="leaves the folder"):
        gpu_pack.unpack_wheel(wheel, tmp_path / "site" / "deep")
    assert not list(tmp_path.rglob("evil.py"))


def test_the_entry_points_are_the_installed_robotwrights(tmp_path) -> None:
    gpu_pack.write_entry_points(tmp_path)
    (carried,) = importlib.metadata.distributions(path=[str(tmp_path)])
    installed = importlib.metadata.distribution("robotwright")
    assert carried.metadata["Name"] == "robotwright"
    assert carried.version == installed.version
    as_set = lambda eps: {(e.group, e.name, e.value) for e in eps}  # noqa: E731
    assert as_set(carried.entry_points) == as_set(installed.entry_points)
    assert ("mjlab.tasks", "robotwright", "robotwright.sensors.mjlab.tasks") in as_set(
        carried.entry_points
    )


def _site(root: Path) -> dict[str, bytes]:
    made = {f"pkg{k}/data.bin": os.urandom(40_000 + k) for k in range(4)}
    made["pkg0/mod.py"] = b"print('hi')\n"
    for rel, data in made.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_bytes(data)
    return made


def _gather(calls: list[Path], folder: Path) -> Path:
    """Every call's files in one folder, as the GPU machine's /tmp/gpu holds them."""
    folder.mkdir()
    for call in calls:
        for f in call.iterdir():
            (folder / f.name).write_bytes(f.read_bytes())
    return folder


@pytest.mark.parametrize("xz_program", [True, False], ids=["xz", "python-lzma"])
def test_the_pieces_fit_a_call_each_and_unpack_to_the_same_files(
    tmp_path, monkeypatch, xz_program
) -> None:
    if xz_program and gpu_pack.shutil.which("xz") is None:
        pytest.skip("no xz program here")
    if not xz_program:
        monkeypatch.setattr(gpu_pack.shutil, "which", lambda name: None)
    made = _site(tmp_path / "site")
    calls = gpu_pack.archive_and_cut(tmp_path / "site", tmp_path / "out", capacity=50_000)
    assert len(calls) >= 3
    for call in calls:
        pieces = list(call.glob("site.tar.xz.part*"))
        assert len(pieces) == 1 and pieces[0].stat().st_size <= 50_000
    gpu_pack.unpack(_gather(calls, tmp_path / "gathered"), tmp_path / "there")
    assert _files(tmp_path / "there") == made


@pytest.mark.parametrize("fault", ["damaged", "missing"])
def test_a_damaged_or_missing_piece_is_refused(tmp_path, fault) -> None:
    _site(tmp_path / "site")
    calls = gpu_pack.archive_and_cut(tmp_path / "site", tmp_path / "out", capacity=50_000)
    gathered = _gather(calls, tmp_path / "gathered")
    piece = gathered / "site.tar.xz.part02"
    if fault == "missing":
        piece.unlink()
    else:
        piece.write_bytes(bytes([piece.read_bytes()[0] ^ 1]) + piece.read_bytes()[1:])
    with pytest.raises(SystemExit, match="missing or damaged"):
        gpu_pack.unpack(gathered, tmp_path / "there")
    assert not (tmp_path / "there").exists()


def test_packing_again_leaves_no_call_of_the_earlier_packing(tmp_path) -> None:
    _site(tmp_path / "site")
    many = gpu_pack.archive_and_cut(tmp_path / "site", tmp_path / "out", capacity=30_000)
    few = gpu_pack.archive_and_cut(tmp_path / "site", tmp_path / "out", capacity=10**6)
    assert len(many) > len(few) == 1
    assert sorted((tmp_path / "out").iterdir()) == few


def test_a_tree_that_fills_the_call_alone_is_an_error(tmp_path) -> None:
    _site(tmp_path / "site")
    with pytest.raises(SystemExit, match="fills a device call"):
        gpu_pack.archive_and_cut(tmp_path / "site", tmp_path / "out", capacity=-5)


def test_the_suite_runs_with_robotwright_from_src_and_the_carried_packages(tmp_path) -> None:
    env = gpu_pack.suite_env(tmp_path, base={"PATH": "/usr/bin"})
    assert env["PYTHONPATH"].split(os.pathsep) == [str(gpu_pack.ROOT / "src"), str(tmp_path)]
    assert env["MUJOCO_GL"] == "disable" and env["PATH"] == "/usr/bin"
    assert env["AMENT_PREFIX_PATH"] == str(tmp_path / "cmeel.prefix")
