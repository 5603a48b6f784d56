"""The device-resident path: torch/warp outputs, device range model, seed paths (``warp``)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from lidar_scenes import RaysPattern, forward, geom_id, random_envs

from robotwright.errors import SensorError
from robotwright.sensors import (
    LidarCfg,
    LidarSensor,
    LivoxPatternCfg,
    SemanticLidarCfg,
    SemanticLidarSensor,
)

pytestmark = pytest.mark.warp
wp = pytest.importorskip(
    "warp", reason="optional robotwright[warp] extra (warp-lang) not installed"
)
mjw = pytest.importorskip(
    "mujoco_warp", reason="optional robotwright[warp] extra (mujoco-warp) not installed"
)
torch = pytest.importorskip("torch", reason="torch not installed (needed for output='torch')")


def _device_data(model: mujoco.MjModel, host: list[mujoco.MjData]):
    """A mujoco_warp.Data on the CPU device holding the poses of ``host``."""
    with wp.ScopedDevice("cpu"):
        mw = mjw.put_model(model)
        dw = mjw.put_data(model, host[0], nworld=len(host))
        dw.qpos.assign(np.stack([d.qpos for d in host]).astype(np.float32))
        mjw.kinematics(mw, dw)
    return mw, dw


def _cfg(**kw) -> SemanticLidarCfg:
    base = dict(prim_path="lidar", engine="warp", device="cpu", max_distance=30.0)
    base.update(kw)
    return SemanticLidarCfg(**base)


def test_torch_outputs_are_views_of_device_buffers_across_updates(clutter_model):
    host = random_envs(clutter_model, 3, seed=4)
    mw, dw = _device_data(clutter_model, host)
    s = SemanticLidarSensor(_cfg(output="torch", return_mesh_ids=True), clutter_model, dw)
    d = s.data
    buffers = (d.distances, d.semantic_labels, d.mesh_ids, d.hit_points_w, d.hit_mask)
    pointers = [t.data_ptr() for t in buffers]
    s.update()
    first = s.get_distances().clone()
    # The tensors are the engine's own buffers, not copies.
    p = s._pipeline
    assert d.distances.data_ptr() == p.distances.ptr
    assert d.semantic_labels.data_ptr() == p.labels.ptr
    assert d.hit_points_w.data_ptr() == p.points.ptr
    # Move every object, step the device data, update: same tensors, new values.
    with wp.ScopedDevice("cpu"):
        q = dw.qpos.numpy()
        q[:, :2] += 0.7
        dw.qpos.assign(q)
        mjw.kinematics(mw, dw)
    s.update()
    assert s.data is d
    assert [t.data_ptr() for t in buffers] == pointers
    assert s.get_distances() is d.distances
    assert not torch.equal(first, d.distances)
    # Shapes, dtypes and devices an RL user relies on.
    e, n = 3, s.num_rays
    assert d.distances.shape == (e, n) and d.distances.dtype == torch.float32
    assert d.semantic_labels.shape == (e, n) and d.semantic_labels.dtype == torch.int32
    assert d.hit_points_w.shape == (e, n, 3) and d.hit_mask.dtype == torch.bool
    assert d.distances.device == torch.device("cpu")
    assert torch.isfinite(d.distances).all()  # misses hold max_distance, never inf


def test_torch_outputs_equal_the_mujoco_engine(clutter_model):
    host = random_envs(clutter_model, 4, seed=5)
    pattern = LivoxPatternCfg(num_rays=20000)
    ref = SemanticLidarSensor(
        SemanticLidarCfg(
            prim_path="lidar", pattern_cfg=pattern, max_distance=30.0, return_mesh_ids=True
        ),
        clutter_model,
        host,
    )
    _, dw = _device_data(clutter_model, host)
    dev = SemanticLidarSensor(
        _cfg(pattern_cfg=pattern, output="torch", return_mesh_ids=True), clutter_model, dw
    )
    for _ in range(3):  # the rosette window advances identically on host and device
        ref.update()
        dev.update()
        ids, ids_ref = dev.get_mesh_ids().numpy(), ref.get_mesh_ids()
        same = ids == ids_ref
        assert same.mean() >= 0.999
        both = same & (ids_ref >= 0)
        assert both.sum() > 0.1 * ids.size
        np.testing.assert_allclose(
            dev.get_distances().numpy()[both], ref.get_distances()[both], atol=1e-5, rtol=0
        )
        np.testing.assert_array_equal(
            dev.get_semantic_labels().numpy()[same], ref.get_semantic_labels()[same]
        )
        pts, pts_ref = dev.get_pointcloud().numpy(), ref.get_pointcloud()
        np.testing.assert_allclose(pts[both], pts_ref[both], atol=2e-5)
        assert np.isnan(pts[ids < 0]).all()
        np.testing.assert_allclose(
            dev.get_pointcloud(frame="sensor").numpy()[both],
            ref.get_pointcloud(frame="sensor")[both],
            atol=2e-5,
        )
        np.testing.assert_allclose(
            dev.data.pattern_directions.numpy(), ref.data.pattern_directions, atol=1e-6
        )
    sel = dev.get_distances(env_ids=[2, 0]).numpy()
    np.testing.assert_allclose(sel, dev.get_distances().numpy()[[2, 0]])


def test_seed_rl_observation_runs_as_written(clutter_model):
    """The seed's ``lidar_semantic_obs`` body, verbatim, on torch outputs."""
    host = random_envs(clutter_model, 2, seed=6)
    _, dw = _device_data(clutter_model, host)
    sensor = SemanticLidarSensor(_cfg(output="torch"), clutter_model, dw)
    sensor.update()
    num_envs = 2
    distances = sensor.get_distances()  # (num_envs, num_rays)
    semantic_labels = sensor.get_semantic_labels()  # (num_envs, num_rays)
    obs = torch.stack([distances, semantic_labels.float()], dim=-1)
    obs = obs.reshape(num_envs, -1)
    assert obs.shape == (2, 2 * sensor.num_rays) and torch.isfinite(obs).all()
    assert set(torch.unique(semantic_labels).tolist()) >= {1, 2}
    # Masks as the seed filters its point cloud.
    pointcloud = sensor.get_pointcloud()
    terrain_points = pointcloud[semantic_labels == 1]
    assert terrain_points.shape[1] == 3 and torch.isfinite(terrain_points).all()


