"""The path that is checked is the path that is read (issue 38, item 2), with the kernel's
confinement off: the checks alone must hold.

An MJCF with ``<compiler strippath="true"/>`` names ``/abs/outside/secret.stl``: MuJoCo
reads ``secret.stl`` from the model's folder (the file name alone), so the check passes
on the decoy of that name inside the folder, and the mesh stager must read that decoy
too, never the absolute path. Without ``strippath`` the absolute path is refused.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh

from robotwright.cli import main

MJCF = """<mujoco model="m">
  <compiler strippath="{strip}" angle="radian"/>
  <asset><mesh name="part" file="{file}"/></asset>
  <worldbody>
    <body name="base"><freejoint/><geom type="mesh" mesh="part" mass="1"/></body>
  </worldbody>
</mujoco>
"""


@pytest.fixture
def layout(tmp_path: Path, monkeypatch) -> tuple[Path, Path]:
    monkeypatch.setenv("ROBOTWRIGHT_CONFINE", "off")
    secret = tmp_path / "outside" / "secret.stl"
    secret.parent.mkdir()
    trimesh.creation.box(extents=(0.9, 0.9, 0.9)).export(str(secret))  # 0.9 m: the secret
    robot = tmp_path / "robot"
    robot.mkdir()
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(str(robot / "secret.stl"))  # decoy
    return robot, secret


def _mesh_extents(folder: Path) -> list[float]:
    stls = sorted(folder.rglob("*.stl"))
    assert stls, f"no mesh written under {folder}"
    return [float(max(trimesh.load(str(p), force="mesh").extents)) for p in stls]


def test_strippath_stages_the_file_mujoco_reads(layout, tmp_path, capsys) -> None:
    robot, secret = layout
    xml = robot / "robot.xml"
    xml.write_text(MJCF.format(strip="true", file=str(secret)), encoding="utf-8")
    out = tmp_path / "out"
    code = main(["convert", str(xml), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err
    secret_bytes = secret.read_bytes()
    assert all(p.read_bytes() != secret_bytes for p in out.rglob("*") if p.is_file())
    assert all(abs(e - 0.1) < 1e-6 for e in _mesh_extents(out))  # the decoy, not the secret


def test_an_outside_mesh_is_refused_without_confinement(layout, tmp_path, capsys) -> None:
    robot, secret = layout
    xml = robot / "robot.xml"
    xml.write_text(MJCF.format(strip="false", file=str(secret)), encoding="utf-8")
    out = tmp_path / "out"
    code = main(["convert", str(xml), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error:") and "Traceback" not in err
    assert "secret.stl" in err and "outside" in err
    assert not out.exists()


def test_the_stager_refuses_what_the_check_would(layout) -> None:
    """The stager itself resolves inside the folder (it does not lean on the check)."""
    import mujoco

    from robotwright.errors import UnsafePathError
    from robotwright.parsers.mjcf.geoms import _mesh_source

    robot, secret = layout
    spec = mujoco.MjSpec.from_string(MJCF.format(strip="false", file=str(secret)))
    with pytest.raises(UnsafePathError, match="outside"):
        _mesh_source(spec.meshes[0], spec, robot, [])
    spec = mujoco.MjSpec.from_string(MJCF.format(strip="true", file=str(secret)))
    assert _mesh_source(spec.meshes[0], spec, robot, []) == (robot / "secret.stl").resolve()
    windows = MJCF.format(strip="true", file="C:\\\\outside\\\\secret.stl")
    spec = mujoco.MjSpec.from_string(windows)
    assert _mesh_source(spec.meshes[0], spec, robot, []) == (robot / "secret.stl").resolve()
