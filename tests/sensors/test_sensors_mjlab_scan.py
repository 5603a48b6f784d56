"""The mjlab sensor as a sensor in time (marked ``mjlab``): the scan follows simulated
time, scans are held between updates, each environment has its own phase and a partial
reset touches only its environments; the realism options; the range image that
accumulates scans; the buffers it does not allocate; debug drawing in one pass.

Runs in the MuJoCo 3.11 environment of ``.ci/run`` on warp's CPU device.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from lidar_scenes import random_envs

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

import torch  # noqa: E402
from mjlab.sensor.builtin_sensor import ObjRef  # noqa: E402
from mjlab.viewer.native.visualizer import MujocoNativeDebugVisualizer  # noqa: E402
from test_sensors_mjlab import _Env, _robot_in_group_3  # noqa: E402

from robotwright.errors import SensorError  # noqa: E402
from robotwright.sensors import GridPatternCfg, LivoxPatternCfg  # noqa: E402
from robotwright.sensors import mjlab as rw_mjlab  # noqa: E402

RATE = 200_000.0  # the Mid-360's published points per second


def _make(model, cfg, envs: int = 3) -> _Env:
    return _Env(_robot_in_group_3(model), random_envs(model, envs, seed=4), cfg)


def _cfg(**kw):
    base = {"name": "lidar", "frame": ObjRef(type="site", name="lidar"), "max_distance": 30.0}
    return rw_mjlab.SemanticLidarSensorCfg(**{**base, **kw})


def _step(env: _Env, dt: float) -> None:
    """``dt`` seconds of simulated time, then one sense (mjlab's order)."""
    env.sensor.update(dt)
    env.ctx.prepare()
    import mujoco_warp as mjw
    import warp as wp

    with wp.ScopedDevice("cpu"):
        mjw.refit_bvh(env.mw, env.dw, env.ctx.render_context)
        env.sensor.raycast_kernel(rc=env.ctx.render_context)
    env.ctx.finalize()


def _local_dirs(sensor) -> np.ndarray:
    """``(E, N, 3)`` this step's ray directions in the sensor frame."""
    q = sensor.data.sensor_quat_w.numpy().astype(np.float64)
    dirs = sensor.data.ray_directions_w.numpy().astype(np.float64)
    out = np.empty_like(dirs)
    for e in range(dirs.shape[0]):
        rot = np.empty(9)
        mujoco.mju_quat2Mat(rot, q[e] / np.linalg.norm(q[e]))
        out[e] = dirs[e] @ rot.reshape(3, 3)
    return out


def test_a_timed_pattern_fires_in_simulated_time_and_a_partial_reset_is_local(clutter_model):
    """The window moves by points_per_second x the time passed (the latest N rays
    fired); a reset of env 1 restarts its window alone."""
    env = _make(clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=2000)))
    s, rows = env.sensor, env.sensor.table.directions.shape[0]
    _step(env, 0.0)
    assert (s.data.window_start.numpy() == 0).all()
    dt = 0.0025  # 500 rays
    for k in range(1, 5):
        _step(env, dt)
        start = s.data.window_start.numpy()
        assert (np.abs(start - round(k * dt * RATE) % rows) <= 1).all(), start
        want = s.table.directions[(start[0] + np.arange(2000)) % rows]
        np.testing.assert_allclose(_local_dirs(s)[0], want, atol=2e-5)
    before = s.data.window_start.numpy().copy()
    s.reset(torch.tensor([1]))
    _step(env, dt)
    after = s.data.window_start.numpy()
    assert after[1] == 0  # restarted at its phase, no time counted for it yet
    assert abs(after[0] - (before[0] + dt * RATE)) <= 1 and after[2] == after[0]
    # A second of simulated time at any step rate moves the window the same (carry kept).
    for dt_k, steps in ((0.02, 50), (0.05, 20)):
        s.reset(None)
        _step(env, 0.0)
        for _ in range(steps):
            _step(env, dt_k)
        assert abs(int(s.data.window_start.numpy()[0]) - RATE % rows) <= 1


