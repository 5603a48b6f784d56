"""LidarSensor on analytic scenes: exact distances, alignment, ranges, noise, batching."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from lidar_scenes import ANALYTIC_XML, RaysPattern, forward, geom_id, random_envs

from robotwright.errors import SensorError
from robotwright.sensors import GridPatternCfg, LidarCfg, LidarSensor, LivoxPatternCfg

AXES = [(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0), (0, 0, -1), (0, 0, 1)]
# +x sphere surface at 2.5, +y box face at 2.5, -x capsule at 2.8, -y cube mesh at 2.5,
# floor 1 below, nothing above.
MISS = 100.0  # a miss reads max_distance by default (finite observations)
EXPECTED = [2.5, 2.5, 2.8, 2.5, 1.0, MISS]
EXPECTED_GEOMS = ["ball", "crate_geom", "pillar_geom", "cube", "floor", None]


@pytest.mark.parametrize("threads", [1, 2])
def test_primitive_and_mesh_distances_are_exact(analytic_model, threads):
    cfg = LidarCfg(prim_path="lidar_site", pattern_cfg=RaysPattern(AXES), num_threads=threads)
    sensor = LidarSensor(cfg, analytic_model, forward(analytic_model)[0])
    sensor.update()
    dist = sensor.get_distances()
    assert dist.shape == (1, 6)
    np.testing.assert_allclose(dist[0, :5], EXPECTED[:5], atol=1e-6, rtol=0)
    assert dist[0, 5] == MISS  # miss
    pts = sensor.get_pointcloud()
    np.testing.assert_allclose(pts[0, 0], [2.5, 0, 0], atol=1e-6)
    np.testing.assert_allclose(pts[0, 4], [0, 0, -1], atol=1e-6)
    assert np.isnan(pts[0, 5]).all()
    assert sensor.get_hit_mask().tolist() == [[True] * 5 + [False]]
    ids = sensor._raw_geom_ids[0].tolist()
    assert ids == [geom_id(analytic_model, n) if n else -1 for n in EXPECTED_GEOMS]


def test_heightfield_distance_is_exact(analytic_model):
    # The XML lists rows from +y down (MuJoCo stores them flipped: hfield_data row 0 is at
    # y=-1), so the ramp falls from 0.4 m at y=-1 to 0 at y=+1: 0.16 m high at y=0.2.
    cfg = LidarCfg(prim_path="hf_site", pattern_cfg=RaysPattern([(0, 0, -1)]))
    sensor = LidarSensor(cfg, analytic_model, forward(analytic_model)[0])
    sensor.update()
    np.testing.assert_allclose(sensor.get_distances()[0, 0], 2.0 - 0.4 * (1 - 0.2) / 2, atol=1e-6)
    np.testing.assert_array_equal(analytic_model.hfield_data[[0, 8]], [1.0, 0.0])
    assert sensor._raw_geom_ids[0, 0] == geom_id(analytic_model, "terrain_hf")


def test_grid_pattern_per_ray_origins(analytic_model):
    # A downward grid 1 m above the floor, away from the objects: every ray at 1.0 m.
    cfg = LidarCfg(
        prim_path="lidar_site",
        pattern_cfg=GridPatternCfg(resolution=0.25, size=(1.0, 0.5)),
        offset_pos=(10.0, 10.0, 0.0),
    )
    sensor = LidarSensor(cfg, analytic_model, forward(analytic_model)[0])
    sensor.update()
    assert sensor.num_rays == 5 * 3
    np.testing.assert_allclose(sensor.get_distances(), 1.0, atol=1e-9)
    pts = sensor.get_pointcloud()[0]
    np.testing.assert_allclose(pts[:, 2], -1.0, atol=1e-9)
    assert len(np.unique(pts[:, :2].round(6), axis=0)) == 15


def test_robot_excluded_by_default(analytic_model):
    data = forward(analytic_model)[0]
    torso = geom_id(analytic_model, "torso")
    on = LidarSensor(
        LidarCfg(prim_path="lidar_site", pattern_cfg=RaysPattern(AXES)), analytic_model, data
    )
    off = LidarSensor(
        LidarCfg(prim_path="lidar_site", pattern_cfg=RaysPattern(AXES), exclude_robot=False),
        analytic_model,
        data,
    )
    on.update()
    off.update()
    assert not on.hittable_geom_mask[torso] and off.hittable_geom_mask[torso]
    assert torso not in on._raw_geom_ids
    # From inside its own box, every ray exits the torso 0.1 m away.
    np.testing.assert_allclose(off.get_distances()[0], 0.1, atol=1e-9)


def test_mesh_prim_paths_select_geoms(analytic_model):
    data = forward(analytic_model)[0]
    cfg = LidarCfg(
        prim_path="lidar_site",
        pattern_cfg=RaysPattern(AXES),
        mesh_prim_paths=["ball", "/world/crate*"],
    )
    sensor = LidarSensor(cfg, analytic_model, data)
    sensor.update()
    d = sensor.get_distances()[0]
    np.testing.assert_allclose(d[:2], [2.5, 2.5], atol=1e-6)
    assert (d[2:] == MISS).all()  # capsule, mesh, floor not selected
    assert not sensor.get_hit_mask()[0, 2:].any()
    with pytest.raises(SensorError, match="'sofa\\*' matches no geom or body"):
        LidarSensor(
            LidarCfg(prim_path="lidar_site", mesh_prim_paths=["sofa*"]), analytic_model, data
        )


def test_unknown_carrier_names_the_problem(analytic_model):
    with pytest.raises(
        SensorError, match="no body or site named 'lidar_sit'.*did you mean 'lidar_site'"
    ):
        LidarSensor(LidarCfg(prim_path="lidar_sit"), analytic_model, forward(analytic_model)[0])


def test_min_max_range_make_misses(analytic_model):
    data = forward(analytic_model)[0]
    far = LidarSensor(
        LidarCfg(prim_path="lidar_site", pattern_cfg=RaysPattern(AXES), max_distance=2.6),
        analytic_model,
        data,
    )
    near = LidarSensor(
        LidarCfg(
            prim_path="lidar_site",
            pattern_cfg=RaysPattern(AXES),
            min_distance=2.0,
            miss_distance=-1.0,
        ),
        analytic_model,
        data,
    )
    far.update()
    near.update()
    assert far.get_hit_mask()[0].tolist() == [True, True, False, True, True, False]
    assert near.get_hit_mask()[0].tolist() == [True, True, True, True, False, False]
    assert near.get_distances()[0, 4] == -1.0  # the configured miss value
    # A hit the range model drops is a miss in every output: no geom id, so no label.
    assert far._raw_geom_ids[0, 2] == -1 and near._raw_geom_ids[0, 4] == -1
    assert far._raw_geom_ids[0, 0] >= 0 and near._raw_geom_ids[0, 3] >= 0


def test_alignment_base_yaw_world(analytic_model):
    # Turn the carrier: pitch 30 deg nose-down, then yaw 90 deg (robot is a fixed body,
    # so set its pose in the model before computing kinematics).
    pitch, yaw = math.radians(30.0), math.pi / 2
    q_yaw = [math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)]
    q_pitch = [math.cos(pitch / 2), 0, math.sin(pitch / 2), 0]
    q = np.empty(4)
    mujoco.mju_mulQuat(q, np.array(q_yaw), np.array(q_pitch))
    analytic_model.body_quat[
        mujoco.mj_name2id(analytic_model, mujoco.mjtObj.mjOBJ_BODY, "robot")
    ] = q
    data = forward(analytic_model)[0]
    res = {}
    for align in ("base", "yaw", "world"):
        s = LidarSensor(
            LidarCfg(
                prim_path="lidar_site", pattern_cfg=RaysPattern([(1, 0, 0)]), ray_alignment=align
            ),
            analytic_model,
            data,
        )
        s.update()
        res[align] = (s.get_distances()[0, 0], s.data.ray_directions_w[0, 0])
    # base: +x points along world +y, 30 deg down -> floor at 1/sin(30) = 2 m (box is 2.5 m away).
    np.testing.assert_allclose(res["base"][1], [0, math.cos(pitch), -math.sin(pitch)], atol=1e-12)
    np.testing.assert_allclose(res["base"][0], 2.0, atol=1e-6)
    # yaw: level ray along world +y -> box face at 2.5 m.
    np.testing.assert_allclose(res["yaw"][1], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(res["yaw"][0], 2.5, atol=1e-6)
    # world: pattern +x stays world +x -> sphere at 2.5 m.
    np.testing.assert_allclose(res["world"][1], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(res["world"][0], 2.5, atol=1e-6)


def test_offset_pose(analytic_model):
    # Carrier body origin + offset 1 m up, turned 90 deg about z: +x ray goes to world +y.
    c = math.cos(math.pi / 4)
    cfg = LidarCfg(
        prim_path="robot",
        pattern_cfg=RaysPattern([(1, 0, 0), (0, 0, -1)]),
        offset_pos=(0, 0, 1.0),
        offset_rot=(c, 0, 0, c),
    )
    s = LidarSensor(cfg, analytic_model, forward(analytic_model)[0])
    s.update()
    np.testing.assert_allclose(s.data.pos_w[0], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(s.data.quat_w[0], [c, 0, 0, c], atol=1e-12)
    d = s.get_distances()[0]
    # The box top is at z=0.5, the ray at z=1 passes over it.
    assert d[0] == MISS and not s.get_hit_mask()[0, 0]
    np.testing.assert_allclose(d[1], 2.0, atol=1e-9)
    np.testing.assert_allclose(s.get_pointcloud(frame="sensor")[0, 1], [0, 0, -2.0], atol=1e-9)


def test_noise_and_dropout_are_seeded_and_keep_misses(analytic_model):
    data = forward(analytic_model)[0]
    dirs = np.tile(AXES, (2000, 1))
    cfg = dict(
        prim_path="lidar_site",
        pattern_cfg=RaysPattern(dirs),
        range_noise_std=0.01,
        dropout_prob=0.2,
        seed=3,
    )
    a, b = (
        LidarSensor(LidarCfg(**cfg), analytic_model, data),
        LidarSensor(LidarCfg(**cfg), analytic_model, data),
    )
    a.update()
    b.update()
    np.testing.assert_array_equal(a.get_distances(), b.get_distances())
    d, hit = a.get_distances()[0], a.get_hit_mask()[0]
    up = np.arange(dirs.shape[0]) % 6 == 5
    assert not hit[up].any() and (d[up] == MISS).all()  # misses stay misses, noise or not
    assert (d[~hit] == MISS).all() and (d[hit] < 3.0).all()
    expected = np.tile(EXPECTED, 2000)
    err = d[hit] - expected[hit]
    assert abs(err.mean()) < 0.01 * 5 / math.sqrt(err.size)
    assert 0.0095 < err.std() < 0.0105
    assert (a._raw_geom_ids[0][~hit] == -1).all() and (a._raw_geom_ids[0][hit] >= 0).all()
    kept = hit[~up].mean()  # binomial(10000, 0.8): std 0.004
    assert abs(kept - 0.8) < 0.02
    a.update()
    assert not np.array_equal(a.get_distances(), b.get_distances())  # fresh noise per frame


@pytest.mark.parametrize("engine", ["mujoco", pytest.param("warp", marks=pytest.mark.warp)])
def test_batched_equals_loop_of_single_envs(clutter_model, engine):
    if engine == "warp":
        pytest.importorskip("mujoco_warp", reason="robotwright[warp] not installed")
    datas = random_envs(clutter_model, 4)
    pattern = LivoxPatternCfg(num_rays=3000)
    batched = LidarSensor(
        LidarCfg(prim_path="lidar", pattern_cfg=pattern, engine=engine), clutter_model, datas
    )
    batched.update()
    assert batched.get_distances().shape == (4, 3000)
    for e, d in enumerate(datas):
        single = LidarSensor(
            LidarCfg(prim_path="lidar", pattern_cfg=pattern, engine=engine), clutter_model, d
        )
        single.update()
        np.testing.assert_array_equal(
            single.get_distances()[0], batched.get_distances(env_ids=[e])[0]
        )
        np.testing.assert_array_equal(single._raw_geom_ids[0], batched._raw_geom_ids[e])
    # Different poses give different scans.
    assert not np.array_equal(batched.get_distances()[0], batched.get_distances()[1])


def test_moving_bodies_seen_after_mj_step():
    xml = """<mujoco><option gravity="0 0 0" timestep="0.01"/><worldbody>
      <site name="s" pos="0 0 0"/>
      <body name="cart" pos="3 0 0"><joint name="x" type="slide" axis="1 0 0"/>
        <geom name="box" type="box" size="0.5 0.5 0.5" mass="1"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = forward(model)[0]
    data.qvel[0] = 2.0
    sensor = LidarSensor(LidarCfg(prim_path="s", pattern_cfg=RaysPattern([(1, 0, 0)])), model, data)
    sensor.update()
    np.testing.assert_allclose(sensor.get_distances()[0, 0], 2.5, atol=1e-9)
    for _ in range(10):
        mujoco.mj_step(model, data)
    assert data.qpos[0] > 0.19  # the box moved about 0.2 m away
    sensor.update()
    np.testing.assert_allclose(sensor.get_distances()[0, 0], 2.5 + data.xpos[1, 0] - 3.0, atol=1e-9)


