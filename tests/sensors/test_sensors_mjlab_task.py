"""The semantic LiDAR inside mjlab's own machinery (marked ``mjlab``): its data read by
mjlab's consumers next to mjlab's RayCastSensor casting the same rays, the observation
terms, debug drawing, tyro overrides and ``train`` on the registered task.

Runs in the MuJoCo 3.11 environment of ``.ci/run`` on warp's CPU device; skipped with a
reason where mjlab is not installed.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

import mjlab  # noqa: E402
import torch  # noqa: E402
import tyro  # noqa: E402
from mjlab.envs import ManagerBasedRlEnv, ManagerBasedRlEnvCfg  # noqa: E402
from mjlab.envs import mdp as envs_mdp  # noqa: E402
from mjlab.managers.reward_manager import RewardTermCfg  # noqa: E402
from mjlab.sensor.raycast_sensor import GridPatternCfg as MjlabGrid  # noqa: E402
from mjlab.sensor.raycast_sensor import RayCastData  # noqa: E402
from mjlab.tasks.registry import list_tasks, load_env_cfg  # noqa: E402
from mjlab.tasks.velocity import mdp as velocity_mdp  # noqa: E402
from mjlab.tasks.velocity.mdp.terrain_utils import terrain_normal_from_sensors  # noqa: E402
from mjlab.viewer.debug_visualizer import NullDebugVisualizer  # noqa: E402
from mjlab_train import run_train  # noqa: E402

from robotwright.sensors import mjlab as rw_mjlab  # noqa: E402
from robotwright.sensors.mjlab.tasks import TASK_ID  # noqa: E402

SMALL_TERRAIN = {"num_rows": 2, "num_cols": 2}


def _small(cfg: ManagerBasedRlEnvCfg, envs: int = 2) -> ManagerBasedRlEnvCfg:
    """``envs`` envs on a 2 x 2 terrain, seeded: the same terrain and resets every run."""
    cfg.scene.num_envs = envs
    cfg.seed = 11
    gen = cfg.scene.terrain.terrain_generator
    gen.num_rows, gen.num_cols = SMALL_TERRAIN["num_rows"], SMALL_TERRAIN["num_cols"]
    gen.seed = 11
    return cfg


def _sensor_index(cfg: ManagerBasedRlEnvCfg, name: str) -> int:
    return [s.name for s in cfg.scene.sensors].index(name)


@pytest.fixture(scope="module")
def task_env():
    """The registered task (2 envs, 2 x 2 terrain) plus a robotwright twin of mjlab's
    ``terrain_scan`` (same grid, frame, alignment, range and groups)."""
    assert TASK_ID in list_tasks()  # registered through mjlab's entry point
    cfg = _small(load_env_cfg(TASK_ID))
    scan = cfg.scene.sensors[_sensor_index(cfg, "terrain_scan")]
    twin = rw_mjlab.SemanticLidarSensorCfg(
        name="terrain_scan_rw",
        frame=scan.frame,
        pattern=MjlabGrid(size=scan.pattern.size, resolution=scan.pattern.resolution),
        ray_alignment=scan.ray_alignment,
        max_distance=scan.max_distance,
        include_geom_groups=scan.include_geom_groups,
        refine_curved_hits=False,  # mjlab's cast is float32 throughout
        debug_vis=True,
    )
    cfg.scene.sensors = (*cfg.scene.sensors, twin)
    env = ManagerBasedRlEnv(cfg, device="cpu")
    env.reset()
    yield env
    env.close()


def _step(env, steps: int, seed: int = 0) -> None:
    gen = torch.Generator().manual_seed(seed)
    for _ in range(steps):
        action = torch.rand(env.num_envs, env.action_manager.total_action_dim, generator=gen)
        env.step(action * 2.0 - 1.0)


def test_mjlab_consumers_read_our_sensor_as_mjlab_s_own(task_env):
    env = task_env
    ours, theirs = env.scene["terrain_scan_rw"], env.scene["terrain_scan"]
    upright_cfg = env.reward_manager.get_term_cfg("upright")
    for step in range(4):
        _step(env, 2, seed=step)
        a, b = ours.data, theirs.data
        assert isinstance(a, RayCastData)
        hit = b.distances >= 0
        assert torch.equal(a.distances >= 0, hit) and torch.equal(a.hit_mask, hit)
        torch.testing.assert_close(a.distances, b.distances, atol=1e-4, rtol=0)
        torch.testing.assert_close(a.hit_pos_w, b.hit_pos_w, atol=1e-4, rtol=0)
        torch.testing.assert_close(a.normals_w, b.normals_w, atol=1e-4, rtol=0)
        torch.testing.assert_close(a.frame_pos_w, b.frame_pos_w, atol=1e-5, rtol=0)
        # Quaternions: the same rotation (q and -q are equal).
        dot = (a.frame_quat_w * b.frame_quat_w).sum(-1).abs()
        torch.testing.assert_close(dot, torch.ones_like(dot), atol=1e-5, rtol=0)
        torch.testing.assert_close(a.pos_w, b.pos_w, atol=1e-5, rtol=0)
        # mjlab's consumers give the same on both.
        torch.testing.assert_close(
            envs_mdp.height_scan(env, "terrain_scan_rw"),
            envs_mdp.height_scan(env, "terrain_scan"),
            atol=1e-4,
            rtol=0,
        )
        n_ours = terrain_normal_from_sensors(env, ("terrain_scan_rw",))
        n_theirs = terrain_normal_from_sensors(env, ("terrain_scan",))
        torch.testing.assert_close(n_ours, n_theirs, atol=1e-3, rtol=0)
        params = dict(upright_cfg.params)
        rewards = []
        for name in ("terrain_scan_rw", "terrain_scan"):
            params["terrain_sensor_names"] = (name,)
            term = velocity_mdp.upright(
                RewardTermCfg(func=velocity_mdp.upright, weight=1.0, params=params), env
            )
            rewards.append(term(env, **params))
        torch.testing.assert_close(rewards[0], rewards[1], atol=1e-4, rtol=0)
    assert hit.any() and torch.isfinite(a.hit_pos_w).all()


class _Recorder(NullDebugVisualizer):
    def __init__(self) -> None:
        super().__init__(env_idx=1, meansize=0.1)
        self.spheres: list[tuple[np.ndarray, tuple]] = []

    def add_sphere(self, center, radius, color, label=None) -> None:
        self.spheres.append((np.asarray(center), tuple(color)))


def test_debug_vis_draws_hit_points_coloured_by_class(task_env):
    sensor = task_env.scene["terrain_scan_rw"]
    recorder = _Recorder()
    sensor.debug_vis(recorder)
    data = sensor.data
    hits = data.hit_mask[1].numpy()
    assert len(recorder.spheres) == min(int(hits.sum()), sensor.cfg.debug_vis_max_points) > 0
    drawn = np.stack([c for c, _ in recorder.spheres])
    expect = data.hit_pos_w[1].numpy()[hits]
    np.testing.assert_allclose(drawn, expect, atol=0)
    colours = [rw_mjlab.CLASS_COLORS[int(k)] for k in data.semantic_labels[1].numpy()[hits]]
    assert [c for _, c in recorder.spheres] == colours
    sensor.cfg.debug_vis_max_points = 7
    recorder = _Recorder()
    sensor.debug_vis(recorder)
    assert len(recorder.spheres) == 7
    sensor.cfg.debug_vis = False
    recorder = _Recorder()
    sensor.debug_vis(recorder)
    assert recorder.spheres == []
    sensor.cfg.debug_vis, sensor.cfg.debug_vis_max_points = True, 2000


def test_the_task_s_lidar_sees_every_class_and_the_actor_reads_the_range_image(task_env):
    env = task_env
    lidar = env.scene["lidar"]
    names = lidar.class_names
    assert names == ("unknown", "terrain", "dynamic_obstacle", "valuable", "robot")
    seen: set[int] = set()
    for step in range(3):
        _step(env, 2, seed=10 + step)
        data = lidar.data
        seen |= set(data.semantic_labels[data.hit_mask].unique().tolist())
    assert {1, 2, 3} <= seen  # terrain, the cracker boxes, the furniture
    assert 0 not in seen  # every hit geom is classed
    obs = env.observation_manager.compute()["actor"]
    image = rw_mjlab.lidar_range_image(env, "lidar", 32, 8)
    assert image.shape == (2, 1 + len(names), 8, 32)
    assert torch.equal(obs[:, -image[0].numel() :], image.reshape(2, -1))


def test_tyro_overrides_every_field_of_the_sensor_config():
    """mjlab's train/play CLI (tyro with mjlab's flags) changes any field; build() and
    the sensor then use the new values."""
    cfg = load_env_cfg(TASK_ID)
    i = _sensor_index(cfg, "lidar")
    p = f"--scene.sensors.{i}."
    args = [
        f"{p}name",
        "front",
        f"{p}frame.name",
        "FR_hip",
        f"{p}pattern.sensor-type",
        "avia",
        f"{p}pattern.num-rays",
        "1000",
        f"{p}offset-pos",
        "(0.1,0.0,0.2)",
        f"{p}offset-rot",
        "(0.0,0.0,0.0,1.0)",
        f"{p}semantic-class-mapping",
        "{'rock':['terrain'],'box':['cracker']}",
        f"{p}self-class",
        "me",
        f"{p}min-distance",
        "0.3",
        f"{p}max-distance",
        "7.5",
        f"{p}range-noise-std",
        "0.01",
        f"{p}dropout-prob",
        "0.1",
        f"{p}seed",
        "5",
        f"{p}miss-distance",
        "9.0",
        f"{p}refine-curved-hits",
        "False",
        f"{p}num-threads",
        "2",
        f"{p}ray-alignment",
        "yaw",
        f"{p}exclude-parent-body",
        "False",
        f"{p}include-geom-groups",
        "(0,3)",
        f"{p}debug-vis",
        "True",
        f"{p}debug-vis-max-points",
        "50",
    ]
    out = tyro.cli(ManagerBasedRlEnvCfg, default=cfg, args=args, config=mjlab.TYRO_FLAGS)
    s = out.scene.sensors[i]
    assert isinstance(s, rw_mjlab.SemanticLidarSensorCfg)
    assert (s.name, s.frame.name, s.pattern.sensor_type, s.pattern.num_rays) == (
        "front",
        "FR_hip",
        "avia",
        1000,
    )
    assert s.offset_pos == (0.1, 0.0, 0.2) and s.offset_rot == (0.0, 0.0, 0.0, 1.0)
    assert (s.min_distance, s.max_distance, s.range_noise_std, s.dropout_prob) == (
        0.3,
        7.5,
        0.01,
        0.1,
    )
    assert (s.seed, s.miss_distance, s.refine_curved_hits, s.num_threads) == (5, 9.0, False, 2)
    assert (s.ray_alignment, s.exclude_parent_body, s.include_geom_groups) == (
        "yaw",
        False,
        (0, 3),
    )
    assert (s.debug_vis, s.debug_vis_max_points) == (True, 50)
    res = rw_mjlab.resolve(s)
    assert res.class_names == ("unknown", "rock", "box", "me")
    assert res.miss_distance == 9.0 and res.self_class_id == 3
    # Only the fields given changed: the task's own default config is untouched.
    assert load_env_cfg(TASK_ID).scene.sensors[i].max_distance == 10.0


def test_importing_the_adapter_changes_no_global_warp_setting():
    code = (
        "import mjlab, warp as wp\n"
        "before = (wp.config.quiet, getattr(wp.config, 'log_level', None), "
        "wp.config.enable_backward)\n"
        "import robotwright.sensors.mjlab, robotwright.sensors.mjlab.tasks\n"
        "after = (wp.config.quiet, getattr(wp.config, 'log_level', None), "
        "wp.config.enable_backward)\n"
        "assert before == after, (before, after)\n"
        "print('same', after)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "MJLAB_WARP_QUIET"}
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "same (False" in done.stdout  # mjlab's verbose default kept


def test_train_runs_two_iterations_of_the_task_on_cpu(tmp_path):
    """mjlab's own ``train`` entry point, with tyro overrides of the sensor."""
    cfg = load_env_cfg(TASK_ID)
    i = _sensor_index(cfg, "lidar")
    args = [
        TASK_ID,
        "--env.scene.num-envs",
        "2",
        "--env.scene.terrain.terrain-generator.num-rows",
        "2",
        "--env.scene.terrain.terrain-generator.num-cols",
        "2",
        "--agent.max-iterations",
        "2",
        "--agent.num-steps-per-env",
        "8",
        "--gpu-ids",
        "None",
        "--log-root",
        str(tmp_path),
        f"--env.scene.sensors.{i}.max-distance",
        "6.0",
        f"--env.scene.sensors.{i}.pattern.num-rays",
        "2000",
    ]
    done = run_train(args, tmp_path)
    runs = list((tmp_path / "go1_velocity_semantic_lidar").iterdir())
    assert len(runs) == 1
    run = runs[0]
    assert (run / "model_1.pt").is_file()
    env_yaml = (run / "params" / "env.yaml").read_text()
    assert "max_distance: 6.0" in env_yaml and "num_rays: 2000" in env_yaml
    assert "Learning iteration 1/2" in done.stdout
    assert "nan" not in done.stdout.split("Learning iteration 1/2")[1].lower()
