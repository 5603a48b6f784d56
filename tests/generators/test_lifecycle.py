"""Seed 000 lifecycle semantics of the generators (each rule one test)."""

from __future__ import annotations

import copy
import os
import warnings
from pathlib import Path

import mujoco
import pytest

from robotwright.errors import GeneratorError
from robotwright.generators import (
    GeneratorBase,
    MJCFHumanoidGenerator,
    URDFHumanoidGenerator,
)
from robotwright.hrdf.model import HRDF

GENERATORS = [MJCFHumanoidGenerator, URDFHumanoidGenerator]


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


@pytest.mark.parametrize("cls", GENERATORS)
def test_init_loads_nothing(cls):
    gen = cls()
    assert isinstance(gen, GeneratorBase)
    assert not gen.loaded
    assert gen.hrdf is None
    assert not gen.generated


@pytest.mark.parametrize("cls", GENERATORS)
def test_load_sets_loaded(cls, synth):
    gen = cls()
    assert gen.load(synth) is gen
    assert gen.loaded
    assert gen.hrdf is synth


@pytest.mark.parametrize("cls", GENERATORS)
def test_generate_and_export_unloaded_raise_clear_error(cls, tmp_path):
    gen = cls()
    with pytest.raises(GeneratorError, match=r"generate\(\): nothing is loaded"):
        gen.generate()
    with pytest.raises(GeneratorError, match=r"export\(\): nothing is loaded"):
        gen.export(tmp_path / "x.xml")
    assert not (tmp_path / "x.xml").exists()


def test_load_rejects_non_hrdf():
    with pytest.raises(GeneratorError, match="expected an HRDF robot, got str"):
        MJCFHumanoidGenerator().load("g1")


@pytest.mark.parametrize("cls", GENERATORS)
def test_clean_returns_to_constructed_state_and_destroys(cls, synth):
    gen = cls.from_hrdf(synth)
    gen.generate()
    assert gen.generated
    gen.clean()
    fresh = cls()
    assert not gen.loaded and gen.hrdf is None and not gen.generated
    assert gen._xml_root is None
    if hasattr(gen, "simulator_config"):
        assert gen.simulator_config == fresh.simulator_config
    with pytest.raises(GeneratorError):
        gen.generate()


@pytest.mark.parametrize("cls", GENERATORS)
def test_destroy_resets_xml_root_only(cls, synth):
    gen = cls.from_hrdf(synth)
    root = gen.generate()
    assert len(root)
    gen.destroy()
    assert gen._xml_root is None and not gen.generated
    assert gen.loaded and gen.hrdf is synth
    assert len(gen.xml_root) == 0  # a new, empty root


@pytest.mark.parametrize("cls", GENERATORS)
def test_export_after_destroy_is_identical(cls, synth):
    gen = cls.from_hrdf(synth)
    s1 = gen.export()
    gen.destroy()
    s2 = gen.export()
    assert s1 == s2


@pytest.mark.parametrize("cls", GENERATORS)
def test_generate_is_idempotent(cls, synth):
    gen = cls.from_hrdf(synth)
    gen.generate()
    s1 = gen.xml_str
    gen.generate()
    s2 = gen.xml_str
    assert s1 == s2
    assert s1.count("<body ") == s2.count("<body ")


def test_from_constructors(synth_hrdf_dir, synth):
    a = MJCFHumanoidGenerator.from_hrdf(synth)
    assert a.loaded and a.hrdf is synth
    b = MJCFHumanoidGenerator.from_hrdf_path(synth_hrdf_dir)
    assert b.loaded and b.hrdf.name == "synth_baseline_hinge"
    c = URDFHumanoidGenerator.from_robot_name("arm6")
    assert c.loaded and c.hrdf.name == "arm6"


def test_hrdf_is_never_mutated(synth):
    before = copy.deepcopy(synth)
    gen = MJCFHumanoidGenerator.from_hrdf(synth)
    gen.export(prefix="p")
    URDFHumanoidGenerator.from_hrdf(synth).export(add_mujoco_tag=True)
    assert synth == before


def test_export_is_atomic_and_loads_from_any_cwd(synth, tmp_path, monkeypatch):
    out = tmp_path / "out" / "deep" / "robot.xml"
    text = MJCFHumanoidGenerator.from_hrdf(synth).export(out)
    assert out.read_text(encoding="utf-8") == text
    assert [p.name for p in out.parent.iterdir()] == ["robot.xml"]  # no temp file left
    monkeypatch.chdir(tmp_path)
    model = mujoco.MjModel.from_xml_path(os.path.relpath(out, tmp_path))
    assert model.nmesh == 2