def test_update_period_holds_the_scan_between_updates(clutter_model):
    env = _make(clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=2000), update_period=0.05))
    s = env.sensor
    _step(env, 0.0)
    assert (s.data.scan_due.numpy() == 1).all()
    published = [s.data.distances.numpy().copy()]
    dues = []
    for _ in range(6):
        _step(env, 0.02)
        dues.append(int(s.data.scan_due.numpy()[0]))
        now = s.data.distances.numpy().copy()
        if dues[-1]:
            assert not np.array_equal(now, published[-1])  # the window moved: a new scan
        else:
            np.testing.assert_array_equal(now, published[-1])  # held
        published.append(now)
    assert dues == [0, 0, 1, 0, 1, 0]  # every 0.05 s of 0.02 s steps (timer keeps the rest)
    s.reset(torch.tensor([2]))
    held = s.data.distances.numpy().copy()
    _step(env, 0.02)
    assert s.data.scan_due.numpy().tolist() == [0, 0, 1]  # a reset env is published at once
    # Only the due environment is cast: the others' rays are sent away from the world
    # (no hit), and their held scans stay as they were.
    cast = s._ray_dist.numpy()
    assert (cast[:2] == -1.0).all() and (cast[2] > 0).any()
    np.testing.assert_array_equal(s.data.distances.numpy()[:2], held[:2])


def test_a_held_scan_is_binned_with_its_own_window(clutter_model):
    """The range image of a held scan is the image of that scan when it was published:
    its window (``window_start``) is held with it while the live window moves on."""
    env = _make(clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=2000), update_period=0.05))
    s = env.sensor
    _step(env, 0.0)
    image = rw_mjlab.lidar_range_image(env, "lidar", 32, 8, scanned=True)
    start = s.data.window_start.numpy().copy()
    for _ in range(2):  # 0.02 and 0.04 s: held
        _step(env, 0.02)
        assert (s.data.scan_due.numpy() == 0).all()
        np.testing.assert_array_equal(s.data.window_start.numpy(), start)
        assert torch.equal(rw_mjlab.lidar_range_image(env, "lidar", 32, 8, scanned=True), image)
    _step(env, 0.02)  # 0.06 s: a new scan, in a window 0.06 s of firing further on
    assert (s.data.scan_due.numpy() == 1).all()
    moved = s.data.window_start.numpy()
    rows = s.table.directions.shape[0]
    assert (np.abs(moved - (start + round(0.06 * RATE)) % rows) <= 1).all()


def test_random_scan_phase_is_per_env_seeded_and_untimed_patterns_move_by_frames(clutter_model):
    cfg = _cfg(pattern=LivoxPatternCfg(num_rays=1000), scan_phase="random", seed=3)
    a, b = _make(clutter_model, cfg), _make(clutter_model, cfg)
    _step(a, 0.0)
    _step(b, 0.0)
    start = a.sensor.data.window_start.numpy().copy()
    assert len(set(start.tolist())) == 3  # each env its own phase
    np.testing.assert_array_equal(start, b.sensor.data.window_start.numpy())  # seeded
    a.sensor.reset(torch.tensor([0]))
    _step(a, 0.0)
    again = a.sensor.data.window_start.numpy()
    assert again[0] != start[0] and (again[1:] == start[1:]).all()
    # An untimed pattern (a grid: one frame) never moves; phases are frame starts.
    grid = _make(clutter_model, _cfg(pattern=GridPatternCfg(), scan_phase="random"))
    for _ in range(3):
        _step(grid, 0.05)
        assert (grid.sensor.data.window_start.numpy() == 0).all()


def test_range_noise_grows_with_distance_and_class_dropout_removes_one_class(clutter_model):
    clean = _make(clutter_model, _cfg(pattern=GridPatternCfg()))
    noisy = _make(clutter_model, _cfg(pattern=GridPatternCfg(), range_noise_per_meter=0.01))
    for env in (clean, noisy):
        _step(env, 0.0)
    hit = clean.sensor.data.hit_mask.numpy() & noisy.sensor.data.hit_mask.numpy()
    d0 = clean.sensor.data.distances.numpy()[hit]
    rel = (noisy.sensor.data.distances.numpy()[hit] - d0) / d0
    assert hit.sum() > 500 and 0.007 < rel.std() < 0.013, rel.std()
    clean = _make(clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=4000)))
    gone = _make(
        clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=4000), class_dropout={"terrain": 1.0})
    )
    for env in (clean, gone):
        _step(env, 0.0)
    names = gone.sensor.class_names
    labels = gone.sensor.data.semantic_labels.numpy()[gone.sensor.data.hit_mask.numpy()]
    clean_labels = clean.sensor.data.semantic_labels.numpy()[clean.sensor.data.hit_mask.numpy()]
    assert (clean_labels == names.index("terrain")).any()
    assert not (labels == names.index("terrain")).any() and labels.size > 0
    miss = ~gone.sensor.data.hit_mask.numpy()
    assert (gone.sensor.data.distances.numpy()[miss] == -1.0).all()  # mjlab's miss values