def test_env_ids_out_of_range(analytic_model):
    s = LidarSensor(
        LidarCfg(prim_path="lidar_site", pattern_cfg=RaysPattern(AXES)),
        analytic_model,
        forward(analytic_model, 2),
    )
    s.update()
    assert s.get_distances(env_ids=[1]).shape == (1, 6)
    with pytest.raises(SensorError, match="env_ids"):
        s.get_distances(env_ids=[2])


def test_data_from_another_model_is_rejected(analytic_model, clutter_model):
    with pytest.raises(SensorError, match="expected an MjData of this model"):
        LidarSensor(LidarCfg(prim_path="lidar_site"), analytic_model, forward(clutter_model)[0])


def test_threads_split_envs_and_chunks_identically(clutter_model):
    datas = random_envs(clutter_model, 3, seed=5)
    pattern = LivoxPatternCfg(num_rays=5000)
    out = []
    for threads in (1, 2, 4):
        cfg = LidarCfg(prim_path="lidar", pattern_cfg=pattern, num_threads=threads)
        s = LidarSensor(cfg, clutter_model, datas)
        s.update()
        out.append((s.get_distances(), s._raw_geom_ids.copy()))
    for dist, ids in out[1:]:
        np.testing.assert_array_equal(dist, out[0][0])
        np.testing.assert_array_equal(ids, out[0][1])


