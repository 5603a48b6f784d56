"""Steps per second of the seed's task (the Go2 among labelled clutter), by env count.

For each environment count, the task is built fresh and stepped with zero actions; the
median wall time of ``env.step()`` gives environment steps per second (all envs) and
per env. With ``--compare`` the same task without the semantic LiDAR (sensor and
observation removed) is timed too, and the LiDAR's share of the step is printed.

    python benchmarks/semantic_nav.py mjlab --envs 4 16              # MuJoCo 3.11 env
    python benchmarks/semantic_nav.py isaaclab --envs 4 16           # Isaac Lab env
    python benchmarks/semantic_nav.py mjlab --envs 4096 --device cuda:0 --json nav.json

Prints the machine, its load and the versions first.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parent))

from _machine import machine, print_machine  # noqa: E402

PACKAGES = {
    "mjlab": ("mjlab", "mujoco", "mujoco-warp", "warp-lang", "torch"),
    "isaaclab": ("isaaclab", "newton", "warp-lang", "torch"),
}


def mjlab_env(num_envs: int, device: str, lidar: bool = True, policy: str = "mlp") -> Any:
    """The mjlab task with ``num_envs`` environments (without the LiDAR when asked)."""
    import mjlab  # noqa: F401 - registers the tasks
    from mjlab.envs import ManagerBasedRlEnv

    from robotwright.sensors.mjlab.semantic_nav import semantic_nav_env_cfg

    cfg = semantic_nav_env_cfg(policy=policy)
    cfg.scene.num_envs = num_envs
    if not lidar:
        cfg.scene.sensors = tuple(s for s in cfg.scene.sensors if s.name != "lidar")
        for group in list(cfg.observations):
            cfg.observations[group].terms.pop("lidar", None)
        cfg.observations.pop("points", None)
    env = ManagerBasedRlEnv(cfg, device=device)
    env.reset()
    return env


def isaaclab_env(num_envs: int, device: str, lidar: bool = True, policy: str = "mlp") -> Any:
    """The Isaac Lab task with ``num_envs`` environments (without the LiDAR when asked)."""
    import gymnasium as gym
    from isaaclab_tasks.utils.hydra import resolve_presets

    from robotwright.sensors.isaaclab import semantic_nav

    cls = semantic_nav.SemanticNavGo2PointNetEnvCfg if policy == "pointnet" else None
    cfg = resolve_presets((cls or semantic_nav.SemanticNavGo2EnvCfg)())
    cfg.scene.num_envs = num_envs
    cfg.sim.device = device
    if not lidar:
        cfg.scene.lidar = None
        cfg.observations.policy.lidar = None
        if policy == "pointnet":
            cfg.observations.points = None
    env = gym.make(semantic_nav.TASK_ID, cfg=cfg).unwrapped
    env.reset()
    return env


def time_steps(env: Any, steps: int, warmup: int = 3) -> float:
    """Median seconds of ``env.step`` with zero actions (after ``warmup`` steps)."""
    import torch

    action = torch.zeros(env.num_envs, env.action_manager.total_action_dim, device=env.device)
    times = []
    for i in range(steps + warmup):
        t0 = time.perf_counter()
        env.step(action)
        if str(env.device).startswith("cuda"):
            torch.cuda.synchronize()
        if i >= warmup:
            times.append(time.perf_counter() - t0)
    return statistics.median(times)


def measure(framework: str, num_envs: int, device: str, steps: int, lidar: bool) -> float:
    """Median step time [s] of a fresh environment."""
    make = mjlab_env if framework == "mjlab" else isaaclab_env
    env = make(num_envs, device, lidar=lidar)
    try:
        return time_steps(env, steps)
    finally:
        env.close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("framework", choices=sorted(PACKAGES))
    ap.add_argument("--envs", type=int, nargs="+", default=[4, 16])
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--compare", action="store_true", help="also time the task without LiDAR")
    ap.add_argument("--json", type=Path, help="write the figures here")
    args = ap.parse_args(argv)
    info = machine(PACKAGES[args.framework])
    print_machine(info)
    rows = []
    for n in args.envs:
        step = measure(args.framework, n, args.device, args.steps, lidar=True)
        row = {"envs": n, "step_s": step, "env_steps_per_s": n / step, "per_env": 1.0 / step}
        line = f"{n:6d} envs: {step * 1e3:9.2f} ms/step  {n / step:10.1f} env-steps/s"
        if args.compare:
            bare = measure(args.framework, n, args.device, args.steps, lidar=False)
            row["step_without_lidar_s"] = bare
            line += f"  (without the LiDAR {bare * 1e3:8.2f} ms: x{step / bare:.2f})"
        print(line, flush=True)
        rows.append(row)
    print(f"load average after: {machine()['load_average']}")
    if args.json:
        args.json.write_text(
            json.dumps({"machine": info, "device": args.device, "rows": rows}, indent=1)
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