def test_angular_jitter_tilts_rays_by_about_its_standard_deviation(clutter_model):
    jitter = 0.01
    env = _make(clutter_model, _cfg(pattern=GridPatternCfg(), angular_jitter_std=jitter))
    ref = _make(clutter_model, _cfg(pattern=GridPatternCfg()))
    _step(env, 0.0)
    _step(ref, 0.0)
    a, b = env.sensor.data.ray_directions_w.numpy(), ref.sensor.data.ray_directions_w.numpy()
    np.testing.assert_allclose(np.linalg.norm(a, axis=-1), 1.0, atol=1e-5)
    angle = np.arccos(np.clip((a * b).sum(-1), -1.0, 1.0))
    # two perpendicular Gaussian components: the tilt is Rayleigh, mean sigma*sqrt(pi/2)
    assert abs(angle.mean() / (jitter * math.sqrt(math.pi / 2)) - 1.0) < 0.1


def test_mount_and_drift_are_drawn_per_env_at_reset(clutter_model):
    cfg = _cfg(
        pattern=LivoxPatternCfg(num_rays=500),
        mount_pos_range=(0.02, 0.02, 0.0),
        mount_rot_range=(0.0, 0.0, 0.1),
        drift_range=(-0.05, 0.05),
    )
    env = _make(clutter_model, cfg)
    nominal = _make(clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=500)))
    _step(env, 0.0)
    _step(nominal, 0.0)
    s, n = env.sensor, nominal.sensor
    shift = np.linalg.norm(s.data.sensor_pos_w.numpy() - n.data.sensor_pos_w.numpy(), axis=1)
    assert (shift > 0).all() and (shift <= 0.02 * math.sqrt(2) + 1e-5).all()
    turn = np.abs(s.data.sensor_quat_w.numpy() - n.data.sensor_quat_w.numpy()).max(axis=1)
    assert (turn > 0).all()

    def drift() -> np.ndarray:  # a Livox ray starts at the sensor: origin - position
        return s.data.ray_origins_w.numpy()[:, 0] - s.data.sensor_pos_w.numpy()

    first = drift()
    assert (np.abs(first) <= 0.05 + 1e-6).all() and len({tuple(d) for d in first.round(6)}) == 3
    _step(env, 0.02)
    np.testing.assert_allclose(drift(), first, atol=1e-6)  # constant within an episode
    s.reset(torch.tensor([1]))
    _step(env, 0.02)
    second = drift()
    np.testing.assert_allclose(second[[0, 2]], first[[0, 2]], atol=1e-6)
    assert not np.allclose(second[1], first[1])


def test_range_image_accumulates_scans_and_forgets_them_at_reset(clutter_model):
    env = _make(clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=400)))
    env.scene = {"lidar": env.sensor}
    _step(env, 0.0)
    for _ in range(3):
        one = rw_mjlab.lidar_range_image(env, "lidar", 32, 8, scanned=True)
        four = rw_mjlab.lidar_range_image(env, "lidar", 32, 8, scanned=True, accumulate=4)
        _step(env, 0.002)
    one = rw_mjlab.lidar_range_image(env, "lidar", 32, 8, scanned=True)
    four = rw_mjlab.lidar_range_image(env, "lidar", 32, 8, scanned=True, accumulate=4)
    again = rw_mjlab.lidar_range_image(env, "lidar", 32, 8, scanned=True, accumulate=4)
    torch.testing.assert_close(four, again)  # read twice in a step: stored once
    assert (four[:, -1] >= one[:, -1]).all() and four[:, -1].sum() > one[:, -1].sum()
    assert (four[:, 0] <= one[:, 0] + 1e-6).all()  # nearest over more rays
    env.sensor.reset(torch.tensor([0]))
    _step(env, 0.002)
    one = rw_mjlab.lidar_range_image(env, "lidar", 32, 8, scanned=True)
    four = rw_mjlab.lidar_range_image(env, "lidar", 32, 8, scanned=True, accumulate=4)
    torch.testing.assert_close(four[0], one[0])  # only the scan since its reset
    assert four[1, -1].sum() > one[1, -1].sum()
    with pytest.raises(SensorError, match="accumulate"):
        rw_mjlab.lidar_range_image(env, "lidar", 32, 8, accumulate=0)


def test_mjlab_s_unused_per_ray_tensors_are_not_allocated(clutter_model):
    env = _make(clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=3000)))
    s = env.sensor
    assert s._distances is None and s._normals_w is None and s._hit_pos_w is None
    assert s._ray_pnt.shape == (3, 3000) and s.num_rays == 3000


