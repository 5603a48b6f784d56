"""The seed's task in Isaac Lab 3 (kit-less, Newton, CPU):
``Robotwright-Isaac-SemanticNav-Go2-v0``.

Registered with gym; the class-labelled objects carry their expected class on every
Newton shape and on every ray that hits one; they stand where the layout says and are
redrawn at reset; the dynamic ones move; the rewards read the layout; and the kit-less
rsl_rl train entry runs both policies (4 envs) with finite losses.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip("isaaclab_newton", reason="Isaac Lab 3 not installed")
    pytest.importorskip("mujoco_usd_converter", reason="mujoco-usd-converter not installed")

from robotwright.catalog import find_entry  # noqa: E402

pytestmark = pytest.mark.skipif(
    find_entry("go2") is None, reason="the Go2 comes from example-robot-data (not installed)"
)


def _small_cfg(task: str, envs: int):
    from isaaclab_tasks.utils.hydra import resolve_presets
    from isaaclab_tasks.utils.parse_cfg import load_cfg_from_registry

    import robotwright.sensors.isaaclab.semantic_nav  # noqa: F401 - registers

    cfg = resolve_presets(load_cfg_from_registry(task, "env_cfg_entry_point"))
    cfg.scene.num_envs = envs
    cfg.scene.terrain.terrain_generator.num_rows = 2
    cfg.scene.terrain.terrain_generator.num_cols = 2
    cfg.sim.device = "cpu"
    cfg.seed = 5
    return cfg


@pytest.fixture(scope="module")
def nav_env():
    import gymnasium as gym

    from robotwright.sensors.isaaclab import semantic_nav

    env = gym.make(semantic_nav.TASK_ID, cfg=_small_cfg(semantic_nav.TASK_ID, 2))
    env.reset()
    yield env.unwrapped
    env.close()


def _term(env):
    return env.event_manager.get_term_cfg("semantic_scene").func


def _step(env, n: int) -> None:
    import torch

    action = torch.zeros(env.num_envs, env.action_manager.total_action_dim)
    for _ in range(n):
        env.step(action)


def test_both_policies_are_registered_with_gym() -> None:
    import gymnasium as gym

    from robotwright.sensors.isaaclab import semantic_nav

    assert {semantic_nav.TASK_ID, semantic_nav.POINTNET_TASK_ID} <= set(gym.registry)


def test_every_object_shape_and_every_ray_on_it_carries_its_expected_class(nav_env) -> None:
    import numpy as np

    env, term = nav_env, _term(nav_env)
    lidar = env.scene["lidar"]
    expected = term.state.cfg.expected_classes()
    names = lidar.class_names
    shapes = lidar.shapes
    owner: dict[int, str] = {}
    for slot in term.state.slots:
        for e in range(env.num_envs):
            prefix = f"/World/envs/env_{e}/{slot.name}"
            mine = [i for i, p in enumerate(shapes.labels) if p.startswith(prefix)]
            assert mine, prefix
            for i in mine:
                assert shapes.visible[i] and names[shapes.classes[i]] == expected[slot.name]
                owner[i] = slot.name
    # The robot is see-through; the terrain is terrain.
    assert not shapes.visible[shapes.own_robot].any()
    seen = set()
    for _ in range(4):
        _step(env, 1)
        ids = lidar.data.shape_ids.torch.numpy()
        labels = lidar.data.semantic_labels.torch.numpy()
        for i, slot in owner.items():
            on = ids == i
            if on.any():
                seen.add(expected[slot])
                assert {names[c] for c in np.unique(labels[on])} == {expected[slot]}
    assert "valuable" in seen


def test_objects_stand_where_the_layout_says_and_are_redrawn_at_reset(nav_env) -> None:
    import torch

    env, term = nav_env, _term(nav_env)
    env.reset()
    state = term.state
    before = state.xy.clone()
    origins = env.scene.env_origins
    for k, slot in enumerate(state.slots):
        pos = env.scene[slot.name].data.root_pos_w.torch
        want, _ = state.poses(torch.arange(env.num_envs), k, origins)
        torch.testing.assert_close(pos, want, atol=1e-4, rtol=0)
    env.reset()
    assert float((state.xy - before).abs().max()) > 0.1


def test_dynamic_obstacles_move_and_valuables_stay(nav_env) -> None:
    """Every environment step moves the dynamic obstacles by their velocity (environments
    that were reset meanwhile, whose layout was redrawn, are left out)."""
    import torch

    env, term = nav_env, _term(nav_env)
    state = term.state
    for _ in range(5):  # until both environments run 3 steps without a reset
        env.reset()
        start = state.xy.clone()
        steps_before = env.episode_length_buf.clone()
        _step(env, 3)
        kept = env.episode_length_buf == steps_before + 3
        if bool(kept.all()):
            break
    assert bool(kept.any())
    pos = torch.stack([env.scene[s.name].data.root_pos_w.torch[:, :2] for s in state.slots], 1)
    torch.testing.assert_close(
        pos, env.scene.env_origins[:, None, :2] + state.xy, atol=1e-4, rtol=0
    )
    moved = (state.xy - start).norm(dim=-1)[kept]
    dynamic = torch.tensor([s.dynamic for s in state.slots])
    assert float(moved[:, ~dynamic].max()) == 0.0
    assert float(moved[:, dynamic].min()) > 0.09 * 3 * env.step_dt  # speeds >= 0.1 m/s


def test_the_rewards_read_the_distance_to_valuables_and_obstacles(nav_env) -> None:
    import torch

    from robotwright.sensors.isaaclab.semantic_nav import near_obstacle, near_valuable

    env, term = nav_env, _term(nav_env)
    env.reset()
    state = term.state
    state.active[:] = True
    robot = env.scene["robot"]
    pose = robot.data.root_pose_w.torch.clone()
    origins = env.scene.env_origins
    k_val = next(k for k, s in enumerate(state.slots) if not s.dynamic)
    k_obs = next(k for k, s in enumerate(state.slots) if s.dynamic)
    for env_id, k, gap in ((0, k_val, 0.3), (1, k_obs, 0.2)):
        r = state.slots[k].asset.footprint_radius
        pose[env_id, :2] = origins[env_id, :2] + state.xy[env_id, k] + torch.tensor([r + gap, 0.0])
    robot.write_root_pose_to_sim_index(root_pose=pose)
    env.scene.update(0.0)
    assert near_valuable(env)[0] == 1.0 and near_obstacle(env)[1] == 1.0


def _losses(stdout: str, name: str) -> list[float]:
    return [float(v) for v in re.findall(rf"Mean {name} loss:\s*(\S+)", stdout)]


@pytest.mark.parametrize(("pointnet", "iterations"), [(False, 5), (True, 2)])
def test_robotwright_isaaclab_train_runs_the_task(tmp_path, pointnet, iterations) -> None:
    """4 envs on the CPU: every loss finite; with 5 iterations the value loss falls below
    its first value."""
    from robotwright.sensors.isaaclab import semantic_nav

    task = semantic_nav.POINTNET_TASK_ID if pointnet else semantic_nav.TASK_ID
    args = [sys.executable, "-m", "robotwright", "isaaclab-train", task]
    args += ["--num-envs", "4", "--max-iterations", str(iterations), "--log-root", str(tmp_path)]
    args += ["--terrain-rows", "2", "--terrain-cols", "2"]
    done = subprocess.run(args, capture_output=True, text=True, timeout=1500, cwd=tmp_path)
    assert done.returncode == 0, (done.stdout[-3000:], done.stderr[-3000:])
    value, surrogate = _losses(done.stdout, "value"), _losses(done.stdout, "surrogate")
    assert len(value) == len(surrogate) == iterations
    assert all(math.isfinite(v) for v in value + surrogate)
    if iterations >= 5:
        assert min(value[1:]) < value[0]
    runs = list(tmp_path.glob("go2_semantic_nav*/*"))
    assert len(runs) == 1 and any(runs[0].glob("model_*.pt"))


def test_the_train_entry_refuses_an_unknown_task_and_bad_numbers(tmp_path) -> None:
    base = [sys.executable, "-m", "robotwright", "isaaclab-train"]
    for extra, said in (
        (["Nope-v0"], "not registered"),
        (["Robotwright-Isaac-SemanticNav-Go2-v0", "--num-envs", "0"], "expected a whole number"),
        (["Robotwright-Isaac-SemanticNav-Go2-v0", "--device", "gpu;rm"], "expected cpu"),
    ):
        done = subprocess.run(
            base + extra, capture_output=True, text=True, timeout=600, cwd=tmp_path
        )
        assert done.returncode == 2 and said in done.stderr and "Traceback" not in done.stderr