def test_failed_export_writes_nothing(synth, tmp_path):
    (synth.root_dir / "meshes" / "box.stl").unlink()
    out = tmp_path / "robot.xml"
    with pytest.raises(GeneratorError, match=r"mesh.csv row 0 .*box.*does not exist"):
        MJCFHumanoidGenerator.from_hrdf(synth).export(out)
    assert not out.exists()
    assert list(tmp_path.glob("*.tmp")) == []


def test_export_copy_meshes_is_self_contained(synth, tmp_path):
    out = tmp_path / "pkg" / "robot.xml"
    MJCFHumanoidGenerator.from_hrdf(synth).export(out, copy_meshes=True)
    URDFHumanoidGenerator.from_hrdf(synth).export(
        out.with_suffix(".urdf"), copy_meshes=True, add_mujoco_tag=True
    )
    assert (tmp_path / "pkg" / "meshes" / "synth" / "box.stl").is_file()
    # Remove the source: the exported folder must not depend on it.
    (synth.root_dir / "meshes" / "box.stl").unlink()
    assert mujoco.MjModel.from_xml_path(str(out)).nmesh == 2
    assert mujoco.MjModel.from_xml_path(str(out.with_suffix(".urdf"))).nbody > 5


def test_generate_string_has_absolute_mesh_paths(synth):
    text = MJCFHumanoidGenerator.from_hrdf(synth).export()
    model = mujoco.MjModel.from_xml_string(text)
    assert model.nmesh == 2
    assert f'meshdir="{(synth.root_dir / "meshes").resolve().as_posix()}"' in text


def test_export_is_deterministic_across_instances(synth, tmp_path):
    a = MJCFHumanoidGenerator.from_hrdf(synth).export(tmp_path / "a.xml")
    b = MJCFHumanoidGenerator.from_hrdf(copy.deepcopy(synth)).export(tmp_path / "b.xml")
    assert a == b
    assert Path(tmp_path / "a.xml").read_bytes() == Path(tmp_path / "b.xml").read_bytes()


def test_copy_meshes_needs_a_file(synth):
    with pytest.raises(GeneratorError, match="needs a file_path"):
        MJCFHumanoidGenerator.from_hrdf(synth).export(None, copy_meshes=True)


def test_invalid_hrdf_is_rejected_on_load(synth):
    bad = HRDF(name="bad", bodies=synth.bodies, joints=[*synth.joints, synth.joints[1]])
    with pytest.raises(Exception, match="bad"):
        MJCFHumanoidGenerator.from_hrdf(bad)


def test_meshes_in_place_refers_to_a_parsers_staged_meshes(tmp_path):
    """A parsed robot's meshes are staged in a temporary folder: an export copies them
    (the folder goes with the robot), unless asked to refer to them where they are (a
    private file read while the robot is held: the USD export's MJCF)."""
    import trimesh

    from robotwright.sources import load_robot

    src = tmp_path / "src"
    src.mkdir()
    trimesh.creation.box(extents=(0.1, 0.2, 0.3)).export(src / "part.stl")
    (src / "robot.urdf").write_text(
        '<robot name="r"><link name="base"><inertial><mass value="1"/><inertia ixx="0.01" '
        'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><visual><geometry>'
        '<mesh filename="part.stl"/></geometry></visual></link></robot>'
    )
    hrdf = load_robot(str(src / "robot.urdf"))
    assert hrdf.temp_assets is not None
    in_place = tmp_path / "in_place" / "robot.xml"
    MJCFHumanoidGenerator.from_hrdf(hrdf).export(in_place, meshes_in_place=True)
    assert [p.name for p in in_place.parent.iterdir()] == ["robot.xml"]  # nothing copied
    model = mujoco.MjModel.from_xml_path(str(in_place))
    assert model.nmesh == 1 and model.mesh_vertnum[0] == 8
    copied = tmp_path / "copied" / "robot.xml"
    MJCFHumanoidGenerator.from_hrdf(hrdf).export(copied)  # staged meshes: always copied
    assert (copied.parent / "meshes").is_dir()
    with pytest.raises(GeneratorError, match="exclude each other"):
        MJCFHumanoidGenerator.from_hrdf(hrdf).export(
            tmp_path / "x.xml", copy_meshes=True, meshes_in_place=True
        )
