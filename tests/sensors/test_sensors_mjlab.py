"""The mjlab adapter: our kernels inside mjlab's ray-cast pipeline (marked ``mjlab``).

Runs in the MuJoCo 3.11 environment of ``.ci/run`` (mjlab pins MuJoCo 3.11), on warp's
CPU device; skipped with a reason where mjlab is not installed.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest
from lidar_scenes import random_envs

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

import torch  # noqa: E402
import warp as wp  # noqa: E402
from mjlab.sensor.builtin_sensor import ObjRef  # noqa: E402
from mjlab.sensor.raycast_sensor import GridPatternCfg as MjlabGridPatternCfg  # noqa: E402
from mjlab.sensor.raycast_sensor import RayCastSensor  # noqa: E402
from mjlab.sensor.sensor_context import SensorContext  # noqa: E402
from mjlab.sim.sim_data import WarpBridge  # noqa: E402

from robotwright.errors import SensorError  # noqa: E402
from robotwright.sensors import (  # noqa: E402
    DEFAULT_SEMANTIC_CLASS_MAPPING,
    FilePatternCfg,
    GridPatternCfg,
    LivoxPatternCfg,
    PinholeCameraPatternCfg,
    SemanticLidarCfg,
    SemanticLidarSensor,
    SpinningLidarPatternCfg,
    classify_path,
    learning_obs,  # noqa: E402
)
from robotwright.sensors import mjlab as rw_mjlab  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _robot_in_group_3(model: mujoco.MjModel) -> mujoco.MjModel:
    """As in mjlab's assets: the robot's geoms outside group 0, which the sensor casts at."""
    root = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "robot")
    robot = np.flatnonzero(model.body_rootid == root)
    model.geom_group[np.isin(model.geom_bodyid, robot)] = 3
    return model


class _Env:
    """The parts of an mjlab env the sensor uses: a scene dict and mjlab's sense sequence
    (``Simulation.sense``: prepare, then refit the BVH and cast, then finalize)."""

    def __init__(self, model: mujoco.MjModel, host: list[mujoco.MjData], cfg) -> None:
        import mujoco_warp as mjw

        with wp.ScopedDevice("cpu"):
            self.mw = mjw.put_model(model)
            self.dw = mjw.put_data(model, host[0], nworld=len(host))
            self.dw.qpos.assign(np.stack([d.qpos for d in host]).astype(np.float32))
            mjw.kinematics(self.mw, self.dw)
        self.sensor = cfg.build()
        mb, db = WarpBridge(self.mw, nworld=len(host)), WarpBridge(self.dw)
        self.sensor.initialize(model, mb, db, "cpu")
        self.ctx = SensorContext(model, mb, db, [], [self.sensor], "cpu")
        self.scene = {cfg.name: self.sensor}
        self.num_envs = len(host)

    def sense(self) -> None:
        """One sensed step; a timed pattern's sensor is told that one frame's time
        passed since the last (mjlab's env tells it every physics step)."""
        import mujoco_warp as mjw

        for s in self.ctx.raycast_sensors:
            if s._rate > 0.0:
                s.update(s.table.rays_per_frame / s._rate)
        self.ctx.prepare()
        with wp.ScopedDevice("cpu"):
            mjw.refit_bvh(self.mw, self.dw, self.ctx.render_context)
            for s in self.ctx.raycast_sensors:
                s.raycast_kernel(rc=self.ctx.render_context)
        self.ctx.finalize()


class _FixedWindow(LivoxPatternCfg):
    """A Mid-360 that casts one window of its firing stream, starting at ray ``first``
    (the window an mjlab sensor casts after some simulated time)."""

    def __init__(self, first: int) -> None:
        super().__init__(sensor_type="mid360")
        self.first = first

    def ray_table(self):  # noqa: ANN201
        from robotwright.sensors.patterns import RayTable

        rows = self.table_frames * self.num_rays
        idx = (self.first + np.arange(self.num_rays)) % rows
        dirs = self._fire(0, rows)[idx]
        return RayTable(np.zeros_like(dirs), dirs, self.num_rays)


def _check_labels(sensor, data) -> None:
    """Each label is the class of the hit geom's path; misses are label 0, id -1."""
    ids, labels = data.geom_ids.numpy(), data.semantic_labels.numpy()
    hit = data.hit_mask.numpy()
    assert ((ids >= 0) == hit).all()
    for g in np.unique(ids[hit]):
        expect = classify_path(sensor.geom_paths[g], sensor.semantic_class_mapping)
        assert (labels[ids == g] == expect).all(), sensor.geom_paths[g]
    assert (labels[~hit] == 0).all()


def _compare_with_core(data, ref: SemanticLidarSensor) -> None:
    """>= 99.9% of geom ids equal; labels equal where ids agree; distances close."""
    ids, ids_ref = data.geom_ids.numpy(), ref.get_mesh_ids()
    same = ids == ids_ref
    assert same.mean() >= 0.999, same.mean()
    labels, labels_ref = data.semantic_labels.numpy(), ref.get_semantic_labels()
    assert (labels[same] == labels_ref[same]).all()
    both = same & (ids_ref >= 0)
    dist_ref = ref.get_distances()[both]
    err = np.abs(data.distances.numpy()[both] - dist_ref)
    # float32 rays (mujoco-warp) against float64 (MuJoCo): directions are rounded to
    # ~1e-7 rad, which grazing hits turn into up to ~1e-6 m per metre of range; float32
    # mesh/heightfield triangles add ~1e-5 m on a few grazing hits.
    assert (err <= 1e-5 + 2e-6 * dist_ref).mean() >= 0.999 and err.max() < 1e-4


def test_mjlab_sensor_matches_the_core_sensor_and_labels_geoms(clutter_model):
    model = _robot_in_group_3(clutter_model)
    host = random_envs(model, 3, seed=9)
    pattern = LivoxPatternCfg(num_rays=20000)
    offset = {"offset_pos": (0.05, -0.02, 0.03), "offset_rot": (0.9659258, 0.0, 0.258819, 0.0)}
    cfg = rw_mjlab.SemanticLidarSensorCfg(
        name="lidar",
        frame=ObjRef(type="site", name="lidar"),
        pattern=pattern,
        max_distance=30.0,
        **offset,
    )
    env = _Env(model, host, cfg)
    assert isinstance(env.sensor, RayCastSensor)  # mjlab's scene treats it as a ray sensor
    ref = SemanticLidarSensor(
        SemanticLidarCfg(
            prim_path="lidar",
            pattern_cfg=pattern,
            max_distance=30.0,
            return_mesh_ids=True,
            **offset,
        ),
        model,
        host,
    )
    # Same hittable geoms: mjlab's groups + parent body vs the core's robot exclusion.
    assert (env.sensor.hittable_geom_mask == ref.hittable_geom_mask).all()
    data = env.sensor.data
    pointer = data.distances.data_ptr()
    first_dirs = None
    for step in range(3):
        env.sense()
        ref.update()
        assert env.sensor.data is data and data.distances.data_ptr() == pointer
        assert data.distances.data_ptr() == env.sensor._buffers["distances"].ptr  # zero-copy
        assert int(data.frame[0]) == step == ref.data.frame
        _compare_with_core(data, ref)
        _check_labels(env.sensor, data)
        np.testing.assert_allclose(data.sensor_pos_w.numpy(), ref.data.pos_w, atol=1e-5)
        miss = ~data.hit_mask.numpy()
        assert (data.distances.numpy()[miss] == -1.0).all()  # mjlab's miss value
        assert (env.sensor.get_distances().numpy()[miss] == 30.0).all()  # the seed's
        assert set(np.unique(data.semantic_labels.numpy()).tolist()) == {0, 1, 2, 3}
        assert data.distances.device == torch.device("cpu") and data.distances.shape == (3, 20000)
        dirs = data.ray_directions_w.numpy().copy()
        if first_dirs is None:
            first_dirs = dirs
        else:
            assert not np.allclose(dirs, first_dirs)  # the Mid-360 window advances
    # Observation terms.
    obs = rw_mjlab.lidar_semantic_obs(env, "lidar")
    assert obs.shape == (3, 40000) and torch.isfinite(obs).all()
    assert torch.equal(obs[:, 0::2], env.sensor.get_distances())
    assert torch.equal(obs[:, 1::2], data.semantic_labels.float())
    norm = rw_mjlab.lidar_distances_normalized(env, "lidar")
    assert float(norm.max()) == 1.0 and float(norm.min()) >= 0.0
    assert torch.equal(norm, env.sensor.get_distances() / 30.0)
    classes = len(env.sensor.class_names)  # unknown, the 3 default classes, robot
    assert classes == 5
    one_hot = rw_mjlab.lidar_one_hot_classes(env, "lidar").reshape(3, 20000, classes)
    assert torch.equal(one_hot.sum(-1), torch.ones(3, 20000))
    assert torch.equal(one_hot.argmax(-1).int(), data.semantic_labels)
    assert torch.equal(rw_mjlab.lidar_class_ids(env, "lidar"), data.semantic_labels.float())


def _angles_file(tmp_path: Path) -> Path:
    path = tmp_path / "rays.csv"
    az = np.linspace(-math.pi, math.pi, 90, endpoint=False)
    rows = [f"{a:.6f},{e:.6f}" for e in (-0.3, -0.1, 0.1) for a in az]
    path.write_text("azimuth,elevation\n" + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize(
    "make_pattern",
    [
        lambda tmp: LivoxPatternCfg(sensor_type="avia", num_rays=1500),
        lambda tmp: SpinningLidarPatternCfg.vlp16(horizontal_resolution=math.radians(2.0)),
        lambda tmp: GridPatternCfg(size=(2.0, 1.0), resolution=0.1),
        lambda tmp: PinholeCameraPatternCfg(width=32, height=24),
        lambda tmp: FilePatternCfg(path=_angles_file(tmp)),
    ],
    ids=["avia", "vlp16", "grid", "pinhole", "file"],
)
def test_every_robotwright_pattern_matches_the_core_sensor(clutter_model, tmp_path, make_pattern):
    model = _robot_in_group_3(clutter_model)
    host = random_envs(model, 2, seed=3)
    pattern = make_pattern(tmp_path)
    cfg = rw_mjlab.SemanticLidarSensorCfg(
        name="lidar", frame=ObjRef(type="site", name="lidar"), pattern=pattern, max_distance=30.0
    )
    env = _Env(model, host, cfg)
    ref = SemanticLidarSensor(
        SemanticLidarCfg(
            prim_path="lidar", pattern_cfg=pattern, max_distance=30.0, return_mesh_ids=True
        ),
        model,
        host,
    )
    assert env.sensor.num_rays == pattern.num_rays == ref.num_rays
    for _ in range(2):
        env.sense()
        ref.update()
        _compare_with_core(env.sensor.data, ref)
        _check_labels(env.sensor, env.sensor.data)
        # Rays start at the pattern's origins: world origin = pos + R @ table origin.
        o, _ = env.sensor.table.window(int(env.sensor.data.frame[0]))
        rot = ref.data.ray_rot_w
        expect = ref.data.pos_w[:, None, :] + np.einsum("eij,nj->eni", rot, o)
        np.testing.assert_allclose(env.sensor.data.ray_origins_w.numpy(), expect, atol=1e-5)
    assert env.sensor.data.hit_mask.numpy().any()


def test_mjlab_patterns_geom_frames_and_alignment(clutter_model):
    """mjlab's own grid pattern, on a geom frame with yaw alignment, casts as mjlab does."""
    model = _robot_in_group_3(clutter_model)
    host = random_envs(model, 2, seed=5)
    grid = MjlabGridPatternCfg(size=(0.6, 0.4), resolution=0.2, direction=(0.0, 0.0, -1.0))
    cfg = rw_mjlab.SemanticLidarSensorCfg(
        name="scan",
        frame=ObjRef(type="geom", name="base"),
        pattern=grid,
        ray_alignment="yaw",
        max_distance=5.0,
    )
    env = _Env(model, host, cfg)
    env.sense()
    data = env.sensor.data
    offsets, dirs = grid.generate_rays(None, "cpu")
    g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "base")
    for e, d in enumerate(host):
        np.testing.assert_allclose(data.pos_w.numpy()[e], d.geom_xpos[g], atol=1e-5)
        mat = d.geom_xmat[g].reshape(3, 3)
        yaw = math.atan2(mat[1, 0], mat[0, 0])
        c, s = math.cos(yaw), math.sin(yaw)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        np.testing.assert_allclose(
            data.ray_origins_w.numpy()[e], d.geom_xpos[g] + offsets.numpy() @ rot.T, atol=1e-5
        )
        np.testing.assert_allclose(data.ray_directions_w.numpy()[e], dirs.numpy(), atol=1e-6)
    # Straight down onto the ground plane (the robot's own geoms are in group 3).
    hit = data.hit_mask.numpy()
    assert hit.all()
    names = {env.sensor.geom_paths[i] for i in np.unique(data.geom_ids.numpy())}
    assert names == {"/world/ground"}
    z = np.array([d.geom_xpos[g][2] for d in host])
    assert data.distances.shape == (2, offsets.shape[0]) == (2, 12)
    np.testing.assert_allclose(data.distances.numpy(), np.repeat(z[:, None], 12, 1), atol=1e-4)
    assert (data.semantic_labels.numpy() == 1).all()


def test_range_model_and_miss_value(clutter_model):
    model = _robot_in_group_3(clutter_model)
    host = random_envs(model, 2, seed=1)
    base = dict(name="lidar", frame=ObjRef(type="site", name="lidar"), max_distance=6.0)
    pattern = LivoxPatternCfg(num_rays=4000)
    clean = _Env(model, host, rw_mjlab.SemanticLidarSensorCfg(**base, pattern=pattern))
    noisy = _Env(
        model,
        host,
        rw_mjlab.SemanticLidarSensorCfg(
            **base,
            pattern=pattern,
            min_distance=0.5,
            range_noise_std=0.01,
            dropout_prob=0.2,
            miss_distance=-1.0,
            seed=7,
        ),
    )
    clean.sense()
    noisy.sense()
    c, n = clean.sensor.data, noisy.sensor.data
    c_hit, n_hit = c.hit_mask.numpy(), n.hit_mask.numpy()
    assert not (n_hit & ~c_hit).any()  # noise and dropout never create hits
    kept = n_hit.sum() / (c_hit & (c.distances.numpy() >= 0.5)).sum()
    assert 0.75 < kept < 0.85  # dropout 0.2
    diff = n.distances.numpy()[n_hit] - c.distances.numpy()[n_hit]
    assert 0.008 < diff.std() < 0.012 and np.abs(diff).max() < 0.1
    assert (n.distances.numpy()[~n_hit] == -1.0).all()
    # mjlab's convention: a miss's hit point is the ray origin, its normal zero.
    np.testing.assert_array_equal(n.hit_pos_w.numpy()[~n_hit], n.ray_origins_w.numpy()[~n_hit])
    assert (n.normals_w.numpy()[~n_hit] == 0.0).all()
    assert np.isnan(noisy.sensor.get_pointcloud().numpy()[~n_hit]).all()
    assert ((n.distances.numpy()[n_hit] >= 0.5) & (n.distances.numpy()[n_hit] <= 6.0)).all()
    # The CPU column blocks (parallel launches) give exactly the one-launch result (the
    # CUDA path), noise and dropout included: each ray's random stream is its own.
    for threads in (1, 3):
        other = _Env(
            model,
            host,
            rw_mjlab.SemanticLidarSensorCfg(
                **base,
                pattern=pattern,
                min_distance=0.5,
                range_noise_std=0.01,
                dropout_prob=0.2,
                miss_distance=-1.0,
                seed=7,
                num_threads=threads,
            ),
        )
        assert len(other.sensor._blocks) == threads
        other.sense()
        o = other.sensor.data
        for key in ("distances", "geom_ids", "semantic_labels", "hit_mask"):
            assert torch.equal(getattr(o, key), getattr(n, key)), (threads, key)


SELF_SEEING_XML = """
<mujoco>
  <worldbody>
    <body name="terrain"><geom name="terrain" type="plane" size="10 10 0.1"/></body>
    <body name="robot" pos="0 0 0.5"><freejoint/>
      <geom name="base" type="box" size="0.2 0.1 0.05" group="3"/>
      <body name="leg" pos="0 0 -0.2"><geom name="shin" type="capsule" size="0.03 0.15"/></body>
    </body>
  </worldbody>
</mujoco>
"""


def test_defaults_class_terrain_and_the_robot_and_warn_only_when_unlabelled():
    model = mujoco.MjModel.from_xml_string(SELF_SEEING_XML)
    host = random_envs(model, 1)
    shin = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "shin")
    base = {
        "name": "lidar",
        "frame": ObjRef(type="body", name="robot"),
        "pattern": GridPatternCfg(),
    }
    # Defaults: mjlab terrain is terrain, the robot's own (included) shin is "robot".
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = _Env(model, host, rw_mjlab.SemanticLidarSensorCfg(**base))
    env.sense()
    names = env.sensor.class_names
    assert names == ("unknown", *DEFAULT_SEMANTIC_CLASS_MAPPING, "robot")
    ids, labels = env.sensor.data.geom_ids.numpy(), env.sensor.data.semantic_labels.numpy()
    assert (ids == shin).any() and (ids == 0).any()
    assert (labels[ids == shin] == names.index("robot")).all()
    assert (labels[ids == 0] == names.index("terrain")).all()
    assert env.sensor.classify_geom(shin) == names.index("robot")
    # self_class=None and a mapping without mjlab's terrain keyword: both warned about.
    cfg = rw_mjlab.SemanticLidarSensorCfg(
        **base, self_class=None, semantic_class_mapping=dict(DEFAULT_SEMANTIC_CLASS_MAPPING)
    )
    with pytest.warns(UserWarning) as caught:
        env = _Env(model, host, cfg)
    text = " ".join(str(w.message) for w in caught)
    assert "/world/robot/leg/shin" in text and "see its own robot" in text
    assert "/world/terrain/terrain" in text and "mjlab_class_mapping" in text
    env.sense()
    ids, labels = env.sensor.data.geom_ids.numpy(), env.sensor.data.semantic_labels.numpy()
    assert (labels[(ids == shin) | (ids == 0)] == 0).all()
    assert (
        rw_mjlab.mjlab_class_mapping()["terrain"][:4] == DEFAULT_SEMANTIC_CLASS_MAPPING["terrain"]
    )


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"frame": "trunk"}, "frame: expected one ObjRef"),
        ({"frame": ObjRef(type="joint", name="hip")}, "frame: expected one ObjRef"),
        ({"pattern": "mid360"}, "pattern: expected a robotwright PatternCfg"),
        ({"max_distance": 0.0}, "min_distance < max_distance"),
        ({"dropout_prob": 1.5}, "dropout_prob"),
        ({"offset_rot": (0.0, 0.0, 0.0, 0.0)}, "offset_rot"),
        ({"semantic_class_mapping": {"terrain": []}}, "empty keyword list"),
        ({"miss_distance": math.inf}, "miss_distance"),
        ({"ray_alignment": "roll"}, "ray_alignment"),
        ({"include_geom_groups": (7,)}, "include_geom_groups"),
        ({"self_class": ""}, "self_class"),
        ({"debug_vis_max_points": -1}, "debug_vis_max_points"),
        ({"refine_curved_hits": 1}, "refine_curved_hits"),
    ],
)
def test_config_is_validated_in_build_after_any_change(kwargs, message):
    """Construction never fails (mjlab changes configs after creating them); build() does,
    whether the bad value was given at construction or set afterwards."""
    base = {"name": "lidar", "frame": ObjRef(type="body", name="trunk", entity="robot")}
    given = rw_mjlab.SemanticLidarSensorCfg(**{**base, **kwargs})
    with pytest.raises(SensorError, match=message) as refused:
        given.build()
    # named in the terms of the config the user wrote, not the core config it fills
    assert str(refused.value).startswith("SemanticLidarSensorCfg")
    assert "SemanticLidarCfg" not in str(refused.value)
    later = rw_mjlab.SemanticLidarSensorCfg(**base)
    later.build()  # the defaults are valid
    for key, value in kwargs.items():
        setattr(later, key, value)
    with pytest.raises(SensorError, match=message):
        later.build()


