"""Train an Isaac Lab task with rsl_rl, kit-less (Newton): what Isaac Lab's
``scripts/reinforcement_learning/rsl_rl/train.py`` does, without Isaac Sim's app.

    python -m robotwright.sensors.isaaclab.train Robotwright-Isaac-SemanticNav-Go2-v0 \\
        --num_envs 4096 --max_iterations 1500 --device cuda:0

The task's env and runner configs come from its gym registration (``env_cfg_entry_point``,
``rsl_rl_cfg_entry_point``); the robotwright tasks are registered on import. Logs and
checkpoints go to ``<log_root>/<experiment_name>/<date-time>/`` (rsl_rl's tensorboard
files, ``model_<i>.pt``). rsl_rl prints each iteration's losses and rewards.
"""

from __future__ import annotations

import argparse
import sys
from datetime import datetime
from pathlib import Path

#: Most environments and iterations a run may ask for.
MAX_ENVS, MAX_ITERATIONS = 1 << 20, 10**7
#: Most rows or columns of sub-terrains.
MAX_TERRAIN_CELLS = 100


def _bounded(low: int, high: int) -> object:
    def parse(text: str) -> int:
        value = int(text)
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{value}: expected a whole number in [{low}, {high}]")
        return value

    return parse


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m robotwright.sensors.isaaclab.train", description=__doc__.split("\n\n")[0]
    )
    p.add_argument("task", help="a registered task id, e.g. Robotwright-Isaac-SemanticNav-Go2-v0")
    p.add_argument("--num_envs", type=_bounded(1, MAX_ENVS), default=None)
    p.add_argument("--max_iterations", type=_bounded(1, MAX_ITERATIONS), default=None)
    p.add_argument("--device", default="cpu", help="cpu or cuda:N")
    p.add_argument("--seed", type=_bounded(0, 2**31 - 1), default=None)
    p.add_argument("--log_root", type=Path, default=Path("logs/rsl_rl"))
    rows = _bounded(1, MAX_TERRAIN_CELLS)
    p.add_argument("--terrain_rows", type=rows, default=None, help="terrain generator rows")
    p.add_argument("--terrain_cols", type=rows, default=None, help="terrain generator columns")
    return p


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
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

    if args.task not in gym.registry:
        print(f"train: task {args.task!r} is not registered", file=sys.stderr)
        return 2
    env_cfg = resolve_presets(load_cfg_from_registry(args.task, "env_cfg_entry_point"))
    agent_cfg = load_cfg_from_registry(args.task, "rsl_rl_cfg_entry_point")
    agent_cfg = handle_deprecated_rsl_rl_cfg(agent_cfg, check_rsl_rl_version())
    if args.num_envs is not None:
        env_cfg.scene.num_envs = args.num_envs
    generator = getattr(env_cfg.scene.terrain, "terrain_generator", None)
    for field in ("num_rows", "num_cols"):
        value = getattr(args, f"terrain_{field[4:]}")
        if value is not None and generator is not None:
            setattr(generator, field, value)
    if args.max_iterations is not None:
        agent_cfg.max_iterations = args.max_iterations
    if args.seed is not None:
        agent_cfg.seed = args.seed
    env_cfg.seed = agent_cfg.seed
    env_cfg.sim.device = agent_cfg.device = args.device
    log_dir = (
        args.log_root / agent_cfg.experiment_name / datetime.now().strftime("%Y-%m-%d_%H-%M-%S")
    )
    env = gym.make(args.task, cfg=env_cfg)
    try:
        wrapped = RslRlVecEnvWrapper(env, clip_actions=agent_cfg.clip_actions)
        runner = create_rsl_rl_runner(wrapped, agent_cfg, log_dir=str(log_dir))
        runner.learn(num_learning_iterations=agent_cfg.max_iterations, init_at_random_ep_len=True)
    finally:
        env.close()
    print(f"logs and checkpoints: {log_dir}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
