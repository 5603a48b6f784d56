"""Containment by construction (issue 26): untrusted robot files are read by a process
the kernel confines, so that a case the path checks miss is still harmless.

Each escape here is tried twice: with the checks in place (they refuse it with a good
message) and with the checks turned off (monkeypatched to accept everything), where the
confinement alone must stop it: nothing outside the robot's folder reaches the result.
The controls run the same inputs with confinement off, to show that the checks-off
state would otherwise leak (so the confined assertion could fail).
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh

import robotwright._paths as paths
import robotwright.parsers.mjcf.reader as mjcf_parser
import robotwright.scene.load as view_scene
from robotwright._confine import ConfinementError, confinement, run_confined
from robotwright.cli import main
from robotwright.errors import ConversionWarning, RobotwrightError, UnsafePathError
from robotwright.parsers import mjcf_to_hrdf, urdf_to_hrdf

CONFINED = confinement().startswith("landlock")
needs_landlock = pytest.mark.skipif(not CONFINED, reason=f"no confinement here: {confinement()}")

SECRET_SIZE = 0.731  # a box whose size is recognisable in the output


def _box(path: Path, size: float) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=(size, size, size)).export(str(path), file_type="stl")
    return path


def _mjcf(folder: Path, asset: str, body: str = "", name: str = "robot.xml") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(
        f"""<mujoco>{asset}
  <worldbody><body name="b"><freejoint/><geom type="box" size=".1 .1 .1"/>{body}</body>
  </worldbody></mujoco>"""
    )
    return path


@pytest.fixture
def layout(tmp_path: Path) -> dict[str, Path]:
    """tmp_path/robot/ (the untrusted robot) and tmp_path/private/ (what it must not
    reach), with a secret mesh and a secret glTF buffer in the private folder."""
    robot = tmp_path / "robot"
    private = tmp_path / "private"
    _box(robot / "own.stl", 0.1)
    _box(private / "secret.stl", SECRET_SIZE)
    return {"robot": robot, "private": private, "tmp": tmp_path}


def _escapes(layout: dict[str, Path]) -> list[tuple[str, Path]]:
    """MJCF files whose mesh comes from the private folder, each by another way."""
    robot, private = layout["robot"], layout["private"]
    secret = private / "secret.stl"
    out = [
        (
            "relative ..",
            _mjcf(
                robot,
                '<asset><mesh name="m" file="../private/secret.stl"/></asset>',
                '<geom type="mesh" mesh="m"/>',
                "rel.xml",
            ),
        ),
        (
            "absolute file",
            _mjcf(
                robot,
                f'<asset><mesh name="m" file="{secret}"/></asset>',
                '<geom type="mesh" mesh="m"/>',
                "abs.xml",
            ),
        ),
        (
            "absolute meshdir",
            _mjcf(
                robot,
                f'<compiler meshdir="{private}"/><asset><mesh name="m" file="secret.stl"/></asset>',
                '<geom type="mesh" mesh="m"/>',
                "dir.xml",
            ),
        ),
    ]
    # A sub-model with its own meshdir, attached (the hole of the issue).
    sub = robot / "sub"
    sub.mkdir(parents=True, exist_ok=True)
    (sub / "sub.xml").write_text(
        f"""<mujoco><compiler meshdir="{private}"/>
  <asset><mesh name="m" file="secret.stl"/></asset>
  <worldbody><body name="s"><geom type="mesh" mesh="m"/></body></worldbody></mujoco>"""
    )
    out.append(
        (
            "sub-model meshdir",
            _mjcf(
                robot,
                '<asset><model name="sub" file="sub/sub.xml"/></asset>',
                '<attach model="sub" body="s" prefix="s_"/>',
                "attach.xml",
            ),
        )
    )
    # A link to the private folder inside the robot's folder.
    (robot / "link").symlink_to(private, target_is_directory=True)
    out.append(
        (
            "symbolic link",
            _mjcf(
                robot,
                '<asset><mesh name="m" file="link/secret.stl"/></asset>',
                '<geom type="mesh" mesh="m"/>',
                "link.xml",
            ),
        )
    )
    return out


@pytest.fixture
def checks_off(monkeypatch):
    """The path checks turned off: every path is accepted as it is."""

    def accept(file, *, base, root, trusted=None, what="", hint=""):
        return (Path(base) / file).resolve()

    from robotwright.parsers.mjcf import geoms as mjcf_geoms

    # The checks and the mesh stager resolve through the same function (the stager
    # imports it by name).
    monkeypatch.setattr(paths, "resolve_inside", accept)
    monkeypatch.setattr(mjcf_geoms, "resolve_inside", accept)
    for module in (mjcf_parser, paths, view_scene):
        if hasattr(module, "check_mjcf_includes"):
            monkeypatch.setattr(module, "check_mjcf_includes", lambda *a, **k: None)
        if hasattr(module, "check_mjcf_spec"):
            monkeypatch.setattr(module, "check_mjcf_spec", lambda *a, **k: None)
    yield


def _largest_extent(hrdf) -> float:
    """The largest mesh extent of a parsed robot (the secret box is 0.731 m)."""
    sizes = [0.0]
    for mesh in hrdf.meshes:
        loaded = trimesh.load(str(hrdf.mesh_path(mesh)), force="mesh")
        sizes.append(float(np.max(loaded.extents)))
    return max(sizes)


def test_the_checks_refuse_every_escape(layout) -> None:
    """The first line: each escape is refused with a message naming the file."""
    for label, path in _escapes(layout):
        with pytest.raises(RobotwrightError) as info:
            mjcf_to_hrdf(path)
        assert path.name in str(info.value), label


@needs_landlock
def test_confinement_alone_stops_every_escape(layout, checks_off) -> None:
    """With the checks off, MuJoCo is asked to open the secret itself: the confined
    reader cannot, so the parse fails or holds no secret."""
    for label, path in _escapes(layout):
        try:
            hrdf = mjcf_to_hrdf(path)
        except RobotwrightError:
            continue  # MuJoCo could not open the file: the wanted outcome
        assert _largest_extent(hrdf) < SECRET_SIZE / 2, label


@needs_landlock
def test_without_confinement_the_checks_off_state_leaks(layout, checks_off, monkeypatch) -> None:
    """Control: the same inputs, checks off and confinement off, do reach the secret
    (so the assertion above could fail)."""
    monkeypatch.setenv("ROBOTWRIGHT_CONFINE", "off")
    leaked = 0
    for _label, path in _escapes(layout):
        try:
            hrdf = mjcf_to_hrdf(path)
        except RobotwrightError:
            continue
        leaked += _largest_extent(hrdf) > SECRET_SIZE / 2
    assert leaked >= 3


@needs_landlock
def test_render_view_loader_confined_with_checks_off(layout, checks_off) -> None:
    """``render``/``view`` compile the MJCF as it stands: with the checks off the
    confined compile cannot open the secret."""
    for label, path in _escapes(layout):
        try:
            model = view_scene.compile_mjcf(path, ())
        except (RobotwrightError, ValueError):
            continue
        assert model.nmesh == 0 or float(np.max(np.abs(model.mesh_vert))) < SECRET_SIZE / 4, label


def test_sub_model_is_checked_with_its_own_compiler_folders(layout, capsys) -> None:
    """The attached sub-model's ``meshdir`` is its own: the pre-check names the
    sub-model and its mesh, for the parser, ``render`` and ``convert``."""
    path = dict(_escapes(layout))["sub-model meshdir"]
    with pytest.raises(RobotwrightError, match="sub.xml"):
        mjcf_to_hrdf(path)
    with pytest.raises(UnsafePathError, match="sub.xml"):
        view_scene.compile_mjcf(path, ())
    assert main(["convert", str(path), "-o", str(layout["tmp"] / "o.xml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "sub.xml" in err and "Traceback" not in err


def test_a_sub_model_inside_the_folder_still_attaches(tmp_path: Path) -> None:
    """Control: a sub-model whose meshes are its own passes the checks and compiles
    (as ``render`` and ``view`` load it)."""
    robot = tmp_path / "robot"
    _box(robot / "sub" / "assets" / "part.stl", 0.2)
    (robot / "sub" / "sub.xml").write_text(
        """<mujoco><compiler meshdir="assets"/>
  <asset><mesh name="m" file="part.stl"/></asset>
  <worldbody><body name="s"><geom type="mesh" mesh="m"/></body></worldbody></mujoco>"""
    )
    path = _mjcf(
        robot,
        '<asset><model name="sub" file="sub/sub.xml"/></asset>',
        '<attach model="sub" body="s" prefix="s_"/>',
    )
    model = view_scene.compile_mjcf(path, ())
    assert model.nmesh == 1
    assert float(np.ptp(model.mesh_vert[:, 0])) == pytest.approx(0.2)


# ----------------------------------------------------------------- the confined process
@needs_landlock
def test_a_confined_step_cannot_write_connect_or_read_outside(tmp_path: Path) -> None:
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "secret.txt").write_text("secret")

    def write() -> None:
        (outside / "planted.txt").write_text("x")

    def read() -> str:
        return (outside / "secret.txt").read_text()

    def connect() -> None:
        server = socket.socket()
        server.bind(("127.0.0.1", 0))

    for step in (write, read, connect):
        with pytest.raises(OSError):
            run_confined(step, roots=[], what="test")
    assert not (outside / "planted.txt").exists()
    # The roots it is given are readable.
    assert run_confined(read, roots=[outside], what="test") == "secret"


@needs_landlock
def test_errors_and_warnings_come_back_with_their_type(tmp_path: Path) -> None:
    def refuse() -> None:
        warnings.warn("a note", ConversionWarning, stacklevel=1)
        raise UnsafePathError("bad path", file="f.urdf", element="<mesh>")

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(UnsafePathError) as info:
            run_confined(refuse, roots=[], what="test")
    assert info.value.file == "f.urdf" and info.value.element == "<mesh>"
    assert [str(w.message) for w in caught if w.category is ConversionWarning] == ["a note"]


@needs_landlock
def test_a_crashed_reader_is_one_error() -> None:
    def crash() -> None:
        os.kill(os.getpid(), 9)

    with pytest.raises(ConfinementError, match="signal 9"):
        run_confined(crash, roots=[], what="robot.xml")


# -------------------------------------------------------------- mesh side files (glTF)
def _urdf_with_mesh(folder: Path, filename: str) -> Path:
    """A URDF whose one link shows the mesh ``filename`` (a glTF is converted by
    trimesh: MuJoCo does not decode glTF)."""
    path = folder / "robot.urdf"
    path.write_text(
        f"""<robot name="r"><link name="base">
  <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  <visual><geometry><mesh filename="{filename}"/></geometry></visual></link></robot>"""
    )
    return path


def _gltf_with_buffer(folder: Path, uri: str, data: bytes) -> Path:
    """A glTF box whose vertex buffer is the file ``uri`` (written by trimesh, then
    repointed)."""
    folder.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=(0.2, 0.2, 0.2)).export(str(folder / "part.gltf"))
    gltf = json.loads((folder / "part.gltf").read_text())
    for k, buffer in enumerate(gltf["buffers"]):
        if k == 0:
            buffer["uri"] = uri
    (folder / "part.gltf").write_text(json.dumps(gltf))
    return folder / "part.gltf"


@pytest.mark.parametrize("uri", ["../../private/secret.bin", "{private}/secret.bin", "link.bin"])
def test_gltf_buffer_outside_is_refused(layout, uri: str) -> None:
    robot, private = layout["robot"], layout["private"]
    meshes = robot / "meshes"
    meshes.mkdir(parents=True, exist_ok=True)
    gltf = _gltf_with_buffer(meshes, uri.format(private=private), b"")
    shutil.copy(meshes / "gltf_buffer_0.bin", private / "secret.bin")
    (meshes / "link.bin").unlink(missing_ok=True)
    (meshes / "link.bin").symlink_to(private / "secret.bin")
    path = _urdf_with_mesh(robot, f"meshes/{gltf.name}")
    with pytest.raises(RobotwrightError, match="secret.bin|link.bin"):
        urdf_to_hrdf(path)


def test_gltf_buffer_that_is_a_fifo_never_blocks(layout) -> None:
    meshes = layout["robot"] / "meshes"
    gltf = _gltf_with_buffer(meshes, "fifo.bin", b"")
    os.mkfifo(meshes / "fifo.bin")
    path = _urdf_with_mesh(layout["robot"], f"meshes/{gltf.name}")
    start = time.monotonic()
    with pytest.raises(RobotwrightError, match="fifo.bin"):
        urdf_to_hrdf(path)
    assert time.monotonic() - start < 60  # returns at all (a blocking read never would)


def test_gltf_with_its_own_buffers_converts(tmp_path: Path) -> None:
    robot = tmp_path / "robot"
    (robot / "meshes").mkdir(parents=True)
    trimesh.creation.box(extents=(0.2, 0.2, 0.2)).export(str(robot / "meshes" / "part.gltf"))
    hrdf = urdf_to_hrdf(_urdf_with_mesh(robot, "meshes/part.gltf"))
    assert _largest_extent(hrdf) == pytest.approx(0.2)


# -------------------------------------------------------------- includes, fan-out
def test_a_file_included_twice_is_refused_at_once(tmp_path: Path) -> None:
    """A fan-out of includes (each file including the next many times) is refused at
    the first repeated include, as MuJoCo refuses it, instead of being expanded."""
    robot = tmp_path / "robot"
    robot.mkdir()
    (robot / "f5.xml").write_text("<mujoco/>")
    for k in range(4, -1, -1):
        inner = "".join(f'<include file="f{k + 1}.xml"/>' for _ in range(40))
        (robot / f"f{k}.xml").write_text(f"<mujoco>{inner}</mujoco>")
    start = time.monotonic()
    with pytest.raises(RobotwrightError, match="included more than once"):
        mjcf_to_hrdf(robot / "f0.xml")
    assert time.monotonic() - start < 30


# -------------------------------------------------------------- no code from the cwd
PLANTED = ("xacro", "yaml", "mujoco", "trimesh", "numpy", "defusedxml")


def _planted_folder(tmp_path: Path) -> tuple[Path, Path]:
    folder = tmp_path / "robot_folder"
    folder.mkdir()
    marker = tmp_path / "ran.txt"
    for name in PLANTED:
        (folder / f"{name}.py").write_text(
            f"open({str(marker)!r}, 'a').write('{name}\\n')\nraise SystemExit(9)\n"
        )
    (folder / "robot.urdf.xacro").write_text(
        """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="m" value="2"/>
  <link name="base"><inertial><mass value="${m}"/>
  <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>"""
    )
    return folder, marker


@pytest.mark.parametrize("how", ["console script", "python -m"])
def test_a_planted_module_in_the_working_folder_never_runs(tmp_path: Path, how: str) -> None:
    pytest.importorskip("xacro", reason="the xacro extra is not installed")
    folder, marker = _planted_folder(tmp_path)
    script = Path(sys.executable).parent / "robotwright"
    if how == "console script" and not script.exists():
        pytest.skip("no robotwright console script next to this Python")
    command = [str(script)] if how == "console script" else [sys.executable, "-m", "robotwright"]
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "MUJOCO_GL")}
    done = subprocess.run(
        [*command, "info", "robot.urdf.xacro"],
        cwd=folder,
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert not marker.exists(), marker.read_text()
    assert done.returncode == 0, done.stderr
    assert "base" in done.stdout


def test_urdf_and_xacro_inside_their_folder_still_read(tmp_path: Path) -> None:
    """Control: a robot that reads only its own files converts confined."""
    robot = tmp_path / "robot"
    _box(robot / "meshes" / "part.stl", 0.3)
    hrdf = urdf_to_hrdf(_urdf_with_mesh(robot, "meshes/part.stl"))
    assert _largest_extent(hrdf) == pytest.approx(0.3)
