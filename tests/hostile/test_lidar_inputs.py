"""``robotwright lidar`` reads its inputs as every other command does (issue 19).

- The scene goes through the MJCF gate: every file it names (mesh, texture, height
  field, include) must be a regular file inside the scene's folder or a folder trusted
  with ``--asset-root``.
- ``--mapping`` is read with the untrusted-input reader (regular file, size cap, UTF-8,
  bounded nesting) and checked as the Python API checks a mapping.

Each refusal is exit 2 with one ``error:`` line and no output file. Tests that could
block on a FIFO or read ``/dev/zero`` run the command in a subprocess whose timeout is
only a guard against a regression (the assertion is the exit code).
"""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
from pathlib import Path

import pytest
import trimesh

from robotwright.cli import main
from robotwright.errors import SensorError
from robotwright.sensors.config import read_class_mapping

SCENE = """<mujoco model="s">
  <compiler angle="radian"{compiler}/>
  <asset>{assets}</asset>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    {geoms}
    <body name="lidar" pos="0 0 1"><geom type="sphere" size="0.05"/></body>
  </worldbody>
</mujoco>
"""


def _stl(path: Path, size: float = 0.5) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=(size, size, size)).export(str(path), file_type="stl")
    return path


def _scene(folder: Path, *, file: str | None = None, compiler: str = "", extra: str = "") -> Path:
    """A scene whose mesh geom reads ``file`` (none: no mesh)."""
    assets, geoms = extra, ""
    if file is not None:
        assets += f'<mesh name="m" file="{file}"/>'
        geoms = '<geom type="mesh" mesh="m" pos="2 0 1"/>'
    path = folder / "scene.xml"
    folder.mkdir(parents=True, exist_ok=True)
    path.write_text(SCENE.format(compiler=compiler, assets=assets, geoms=geoms))
    return path


def _lidar(scene: Path, out: Path, *extra: str) -> list[str]:
    return ["lidar", str(scene), "--sensor", "lidar", "--pattern", "grid", "-o", str(out), *extra]


def _refused(argv: list[str], out: Path, capsys) -> str:
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and "Traceback" not in err
    assert not out.exists()
    return err


def _subprocess(argv: list[str]) -> subprocess.CompletedProcess:
    # The timeout only guards against a regression that blocks; it is not asserted.
    return subprocess.run(
        [sys.executable, "-m", "robotwright", *argv], capture_output=True, text=True, timeout=300
    )


@pytest.fixture
def shared(tmp_path: Path) -> Path:
    _stl(tmp_path / "scene" / "box.stl")
    _stl(tmp_path / "private" / "secret.stl", size=0.3)
    return tmp_path


def test_control_scene_scans(shared: Path) -> None:
    scene = _scene(shared / "scene", file="box.stl")
    out = shared / "ok.npz"
    assert main(_lidar(scene, out)) == 0
    assert out.is_file()


def _scene_escapes(shared: Path) -> list[tuple[str, dict]]:
    secret = shared / "private" / "secret.stl"
    rng = random.Random(19)
    files = ["../private/secret.stl", str(secret), "./../private/secret.stl"]
    files += ["sub/../../private/secret.stl", "/" + "/".join([".."] * 12) + str(secret)]
    for _ in range(4):
        detour = "/".join(rng.choice(["a", "b"]) for _ in range(rng.randint(1, 3)))
        ups = "/".join([".."] * (detour.count("/") + 2))
        files.append(f"{detour}/{ups}/private/secret.stl")
    cases = [(f"file={f}", {"file": f}) for f in files]
    cases += [
        ("symlink file", {"file": "link.stl"}),
        ("symlink folder", {"file": "out/secret.stl"}),
    ]
    cases += [("meshdir", {"file": "secret.stl", "compiler": ' meshdir="../private"'})]
    cases += [("assetdir", {"file": "secret.stl", "compiler": f' assetdir="{secret.parent}"'})]
    texture = f'<texture name="t" type="2d" file="{shared / "private" / "tex.png"}"/>'
    cases += [("texture", {"extra": texture})]
    hfield = '<hfield name="h" file="../private/h.png" size="1 1 1 0.1"/>'
    cases += [("hfield", {"extra": hfield})]
    cases += [("include", {"extra": '</asset><include file="../private/inc.xml"/><asset>'})]
    return cases


def test_scene_files_outside_its_folder_are_refused(shared: Path, capsys) -> None:
    folder = shared / "scene"
    (folder / "link.stl").symlink_to(shared / "private" / "secret.stl")
    (folder / "out").symlink_to(shared / "private", target_is_directory=True)
    (shared / "private" / "inc.xml").write_text("<mujoco/>")
    cases = _scene_escapes(shared)
    assert len(cases) >= 15
    for k, (label, kw) in enumerate(cases):
        scene = _scene(folder, **kw)
        out = shared / f"s{k}.npz"
        try:
            err = _refused(_lidar(scene, out), out, capsys)
        except BaseException as exc:
            raise AssertionError(f"scene escape not refused: {label}") from exc
        assert "outside" in err, label


def test_asset_root_trusts_a_folder(shared: Path) -> None:
    scene = _scene(shared / "scene", file=str(shared / "private" / "secret.stl"))
    out = shared / "trusted.npz"
    assert main(_lidar(scene, out)) == 2
    assert main(_lidar(scene, out, "--asset-root", str(shared / "private"))) == 0


