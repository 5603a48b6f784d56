"""What the viewer draws, checked against MuJoCo's own scene (``mjv_updateScene``) and
compiled model: one drawn mesh per visible geom, colours, sizes, poses."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.scene.geometry import (
    body_poses,
    geom_rgba,
    geom_shapes,
    primitive_mesh,
    site_frames,
)

PRIMITIVES = """
<mujoco>
  <compiler angle="radian"/>
  <asset>
    <material name="red" rgba="0.9 0.1 0.1 1"/>
    <mesh name="tet" vertex="0 0 0  0.3 0 0  0 0.2 0  0 0 0.1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="2 3 0.1"/>
    <body name="base" pos="0.1 0.2 0.3" quat="0.9 0.1 0.3 0.2">
      <joint name="j0" type="hinge" axis="0 1 0"/>
      <geom name="box" type="box" size="0.1 0.2 0.3" pos="0.05 0 0" euler="0.3 0.2 0.1"/>
      <geom name="ball" type="sphere" size="0.07" pos="0 0.3 0" material="red"/>
      <geom name="pill" type="capsule" size="0.04 0.12" pos="0 0 0.4" material="red"
            rgba="0 1 0 1"/>
      <site name="tip" pos="0.2 0 0" quat="0 1 0 0"/>
      <body name="child" pos="0.3 0 0">
        <joint name="j1" type="slide" axis="1 0 0" range="-0.2 0.2"/>
        <geom name="can" type="cylinder" size="0.05 0.1"/>
        <geom name="egg" type="ellipsoid" size="0.03 0.05 0.08" pos="0 0 0.2"/>
        <geom name="tet" type="mesh" mesh="tet" pos="0 0.2 0"/>
        <geom name="hidden" type="box" size="0.1 0.1 0.1" rgba="1 1 1 0"/>
        <geom name="collision" type="sphere" size="0.2" group="3"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.fixture
def model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(PRIMITIVES)


def _mjv_geoms(model: mujoco.MjModel, data: mujoco.MjData) -> dict[int, mujoco.MjvGeom]:
    """MuJoCo's own drawn geoms (default visual options: groups 0-2), by geom id."""
    mujoco.mj_forward(model, data)
    scn = mujoco.MjvScene(model, maxgeom=10_000)
    mujoco.mjv_updateScene(
        model,
        data,
        mujoco.MjvOption(),
        None,
        mujoco.MjvCamera(),
        int(mujoco.mjtCatBit.mjCAT_ALL),
        scn,
    )
    return {
        scn.geoms[i].objid: scn.geoms[i]
        for i in range(scn.ngeom)
        if scn.geoms[i].objtype == int(mujoco.mjtObj.mjOBJ_GEOM)
    }


