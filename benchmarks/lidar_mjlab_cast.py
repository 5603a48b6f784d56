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
5 senses each; ratios to mjlab's sense in the same run. Before each sense every sensor is
told that one policy step (0.02 s) of simulated time passed, as mjlab's physics loop does.

With --options, one more sensor per realism option (each alone, on top of the default
sensor) runs in the same rounds, and each one's cost is printed as a ratio to the default
sensor: what a user pays for that option. Needs mjlab (the MuJoCo 3.11 environment of
.ci/run).

Run: python benchmarks/lidar_mjlab_cast.py [--envs 16] [--scenes go1 seeker] [--options]
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
#: Simulated seconds between two senses (a 50 Hz policy).
POLICY_DT = 0.02

#: One sensor per realism option, each alone: label -> the config fields it sets.
OPTIONS: dict[str, dict[str, Any]] = {
    "range_noise_std 0.01 m": {"range_noise_std": 0.01},
    "dropout_prob 0.1": {"dropout_prob": 0.1},
    "range_noise_per_meter 0.005": {"range_noise_per_meter": 0.005},
    "angular_jitter_std 0.002 rad": {"angular_jitter_std": 0.002},
    "class_dropout terrain 0.3": {"class_dropout": {"terrain": 0.3}},
    "mount_pos_range 0.01 m": {"mount_pos_range": (0.01, 0.01, 0.01)},
    "drift_range +-0.01 m": {"drift_range": (-0.01, 0.01)},
    "update_period 0.1 s (a scan every 5th sense)": {"update_period": 0.1},
}


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


def _sensors(scene: str, options: bool) -> list[Any]:
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
    if options:
        for i, fields in enumerate(OPTIONS.values()):
            ours[f"rw_option{i}"] = SemanticLidarSensorCfg(
                name=f"rw_option{i}", frame=frame, pattern=pattern, max_distance=40.0, **fields
            )
    return [mjlab_cfg, *ours.values()]


def _sense(env: Any, sensor: Any) -> Callable[[], None]:
    """One sense of ``sensor`` alone, as mjlab's sense pipeline runs it."""
    import warp as wp

    rc = env.sim._sensor_context.render_context

    def run() -> None:
        sensor.update(POLICY_DT)
        sensor.prepare_rays()
        with wp.ScopedDevice(env.sim.wp_device):
            sensor.raycast_kernel(rc=rc)
        wp.synchronize()
        sensor.postprocess_rays()
        _ = sensor.data  # what an observation reads

    return run


def bench(scene: str, envs: int, options: bool) -> dict[str, float]:
    env = _scene(scene, envs, _sensors(scene, options))
    names = {"mjlab RayCastSensor": "mid360_mjlab", "ours, 1 thread": "rw_1"}
    names["ours, default threads"] = "rw_None"
    if options:
        names.update({f"+ {label}": f"rw_option{i}" for i, label in enumerate(OPTIONS)})
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
    ap.add_argument("--options", action="store_true", help="also time each realism option alone")
    args = ap.parse_args()
    for scene in args.scenes:
        times = bench(scene, args.envs, args.options)
        base = times["mjlab RayCastSensor"]
        ours = times["ours, default threads"]
        print(
            f"{scene}: {args.envs} envs x {RAYS} rays, one sense (median of {ROUNDS}x{PER_ROUND})"
        )
        for label, t in times.items():
            line = f"  {label:48s} {t * 1e3:8.2f} ms  {t / base:5.2f}x mjlab's"
            if label.startswith("+ "):
                line += f"  {t / ours:5.2f}x ours without it"
            print(line)


if __name__ == "__main__":
    with measured(("mujoco-warp", "warp-lang", "mjlab", "torch")):
        main()
