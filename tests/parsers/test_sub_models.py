"""A sub-model attached with ``<asset><model file>`` keeps its own ``<compiler meshdir>``:
its meshes are read where MuJoCo reads them (a Menagerie scene MuJoCo compiles used to
be refused with "cannot read mesh")."""

from __future__ import annotations

import mujoco
import trimesh

from robotwright.proof.compare import compare_models
from robotwright.proof.convert import convert

ARM = """<mujoco model="arm">
  <compiler meshdir="assets"/>
  <asset><mesh name="link" file="link.stl"/></asset>
  <worldbody>
    <body name="link" pos="0 0 0.1">
      <joint name="j" axis="0 1 0"/>
      <geom type="mesh" mesh="link"/>
    </body>
  </worldbody>
</mujoco>
"""
MAIN = """<mujoco model="main">
  <compiler meshdir="main_meshes"/>
  <asset>
    <mesh name="base" file="base.stl"/>
    <model name="arm" file="arm/arm.xml"/>
  </asset>
  <worldbody>
    <body name="base">
      <geom type="mesh" mesh="base"/>
      <attach model="arm" body="link" prefix="arm_"/>
    </body>
  </worldbody>
</mujoco>
"""


def test_sub_model_meshes_come_from_its_own_mesh_folder(tmp_path):
    (tmp_path / "arm" / "assets").mkdir(parents=True)
    (tmp_path / "main_meshes").mkdir()
    trimesh.creation.box(extents=(0.3, 0.1, 0.05)).export(tmp_path / "main_meshes" / "base.stl")
    link = trimesh.creation.cylinder(radius=0.03, height=0.4)  # another shape: not mixed up
    link.export(tmp_path / "arm" / "assets" / "link.stl")
    (tmp_path / "arm" / "arm.xml").write_text(ARM)
    (tmp_path / "main.xml").write_text(MAIN)
    convert(tmp_path / "main.xml", tmp_path / "out.xml", strict=True)
    source = mujoco.MjModel.from_xml_path(str(tmp_path / "main.xml"))
    result = mujoco.MjModel.from_xml_path(str(tmp_path / "out.xml"))
    assert not compare_models(source, result)
    assert sorted(result.mesh_vertnum) == sorted(source.mesh_vertnum)