def test_sensor_on_world_body_excludes_nothing():
    spec = mujoco.MjSpec.from_string(ANALYTIC_XML)
    spec.worldbody.add_site(name="world_site", pos=[0, 0, 0])
    model = spec.compile()
    s = LidarSensor(
        LidarCfg(prim_path="world_site", pattern_cfg=RaysPattern(AXES)), model, forward(model)
    )
    assert s.robot_body_ids().size == 0 and s.hittable_geom_mask.all()
    s.update()
    # The torso (0.1 m box around the origin) is hit from inside on every ray.
    np.testing.assert_allclose(s.get_distances()[0], 0.1, atol=1e-9)


@pytest.mark.parametrize("engine", ["mujoco", pytest.param("warp", marks=pytest.mark.warp)])
def test_ellipsoid_and_cylinder_distances(engine):
    if engine == "warp":
        pytest.importorskip("mujoco_warp", reason="robotwright[warp] not installed")
    xml = """<mujoco><worldbody>
      <site name="s" pos="0 0 0"/><site name="above" pos="0 3 2"/>
      <geom name="ell" type="ellipsoid" size="0.5 1.0 0.3" pos="3 0 0"/>
      <geom name="cyl" type="cylinder" size="0.4 0.5" pos="0 3 0"/>
      <geom name="ell_tilted" type="ellipsoid" size="0.2 0.2 0.6" pos="-3 0 0" euler="0 90 0"/>
    </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = forward(model)
    side = LidarSensor(LidarCfg(prim_path="s", pattern_cfg=RaysPattern([(1, 0, 0), (0, 1, 0), (-1, 0, 0)]),
                                engine=engine), model, data)  # fmt: skip
    side.update()
    # Ellipsoid x semi-axis 0.5; cylinder side r=0.4; tilted ellipsoid's long axis along x (0.6).
    np.testing.assert_allclose(
        side.get_distances()[0], [2.5, 2.6, 2.4], atol=1e-6 if engine == "mujoco" else 1e-5
    )
    top = LidarSensor(
        LidarCfg(prim_path="above", pattern_cfg=RaysPattern([(0, 0, -1)]), engine=engine),
        model,
        data,
    )
    top.update()
    np.testing.assert_allclose(
        top.get_distances()[0, 0], 1.5, atol=1e-6 if engine == "mujoco" else 1e-5
    )  # cap


def test_sensor_frame_points_use_the_pose_at_scan_time():
    xml = """<mujoco><worldbody><geom name="floor" type="plane" size="10 10 0.1"/>
      <body name="bot" pos="0 0 1"><freejoint/><geom type="sphere" size="0.05"/></body>
      </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = forward(model)[0]
    s = LidarSensor(LidarCfg(prim_path="bot", pattern_cfg=RaysPattern([(1, 0, -1)])), model, data)
    s.update()
    before = s.get_pointcloud(frame="sensor")
    np.testing.assert_allclose(before[0, 0], [1.0, 0.0, -1.0], atol=1e-9)
    data.qpos[:3] = [5.0, 5.0, 3.0]  # move after the scan: the scan's points do not change
    mujoco.mj_forward(model, data)
    np.testing.assert_array_equal(s.get_pointcloud(frame="sensor"), before)
    np.testing.assert_allclose(s.get_pointcloud()[0, 0], [1.0, 0.0, 0.0], atol=1e-9)
    with pytest.raises(SensorError, match="frame: expected 'world' or 'sensor'"):
        s.get_pointcloud(frame="body")
