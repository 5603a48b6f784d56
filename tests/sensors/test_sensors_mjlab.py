"""The mjlab adapter: our kernels inside mjlab's ray-cast pipeline (marked ``mjlab``)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from lidar_scenes import random_envs

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

import torch  # noqa: E402
import warp as wp  # noqa: E402
from mjlab.sensor.builtin_sensor import ObjRef  # noqa: E402
from mjlab.sensor.raycast_sensor import RayCastSensor  # noqa: E402
from mjlab.sensor.sensor_context import SensorContext  # noqa: E402
from mjlab.sim.sim_data import WarpBridge  # noqa: E402

from robotwright.sensors import (  # noqa: E402
    LivoxPatternCfg,
    SemanticLidarCfg,
    SemanticLidarSensor,
    classify_path,
)
from robotwright.sensors import mjlab as rw_mjlab  # noqa: E402


def _robot_in_group_3(model: mujoco.MjModel) -> mujoco.MjModel:
    """As in mjlab's assets: the robot's geoms outside group 0, which the sensor casts at."""
    root = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "robot")
    robot = np.flatnonzero(model.body_rootid == root)
    model.geom_group[np.isin(model.geom_bodyid, robot)] = 3
    return model


class _Env:
    """The parts of an mjlab env the sensor uses: a scene dict and mjlab's sense sequence."""

    def __init__(self, model, host, cfg) -> None:
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
        import mujoco_warp as mjw

        self.ctx.prepare()
        with wp.ScopedDevice("cpu"):
            mjw.refit_bvh(self.mw, self.dw, self.ctx.render_context)
            for s in self.ctx.raycast_sensors:
                s.raycast_kernel(rc=self.ctx.render_context)
        self.ctx.finalize()


def test_mjlab_sensor_matches_the_core_sensor_and_labels_geoms(clutter_model):
    model = _robot_in_group_3(clutter_model)
    host = random_envs(model, 3, seed=9)
    pattern = LivoxPatternCfg(num_rays=20000)
    cfg = rw_mjlab.SemanticLidarSensorCfg(
        name="lidar",
        frame=ObjRef(type="site", name="lidar"),
        lidar_pattern=pattern,
        max_distance=30.0,
    )
    env = _Env(model, host, cfg)
    assert isinstance(env.sensor, RayCastSensor)  # mjlab's scene treats it as a ray sensor
    ref = SemanticLidarSensor(
        SemanticLidarCfg(
            prim_path="lidar", pattern_cfg=pattern, max_distance=30.0, return_mesh_ids=True
        ),
        model,
        host,
    )
    data = env.sensor.data
    first_dirs = None
    for _step in range(3):
        env.sense()
        ref.update()
        assert env.sensor.data is data  # same tensors every step (zero-copy views)
        ids, ids_ref = data.geom_ids.numpy(), ref.get_mesh_ids()
        same = ids == ids_ref
        assert same.mean() >= 0.999
        both = same & (ids_ref >= 0)
        err = np.abs(data.distances.numpy()[both] - ref.get_distances()[both])
        # float32 mesh/heightfield triangles (mujoco-warp 3.11): a few grazing hits differ
        # by up to ~2e-5 m; the rest agree to 1e-5 m.
        assert (err <= 1e-5).mean() >= 0.999 and err.max() < 1e-4
        # Labels are the class of the hit geom's path, as the seed classifies it.
        labels = data.semantic_labels.numpy()
        for g in np.unique(ids[ids >= 0]):
            expect = classify_path(env.sensor.geom_paths[g], env.sensor.semantic_class_mapping)
            assert (labels[ids == g] == expect).all()
        assert (labels[ids < 0] == 0).all() and (data.distances.numpy()[ids < 0] == 30.0).all()
        assert set(np.unique(labels).tolist()) == {0, 1, 2, 3}
        assert data.distances.device == torch.device("cpu") and data.distances.shape == (3, 20000)
        dirs = data.ray_directions_w.numpy().copy()
        if first_dirs is None:
            first_dirs = dirs
        else:
            assert not np.allclose(dirs, first_dirs)  # the Mid-360 window advances
    # Observation terms.
    obs = rw_mjlab.lidar_semantic_obs(env, "lidar")
    assert obs.shape == (3, 40000) and torch.isfinite(obs).all()
    assert torch.equal(obs[:, 1::2], data.semantic_labels.float())
    norm = rw_mjlab.lidar_distances_normalized(env, "lidar")
    assert float(norm.max()) == 1.0 and float(norm.min()) >= 0.0
    one_hot = rw_mjlab.lidar_one_hot_classes(env, "lidar").reshape(3, 20000, 4)
    assert torch.equal(one_hot.argmax(-1).int(), data.semantic_labels)
    assert torch.equal(rw_mjlab.lidar_class_ids(env, "lidar"), data.semantic_labels.float())


def test_go1_example_labels_every_class(tmp_path):
    """The example's Go1 task on the CPU device: labels are the classes of the hit geoms."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "examples"))
    import mjlab_go1_semantic_lidar as example

    env = example.make_env(2, "cpu")
    sensor = env.scene["lidar"]
    data = sensor.data
    action = torch.zeros(env.num_envs, env.action_manager.total_action_dim)
    dirs = []
    for _ in range(3):
        env.step(action)
        assert env.scene["lidar"].data is data  # the same tensors every step
        dirs.append(data.ray_directions_w.numpy().copy())
    assert not np.allclose(dirs[0], dirs[1])  # the Mid-360 window advanced
    ids, labels = data.geom_ids.numpy(), data.semantic_labels.numpy()
    for g in np.unique(ids[ids >= 0]):
        expect = classify_path(sensor.geom_paths[g], sensor.semantic_class_mapping)
        assert (labels[ids == g] == expect).all(), sensor.geom_paths[g]
    hit_names = {sensor.geom_paths[g].rsplit("/", 1)[-1] for g in np.unique(ids[ids >= 0])}
    assert {"sofa_0_geom", "cracker_box_0_geom"} <= hit_names
    assert set(np.unique(labels[data.hit_mask.numpy()]).tolist()) == {1, 2, 3}
    dist = data.distances.numpy()
    assert (dist[~data.hit_mask.numpy()] == 20.0).all() and (dist >= 0).all() and (dist <= 20).all()
    # The seed's stacked observation is part of the actor's observation.
    obs = env.observation_manager.compute()["actor"]
    assert obs.shape[1] >= 2 * sensor.num_rays
    summary = example.run(tmp_path, num_envs=2, steps=5, device="cpu")
    assert Path(summary["png"]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert all(
        summary["hits_per_class"][c] > 0 for c in ("terrain", "dynamic_obstacle", "valuable")
    )
