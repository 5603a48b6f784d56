"""Hostile inputs to the Things reader and writer (issue 11): files outside the model's
folder, includes, injected flag names, bodies nested deeper than MuJoCo reads."""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh

from robotwright._paths import trusted_asset_roots
from robotwright.errors import GeneratorError, UnsafePathError
from robotwright.things import Body, World
from robotwright.things.attrs import ThingAttributeError

MODEL = """<mujoco model="m">
  <asset><mesh name="part" file="{file}"/></asset>
  <worldbody><body name="base"><joint/><geom type="mesh" mesh="part" mass="1"/></body></worldbody>
</mujoco>
"""


@pytest.fixture
def secret(tmp_path: Path) -> Path:
    path = tmp_path / "outside" / "secret.stl"
    path.parent.mkdir()
    trimesh.creation.box(extents=(0.3, 0.3, 0.3)).export(str(path), file_type="stl")
    return path


def test_mesh_outside_the_folder_is_refused_unless_trusted(tmp_path, secret) -> None:
    model = tmp_path / "robot" / "m.xml"
    model.parent.mkdir()
    model.write_text(MODEL.format(file=str(secret)))
    with pytest.raises(UnsafePathError) as exc:
        World.from_xml_path(model)
    assert exc.value.file == str(model)
    assert exc.value.element == f'<mesh name="part" file="{secret}">'
    assert "outside the robot folder" in exc.value.reason
    world = World.from_xml_path(model, asset_roots=[secret.parent])
    assert world.model.nmesh == 1
    with trusted_asset_roots([secret.parent]):
        assert World.from_xml_path(model).model.nmesh == 1


def test_string_base_dir_bounds_meshes_and_cwd_bounds_includes(
    tmp_path, secret, monkeypatch
) -> None:
    base = tmp_path / "robot"
    base.mkdir()
    with pytest.raises(UnsafePathError, match="outside the robot folder"):
        World.from_xml_string(MODEL.format(file="../outside/secret.stl"), base_dir=base)
    # MuJoCo reads <include> from the working folder: it must lie inside base_dir too.
    monkeypatch.chdir(tmp_path / "outside")
    (tmp_path / "outside" / "inc.xml").write_text("<mujoco/>")
    text = '<mujoco><include file="inc.xml"/></mujoco>'
    with pytest.raises(UnsafePathError, match=r'<include file="inc\.xml">'):
        World.from_xml_string(text, base_dir=base)


def test_flag_names_are_vocabulary() -> None:
    world = World(disabled={'gravity="disable"/><body name="INJECTED"/><flag x'})
    with pytest.raises(ThingAttributeError, match="disabled flags"):
        world.to_xml_string()
    assert "gravity" in World(disabled={"gravity"}).to_xml_string()


def test_bodies_nested_deeper_than_mujoco_reads_are_refused() -> None:
    world = World()
    parent: Body | World = world
    for i in range(600):
        child = Body(f"b{i}", mass=1.0)
        parent.attach(child)
        parent = child
    with pytest.raises(GeneratorError, match="nested 497 bodies deep; .* at most 496"):
        world.to_xml_string()