def test_pattern_fields_edited_after_construction_are_checked_in_build():
    """mjlab's CLI edits ``cfg.pattern.*`` after the config is made: the edit takes effect
    (the Avia preset, not the Mid-360's under its name) and a bad value fails in build()."""
    base = {"name": "lidar", "frame": ObjRef(type="body", name="trunk", entity="robot")}
    cfg = rw_mjlab.SemanticLidarSensorCfg(**base, pattern=LivoxPatternCfg(num_rays=500))
    cfg.pattern.sensor_type = "avia"
    rw_mjlab.resolve(cfg)  # valid
    avia = LivoxPatternCfg(sensor_type="avia", num_rays=500)
    np.testing.assert_array_equal(cfg.pattern.ray_table().directions, avia.ray_table().directions)
    cfg.pattern.num_rays = 0
    with pytest.raises(SensorError, match=r"SemanticLidarSensorCfg\.pattern: .*num_rays: expected"):
        cfg.build()


def test_class_mapping_from_a_command_line():
    """mjlab's train/play CLI (tyro) reads a dict of lists as one class only; the string
    field ``semantic_classes`` sets the whole mapping from a command line."""
    import dataclasses

    import tyro

    base = {"name": "lidar", "frame": ObjRef(type="body", name="trunk", entity="robot")}

    @dataclasses.dataclass
    class Scene:
        lidar: rw_mjlab.SemanticLidarSensorCfg = dataclasses.field(
            default_factory=lambda: rw_mjlab.SemanticLidarSensorCfg(**base)
        )

    text = "valuable = sofa, table; dynamic_obstacle=box"
    scene = tyro.cli(Scene, args=["--lidar.semantic-classes", text])
    resolved = rw_mjlab.resolve(scene.lidar)
    assert resolved.mapping == {"valuable": ["sofa", "table"], "dynamic_obstacle": ["box"]}
    assert resolved.class_names == ("unknown", "valuable", "dynamic_obstacle", "robot")
    for bad, words in [
        ("valuable", "expected CLASS=KEYWORD"),
        ("a=x;a=y", "class 'a' given twice"),
        ("a=x,,y", "expected CLASS=KEYWORD"),
        ("unknown=x", "unknown"),
    ]:
        cfg = rw_mjlab.SemanticLidarSensorCfg(**base, semantic_classes=bad)
        with pytest.raises(SensorError, match=words) as refused:
            cfg.build()
        assert str(refused.value).startswith("SemanticLidarSensorCfg")
    both = rw_mjlab.SemanticLidarSensorCfg(
        **base, semantic_classes="a=x", semantic_class_mapping={"a": ["x"]}
    )
    with pytest.raises(SensorError, match="both given"):
        both.build()


