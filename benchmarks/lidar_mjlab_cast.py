"""One sense of the semantic LiDAR against mjlab's own RayCastSensor, the same rays, in
the same environment: prepare (host), cast (warp) and post-process, timed sensor by
sensor, interleaved, on two scenes:

  go1      mjlab's Mjlab-Velocity-Rough-Unitree-Go1 (rough terrain), the sensors on the
           trunk
  seeker   robotwright's Mjlab-Semantic-Seeker-PointMass (five cylinders), the sensors
           on the agent

Each scene carries mjlab's RayCastSensor casting our Mid-360 frame-0 directions (20 000
rays, no labels), our SemanticLidarSensorCfg with the same pattern on one warp thread
(num_threads=1) and with its default split on warp's CPU device. Medians of 15 rounds of
5 senses each; ratios to mjlab's sense in the same run. Needs mjlab (the MuJoCo 3.11
environment of .ci/run).

Run: python benchmarks/lidar_mjlab_cast.py [--envs 16] [--scenes go1 seeker]
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from typing import Any

from _machine import measured
from lidar_mjlab_step import mjlab_same_rays

from robotwright.sensors import LivoxPatternCfg

RAYS = 20_000
ROUNDS, PER_ROUND = 15, 5


def _scene(name: str, envs: int, sensors: list[Any]) -> Any:
    """The environment of scene ``name`` with ``sensors`` added, reset and stepped once."""
    import mjlab.tasks  # noqa: F401  (registers the tasks)
    import torch
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.tasks.registry import load_env_cfg

    if name == "go1":
        cfg = load_env_cfg("Mjlab-Velocity-Rough-Unitree-Go1")
    else:
        from robotwright.sensors.mjlab.seeker import seeker_env_cfg

        cfg = seeker_env_cfg()
    cfg.scene.num_envs = envs
    cfg.scene.sensors = tuple(cfg.scene.sensors or ()) + tuple(sensors)
    env = ManagerBasedRlEnv(cfg, device="cpu")
    env.reset()
    env.step(torch.zeros(envs, env.action_manager.total_action_dim))
    return env


def _sensors(scene: str) -> list[Any]:
    from mjlab.sensor.builtin_sensor import ObjRef

    from robotwright.sensors.mjlab import SemanticLidarSensorCfg

    frame = (
        ObjRef(type="body", name="trunk", entity="robot")
        if scene == "go1"
        else ObjRef(type="body", name="agent", entity="agent")
    )
    pattern = LivoxPatternCfg(num_rays=RAYS)
    mjlab_cfg = mjlab_same_rays(pattern.rays(0)[1])
    mjlab_cfg.frame = frame
    ours = {
        f"rw_{k}": SemanticLidarSensorCfg(
            name=f"rw_{k}", frame=frame, pattern=pattern, max_distance=40.0, num_threads=k
        )
        for k in (1, None)
    }
    return [mjlab_cfg, *ours.values()]


def _sense(env: Any, sensor: Any) -> Callable[[], None]:
    """One sense of ``sensor`` alone, as mjlab's sense pipeline runs it."""
    import warp as wp

    rc = env.sim._sensor_context.render_context

    def run() -> None:
        sensor.prepare_rays()
        with wp.ScopedDevice(env.sim.wp_device):
            sensor.raycast_kernel(rc=rc)
        wp.synchronize()
        sensor.postprocess_rays()
        _ = sensor.data  # what an observation reads

    return run


def bench(scene: str, envs: int) -> dict[str, float]:
    env = _scene(scene, envs, _sensors(scene))
    names = {"mjlab RayCastSensor": "mid360_mjlab", "ours, 1 thread": "rw_1"}
    names["ours, default threads"] = "rw_None"
    runs = {label: _sense(env, env.scene.sensors[key]) for label, key in names.items()}
    for run in runs.values():
        run()  # warm-up: kernels loaded, caches filled
    samples: dict[str, list[float]] = {label: [] for label in runs}
    for _ in range(ROUNDS):  # interleaved: a load change touches every sensor alike
        for label, run in runs.items():
            t0 = time.perf_counter()
            for _ in range(PER_ROUND):
                run()
            samples[label].append((time.perf_counter() - t0) / PER_ROUND)
    return {label: statistics.median(s) for label, s in samples.items()}


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--envs", type=int, default=16)
    ap.add_argument("--scenes", nargs="+", default=["go1", "seeker"], choices=["go1", "seeker"])
    args = ap.parse_args()
    for scene in args.scenes:
        times = bench(scene, args.envs)
        base = times["mjlab RayCastSensor"]
        print(
            f"{scene}: {args.envs} envs x {RAYS} rays, one sense (median of {ROUNDS}x{PER_ROUND})"
        )
        for label, t in times.items():
            print(f"  {label:24s} {t * 1e3:8.2f} ms  {t / base:5.2f}x mjlab's")


if __name__ == "__main__":
    with measured(("mujoco-warp", "warp-lang", "mjlab", "torch")):
        main()
