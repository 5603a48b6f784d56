"""The converter's asset flattened in memory (robotwright.generators.usd_converted): the
same layer as flattening the files the converter writes, the saves of other threads
untouched, and a converter that works otherwise read from its files.

Runs where mujoco-usd-converter is installed (Isaac Lab's and the USD environments).
"""

from __future__ import annotations

import os
import threading
import types
from pathlib import Path

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip(
        "mujoco_usd_converter", reason="mujoco-usd-converter not installed (Isaac Lab stage)"
    )

import mujoco_usd_converter  # noqa: E402
import usdex.core  # noqa: E402
from pxr import Sdf, Usd, UsdGeom  # noqa: E402
from usd_robots import robot as robot_named  # noqa: E402

from robotwright._library_output import captured_library_output  # noqa: E402
from robotwright.generators.usd import _robot_mjcf  # noqa: E402
from robotwright.generators.usd_converted import converted_stage  # noqa: E402


def _text(layer: Sdf.Layer, folder: Path) -> str:
    """The layer as text, the conversion's folder (named in asset paths) left out."""
    return layer.ExportToString().replace(folder.as_posix(), "<folder>")


@pytest.mark.parametrize("name", ["g1", "talos", "arm6"])  # meshes in a library; none
def test_the_stage_in_memory_is_the_flattened_files(name, tmp_path) -> None:
    hrdf = robot_named(name)  # held: its MJCF refers to a parser's staged meshes
    mjcf, _ = _robot_mjcf(hrdf, tmp_path / "robot")
    with captured_library_output():
        asset = mujoco_usd_converter.Converter().convert(str(mjcf), str(tmp_path / "files"))
        ours = converted_stage(mujoco_usd_converter, mjcf, tmp_path / "memory")
    written = Usd.Stage.Open(asset.path).Flatten()
    assert _text(ours.GetRootLayer(), tmp_path / "memory") == _text(written, tmp_path / "files")
    assert ours.GetRootLayer().anonymous and ours.GetDefaultPrim().IsValid()
    assert usdex.core.saveStage is _REAL_SAVE  # the converter's saves are its own again


_REAL_SAVE = usdex.core.saveStage


def _stage_with_a_cube(path: Path) -> Usd.Stage:
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.Cube.Define(stage, "/robot/box")
    stage.SetDefaultPrim(stage.GetPrimAtPath("/robot"))
    return stage


def _converter_module(convert) -> types.SimpleNamespace:
    """A stand-in for the converter's module: ``Converter().convert`` is ``convert``."""
    return types.SimpleNamespace(Converter=lambda: types.SimpleNamespace(convert=convert))


def test_a_converter_that_saves_another_stage_is_read_from_its_files(tmp_path) -> None:
    """The asset returned is not a stage handed to saveStage: every held stage is saved
    as the converter asked, and the asset is read from the files."""

    def convert(mjcf: str, folder: str) -> Sdf.AssetPath:
        Path(folder).mkdir()
        library = _stage_with_a_cube(Path(folder) / "library.usda")
        usdex.core.saveStage(library, comment="the library")
        asset = Path(folder) / "asset.usda"
        layer = Sdf.Layer.CreateNew(str(asset))
        layer.subLayerPaths.append("./library.usda")
        layer.Save()
        return Sdf.AssetPath(str(asset))

    stage = converted_stage(_converter_module(convert), tmp_path / "robot.xml", tmp_path / "out")
    saved = Sdf.Layer.OpenAsAnonymous(str(tmp_path / "out" / "library.usda"))
    assert saved.GetPrimAtPath("/robot/box") and saved.comment == "the library"
    assert stage.GetPrimAtPath("/robot/box").IsA(UsdGeom.Cube)
    assert usdex.core.saveStage is _REAL_SAVE


def test_saves_of_other_threads_are_written_while_converting(tmp_path) -> None:
    other = tmp_path / "other.usda"

    def convert(mjcf: str, folder: str) -> Sdf.AssetPath:
        Path(folder).mkdir()
        elsewhere = _stage_with_a_cube(other)
        thread = threading.Thread(target=usdex.core.saveStage, args=(elsewhere,))
        thread.start()
        thread.join()
        asset = _stage_with_a_cube(Path(folder) / "asset.usda")
        usdex.core.saveStage(asset)  # held: not written
        return Sdf.AssetPath(asset.GetRootLayer().identifier)

    stage = converted_stage(_converter_module(convert), tmp_path / "robot.xml", tmp_path / "out")
    assert Sdf.Layer.OpenAsAnonymous(str(other)).GetPrimAtPath("/robot/box")
    assert not Sdf.Layer.OpenAsAnonymous(str(tmp_path / "out" / "asset.usda")).GetPrimAtPath(
        "/robot/box"
    )  # created empty by CreateNew, never saved
    assert stage.GetPrimAtPath("/robot/box").IsA(UsdGeom.Cube)  # from memory


