"""Progress with time left on steps a user waits on (robotwright._progress).

The clock is replaced by one that advances a second per reading, so the steps "take"
seconds whatever the machine's load: the tests assert what is printed, never a time.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from robotwright import _progress
from robotwright.cli import main

#: ``  3/12 links read (6 s, about 18 s left)``
LINE = re.compile(r"^  (\d+)/(\d+) (.+) \((\d+) s(?:, about .+ left)?\)$")


@pytest.fixture
def slow_clock(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every reading of the progress clock is one second later than the one before."""
    ticks = iter(range(10**6))
    monkeypatch.setattr(_progress, "_clock", lambda: float(next(ticks)))


def _chain_urdf(links: int, mesh: str | None = None) -> str:
    """A chain of ``links`` links joined by revolute joints (``mesh``: each link's
    visual mesh file, ``{i}`` standing for the link's number)."""

    def visual(i: int) -> str:
        if mesh is None:
            return ""
        return f'<visual><geometry><mesh filename="{mesh.format(i=i)}"/></geometry></visual>'

    body = "".join(
        f'<link name="l{i}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
        f'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>{visual(i)}</link>'
        for i in range(links)
    )
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i in range(1, links)
    )
    return f'<robot name="chain">{body}{joints}</robot>'


def _progress_lines(err: str, what: str) -> list[re.Match]:
    return [m for m in map(LINE.match, err.splitlines()) if m and m[3] == what]


def test_a_long_urdf_parse_shows_progress_with_time_left(
    tmp_path: Path, slow_clock: None, capsys
) -> None:
    urdf = tmp_path / "chain.urdf"
    urdf.write_text(_chain_urdf(12))
    assert main(["convert", str(urdf), "-o", str(tmp_path / "chain.xml")]) == 0
    lines = _progress_lines(capsys.readouterr().err, "links read")
    assert lines, "no progress line for the links"
    assert all(int(m[2]) == 12 and 0 < int(m[1]) < 12 for m in lines)
    assert any("left" in m[0] for m in lines)
    # At most one line per STEP_REPORT_S seconds: fewer lines than links.
    assert len(lines) < 12


def test_mesh_copies_show_progress(tmp_path: Path, slow_clock: None, capsys) -> None:
    (tmp_path / "src").mkdir()
    for i in range(6):
        (tmp_path / "src" / f"m{i}.stl").write_bytes(_binary_stl_tetrahedron())
    urdf = tmp_path / "src" / "chain.urdf"
    urdf.write_text(_chain_urdf(6, mesh="m{i}.stl"))
    out = tmp_path / "out" / "chain.xml"
    assert main(["export", str(urdf), "-o", str(out), "--copy-meshes"]) == 0
    assert len(list((tmp_path / "out").rglob("*.stl"))) == 6
    lines = _progress_lines(capsys.readouterr().err, "meshes copied")
    assert lines and all(int(m[2]) == 6 for m in lines)


def test_animation_frames_show_progress(tmp_path: Path, slow_clock: None, capsys) -> None:
    pytest.importorskip("imageio")
    out = tmp_path / "arm.gif"
    argv = ["render", "arm6", "-o", str(out), "--sweep", "0.5", "--fps", "12", "--size", "64x48"]
    assert main(argv) == 0
    assert out.is_file()
    lines = _progress_lines(capsys.readouterr().err, "frames drawn")
    assert lines and all(int(m[2]) == 6 for m in lines)


def test_the_library_prints_no_progress(tmp_path: Path, slow_clock: None, capsys) -> None:
    """A program calling the library gets no lines on its stderr: progress is the
    command line's."""
    from robotwright.proof.convert import convert

    urdf = tmp_path / "chain.urdf"
    urdf.write_text(_chain_urdf(12))
    convert(urdf, tmp_path / "chain.xml")
    assert not _progress_lines(capsys.readouterr().err, "links read")


def test_duration_units() -> None:
    assert _progress.duration(90) == "90 s"
    assert _progress.duration(3 * 3600) == "3 h"
    assert _progress.duration(5 * 60) == "5 min"


def _binary_stl_tetrahedron() -> bytes:
    import struct

    v = [(0, 0, 0), (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    data = bytearray(b"\0" * 80 + struct.pack("<I", len(faces)))
    for f in faces:
        data += struct.pack("<3f", 0, 0, 0)
        for i in f:
            data += struct.pack("<3f", *v[i])
        data += b"\0\0"
    return bytes(data)


def test_meshes_saved_into_an_hrdf_folder_show_progress(
    tmp_path: Path, slow_clock: None, capsys
) -> None:
    (tmp_path / "src").mkdir()
    for i in range(6):
        (tmp_path / "src" / f"m{i}.stl").write_bytes(_binary_stl_tetrahedron())
    urdf = tmp_path / "src" / "chain.urdf"
    urdf.write_text(_chain_urdf(6, mesh="m{i}.stl"))
    out = tmp_path / "chain_hrdf"
    assert main(["convert", str(urdf), "-o", str(out)]) == 0
    assert len(list(out.rglob("*.stl"))) == 6
    lines = _progress_lines(capsys.readouterr().err, "meshes copied")
    assert lines and all(int(m[2]) == 6 for m in lines)


def test_a_long_single_step_says_it_is_still_at_work(monkeypatch) -> None:
    """working(): one line every STEP_REPORT_S while the block runs; the block here waits
    until the first line is written, so no clock decides the outcome."""
    import io
    import sys
    import threading

    written = threading.Event()

    class Stderr(io.StringIO):
        def write(self, text: str) -> int:
            n = super().write(text)
            written.set()
            return n

    err = Stderr()
    monkeypatch.setattr(sys, "stderr", err)
    monkeypatch.setattr(_progress, "STEP_REPORT_S", 0.01)
    with _progress.shown(), _progress.working("drawing go2.png"):
        assert written.wait(60)
    lines = err.getvalue().splitlines()
    assert lines and all(re.fullmatch(r"  drawing go2\.png \(\d+ s\)", line) for line in lines)
    # The reporting thread ends with the block.
    assert not [t for t in threading.enumerate() if t.name == "robotwright-progress"]


def test_a_single_step_is_silent_in_the_library(monkeypatch, capsys) -> None:
    monkeypatch.setattr(_progress, "STEP_REPORT_S", 0.0)
    with _progress.working("drawing"):
        pass
    assert capsys.readouterr().err == ""