def test_warp_output_and_range_model_on_device(analytic_model):
    axes = np.tile([(1, 0, 0), (0, 1, 0), (0, 0, -1), (0, 0, 1)], (3000, 1))
    data = forward(analytic_model, 2)
    kw = dict(
        prim_path="lidar_site",
        pattern_cfg=RaysPattern(axes),
        engine="warp",
        device="cpu",
        range_noise_std=0.01,
        dropout_prob=0.25,
        seed=11,
        miss_distance=-1.0,
    )
    a = LidarSensor(LidarCfg(output="warp", **kw), analytic_model, data)
    b = LidarSensor(LidarCfg(output="warp", **kw), analytic_model, data)
    a.update()
    b.update()
    assert isinstance(a.get_distances(), wp.array)
    # On the CPU device .numpy() is a view: copy what must outlive the next update.
    d, hit = a.get_distances().numpy().copy(), a.get_hit_mask().numpy().copy()
    np.testing.assert_array_equal(d, b.get_distances().numpy())  # seeded
    up = np.arange(axes.shape[0]) % 4 == 3
    assert not hit[:, up].any() and (d[~hit] == -1.0).all()
    # Each environment draws its own noise and dropout.
    assert not np.array_equal(hit[0], hit[1])
    kept = hit[:, ~up].mean()
    assert abs(kept - 0.75) < 0.02  # binomial(18000, 0.75): std 0.003
    expected = np.tile([2.5, 2.5, 1.0, 0.0], 3000)[None].repeat(2, 0)
    err = d[hit] - expected[hit]
    assert abs(err.mean()) < 0.001 and 0.0095 < err.std() < 0.0105
    # Frames differ: the generator is seeded per (environment, frame).
    a.update()
    assert not np.array_equal(a.get_hit_mask().numpy(), hit)
    with pytest.raises(SensorError, match="needs engine='warp'"):
        LidarCfg(prim_path="x", output="torch")


