"""Train an Isaac Lab task with rsl_rl, kit-less (Newton): what Isaac Lab's
``scripts/reinforcement_learning/rsl_rl/train.py`` does, without Isaac Sim's app. The
command line is ``robotwright isaaclab-train TASK`` (:mod:`robotwright.cli.train`).

The task's env and runner configs come from its gym registration (``env_cfg_entry_point``,
``rsl_rl_cfg_entry_point``; the robotwright tasks are registered on import), Isaac Lab's
physics presets resolved to their defaults. Logs and checkpoints go to
``<log_root>/<experiment_name>/<date-time>/`` (rsl_rl's tensorboard files,
``model_<i>.pt``); rsl_rl prints each iteration's losses and rewards.
"""

from __future__ import annotations

from datetime import datetime
from pathlib import Path

from robotwright.errors import SensorError

__all__ = ["train"]


def train(
    task: str,
    *,
    num_envs: int | None = None,
    max_iterations: int | None = None,
    device: str = "cpu",
    seed: int | None = None,
    log_root: str | Path = "logs/rsl_rl",
    terrain_rows: int | None = None,
    terrain_cols: int | None = None,
) -> Path:
    """Train ``task`` (a gym id); ``None`` keeps the task's own value. Returns the run's
    log folder.

    Raises:
        SensorError: the task is not registered.
    """
    import gymnasium as gym
    from isaaclab_rl.rsl_rl import RslRlVecEnvWrapper
    from isaaclab_rl.rsl_rl.utils import (
        check_rsl_rl_version,
        create_rsl_rl_runner,
        handle_deprecated_rsl_rl_cfg,
    )
    from isaaclab_tasks.utils.hydra import resolve_presets
    from isaaclab_tasks.utils.parse_cfg import load_cfg_from_registry

    import robotwright.sensors.isaaclab.semantic_nav  # noqa: F401 - registers the tasks

    if task not in gym.registry:
        ours = sorted(t for t in gym.registry if t.startswith("Robotwright-"))
        raise SensorError(f"task {task!r} is not registered; robotwright's: {', '.join(ours)}")
    env_cfg = resolve_presets(load_cfg_from_registry(task, "env_cfg_entry_point"))
    agent_cfg = load_cfg_from_registry(task, "rsl_rl_cfg_entry_point")
    agent_cfg = handle_deprecated_rsl_rl_cfg(agent_cfg, check_rsl_rl_version())
    if num_envs is not None:
        env_cfg.scene.num_envs = num_envs
    generator = getattr(getattr(env_cfg.scene, "terrain", None), "terrain_generator", None)
    for field, value in (("num_rows", terrain_rows), ("num_cols", terrain_cols)):
        if value is not None and generator is not None:
            setattr(generator, field, value)
    if max_iterations is not None:
        agent_cfg.max_iterations = max_iterations
    if seed is not None:
        agent_cfg.seed = seed
    env_cfg.seed = agent_cfg.seed
    env_cfg.sim.device = agent_cfg.device = device
    stamp = datetime.now().strftime("%Y-%m-%d_%H-%M-%S")
    log_dir = Path(log_root) / agent_cfg.experiment_name / stamp
    env = gym.make(task, cfg=env_cfg)
    try:
        wrapped = RslRlVecEnvWrapper(env, clip_actions=agent_cfg.clip_actions)
        runner = create_rsl_rl_runner(wrapped, agent_cfg, log_dir=str(log_dir))
        runner.learn(num_learning_iterations=agent_cfg.max_iterations, init_at_random_ep_len=True)
    finally:
        env.close()
    return log_dir
