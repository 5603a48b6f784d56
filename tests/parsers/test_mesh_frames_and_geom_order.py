"""A mesh's refpos/refquat is folded into its geoms' poses (the mesh file is kept as it
is), and a body whose mesh and primitive geoms interleave keeps their order (MuJoCo's
contact order follows geom order); the proof sees a reordered body."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
import trimesh

from robotwright.hrdf.model import HRDF
from robotwright.parsers import mjcf_to_hrdf
from robotwright.proof.compare import compare_models
from robotwright.proof.convert import convert

REF = """<mujoco model="ref">
  <asset>
    <mesh name="part" file="part.stl" refpos="0.1 0.02 -0.05" refquat="0.9238795 0 0.3826834 0"/>
    <mesh name="plain" file="plain.stl"/>
  </asset>
  <worldbody>
    <body name="b" pos="0 0 1">
      <freejoint name="root"/>
      <geom name="sphere" type="sphere" size="0.05"/>
      <geom name="turned" type="mesh" mesh="part" pos="0.01 0.02 0.03" quat="0.9659258 0.258819 0 0"/>
      <geom name="box" type="box" size="0.05 0.05 0.05" pos="0.2 0 0"/>
      <geom name="as_is" type="mesh" mesh="plain" pos="0 0 -0.3"/>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.fixture
def source(tmp_path):
    part = trimesh.creation.box(extents=(0.3, 0.1, 0.05))
    part.apply_translation((0.2, 0.05, -0.1))  # off its own origin: MuJoCo re-centres it
    part.export(tmp_path / "part.stl")
    # Another mesh in its own file: MuJoCo 3.11 reuses a processed mesh (its refpos
    # included) for a mesh of the same file.
    trimesh.creation.box(extents=(0.1, 0.1, 0.2)).export(tmp_path / "plain.stl")
    (tmp_path / "ref.xml").write_text(REF)
    return tmp_path / "ref.xml"


def _world_geoms(model):
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return data.geom_xpos.copy(), data.geom_xmat.copy()


def test_refpos_refquat_folded_and_order_kept(source, tmp_path):
    messages = convert(source, tmp_path / "out.xml", strict=True)
    assert not any("refpos" in m for m in messages)
    src = mujoco.MjModel.from_xml_path(str(source))
    out = mujoco.MjModel.from_xml_path(str(tmp_path / "out.xml"))
    assert not compare_models(src, out)
    names = [mujoco.mj_id2name(out, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(out.ngeom)]
    assert names == ["sphere", "turned", "box", "as_is"]
    (xa, ma), (xb, mb) = _world_geoms(src), _world_geoms(out)
    assert np.abs(xa - xb).max() < 1e-9 and np.abs(ma - mb).max() < 1e-9


def test_order_survives_the_folder(source, tmp_path):
    mjcf_to_hrdf(source).save(tmp_path / "folder")
    loaded = HRDF.from_dir(tmp_path / "folder")
    geoms = sorted([*loaded.meshes, *loaded.simple_geoms], key=lambda g: g.order)
    assert [g.geom_name for g in geoms] == ["sphere", "turned", "box", "as_is"]
    assert "order" in (tmp_path / "folder" / "mesh.csv").read_text().splitlines()[0]


def test_proof_sees_geoms_in_another_order(source):
    src = mujoco.MjModel.from_xml_path(str(source))
    swapped = REF.replace('<geom name="sphere" type="sphere" size="0.05"/>\n', "").replace(
        '<geom name="box"', '<geom name="sphere" type="sphere" size="0.05"/>\n<geom name="box"'
    )
    spec = mujoco.MjSpec.from_string(swapped)
    spec.modelfiledir = str(source.parent)
    found = compare_models(src, spec.compile())
    assert [d.field for d in found] == ["geom order"]
    assert "sphere" in found[0].source and "'b'" in found[0].obj