def test_a_failing_converter_leaves_the_saves_as_they_were(tmp_path) -> None:
    def convert(mjcf: str, folder: str) -> Sdf.AssetPath:
        raise ValueError("not an MJCF")

    with pytest.raises(ValueError, match="not an MJCF"):
        converted_stage(_converter_module(convert), tmp_path / "robot.xml", tmp_path / "out")
    assert usdex.core.saveStage is _REAL_SAVE


def test_the_spec_given_is_what_the_converter_reads(tmp_path) -> None:
    """Given MuJoCo's parse of the MJCF, the converter's own MjSpec.from_file of that file
    gets a copy of it (this thread only: another thread's read parses the file), and
    MjSpec.from_file is MuJoCo's own again after; the G1's asset is the same layer."""
    import mujoco

    raw = mujoco.MjSpec.__dict__["from_file"]
    hrdf = robot_named("arm6")
    mjcf, _ = _robot_mjcf(hrdf, tmp_path / "robot")
    parsed = mujoco.MjSpec.from_file(str(mjcf))
    parsed.modelname = "given"  # what tells the copy from a new parse
    seen: dict[str, str] = {}

    def convert(path: str, folder: str) -> Sdf.AssetPath:
        Path(folder).mkdir()
        seen["mine"] = mujoco.MjSpec.from_file(path).modelname
        other = threading.Thread(
            target=lambda: seen.setdefault("other", mujoco.MjSpec.from_file(path).modelname)
        )
        other.start()
        other.join()
        asset = _stage_with_a_cube(Path(folder) / "asset.usda")
        usdex.core.saveStage(asset)
        return Sdf.AssetPath(asset.GetRootLayer().identifier)

    converted_stage(_converter_module(convert), mjcf, tmp_path / "out", parsed)
    assert seen == {"mine": "given", "other": mjcf.stem}
    assert mujoco.MjSpec.__dict__["from_file"] is raw and parsed.modelname == "given"

    g1 = robot_named("g1")
    mjcf, _ = _robot_mjcf(g1, tmp_path / "g1")
    with captured_library_output():
        read = converted_stage(mujoco_usd_converter, mjcf, tmp_path / "read")
        given = converted_stage(
            mujoco_usd_converter, mjcf, tmp_path / "given", mujoco.MjSpec.from_file(str(mjcf))
        )
    assert _text(given.GetRootLayer(), tmp_path / "given") == _text(
        read.GetRootLayer(), tmp_path / "read"
    )
    assert mujoco.MjSpec.__dict__["from_file"] is raw


def test_the_usd_export_parses_the_robot_once(tmp_path, monkeypatch, capsys) -> None:
    """`robotwright export --format usd`: the compile check, the converter and the proof
    read one MuJoCo parse of the robot's MJCF (it costs as the bodies squared; three
    before), and the file is the same."""
    from collections import OrderedDict

    import mujoco

    import robotwright._mjspec_cache
    from robotwright.cli import main

    monkeypatch.setattr(robotwright._mjspec_cache, "_parsed", OrderedDict())  # none kept
    hrdf = robot_named("arm6")
    hrdf.save(tmp_path / "arm6")
    marker = hrdf.bodies[-1].name  # in the robot's MJCF, not in MuJoCo's own probes
    parses: list[str] = []
    real_string, real_file = mujoco.MjSpec.from_string, mujoco.MjSpec.from_file

    def from_string(xml, *args, **kwargs):
        if f'"{marker}"' in xml:
            parses.append("text")
        return real_string(xml, *args, **kwargs)

    def from_file(path, *args, **kwargs):
        parses.append(str(path))
        return real_file(path, *args, **kwargs)

    monkeypatch.setattr(mujoco.MjSpec, "from_string", staticmethod(from_string))
    monkeypatch.setattr(mujoco.MjSpec, "from_file", staticmethod(from_file))
    out = tmp_path / "arm6.usda"
    assert main(["export", str(tmp_path / "arm6"), "--format", "usd", "-o", str(out)]) == 0
    assert "0 difference(s)" in capsys.readouterr().out
    assert parses == ["text"]
    monkeypatch.undo()
    again = tmp_path / "again.usda"
    assert main(["export", str(tmp_path / "arm6"), "--format", "usd", "-o", str(again)]) == 0
    assert out.read_bytes() == again.read_bytes()
