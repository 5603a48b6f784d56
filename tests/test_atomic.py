"""All-or-nothing writing: success replaces the target, failure leaves nothing behind."""

from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest

import robotwright._atomic as atomic_module
from robotwright._atomic import (
    atomic_dir,
    atomic_files,
    atomic_open,
    atomic_path,
    check_output_path,
    copy_file_atomic,
    write_text_atomic,
)
from robotwright.errors import OutputPathError, RobotwrightError


class Boom(Exception):
    pass


def test_write_text_atomic_creates_folder_and_replaces(tmp_path: Path) -> None:
    target = tmp_path / "sub" / "a.xml"
    write_text_atomic(target, "first é")
    write_text_atomic(target, "second")
    assert target.read_text(encoding="utf-8") == "second"
    assert sorted(p.name for p in target.parent.iterdir()) == ["a.xml"]


def test_atomic_open_failure_keeps_old_file_and_no_temp(tmp_path: Path) -> None:
    target = tmp_path / "a.txt"
    target.write_text("old", encoding="utf-8")
    with pytest.raises(Boom), atomic_open(target, "w") as fh:
        fh.write("half")
        raise Boom
    assert target.read_text(encoding="utf-8") == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def test_atomic_open_binary_and_bad_mode(tmp_path: Path) -> None:
    target = tmp_path / "b.bin"
    with atomic_open(target, "wb") as fh:
        fh.write(b"\x00\x01")
    assert target.read_bytes() == b"\x00\x01"
    with pytest.raises(ValueError, match="mode must be 'w' or 'wb'"), atomic_open(target, "a"):
        pass


def test_atomic_path_failure_leaves_no_file(tmp_path: Path) -> None:
    target = tmp_path / "m.stl"
    with pytest.raises(Boom), atomic_path(target) as tmp:
        tmp.write_bytes(b"partial")
        raise Boom
    assert list(tmp_path.iterdir()) == []


def test_copy_file_atomic(tmp_path: Path) -> None:
    src = tmp_path / "src.bin"
    src.write_bytes(b"mesh")
    dst = tmp_path / "out" / "dst.bin"
    copy_file_atomic(src, dst)
    assert dst.read_bytes() == b"mesh"
    with pytest.raises(FileNotFoundError):
        copy_file_atomic(tmp_path / "missing.bin", dst)
    assert dst.read_bytes() == b"mesh"
    assert [p.name for p in dst.parent.iterdir()] == ["dst.bin"]


def test_atomic_dir_replaces_existing_folder_only_on_success(tmp_path: Path) -> None:
    target = tmp_path / "parent" / "robot"
    with atomic_dir(target) as tmp:
        (tmp / "meta.yaml").write_text("v: 1\n", encoding="utf-8")
    assert (target / "meta.yaml").read_text(encoding="utf-8") == "v: 1\n"

    with pytest.raises(Boom), atomic_dir(target) as tmp:
        (tmp / "meta.yaml").write_text("v: 2\n", encoding="utf-8")
        raise Boom
    assert (target / "meta.yaml").read_text(encoding="utf-8") == "v: 1\n"
    assert [p.name for p in target.parent.iterdir()] == ["robot"]

    with atomic_dir(target) as tmp:
        (tmp / "other.csv").write_text("x\n", encoding="utf-8")
    assert sorted(p.name for p in target.iterdir()) == ["other.csv"]
    assert [p.name for p in target.parent.iterdir()] == ["robot"]


def test_output_that_is_a_folder_is_refused_before_writing(tmp_path):
    (tmp_path / "out.xml").mkdir()
    with pytest.raises(OutputPathError, match="out.xml: is a folder; expected the path of a file"):
        write_text_atomic(tmp_path / "out.xml", "x")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.xml"]


def test_output_under_a_file_is_refused_naming_the_file(tmp_path):
    (tmp_path / "a.txt").write_text("keep", encoding="utf-8")
    target = tmp_path / "a.txt" / "sub" / "out.xml"
    with pytest.raises(OutputPathError, match=r"a\.txt is a file, not a folder"):
        check_output_path(target)
    with pytest.raises(OutputPathError), atomic_dir(tmp_path / "a.txt" / "d"):
        pass
    assert (tmp_path / "a.txt").read_text(encoding="utf-8") == "keep"


def test_output_in_a_missing_folder_is_an_error_for_atomic_path(tmp_path):
    with (
        pytest.raises(OutputPathError, match="cannot write in folder"),
        atomic_path(tmp_path / "missing" / "x.bin"),
    ):
        pass
    assert isinstance(OutputPathError("x"), RobotwrightError)
    assert isinstance(OutputPathError("x"), OSError)


def _full_disk(*args: object) -> None:
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_a_full_disk_names_the_output_and_the_copied_source(tmp_path: Path, monkeypatch) -> None:
    src = tmp_path / "src.bin"
    src.write_bytes(b"mesh")
    monkeypatch.setattr(atomic_module, "copy_mesh_file", _full_disk)
    dst = tmp_path / "out" / "dst.bin"
    full = f"{dst}: cannot write it: No space left on device (copying {src})"
    with pytest.raises(OutputPathError) as info:
        copy_file_atomic(src, dst)
    assert str(info.value) == full and info.value.__cause__.errno == errno.ENOSPC
    assert sorted(p.name for p in tmp_path.iterdir()) == ["src.bin"]  # no folder "out" left
    with pytest.raises(OutputPathError) as info, atomic_files(tmp_path / "out") as staged:
        staged.copy(src, "dst.bin")
    assert str(info.value) == full
    assert sorted(p.name for p in tmp_path.iterdir()) == ["src.bin"]


def test_other_errors_of_a_write_pass_unchanged(tmp_path: Path, monkeypatch) -> None:
    """Only errors of the output side (no space, quota, read-only) become OutputPathError."""

    def denied(*args: object) -> None:
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES))

    monkeypatch.setattr(os, "replace", denied)
    with pytest.raises(PermissionError) as info:
        write_text_atomic(tmp_path / "sub" / "a.txt", "x")
    assert not isinstance(info.value, OutputPathError)
    assert list(tmp_path.iterdir()) == []


def test_the_output_path_is_checked_once_per_write(tmp_path: Path, monkeypatch) -> None:
    checked: list[Path] = []
    real = atomic_module.check_output_path

    def check(path, **kwargs) -> None:
        checked.append(Path(path))
        real(path, **kwargs)

    monkeypatch.setattr(atomic_module, "check_output_path", check)
    src = tmp_path / "src.bin"
    src.write_bytes(b"mesh")
    write_text_atomic(tmp_path / "a" / "t.txt", "x")
    copy_file_atomic(src, tmp_path / "b" / "c.bin")
    with atomic_path(tmp_path / "p.bin") as tmp:
        tmp.write_bytes(b"1")
    assert checked == [tmp_path / "a" / "t.txt", tmp_path / "b" / "c.bin", tmp_path / "p.bin"]