def test_debug_vis_writes_every_point_into_the_native_viewer_s_scene(clutter_model):
    env = _make(clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=4000), debug_vis=True))
    _step(env, 0.0)
    s = env.sensor
    s._debug_vis_enabled = True
    scene = mujoco.MjvScene(env.sensor._mj_model, maxgeom=10_000)
    vis = MujocoNativeDebugVisualizer(scene, env.sensor._mj_model, env_idx=1)
    before = scene.ngeom
    s.debug_vis(vis)
    hits = s.data.hit_mask[1].numpy()
    drawn = scene.ngeom - before
    assert drawn == min(int(hits.sum()), s.cfg.debug_vis_max_points) > 0
    pos = np.array([scene.geoms[before + j].pos for j in range(drawn)])
    expect = s.data.hit_pos_w[1].numpy()[hits]
    idx = np.arange(len(expect))
    if len(expect) > drawn:
        idx = np.linspace(0, len(expect) - 1, drawn).astype(np.int64)
    np.testing.assert_allclose(pos, expect[idx], atol=1e-6)
    labels = s.data.semantic_labels[1].numpy()[hits][idx]
    rgba = np.array([scene.geoms[before + j].rgba for j in range(drawn)])
    want = np.asarray(rw_mjlab.CLASS_COLORS, np.float32)[labels % len(rw_mjlab.CLASS_COLORS)]
    np.testing.assert_allclose(rgba, want)


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("update_period", -1.0, "update_period"),
        ("scan_phase", "late", "scan_phase"),
        ("range_noise_per_meter", float("nan"), "range_noise_per_meter"),
        ("angular_jitter_std", -0.1, "angular_jitter_std"),
        ("class_dropout", {"nothing": 0.5}, "class_dropout"),
        ("class_dropout", {"terrain": 1.5}, r"class_dropout\['terrain'\]"),
        ("mount_pos_range", (0.1, 0.1), "mount_pos_range"),
        ("mount_rot_range", (0.0, -1.0, 0.0), "mount_rot_range"),
        ("drift_range", (0.1, -0.1), "drift_range"),
    ],
)
def test_bad_timing_and_realism_fields_are_refused_naming_them(field, value, match):
    cfg = _cfg(pattern=GridPatternCfg())
    setattr(cfg, field, value)  # as tyro or a user would, after construction
    with pytest.raises(SensorError, match=f"SemanticLidarSensorCfg.{match}"):
        cfg.build()


def test_timing_and_realism_fields_are_set_from_mjlab_s_command_line() -> None:
    """tyro (mjlab's ``train``/``play``) reads the new fields, the class dropout as
    ``CLASS PROBABILITY`` pairs."""
    import tyro

    args = [
        "--class-dropout",
        "valuable",
        "0.3",
        "--update-period",
        "0.1",
        "--scan-phase",
        "random",
        "--mount-rot-range",
        "0",
        "0",
        "0.1",
        "--drift-range",
        "-0.01",
        "0.01",
    ]
    cfg = tyro.cli(type(_cfg()), default=_cfg(), args=args)
    assert cfg.class_dropout == {"valuable": 0.3} and cfg.update_period == 0.1
    assert cfg.scan_phase == "random" and cfg.mount_rot_range == (0.0, 0.0, 0.1)
    assert cfg.drift_range == (-0.01, 0.01)
    res = rw_mjlab.resolve(cfg)
    assert res.class_dropout[res.class_names.index("valuable")] == pytest.approx(0.3)


def test_point_cloud_accumulates_the_hits_of_the_last_scans(clutter_model):
    env = _make(clutter_model, _cfg(pattern=LivoxPatternCfg(num_rays=400)))
    env.scene = {"lidar": env.sensor}
    data = env.sensor.data
    hits = []
    _step(env, 0.0)
    for _ in range(3):
        hits.append(data.hit_mask.numpy().sum(axis=1))
        cloud = rw_mjlab.lidar_point_cloud(env, "lidar", 4096, frame="world", accumulate=3)
        _step(env, 0.002)
    hits.append(data.hit_mask.numpy().sum(axis=1))
    cloud = rw_mjlab.lidar_point_cloud(env, "lidar", 4096, frame="world", accumulate=3)
    used = (cloud[..., 3:].sum(-1) > 0).sum(dim=1).numpy()
    np.testing.assert_array_equal(used, np.sum(hits[-3:], axis=0))
    now = data.hit_pos_w.numpy()[0][data.hit_mask.numpy()[0]]
    got = cloud[0, : used[0], :3].numpy()
    # this step's hits are among the accumulated points, in the world frame
    assert all(np.abs(got - p).sum(axis=1).min() < 1e-5 for p in now[:50])
    env.sensor.reset(torch.tensor([0]))
    _step(env, 0.002)
    cloud = rw_mjlab.lidar_point_cloud(env, "lidar", 4096, frame="world", accumulate=3)
    used = (cloud[..., 3:].sum(-1) > 0).sum(dim=1).numpy()
    assert used[0] == data.hit_mask.numpy()[0].sum() and used[1] > data.hit_mask.numpy()[1].sum()
