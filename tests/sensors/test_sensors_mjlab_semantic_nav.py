"""The seed's task in mjlab (marked ``mjlab``): ``Robotwright-Mjlab-SemanticNav-Go2``.

The class-labelled scene puts named objects in every environment whose labels come out
right by construction (the sensor's class of every object geom, and of every ray that
hits one, is the class the config expects), draws them anew at each reset, moves the
dynamic ones along their paths, and hides obstacles the clutter curriculum has not
reached yet; the rewards read the layout; mjlab's own ``train`` runs both policies.

Runs in the MuJoCo 3.11 environment of ``.ci/run`` on warp's CPU device; skipped with a
reason where mjlab or example-robot-data is not installed.
"""

from __future__ import annotations

import math
import re

import pytest

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

import mjlab  # noqa: E402, F401 - loads the entry points
import torch  # noqa: E402
from mjlab.envs import ManagerBasedRlEnv  # noqa: E402
from mjlab.tasks.registry import list_tasks, load_env_cfg, load_rl_cfg  # noqa: E402
from mjlab_train import run_train  # noqa: E402

from robotwright.catalog import find_entry  # noqa: E402
from robotwright.sensors.mjlab import semantic_nav  # noqa: E402
from robotwright.sensors.semantic_scene import PARK_DEPTH, SemanticSceneCfg  # noqa: E402

needs_go2 = pytest.mark.skipif(
    find_entry("go2") is None, reason="the Go2 comes from example-robot-data (not installed)"
)


def _small(cfg, envs: int = 2):
    cfg.scene.num_envs = envs
    cfg.scene.terrain.terrain_generator.num_rows = 2
    cfg.scene.terrain.terrain_generator.num_cols = 2
    cfg.seed = 3
    return cfg


@pytest.fixture(scope="module")
def nav_env():
    if find_entry("go2") is None:
        pytest.skip("the Go2 comes from example-robot-data (not installed)")
    env = ManagerBasedRlEnv(cfg=_small(load_env_cfg(semantic_nav.TASK_ID)), device="cpu")
    env.reset()
    yield env
    env.close()


def _scene_term(env):
    return env.event_manager.get_term_cfg("semantic_scene").func.state


def _step(env, n: int) -> None:
    action = torch.zeros(env.num_envs, env.action_manager.total_action_dim)
    for _ in range(n):
        env.step(action)


def test_both_policies_are_registered_and_registering_reads_no_robot() -> None:
    assert {semantic_nav.TASK_ID, semantic_nav.POINTNET_TASK_ID} <= set(list_tasks())
    from mjlab.tasks.registry import _REGISTRY

    # What the registry holds builds the config (and reads the Go2) only when copied.
    assert isinstance(_REGISTRY[semantic_nav.TASK_ID].env_cfg, semantic_nav._BuiltWhenCopied)
    rl = load_rl_cfg(semantic_nav.POINTNET_TASK_ID)
    assert rl.actor.class_name == "robotwright.sensors.pointnet:PointNetModel"
    assert rl.obs_groups["actor"] == ("actor", "points")


@needs_go2
def test_the_go2_is_the_one_command_robot_with_its_standing_pose() -> None:
    cfg = load_env_cfg(semantic_nav.TASK_ID)
    robot = cfg.scene.entities["robot"]
    assert 0.25 < robot.init_state.pos[2] < 0.45
    pose = robot.init_state.joint_pos
    assert pose["FL_thigh_joint"] == 0.8 and pose["RR_thigh_joint"] == 1.0
    assert pose["FR_calf_joint"] == -1.5 and pose["FR_hip_joint"] == -0.1
    spec = robot.spec_fn()
    model = spec.compile()
    assert model.nu == 12 and model.actuator_gainprm[:, 0].tolist() == [50.0] * 12
    assert model.actuator_biasprm[:, 2].tolist() == [-1.0] * 12  # kv 1
    # No two of the robot's collision geoms can collide (no self-collision); every one
    # collides with a default geom (terrain, objects).
    colliding = [
        g for g in range(model.ngeom) if model.geom_contype[g] or model.geom_conaffinity[g]
    ]
    assert colliding
    for a in colliding:
        assert model.geom_contype[a] & 1 or model.geom_conaffinity[a] & 1
        for b in colliding:
            assert not (model.geom_contype[a] & model.geom_conaffinity[b])


def test_every_object_and_every_ray_on_it_carries_its_expected_class(nav_env) -> None:
    env, term = nav_env, _scene_term(nav_env)
    lidar = env.scene["lidar"]
    expected = term.cfg.expected_classes()
    names = lidar.class_names
    model = env.sim.mj_model
    object_geoms = {}
    for slot in term.slots:
        gid = model.geom(f"{slot.name}/{slot.asset.name}").id
        object_geoms[gid] = slot.name
        assert names[lidar.geom_semantic_class[gid]] == expected[slot.name]
    assert set(expected.values()) == {"dynamic_obstacle", "valuable"}
    seen = set()
    for _ in range(6):
        _step(env, 1)
        ids, labels = lidar.data.geom_ids, lidar.data.semantic_labels
        for gid, slot in object_geoms.items():
            on = ids == gid
            if on.any():
                seen.add(expected[slot])
                assert {names[int(c)] for c in labels[on].unique()} == {expected[slot]}
    assert "valuable" in seen  # furniture is big enough to be hit from any layout