def test_fifo_mesh_is_refused_without_blocking(shared: Path) -> None:
    os.mkfifo(shared / "scene" / "pipe.stl")
    scene = _scene(shared / "scene", file="pipe.stl")
    out = shared / "fifo.npz"
    done = _subprocess(_lidar(scene, out))
    assert done.returncode == 2, done.stderr
    assert "FIFO" in done.stderr and "Traceback" not in done.stderr
    assert not out.exists()


def test_device_mesh_is_refused_even_when_trusted(shared: Path) -> None:
    scene = _scene(shared / "scene", file="/dev/zero")
    out = shared / "dev.npz"
    done = _subprocess(_lidar(scene, out, "--asset-root", "/dev"))
    assert done.returncode == 2, done.stderr
    assert "device" in done.stderr and not out.exists()


def test_fifo_scene_is_refused_without_blocking(shared: Path) -> None:
    scene = shared / "scene" / "pipe.xml"
    os.mkfifo(scene)
    done = _subprocess(_lidar(scene, shared / "x.npz"))
    assert done.returncode == 2 and "FIFO" in done.stderr


@pytest.mark.parametrize("kind", ["fifo", "/dev/zero", "/dev/urandom", "folder"])
def test_mapping_that_is_not_a_regular_file_is_refused(shared: Path, kind: str) -> None:
    scene = _scene(shared / "scene", file="box.stl")
    if kind == "fifo":
        mapping = shared / "map.json"
        os.mkfifo(mapping)
    elif kind == "folder":
        mapping = shared / "private"
    else:
        mapping = Path(kind)
    out = shared / "m.npz"
    done = _subprocess(_lidar(scene, out, "--mapping", str(mapping)))
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("error: --mapping") and "Traceback" not in done.stderr
    assert not out.exists()


def _bad_mappings() -> list[tuple[str, bytes]]:
    """(label, file content) of mappings the Python API refuses, and unreadable ones."""
    values = {
        "string keywords": {"terrain": "floor"},
        "number keywords": {"terrain": 3},
        "null keywords": {"terrain": None},
        "object keywords": {"terrain": {"floor": 1}},
        "empty keywords": {"terrain": []},
        "non-string keyword": {"terrain": ["floor", 3]},
        "empty keyword": {"terrain": [""]},
        "nested keyword": {"terrain": [["floor"]]},
        "empty class name": {"": ["floor"]},
        "class unknown": {"unknown": ["floor"]},
        "class Unknown": {"terrain": ["floor"], "Unknown": ["box"]},
        "class UNKNOWN": {"UNKNOWN": ["floor"]},
        "top-level list": [["terrain", ["floor"]]],
        "top-level string": "terrain",
        "top-level number": 1,
        "top-level null": None,
    }
    cases = [(k, json.dumps(v).encode()) for k, v in values.items()]
    rng = random.Random(19)
    for depth in (200, 5_000, 100_000):
        opener = rng.choice(["[", '{"a":'])
        closer = "]" if opener == "[" else "}"
        cases.append((f"nested {depth}", (opener * depth + closer * depth).encode()))
    cases.append(("latin-1", '{"terrain": ["sol", "b\xe9ton"]}'.encode("latin-1")))
    cases.append(("binary", bytes(rng.randrange(256) for _ in range(64)) + b"\xff"))
    cases.append(("not JSON", b"{terrain: [floor]}"))
    cases.append(("truncated", b'{"terrain": ["floor"'))
    cases.append(("empty", b""))
    cases.append(("too large", b'{"terrain": ["' + b"f" * (2 << 20) + b'"]}'))
    return cases


def test_bad_mappings_are_refused(shared: Path, capsys) -> None:
    scene = _scene(shared / "scene", file="box.stl")
    cases = _bad_mappings()
    for k, (label, content) in enumerate(cases):
        mapping = shared / f"map{k}.json"
        mapping.write_bytes(content)
        out = shared / f"b{k}.npz"
        try:
            err = _refused(_lidar(scene, out, "--mapping", str(mapping)), out, capsys)
            with pytest.raises(SensorError):
                read_class_mapping(mapping)
        except BaseException as exc:
            raise AssertionError(f"mapping not refused: {label}") from exc
        assert str(mapping) in err and err.count("\n") == 1, label


def test_string_keywords_are_not_split_into_letters(shared: Path) -> None:
    """The Python API refuses a keyword string too (``list("floor")`` matched every
    geom whose path holds an 'f', 'l', 'o' or 'r')."""
    import mujoco

    from robotwright.sensors import scan_to_files

    model = mujoco.MjModel.from_xml_path(str(_scene(shared / "scene", file="box.stl")))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    with pytest.raises(SensorError, match="expected a list of keywords"):
        scan_to_files(model, data, "lidar", "grid", semantic_class_mapping={"terrain": "floor"})


def test_good_mapping_is_read(shared: Path) -> None:
    mapping = shared / "map.json"
    mapping.write_text(json.dumps({"terrain": ["floor"], "obstacle": ["geom"]}))
    assert read_class_mapping(mapping) == {"terrain": ["floor"], "obstacle": ["geom"]}
    scene = _scene(shared / "scene", file="box.stl")
    assert main(_lidar(scene, shared / "good.npz", "--mapping", str(mapping))) == 0
