"""The proof compares what simulates beyond the per-object arrays: contact pairs (their
geoms and parameters), contact excludes, each tendon's path, and the mesh each mesh geom
holds (vertex count and bounds). A change to any is one difference naming it."""

from __future__ import annotations

import mujoco
import pytest
import trimesh

from robotwright.proof.compare import compare_models

MODEL = """<mujoco model="families">
  <asset><mesh name="m" file="{mesh}"/></asset>
  <worldbody>
    <site name="anchor" pos="0 0 1"/>
    <body name="a" pos="0 0 1">
      <joint name="ja" axis="0 1 0"/>
      <geom name="ga" type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
      <site name="sa" pos="0 0 -0.3"/>
      <body name="b" pos="0 0 -0.3">
        <joint name="jb" axis="0 1 0"/>
        <geom name="gb" type="mesh" mesh="m"/>
        <geom name="wrap" type="sphere" size="0.04" contype="0" conaffinity="0"/>
        <site name="sb" pos="0.1 0 -0.1"/>
      </body>
    </body>
  </worldbody>
  <contact>
    <pair geom1="ga" geom2="gb" condim="4" friction="0.7 0.7 0.01 0.001 0.001"/>
    <exclude body1="a" body2="b"/>
  </contact>
  <tendon>
    <spatial name="cable">
      <site site="anchor"/><site site="sa"/><geom geom="wrap"/><site site="sb"/>
    </spatial>
  </tendon>
</mujoco>
"""


@pytest.fixture
def model_of(tmp_path):
    box = trimesh.creation.box(extents=(0.1, 0.1, 0.1))
    box.export(tmp_path / "box.stl")
    trimesh.creation.box(extents=(0.1, 0.1, 0.12)).export(tmp_path / "taller.stl")
    trimesh.creation.icosphere(subdivisions=1, radius=0.05).export(tmp_path / "ball.stl")

    def build(text: str = MODEL, mesh: str = "box.stl") -> mujoco.MjModel:
        spec = mujoco.MjSpec.from_string(text.format(mesh=mesh))
        spec.modelfiledir = str(tmp_path)
        return spec.compile()

    return build


def test_equal_models_have_no_difference(model_of):
    assert compare_models(model_of(), model_of()) == []


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ('condim="4"', 'condim="3"', "pair_dim"),
        ('friction="0.7 0.7', 'friction="0.6 0.7', "pair_friction"),
        ('<exclude body1="a" body2="b"/>', "", "(object)"),
        ('<geom geom="wrap"/>', "", "tendon path"),
        ('<site site="sa"/><geom geom="wrap"/>', '<geom geom="wrap"/><site site="sa"/>',
         "tendon path"),
    ],
)  # fmt: skip
def test_a_changed_contact_or_tendon_is_named(model_of, old, new, field):
    assert old in MODEL
    found = compare_models(model_of(), model_of(MODEL.replace(old, new)))
    assert [d.field for d in found] == [field], found
    assert ("exclude" in found[0].obj) or ("pair" in found[0].obj) or ("cable" in found[0].obj)


@pytest.mark.parametrize(
    ("mesh", "field"), [("taller.stl", "mesh bounds"), ("ball.stl", "mesh_vertnum")]
)
def test_another_mesh_is_named(model_of, mesh, field):
    found = compare_models(model_of(), model_of(mesh=mesh))
    meshes = [d for d in found if d.field in ("mesh_vertnum", "mesh bounds")]
    assert [(d.field, d.obj) for d in meshes] == [(field, "geom 'gb'")]