def test_objects_stand_where_the_layout_says_and_are_redrawn_at_reset(nav_env) -> None:
    env, term = nav_env, _scene_term(nav_env)
    env.reset()
    env.sim.forward()
    before = term.xy.clone()
    origins = env.scene.env_origins
    for k, slot in enumerate(term.slots):
        pos = env.scene[slot.name].data.root_link_pos_w
        on = term.active[:, k]
        torch.testing.assert_close(pos[on, :2], origins[on, :2] + term.xy[on, k], atol=1e-5, rtol=0)
        z = torch.where(on, origins[:, 2] + slot.asset.half_height, origins[:, 2] - PARK_DEPTH)
        torch.testing.assert_close(pos[:, 2], z, atol=1e-5, rtol=0)
    env.reset()
    assert float((term.xy - before).abs().max()) > 0.1


def test_dynamic_obstacles_move_along_their_paths_and_valuables_stay(nav_env) -> None:
    env, term = nav_env, _scene_term(nav_env)
    env.reset()
    xy, vel = term.xy.clone(), term.velocity.clone()
    _step(env, 3)
    moved = term.xy - xy
    for k, slot in enumerate(term.slots):
        if slot.dynamic:
            bounced = (xy[:, k] + vel[:, k] * 3 * env.step_dt).abs() > term.cfg.arena_half
            keep = ~bounced.any(dim=1)
            want = vel[keep, k] * 3 * env.step_dt
            torch.testing.assert_close(moved[keep, k], want, atol=1e-5, rtol=0)
        else:
            assert float(moved[:, k].abs().max()) == 0.0
    assert float(moved.abs().max()) > 0.0


def test_the_clutter_curriculum_parks_obstacles_of_low_levels(nav_env) -> None:
    env, term = nav_env, _scene_term(nav_env)
    terrain = env.scene.terrain
    top = int(terrain.max_terrain_level)
    saved = terrain.terrain_levels.clone()
    try:
        terrain.terrain_levels[:] = 0
        env.event_manager.get_term_cfg("semantic_scene").func.reset(torch.arange(env.num_envs))
        dynamic = [k for k, s in enumerate(term.slots) if s.dynamic]
        want = math.ceil(len(dynamic) / top)
        assert term.active[:, dynamic].sum(dim=1).tolist() == [want] * env.num_envs
        assert bool(term.active[:, [k for k in range(len(term.slots)) if k not in dynamic]].all())
        terrain.terrain_levels[:] = top - 1
        env.event_manager.get_term_cfg("semantic_scene").func.reset(torch.arange(env.num_envs))
        assert bool(term.active.all())
    finally:
        terrain.terrain_levels[:] = saved


def test_the_rewards_read_the_distance_to_valuables_and_obstacles(nav_env) -> None:
    env, term = nav_env, _scene_term(nav_env)
    env.reset()
    robot = env.scene["robot"]
    k_val = next(k for k, s in enumerate(term.slots) if not s.dynamic)
    k_obs = next(k for k, s in enumerate(term.slots) if s.dynamic)
    term.active[:] = True
    root = robot.data.default_root_state.clone()
    origins = env.scene.env_origins
    # Env 0 beside a valuable's footprint, env 1 beside an obstacle's.
    for env_id, k, gap in ((0, k_val, 0.3), (1, k_obs, 0.2)):
        r = term.slots[k].asset.footprint_radius
        root[env_id, :2] = origins[env_id, :2] + term.xy[env_id, k] + torch.tensor([r + gap, 0.0])
        root[env_id, 2] += origins[env_id, 2]
    robot.write_root_state_to_sim(root)
    env.sim.forward()
    env.scene.update(env.physics_dt)
    valuable, obstacle = semantic_nav.near_valuable(env), semantic_nav.near_obstacle(env)
    assert valuable[0] == 1.0 and obstacle[1] == 1.0


def _losses(stdout: str, name: str) -> list[float]:
    return [float(v) for v in re.findall(rf"Mean {name} loss:\s*(\S+)", stdout)]


@needs_go2
@pytest.mark.parametrize(
    ("task", "iterations"), [(semantic_nav.TASK_ID, 5), (semantic_nav.POINTNET_TASK_ID, 3)]
)
def test_mjlab_s_train_runs_the_task_with_finite_losses(tmp_path, task, iterations) -> None:
    """4 envs on the CPU: every loss finite, the value loss below its first value."""
    args = [task, "--env.scene.num-envs", "4", "--agent.max-iterations", str(iterations)]
    args += ["--env.scene.terrain.terrain-generator.num-rows", "2"]
    args += ["--env.scene.terrain.terrain-generator.num-cols", "2"]
    args += ["--gpu-ids", "None", "--log-root", str(tmp_path)]
    done = run_train(args, tmp_path)
    value, surrogate = _losses(done.stdout, "value"), _losses(done.stdout, "surrogate")
    assert len(value) == len(surrogate) == iterations
    assert all(math.isfinite(v) for v in value + surrogate)
    assert min(value[1:]) < value[0]
    runs = list((tmp_path / load_rl_cfg(task).experiment_name).iterdir())
    assert len(runs) == 1 and (runs[0] / "params" / "env.yaml").is_file()


def test_a_bad_scene_config_is_refused_when_the_task_is_built() -> None:
    from robotwright.errors import SensorError

    scene = SemanticSceneCfg(num_obstacles=-2)
    with pytest.raises(SensorError, match="num_obstacles"):
        semantic_nav.semantic_nav_env_cfg(scene=scene)


def test_the_lidar_sits_where_the_go2_carries_its_own_with_the_base_s_axes(nav_env) -> None:
    env = nav_env
    _step(env, 2)
    lidar, robot = env.scene["lidar"], env.scene["robot"]
    radar = robot.body_names.index("radar")
    torch.testing.assert_close(
        lidar.data.sensor_pos_w, robot.data.body_link_pos_w[:, radar], atol=1e-5, rtol=0
    )
    base_quat = robot.data.root_link_quat_w
    dot = (lidar.data.sensor_quat_w * base_quat).sum(-1).abs()
    torch.testing.assert_close(dot, torch.ones_like(dot), atol=1e-5, rtol=0)
