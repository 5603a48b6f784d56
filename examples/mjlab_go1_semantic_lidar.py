"""A Unitree Go1 in mjlab with a semantic Mid-360 on its trunk, among furniture.

mjlab's `Mjlab-Velocity-Flat-Unitree-Go1` task, plus:
  * props named for the default classes (a sofa and a table: "valuable"; cracker boxes:
    "dynamic_obstacle") as a static entity around the origin, where every environment's
    robot is moved after reset (each environment is its own MuJoCo world);
  * the seed's default class mapping with one keyword added: mjlab names its terrain
    geoms ``terrain/terrain_<n>``, which none of "ground", "wall", "floor", "plane" match;
  * robotwright's SemanticLidarSensorCfg (20 000 Mid-360 rays advancing each step) on
    the trunk, and the seed's stacked observation as an extra actor term.
Steps the environments with zero actions, then saves a labelled scan picture of
environment 0 and prints rays, hits per class and steps per second.

Needs mjlab (pip install 'robotwright[mjlab]'; mjlab pins MuJoCo 3.11).
Run: python examples/mjlab_go1_semantic_lidar.py [OUT_DIR] [--envs 4] [--steps 200]
     [--device cpu|cuda]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import mujoco

TASK = "Mjlab-Velocity-Flat-Unitree-Go1"

#: Props around each robot: (name, size of the box [m], position in the env [m]).
PROPS = (
    ("sofa_0", (0.9, 0.4, 0.4), (2.5, 1.5, 0.4)),
    ("dining_table_0", (0.8, 0.5, 0.4), (-2.0, -2.0, 0.4)),
    ("cracker_box_0", (0.1, 0.08, 0.15), (1.5, -1.0, 0.15)),
    ("cracker_box_1", (0.1, 0.08, 0.15), (-1.2, 1.8, 0.15)),
)


def props_spec() -> mujoco.MjSpec:
    """A static entity of named boxes (group 0: the LiDAR sees them)."""
    spec = mujoco.MjSpec()
    for name, size, pos in PROPS:
        body = spec.worldbody.add_body(name=name, pos=pos)
        body.add_geom(name=f"{name}_geom", type=mujoco.mjtGeom.mjGEOM_BOX, size=size)
    return spec


def make_env(num_envs: int, device: str) -> Any:
    import mjlab.tasks  # noqa: F401  (registers the tasks)
    from mjlab.entity import EntityCfg
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.managers.observation_manager import ObservationTermCfg
    from mjlab.sensor.builtin_sensor import ObjRef
    from mjlab.tasks.registry import load_env_cfg

    from robotwright.sensors import DEFAULT_SEMANTIC_CLASS_MAPPING, LivoxPatternCfg
    from robotwright.sensors.mjlab import SemanticLidarSensorCfg, lidar_semantic_obs

    cfg = load_env_cfg(TASK)
    cfg.scene.num_envs = num_envs
    cfg.scene.entities = {**cfg.scene.entities, "props": EntityCfg(spec_fn=props_spec)}
    lidar = SemanticLidarSensorCfg(
        name="lidar",
        frame=ObjRef(type="body", name="trunk", entity="robot"),
        lidar_pattern=LivoxPatternCfg(sensor_type="mid360"),
        max_distance=20.0,
        semantic_class_mapping=mapping(DEFAULT_SEMANTIC_CLASS_MAPPING),
    )
    cfg.scene.sensors = (*(cfg.scene.sensors or ()), lidar)
    cfg.observations["actor"].terms["lidar"] = ObservationTermCfg(
        func=lidar_semantic_obs, params={"sensor_name": "lidar"}
    )
    env = ManagerBasedRlEnv(cfg, device=device)
    env.reset()
    robot = env.scene["robot"]
    pose = robot.data.root_link_pose_w.clone()
    pose[:, :2] = 0.0  # every robot among the props (one world per environment)
    robot.write_root_link_pose_to_sim(pose)
    return env


def mapping(default: dict[str, list[str]]) -> dict[str, list[str]]:
    """The default classes, with mjlab's terrain geom name as a terrain keyword."""
    out = {k: list(v) for k, v in default.items()}
    out["terrain"].append("terrain")
    return out


def run(
    out_dir: Path | None, num_envs: int = 4, steps: int = 200, device: str | None = None
) -> dict:
    """Step the task and scan; returns a summary (and writes the picture into ``out_dir``)."""
    import torch

    from robotwright.sensors.plot import plot_scan

    device = device or ("cuda" if torch.cuda.is_available() else "cpu")
    env = make_env(num_envs, device)
    sensor = env.scene["lidar"]
    action = torch.zeros(env.num_envs, env.action_manager.total_action_dim, device=env.device)
    t0 = time.perf_counter()
    for _ in range(steps):
        obs, *_ = env.step(action)
    elapsed = time.perf_counter() - t0
    data = sensor.data
    labels = data.semantic_labels.cpu().numpy()
    hits = data.hit_mask.cpu().numpy()
    counts = {n: int(((labels == i) & hits).sum()) for i, n in enumerate(sensor.class_names)}
    summary = {
        "envs": env.num_envs,
        "rays": int(labels.shape[1]),
        "steps_per_s": steps / elapsed,
        "hits_per_class": counts,
        "actor_obs": tuple(obs["actor"].shape),
        "png": None,
    }
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        png = out_dir / "go1_semantic_scan.png"
        plot_scan(
            data.hit_pos_w[0].cpu().numpy(),
            labels[0],
            sensor.class_names,
            png,
            sensor_pos=data.pos_w[0].cpu().numpy(),
            title=f"Go1 in mjlab, Mid-360 after {steps} steps (env 0)",
            view_radius=8.0,
        )
        summary["png"] = str(png)
    return summary


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("out_dir", nargs="?", type=Path, default=None)
    ap.add_argument("--envs", type=int, default=4)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--device", default=None)
    args = ap.parse_args()
    s = run(args.out_dir, args.envs, args.steps, args.device)
    print(f"{s['envs']} envs x {s['rays']} rays, {s['steps_per_s']:.1f} env steps/s")
    print("hits per class:", ", ".join(f"{k}={v}" for k, v in s["hits_per_class"].items()))
    print(f"actor observation {s['actor_obs']}" + (f"; picture: {s['png']}" if s["png"] else ""))


if __name__ == "__main__":
    main()
