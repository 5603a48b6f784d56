"""The semantic seeker tasks (marked ``mjlab``): registered through mjlab's entry point,
the labels variant sees classes the other does not, the layout and rewards mean what
they say, and a short PPO run of each goes through mjlab's runner.

Runs in the MuJoCo 3.11 environment of ``.ci/run`` on warp's CPU device; skipped with a
reason where mjlab is not installed.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

import mjlab  # noqa: E402, F401 - loads the entry points
import torch  # noqa: E402
from mjlab.envs import ManagerBasedRlEnv  # noqa: E402
from mjlab.tasks.registry import list_tasks, load_env_cfg, load_rl_cfg  # noqa: E402
from mjlab_train import run_train  # noqa: E402

from robotwright.sensors.mjlab import seeker  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def _env(cfg, envs: int = 3) -> ManagerBasedRlEnv:
    """A seeded env of ``cfg``: the layouts a test sees are the same on every run."""
    cfg.scene.num_envs = envs
    cfg.seed = 7
    return ManagerBasedRlEnv(cfg=cfg, device="cpu")


def _place(env: ManagerBasedRlEnv, agent_x: float, target_x: float) -> None:
    """The agent and the target on the x axis, the obstacles 2 m off it on either side
    (nothing between the two), everything at rest."""
    n = env.num_envs
    layout = torch.tensor([[agent_x, 0.0], [target_x, 0.0], [0.0, 2.0], [0.0, -2.0]])
    seeker.place_layout(env, torch.arange(n), layout.expand(n, 4, 2).clone())
    env.sim.forward()


@pytest.fixture(scope="module")
def labelled():
    env = _env(load_env_cfg(seeker.TASK_ID))
    yield env
    env.close()


def test_both_variants_are_registered_with_the_same_network_and_budget() -> None:
    assert {seeker.TASK_ID, seeker.NO_LABELS_TASK_ID} <= set(list_tasks())
    a, b = load_rl_cfg(seeker.TASK_ID), load_rl_cfg(seeker.NO_LABELS_TASK_ID)
    assert a.actor.hidden_dims == b.actor.hidden_dims == (128, 64)
    assert a.num_steps_per_env == b.num_steps_per_env
    assert a.algorithm == b.algorithm


def test_only_the_labels_variant_observes_classes(labelled) -> None:
    obs, _ = labelled.reset()
    sensor = labelled.scene["lidar"]
    classes = len(sensor.class_names)
    rays = seeker.RING_RAYS
    assert obs["actor"].shape == (3, rays + rays * classes + 2)
    other = _env(load_env_cfg(seeker.NO_LABELS_TASK_ID))
    try:
        obs_b, _ = other.reset()
        assert obs_b["actor"].shape == (3, rays + 2)
    finally:
        other.close()


def test_the_ring_sees_the_target_as_valuable_and_the_obstacles_as_dynamic(labelled) -> None:
    """Every ray that hits a cylinder carries the class of the cylinder it hit; the target
    and both obstacles are seen (placed at least 1 m apart, within 6 m range)."""
    labelled.reset()
    sensor = labelled.scene["lidar"]
    names = sensor.class_names
    data = sensor.data
    target = labelled.scene["target"].data.root_link_pos_w[:, :2]
    hits = data.hit_pos_w[..., :2]
    near_target = (hits - target[:, None]).norm(dim=2) < seeker.CYLINDER_RADIUS + 1e-3
    labels = data.semantic_labels
    assert near_target.any()
    assert (labels[near_target & data.hit_mask] == names.index("valuable")).all()
    assert (labels[~near_target & data.hit_mask] == names.index("dynamic_obstacle")).all()


def test_reset_places_everything_apart_inside_the_arena(labelled) -> None:
    for _ in range(3):
        labelled.reset()
        agent, target, obstacles = seeker._positions(labelled)
        pts = torch.cat([agent[:, None], target[:, None], obstacles], dim=1)
        assert pts.abs().max() <= seeker.ARENA_HALF
        gaps = torch.cdist(pts, pts) + torch.eye(4) * 1e3
        # 16 tries per env: with 4 points in a 5 m square the layout nearly always fits
        assert (gaps.amin(dim=(1, 2)) >= seeker.MIN_SEPARATION).float().mean() >= 2 / 3


def test_rewards_follow_the_distance_to_the_target(labelled) -> None:
    """Pushing toward the target earns progress; sitting on it counts as at target."""
    labelled.reset()
    agent_ent = labelled.scene["agent"]
    _, target, _ = seeker._positions(labelled)
    assert (seeker.near_target(labelled) == 0).all()
    speed = seeker.progress_to_target(labelled)
    assert torch.allclose(speed, torch.zeros(3), atol=1e-6)  # at rest after the reset
    agent, target, _ = seeker._positions(labelled)
    toward = (target - agent) / (target - agent).norm(dim=1, keepdim=True)
    for _ in range(3):
        labelled.step(toward)
    assert (seeker.progress_to_target(labelled) > 0).all()
    agent_ent.write_joint_state_to_sim(target.clone(), torch.zeros_like(target))
    labelled.sim.forward()
    assert (seeker.near_target(labelled) == 1).all()


def test_the_benchmark_trains_both_variants_and_prints_the_comparison(tmp_path) -> None:
    """Two short runs through the benchmark script: it finishes, writes its files and
    prints the summary line with two shares in [0, 1]."""
    done = subprocess.run(
        [
            sys.executable,
            str(ROOT / "benchmarks" / "semantic_seeker.py"),
            "--iterations",
            "2",
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    # The comparison is the last figure; the load after the run follows it.
    *_, last, after = done.stdout.strip().splitlines()
    assert last.startswith("at target: labels ")
    assert after.startswith("load average after: ")
    values = [float(v.split()[-1]) for v in last.split(":", 1)[1].split(",")]
    assert len(values) == 2 and all(0.0 <= v <= 1.0 and not math.isnan(v) for v in values)
    assert (tmp_path / "seeker_runs.json").is_file()


def test_mjlab_s_train_runs_the_seeker(tmp_path) -> None:
    """mjlab's own ``train`` entry point on the registered task (2 iterations)."""
    args = [
        seeker.NO_LABELS_TASK_ID,
        "--env.scene.num-envs",
        "4",
        "--agent.max-iterations",
        "2",
        "--agent.num-steps-per-env",
        "8",
        "--gpu-ids",
        "None",
        "--log-root",
        str(tmp_path),
    ]
    done = run_train(args, tmp_path, timeout=600)
    runs = list((tmp_path / "semantic_seeker_no_labels").iterdir())
    assert len(runs) == 1 and (runs[0] / "model_1.pt").is_file()
    assert "Learning iteration 1/2" in done.stdout


@pytest.mark.parametrize("solid", [False, True])
def test_solid_obstacles_stop_the_agent_at_their_surface(solid) -> None:
    """Pushed straight at the target for 4 s (2 m away, nothing between), the agent
    passes through it without contacts and stops at its surface with them (centres
    0.35 m apart: radii 0.25 and 0.1, less the contacts' softness)."""
    env = _env(seeker.seeker_env_cfg(True, solid=solid), envs=2)
    try:
        env.reset()
        _place(env, -1.0, 1.0)
        closest = float("inf")
        for _ in range(40):
            agent, target, _ = seeker._positions(env)
            env.step((target - agent) / (target - agent).norm(dim=1, keepdim=True))
            agent, target, _ = seeker._positions(env)
            closest = min(closest, float((target - agent).norm(dim=1).min()))
    finally:
        env.close()
    if solid:
        assert 0.3 < closest < seeker.NEAR  # stopped at the surface, still "at the target"
    else:
        assert closest < 0.15  # through it
