"""Cost of a semantic LiDAR inside an mjlab environment step (Go1 rough-terrain velocity task).

Variants of `Mjlab-Velocity-Rough-Unitree-Go1`, each built fresh, stepped with zero
actions; the median wall time of `env.step()` is compared with the task as shipped
(which already casts its own 17x11 `terrain_scan` grid):

  task                        the task as shipped
  + mjlab RayCastSensor       plus mjlab's own RayCastSensor on the trunk casting the
                              20 000 directions of our Mid-360 frame 0 (no labels)
  + robotwright (mjlab)       plus robotwright.sensors.mjlab.SemanticLidarSensorCfg, the
                              same 20 000-ray Mid-360 advancing each step, labels on
                              (when that module is present)
  + robotwright (core)        the task plus a core SemanticLidarSensor (engine "warp",
                              output "torch") reading the env's mujoco_warp.Data in
                              place, updated after every step

The added cost is reported per step and relative to the step that already casts the
same rays with mjlab's sensor (the issue's target: <= 10% on CUDA).
Needs mjlab (the MuJoCo 3.11 environment of .ci/run).
Run: python benchmarks/lidar_mjlab_step.py [--envs 16] [--steps 20] [--device cpu|cuda]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from _machine import measured

from robotwright.sensors import LivoxPatternCfg, SemanticLidarCfg, SemanticLidarSensor

TASK = "Mjlab-Velocity-Rough-Unitree-Go1"


def make_env(num_envs: int, device: str, extra_sensors: list[Any]) -> Any:
    import mjlab.tasks  # noqa: F401  (registers the tasks)
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.tasks.registry import load_env_cfg

    cfg = load_env_cfg(TASK)
    cfg.scene.num_envs = num_envs
    cfg.scene.sensors = tuple(cfg.scene.sensors or ()) + tuple(extra_sensors)
    env = ManagerBasedRlEnv(cfg, device=device)
    env.reset()
    return env


def mjlab_same_rays(directions: np.ndarray) -> Any:
    import torch
    from mjlab.sensor.builtin_sensor import ObjRef
    from mjlab.sensor.raycast_sensor import RayCastSensorCfg

    class SameRays:
        """An mjlab pattern casting our Mid-360 frame-0 directions."""

        def generate_rays(self, mj_model: Any, dev: str) -> tuple[Any, Any]:
            d = torch.as_tensor(directions, dtype=torch.float32, device=dev)
            return torch.zeros_like(d), d

    return RayCastSensorCfg(
        name="mid360_mjlab",
        frame=ObjRef(type="body", name="trunk", entity="robot"),
        pattern=SameRays(),  # type: ignore[arg-type]
        max_distance=40.0,
        include_geom_groups=None,
    )


def time_steps(env: Any, steps: int, after: Callable[[], None] | None = None) -> float:
    import torch

    action = torch.zeros(env.num_envs, env.action_manager.total_action_dim, device=env.device)
    times = []
    for i in range(steps + 3):  # three warm-up steps
        t0 = time.perf_counter()
        env.step(action)
        if after is not None:
            after()
        if env.device != "cpu":
            torch.cuda.synchronize()
        if i >= 3:
            times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--envs", type=int, default=16)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--device", default="cpu")
    args = ap.parse_args()
    pattern = LivoxPatternCfg(num_rays=20_000)
    dirs = pattern.rays(0)[1]
    print(f"{TASK}, {args.envs} envs, device {args.device}, {os.cpu_count()} CPU cores")
    results: dict[str, float] = {}

    env = make_env(args.envs, args.device, [])
    results["task"] = time_steps(env, args.steps)
    model = env.sim.mj_model
    lidar = SemanticLidarSensor(
        SemanticLidarCfg(
            prim_path="robot/trunk",
            pattern_cfg=pattern,
            max_distance=40.0,
            engine="warp",
            device=args.device,
            output="torch",
        ),
        model,
        env.sim.wp_data,
    )
    results["+ robotwright (core, after each step)"] = time_steps(env, args.steps, lidar.update)
    del env

    env = make_env(args.envs, args.device, [mjlab_same_rays(dirs)])
    results["+ mjlab RayCastSensor, same rays"] = time_steps(env, args.steps)
    del env

    try:
        from robotwright.sensors.mjlab import SemanticLidarSensorCfg
    except ImportError as exc:
        print(f"  (robotwright.sensors.mjlab not available: {exc})")
    else:
        from mjlab.sensor.builtin_sensor import ObjRef

        cfg = SemanticLidarSensorCfg(
            name="lidar",
            frame=ObjRef(type="body", name="trunk", entity="robot"),
            pattern=pattern,
            max_distance=40.0,
        )
        env = make_env(args.envs, args.device, [cfg])
        results["+ robotwright (mjlab sensor)"] = time_steps(env, args.steps)
        del env

    base = results["task"]
    mj = results["+ mjlab RayCastSensor, same rays"]
    rays = args.envs * 20_000
    for label, t in results.items():
        extra = t - base
        line = f"  {label:42s} {t * 1e3:9.2f} ms/step  +{extra * 1e3:8.2f} ms"
        if label != "task":
            line += f"  ({rays / max(extra, 1e-9) / 1e6:7.2f} Mrays/s added)"
        if label.startswith("+ robotwright"):
            line += f"  {100 * (t - mj) / mj:+6.1f}% vs the step with mjlab's cast"
        print(line)


if __name__ == "__main__":
    with measured(("mujoco-warp", "warp-lang", "mjlab", "torch")):
        main()