def test_seed_configuration_paths():
    """Isaac Lab style paths of the seed work as written."""
    from lidar_scenes import CLUTTER_XML

    # The seed's robot carries the sensor on a body "base" of the entity "Robot".
    xml = CLUTTER_XML.replace('<geom name="base"', '<geom name="chassis"')
    model = mujoco.MjModel.from_xml_string(xml.replace('<body name="robot"', '<body name="base"'))
    cfg = SemanticLidarCfg(
        prim_path="{ENV_REGEX_NS}/Robot/base",
        mesh_prim_paths=[
            "/World/ground",
            "/world/SOFA_1",
            "{ENV_REGEX_NS}/cracker_box_0/_03_cracker_box",
        ],
        max_distance=40.0,
    )
    s = SemanticLidarSensor(cfg, model, forward(model))
    assert (s._carrier_kind, s._carrier_id) == (
        "body",
        mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base"),
    )
    hittable = set(np.flatnonzero(s.hittable_geom_mask).tolist())
    expected = {geom_id(model, n) for n in ("ground", "sofa_seat", "_03_cracker_box")}
    assert hittable == expected
    assert sorted(s.mesh_id_to_semantic_class[g] for g in expected) == [1, 2, 3]
    s.update()
    assert set(np.unique(s.get_semantic_labels()[s.get_hit_mask()]).tolist()) == {1, 2, 3}
    with pytest.raises(SensorError, match="no body or site named"):
        SemanticLidarSensor(
            SemanticLidarCfg(prim_path="{ENV_REGEX_NS}/Robot/trunk"), model, forward(model)
        )


def test_unnamed_plane_is_terrain():
    xml = """<mujoco><worldbody><geom type="plane" size="5 5 0.1"/>
      <body name="bot" pos="0 0 1"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
    </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    s = SemanticLidarSensor(
        SemanticLidarCfg(prim_path="bot", pattern_cfg=RaysPattern([(0, 0, -1)])),
        model,
        forward(model)[0],
    )
    s.update()
    assert s.geom_path(0) == "/world/geom0_plane"
    assert s.get_semantic_labels()[0, 0] == 1 and math.isclose(s.get_distances()[0, 0], 1.0)


def test_cpu_blocks_give_the_same_frame_as_one_launch(clutter_model):
    """Rays split over threads on warp's CPU device: same distances, labels, noise."""
    host = random_envs(clutter_model, 2, seed=8)
    kw = dict(
        pattern_cfg=LivoxPatternCfg(num_rays=3001),
        output="torch",
        range_noise_std=0.02,
        dropout_prob=0.1,
        seed=5,
    )
    one = SemanticLidarSensor(_cfg(num_threads=1, **kw), clutter_model, host)
    three = SemanticLidarSensor(_cfg(num_threads=3, **kw), clutter_model, host)
    assert len(one._pipeline._blocks) == 1 and len(three._pipeline._blocks) == 3
    for _ in range(2):
        one.update()
        three.update()
        assert torch.equal(one.get_distances(), three.get_distances())
        assert torch.equal(one.get_semantic_labels(), three.get_semantic_labels())
        assert torch.equal(one.get_hit_mask(), three.get_hit_mask())
        assert torch.equal(one.data.ray_directions_w, three.data.ray_directions_w)
    assert 0.0 < one.get_hit_mask().float().mean() < 1.0


def test_a_pipeline_refused_while_made_closes_cleanly() -> None:
    """An unknown device is refused in ``__init__``; the half-made pipeline's ``close``
    (which ``__del__`` calls) must not raise, or the refusal ends in a second error."""
    from robotwright.sensors.device import WarpLidarPipeline

    model = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><geom size='1'/></worldbody></mujoco>"
    )
    pipeline = WarpLidarPipeline.__new__(WarpLidarPipeline)
    with pytest.raises(SensorError, match="warp device 'nope:7' is not available"):
        pipeline.__init__(model, 1, "nope:7", None, ("body", 0), None, None, "yaw", None, None)
    pipeline.close()  # raised AttributeError ('_pool') before
    assert getattr(pipeline, "_pool", None) is None