def test_a_config_that_is_not_an_mjlab_sensor_config_is_named():
    core = SemanticLidarCfg(prim_path="trunk")
    with pytest.raises(SensorError, match="not an mjlab sensor config"):
        rw_mjlab.resolve(core)
    # Put into mjlab's scene.sensors by mistake, the core config says what to use.
    with pytest.raises(SensorError, match="robotwright.sensors.mjlab.SemanticLidarSensorCfg"):
        core.build()


def test_observation_terms_refuse_other_sensors():
    class _FakeEnv:
        scene = {"terrain_scan": object()}

    with pytest.raises(SensorError, match="not a robotwright"):
        rw_mjlab.lidar_semantic_obs(_FakeEnv(), "terrain_scan")


# ------------------------------------------------------------------ the Go1 example
@pytest.fixture(scope="module")
def example():
    sys.path.insert(0, str(EXAMPLES))
    try:
        import mjlab_go1_semantic_lidar as module
    finally:
        sys.path.remove(str(EXAMPLES))
    return module


def _host_datas(env) -> list[mujoco.MjData]:
    """Host MjData of every environment from the mjlab simulation's state."""
    model = env.sim.mj_model
    qpos = env.sim.data.qpos.cpu().numpy().astype(np.float64)
    datas = []
    for q in qpos:
        d = mujoco.MjData(model)
        d.qpos[:] = q
        mujoco.mj_kinematics(model, d)
        datas.append(d)
    return datas