def _world(shape, xpos: np.ndarray, xquat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A shape's geom pose in the world from its body's world pose."""
    rb, rg = np.zeros(9), np.zeros(9)
    mujoco.mju_quat2Mat(rb, xquat[shape.body_id])
    mujoco.mju_quat2Mat(rg, shape.quat)
    rb, rg = rb.reshape(3, 3), rg.reshape(3, 3)
    return xpos[shape.body_id] + rb @ shape.pos, rb @ rg


def test_every_geom_but_the_transparent_one_is_drawn(model: mujoco.MjModel) -> None:
    skipped: list[str] = []
    shapes = geom_shapes(model, skipped=skipped)
    names = {s.name for s in shapes}
    assert len(shapes) == model.ngeom - 1
    assert "hidden" not in names and any("'hidden'" in line for line in skipped)
    assert {s.group for s in shapes if s.name == "collision"} == {3}


def test_colours_follow_mujoco(model: mujoco.MjModel) -> None:
    data = mujoco.MjData(model)
    drawn = _mjv_geoms(model, data)
    shapes = {s.name: s for s in geom_shapes(model)}
    # material colour where the geom keeps MuJoCo's default rgba, the geom's own otherwise
    np.testing.assert_allclose(shapes["ball"].rgba, [0.9, 0.1, 0.1, 1.0], atol=1e-6)
    np.testing.assert_allclose(shapes["pill"].rgba, [0.0, 1.0, 0.0, 1.0], atol=1e-6)
    for s in shapes.values():
        if s.geom_id in drawn:
            np.testing.assert_allclose(s.rgba, drawn[s.geom_id].rgba, atol=1e-6, err_msg=s.name)


def test_sizes_match_mujoco_bounding_boxes(model: mujoco.MjModel) -> None:
    """Tessellated vertices span the geom's own bounding box (``geom_aabb``, geom frame);
    an infinite-looking plane keeps its half-sizes here (2 x 3 m)."""
    for s in geom_shapes(model):
        centre, half = model.geom_aabb[s.geom_id][:3], model.geom_aabb[s.geom_id][3:]
        lo, hi = s.vertices.min(axis=0), s.vertices.max(axis=0)
        if model.geom_type[s.geom_id] == int(mujoco.mjtGeom.mjGEOM_PLANE):
            np.testing.assert_allclose(hi[:2], [2.0, 3.0])
            continue
        # Sphere-like tessellations reach the true surface within 2 %.
        np.testing.assert_allclose(0.5 * (hi + lo), centre, atol=0.02 * half.max(), err_msg=s.name)
        np.testing.assert_allclose(0.5 * (hi - lo), half, rtol=0.02, err_msg=s.name)
        assert s.faces.max() < len(s.vertices)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_poses_match_mujoco_at_random_configurations(model: mujoco.MjModel, seed: int) -> None:
    rng = np.random.default_rng(seed)
    data = mujoco.MjData(model)
    qpos = rng.uniform(-0.2, 0.2, model.nq)
    xpos, xquat = body_poses(model, data, qpos)
    drawn = _mjv_geoms(model, data)  # mj_forward at the same qpos
    for s in geom_shapes(model):
        pos, mat = _world(s, xpos, xquat)
        np.testing.assert_allclose(pos, data.geom_xpos[s.geom_id], atol=1e-9, err_msg=s.name)
        np.testing.assert_allclose(mat.reshape(-1), data.geom_xmat[s.geom_id], atol=1e-9)
        if s.geom_id in drawn:
            np.testing.assert_allclose(pos, drawn[s.geom_id].pos, atol=1e-5)
    for site in site_frames(model):
        rb = np.zeros(9)
        mujoco.mju_quat2Mat(rb, xquat[site.body_id])
        world = xpos[site.body_id] + rb.reshape(3, 3) @ site.pos
        np.testing.assert_allclose(world, data.site_xpos[site.site_id], atol=1e-9)


@pytest.mark.realdata
def test_unitree_g1_meshes(testdata_dir: Path) -> None:
    """The mjlab G1: every mesh geom drawn with MuJoCo's compiled vertices and colours."""
    path = testdata_dir / "mjlab/mjlab/asset_zoo/robots/unitree_g1/xmls/g1.xml"
    if not path.is_file():
        pytest.skip(f"mjlab G1 absent: {path} (run tools/fetch_test_data.py)")
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    drawn = _mjv_geoms(model, data)
    shapes = geom_shapes(model)
    meshes = [s for s in shapes if model.geom_type[s.geom_id] == int(mujoco.mjtGeom.mjGEOM_MESH)]
    assert len(meshes) == int((model.geom_type == int(mujoco.mjtGeom.mjGEOM_MESH)).sum())
    visible = [s for s in shapes if s.group in (0, 1, 2)]
    assert {s.geom_id for s in visible} == set(drawn)
    for s in meshes:
        mesh_id = model.geom_dataid[s.geom_id]
        assert len(s.vertices) == model.mesh_vertnum[mesh_id]
        assert len(s.faces) == model.mesh_facenum[mesh_id]
    for s in visible:
        np.testing.assert_allclose(s.rgba, drawn[s.geom_id].rgba, atol=1e-6)
        np.testing.assert_allclose(s.rgba, geom_rgba(model, s.geom_id))


def test_height_field_surface_matches_mujoco_ray_casts() -> None:
    """Each vertex of a drawn height field lies on the surface MuJoCo collides with: a
    ray cast straight down at its (x, y) hits at its height."""
    model = mujoco.MjModel.from_xml_string(
        """
        <mujoco>
          <asset>
            <hfield name="h" nrow="3" ncol="4" size="1 2 0.5 0.1"
                    elevation="0 1 2 3  1 2 3 4  4 3 1 0"/>
          </asset>
          <worldbody><geom type="hfield" hfield="h" pos="0.3 -0.2 0.1"/></worldbody>
        </mujoco>
        """
    )
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    (shape,) = geom_shapes(model)
    assert len(shape.vertices) == 12 and len(shape.faces) == 2 * 2 * 3
    geomid = np.zeros(1, np.int32)
    for v in shape.vertices.astype(np.float64):
        # a hair inside the edge, where the vertex's own height is what the ray meets
        x, y = v[0] * 0.999, v[1] * 0.999
        start = np.array([x + 0.3, y - 0.2, 5.0])
        dist = mujoco.mj_ray(model, data, start, np.array([0.0, 0.0, -1.0]), None, 1, -1, geomid)
        np.testing.assert_allclose(5.0 - dist, v[2] + 0.1, atol=2e-3)


def test_textures_are_named_as_not_drawn() -> None:
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><asset><texture name="t" type="2d" builtin="checker" width="8" height="8"/>'
        '<material name="m" texture="t" rgba="0.2 0.4 0.6 1"/></asset><worldbody>'
        '<geom name="tiled" size="0.1" material="m"/><geom name="plain" size="0.1"/>'
        "</worldbody></mujoco>"
    )
    skipped: list[str] = []
    shapes = geom_shapes(model, skipped=skipped)
    assert len(shapes) == 2  # drawn, in the material's colour
    np.testing.assert_allclose(shapes[0].rgba, [0.2, 0.4, 0.6, 1.0], atol=1e-6)
    assert skipped == ["geom 'tiled': texture not drawn, only its colour"]


G = mujoco.mjtGeom