def test_go1_example_env_labels_every_class_and_matches_the_core_sensor(example):
    """The example's Go1 task on the CPU device, 3 envs, 12 steps of random actions."""
    env = example.make_env(3, "cpu")
    sensor = env.scene["lidar"]
    assert isinstance(sensor, RayCastSensor) and sensor in env.sim._sensor_context.raycast_sensors
    data = sensor.data
    views = {k: getattr(data, k).data_ptr() for k in ("distances", "semantic_labels", "geom_ids")}
    device = torch.device(env.device)
    table = sensor.table
    generator = torch.Generator().manual_seed(1)
    seen: set[int] = set()
    frames, starts, dirs_prev = [], [], None
    rows = table.directions.shape[0]
    fired_per_step = LivoxPatternCfg(sensor_type="mid360").firing_rate() * env.step_dt
    for _ in range(12):
        action = torch.rand(env.num_envs, env.action_manager.total_action_dim, generator=generator)
        obs, *_ = env.step(action * 2.0 - 1.0)
        # The same tensors every step, views of the device buffers, on the env's device.
        assert env.scene["lidar"].data is data
        assert {k: getattr(data, k).data_ptr() for k in views} == views
        assert data.distances.data_ptr() == sensor._buffers["distances"].ptr
        for t in (data.distances, data.semantic_labels, data.geom_ids, data.hit_pos_w):
            assert t.device == device
        assert data.distances.shape == (3, table.rays_per_frame) == data.geom_ids.shape
        assert data.hit_pos_w.shape == (3, table.rays_per_frame, 3)
        # The Mid-360 fires in simulated time: its window moves by the rays fired in a
        # step (200 000/s x step_dt), the same for every env (same phase); the
        # directions change and, in the sensor frame, are the window's table rows.
        frames.append(int(data.frame[0]))
        start = data.window_start.numpy().copy()
        assert (start == start[0]).all()
        if starts:
            moved = (int(start[0]) - starts[-1]) % rows
            assert abs(moved - fired_per_step) <= 1, (moved, fired_per_step)
        starts.append(int(start[0]))
        window = table.directions[(starts[-1] + np.arange(table.rays_per_frame)) % rows]
        dirs = data.ray_directions_w.numpy().copy()
        if dirs_prev is not None:
            assert not np.allclose(dirs, dirs_prev)
        dirs_prev = dirs
        q = data.sensor_quat_w.numpy().astype(np.float64)
        for e in range(env.num_envs):
            rot = np.empty(9)
            mujoco.mju_quat2Mat(rot, q[e] / np.linalg.norm(q[e]))
            local = dirs[e] @ rot.reshape(3, 3)
            np.testing.assert_allclose(local, window, atol=2e-5)
        _check_labels(sensor, data)
        hit = data.hit_mask.numpy()
        seen |= set(np.unique(data.semantic_labels.numpy()[hit]).tolist())
        dist = data.distances.numpy()
        assert (dist[hit] >= 0).all() and (dist <= example.MAX_DISTANCE).all()
        assert (dist[~hit] == -1.0).all()
        np.testing.assert_array_equal(
            data.hit_pos_w.numpy()[~hit], data.ray_origins_w.numpy()[~hit]
        )
        expect = data.ray_origins_w.numpy() + dirs * dist[..., None]
        np.testing.assert_allclose(data.hit_pos_w.numpy()[hit], expect[hit], atol=1e-4)
    assert frames == list(range(frames[0], frames[0] + 12))
    # Every class of the default mapping appears among the hits (and nothing unknown);
    # the robot's own class is last, never hit: its geoms are in groups the rays skip.
    assert sensor.class_names == ("unknown", *DEFAULT_SEMANTIC_CLASS_MAPPING, "robot")
    assert seen == set(range(1, len(DEFAULT_SEMANTIC_CLASS_MAPPING) + 1))
    hit_names = {sensor.geom_paths[g] for g in np.unique(data.geom_ids.numpy()) if g >= 0}
    assert "/world/terrain/terrain" in hit_names
    # The seed's stacked observation is the actor's last term, exactly.
    n = sensor.num_rays
    stacked = rw_mjlab.lidar_semantic_obs(env, "lidar")
    assert obs["actor"].shape[1] > 2 * n and torch.equal(obs["actor"][:, -2 * n :], stacked)
    # The core sensor (MuJoCo engine, float64) on host MjData made from the sim state,
    # casting the same window of the same pattern, with the same hittable geoms.
    model = env.sim.mj_model
    ref = SemanticLidarSensor(
        SemanticLidarCfg(
            prim_path="robot/trunk",
            pattern_cfg=_FixedWindow(first=starts[-1]),
            offset_pos=sensor.cfg.offset_pos,
            max_distance=example.MAX_DISTANCE,
            semantic_class_mapping=sensor.semantic_class_mapping,
            return_mesh_ids=True,
        ),
        model,
        _host_datas(env),
    )
    assert (ref.hittable_geom_mask == sensor.hittable_geom_mask).all()
    robot = np.flatnonzero(model.body_rootid == model.body("robot/trunk").id)
    assert not sensor.hittable_geom_mask[np.isin(model.geom_bodyid, robot)].any()
    ref.update()
    np.testing.assert_allclose(data.sensor_pos_w.numpy(), ref.data.pos_w, atol=1e-4)
    _compare_with_core(data, ref)
    env.close()


def test_go1_example_main_prints_a_summary_and_saves_the_picture(example, tmp_path, capsys):
    summary = example.main([str(tmp_path), "--envs", "2", "--steps", "5", "--device", "cpu"])
    out = capsys.readouterr().out
    assert "2 envs x 20000 rays on cpu: 5 steps" in out and "hits per class" in out
    assert Path(summary["png"]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    counts = summary["hits_per_class"]
    assert counts["unknown"] == 0
    assert all(counts[c] > 0 for c in DEFAULT_SEMANTIC_CLASS_MAPPING)
    assert summary["actor_obs"][1] > 2 * summary["rays"]


def test_seed_getters_point_cloud_and_range_image(clutter_model):
    model = _robot_in_group_3(clutter_model)
    host = random_envs(model, 3, seed=4)
    pattern = LivoxPatternCfg(num_rays=3000)
    offset = {"offset_pos": (0.05, -0.02, 0.03), "offset_rot": (0.9659258, 0.0, 0.258819, 0.0)}
    cfg = rw_mjlab.SemanticLidarSensorCfg(
        name="lidar", frame=ObjRef(type="site", name="lidar"), pattern=pattern, **offset
    )
    env = _Env(model, host, cfg)
    ref = SemanticLidarSensor(
        SemanticLidarCfg(prim_path="lidar", pattern_cfg=pattern, return_mesh_ids=True, **offset),
        model,
        host,
    )
    env.sense()
    ref.update()
    s, data = env.sensor, env.sensor.data
    hit = data.hit_mask
    # The seed's getters, with env_ids; mesh_ids is geom_ids.
    assert torch.equal(s.get_semantic_labels([2, 0]), data.semantic_labels[[2, 0]])
    assert torch.equal(s.mesh_ids, data.geom_ids) and torch.equal(data.mesh_ids, data.geom_ids)
    assert torch.equal(s.get_mesh_ids(torch.tensor([1])), data.geom_ids[1:2])
    assert s.get_distances([1]).shape == (1, 3000)
    same = (data.geom_ids.numpy() == ref.get_mesh_ids()) & hit.numpy()
    for frame in ("world", "sensor"):
        ours = s.get_pointcloud([0, 2], frame=frame).numpy()
        theirs = ref.get_pointcloud([0, 2], frame=frame)
        both = same[[0, 2]]
        np.testing.assert_allclose(ours[both], theirs[both], atol=1e-4)
        assert np.isnan(ours[~hit.numpy()[[0, 2]]]).all()
    with pytest.raises(SensorError, match="frame must be"):
        s.get_pointcloud(frame="base")
    # Point cloud: a deterministic, evenly spaced sample of the hits, padded with zeros.
    classes = len(s.class_names)
    cloud = rw_mjlab.lidar_point_cloud(env, "lidar", max_points=512)
    assert cloud.shape == (3, 512, 3 + classes)
    assert torch.equal(cloud, rw_mjlab.lidar_point_cloud(env, "lidar", max_points=512))
    sensor_points = s.get_pointcloud(frame="sensor")
    for e in range(3):
        idx = torch.nonzero(hit[e]).flatten()
        take = idx[(torch.arange(512) * idx.numel()) // 512] if idx.numel() > 512 else idx
        k = take.numel()
        torch.testing.assert_close(cloud[e, :k, :3], sensor_points[e, take], atol=1e-5, rtol=0)
        labels = cloud[e, :k, 3:].argmax(-1)
        assert torch.equal(labels, data.semantic_labels[e, take].long())
        assert (cloud[e, k:] == 0).all() and (cloud[e, :k, 3:].sum(-1) == 1).all()
    big = rw_mjlab.lidar_point_cloud(env, "lidar", max_points=3000, frame="world")
    counts = (big[..., 3:].sum(-1) > 0).sum(-1)
    assert torch.equal(counts, hit.sum(-1))  # fewer hits than slots: all of them, padded
    k = int(counts[0])
    torch.testing.assert_close(big[0, :k, :3], data.hit_pos_w[0][hit[0]], atol=0, rtol=0)
    # Range image: every ray's cell from its sensor-frame direction.
    image = rw_mjlab.lidar_range_image(env, "lidar", width=16, height=4)
    assert image.shape == (3, 1 + classes, 4, 16)
    assert torch.equal(
        rw_mjlab.lidar_range_image(env, "lidar", 16, 4, flatten=True), image.reshape(3, -1)
    )
    frame = int(data.frame[0])
    d = s.table.window(frame)[1]
    az = np.arctan2(d[:, 1], d[:, 0])
    el = np.arctan2(d[:, 2], np.hypot(d[:, 0], d[:, 1]))
    all_d = s.table.directions
    all_el = np.arctan2(all_d[:, 2], np.hypot(all_d[:, 0], all_d[:, 1]))
    col = np.clip(np.floor((az + np.pi) / (2 * np.pi) * 16), 0, 15).astype(int)
    row = np.clip(np.floor((all_el.max() - el) / (all_el.max() - all_el.min()) * 4), 0, 3)
    row = row.astype(int)
    dist, labels, h = data.distances.numpy(), data.semantic_labels.numpy(), hit.numpy()
    for e in range(3):
        for r in range(4):
            for c in range(16):
                in_cell = (row == r) & (col == c)
                hits = in_cell & h[e]
                near = dist[e][hits].min() / 40.0 if hits.any() else 1.0
                assert abs(float(image[e, 0, r, c]) - near) < 1e-5
                for k in range(classes):
                    frac = (hits & (labels[e] == k)).sum() / max(in_cell.sum(), 1)
                    assert abs(float(image[e, 1 + k, r, c]) - frac) < 1e-5
    assert float(image[:, 0].min()) < 1.0
    # scanned: a last channel, 1 where a ray of this frame fell in the cell, else 0
    marked = rw_mjlab.lidar_range_image(env, "lidar", 16, 4, scanned=True)
    assert marked.shape == (3, 2 + classes, 4, 16) and torch.equal(marked[:, :-1], image)
    scanned = np.zeros((4, 16), bool)
    scanned[row, col] = True
    assert (marked[:, -1].numpy() == scanned).all() and not scanned.all()
    # The cells are looked up per pattern frame: after more steps (other windows of the
    # rosette) the image equals one binned from this step's window of the table.
    for _ in range(2):
        env.sense()
        window = torch.as_tensor(s.table.window(int(data.frame[0]))[1])
        local = window.expand(3, *window.shape)
        again = learning_obs.range_image(
            local,
            data.hit_mask,
            data.distances,
            40.0,
            data.semantic_labels,
            classes,
            learning_obs.direction_bounds(torch.as_tensor(s.table.directions)),
            16,
            4,
            scanned=True,
        )
        assert torch.equal(rw_mjlab.lidar_range_image(env, "lidar", 16, 4, scanned=True), again)