def _signed_volume(v: np.ndarray, f: np.ndarray) -> float:
    """Volume enclosed by triangles (divergence theorem): positive when they face out."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


@pytest.mark.parametrize(
    ("gtype", "size", "half_extent", "volume"),
    [
        (G.mjGEOM_SPHERE, [0.07], [0.07, 0.07, 0.07], 4 / 3 * np.pi * 0.07**3),
        (
            G.mjGEOM_ELLIPSOID,
            [0.03, 0.05, 0.08],
            [0.03, 0.05, 0.08],
            4 / 3 * np.pi * 0.03 * 0.05 * 0.08,
        ),
        (G.mjGEOM_BOX, [0.1, 0.2, 0.3], [0.1, 0.2, 0.3], 8 * 0.1 * 0.2 * 0.3),
        (G.mjGEOM_CYLINDER, [0.05, 0.1], [0.05, 0.05, 0.1], np.pi * 0.05**2 * 0.2),
        (
            G.mjGEOM_CAPSULE,
            [0.04, 0.12],
            [0.04, 0.04, 0.12 + 0.04],
            np.pi * 0.04**2 * 0.24 + 4 / 3 * np.pi * 0.04**3,
        ),
    ],
)
def test_primitive_mesh_spans_the_geom_size(gtype, size, half_extent, volume) -> None:
    """Each closed primitive spans exactly its MuJoCo size (a box 2 x half sizes, a
    capsule 2 x (half length + radius) along z), faces outwards, and encloses about
    the shape's volume (tessellation loses at most 3 %)."""
    v, f = primitive_mesh(gtype, size, plane_extent=50.0)
    assert v.dtype == np.float64 and f.shape[1] == 3 and f.max() < len(v)
    np.testing.assert_allclose(v.max(axis=0), half_extent, rtol=0, atol=1e-12)
    np.testing.assert_allclose(v.min(axis=0), -np.asarray(half_extent), rtol=0, atol=1e-12)
    assert 0.97 * volume <= _signed_volume(v, f) <= volume * (1 + 1e-12)
    if gtype == G.mjGEOM_SPHERE:
        np.testing.assert_allclose(np.linalg.norm(v, axis=1), 0.07, rtol=0, atol=1e-12)
    if gtype == G.mjGEOM_ELLIPSOID:
        np.testing.assert_allclose(np.linalg.norm(v / size, axis=1), 1.0, atol=1e-12)
    if gtype in (G.mjGEOM_CYLINDER, G.mjGEOM_CAPSULE):
        assert np.linalg.norm(v[:, :2], axis=1).max() == pytest.approx(size[0], abs=1e-12)
    v32, f32 = primitive_mesh(gtype, size, plane_extent=50.0, dtype=np.float32)
    assert v32.dtype == np.float32 and np.array_equal(f32, f)
    np.testing.assert_allclose(v32, v, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize(
    ("size", "cells", "half"),
    [
        ([2.0, 3.0, 0.1], 1, [2.0, 3.0]),
        ([0.0, 0.0, 0.1], 24, [50.0, 50.0]),
        ([0.0, 0.5, 0.1], 3, [50.0, 0.5]),
    ],
)
def test_primitive_mesh_plane(size, cells, half) -> None:
    """A plane spans its half sizes; a side of size 0 (infinite in MuJoCo) reaches the
    extent given; it is ``cells`` x ``cells`` squares at z = 0 facing +z."""
    v, f = primitive_mesh(G.mjGEOM_PLANE, size, plane_extent=50.0, plane_cells=cells)
    np.testing.assert_array_equal(v.max(axis=0), [*half, 0.0])
    np.testing.assert_array_equal(v.min(axis=0), [-half[0], -half[1], 0.0])
    assert len(f) == 2 * cells * cells and len(v) == (cells + 1) ** 2
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    normal_z = np.cross(b - a, c - a)[:, 2]
    np.testing.assert_allclose(normal_z.sum() / 2, 4 * half[0] * half[1])
    assert (normal_z > 0).all()


def test_primitive_mesh_is_none_for_meshes_and_height_fields() -> None:
    for gtype in (G.mjGEOM_MESH, G.mjGEOM_HFIELD, G.mjGEOM_SDF):
        assert primitive_mesh(gtype, [0.1, 0.1, 0.1], plane_extent=1.0) is None


def test_view_says_nothing_of_its_own_floor_texture_without_v() -> None:
    from robotwright.cli.view import note_lines
    from robotwright.scene.geometry import geom_shapes
    from robotwright.scene.load import load_source

    scene = load_source("mini_humanoid")  # generated with our floor: a textured plane
    skipped: list[str] = []
    geom_shapes(scene.model, skipped=skipped)
    assert any("'floor'" in s for s in skipped)
    quiet = note_lines(scene.notes, skipped, verbose=False)
    assert not any("texture" in line for line in quiet) and len(quiet) <= 1
    assert any("'floor'" in line for line in note_lines(scene.notes, skipped, verbose=True))
    # Other notes still make their one line.
    assert note_lines(["a robot note"], skipped, verbose=False) == ["note: a robot note"]
