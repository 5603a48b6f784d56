"""A Unitree Go1 in mjlab with a semantic Mid-360 on its trunk, among furniture.

mjlab's `Mjlab-Velocity-Flat-Unitree-Go1` task, plus:
  * props named for the default classes: a sofa, a dining table and an armchair
    ("valuable") as a static entity, and two cracker boxes ("dynamic_obstacle") as
    free-floating entities that fall onto the floor and can be pushed;
  * every environment's origin at (0, 0) (env_spacing 0: each environment is its own
    MuJoCo world, so the robots never meet), so every robot stands among the props;
  * robotwright's SemanticLidarSensorCfg (20 000 Mid-360 rays, the window advancing
    each step) on the trunk, 0.1 m above its centre, with the seed's default classes
    plus mjlab's terrain geoms (`/world/terrain/...`) as terrain
    (`mjlab_class_mapping()`; the seed's keywords "ground", "floor", ... match no mjlab
    terrain name);
  * the seed's stacked observation `lidar_semantic_obs` as an extra actor term.
Steps the environments with zero or random actions, then saves a labelled scan picture
of environment 0 and prints rays, hits per class and environment steps per second.

Needs mjlab (pip install 'robotwright[mjlab]'; mjlab pins MuJoCo 3.11).
Run: python examples/mjlab_go1_semantic_lidar.py [OUT_DIR] [--envs 4] [--steps 200]
     [--device cpu|cuda] [--actions zero|random]
"""

from __future__ import annotations

import argparse
import functools
import time
from pathlib import Path
from typing import Any

import mujoco

TASK = "Mjlab-Velocity-Flat-Unitree-Go1"
MAX_DISTANCE = 20.0  # [m]

#: Static furniture: (body name, box half-sizes [m], position [m]).
FURNITURE = (
    ("sofa_0", (0.9, 0.4, 0.4), (2.5, 1.5, 0.4)),
    ("dining_table_0", (0.8, 0.5, 0.4), (-2.0, -2.0, 0.4)),
    ("armchair_0", (0.4, 0.4, 0.45), (-2.5, 2.0, 0.45)),
)
#: Free cracker boxes: (entity name, position [m]); half-sizes CRACKER_BOX.
CRACKER_BOXES = (("cracker_box_0", (1.5, -1.0, 0.3)), ("cracker_box_1", (-1.2, 1.8, 0.3)))
CRACKER_BOX = (0.08, 0.03, 0.11)


def furniture_spec() -> mujoco.MjSpec:
    """Static named boxes in geom group 0 (the group the LiDAR casts at)."""
    spec = mujoco.MjSpec()
    for name, size, pos in FURNITURE:
        body = spec.worldbody.add_body(name=name, pos=pos)
        body.add_geom(name=f"{name}_geom", type=mujoco.mjtGeom.mjGEOM_BOX, size=size)
    return spec


def cracker_box_spec(pos: tuple[float, float, float]) -> mujoco.MjSpec:
    """One free cracker box (0.41 kg) at ``pos`` [m], named like the seed's YCB object.

    The body position is the free joint's initial pose (mjlab applies an entity's
    ``init_state`` only in reset events, and this task resets only the robot).
    """
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="box", pos=pos)
    body.add_freejoint()
    body.add_geom(
        name="_03_cracker_box", type=mujoco.mjtGeom.mjGEOM_BOX, size=CRACKER_BOX, mass=0.41
    )
    return spec


def make_env(num_envs: int, device: str) -> Any:
    """The Go1 task with props and the semantic LiDAR ``"lidar"``, reset and ready."""
    import mjlab.tasks  # noqa: F401  (registers the tasks)
    from mjlab.entity import EntityCfg
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.managers.observation_manager import ObservationTermCfg
    from mjlab.sensor.builtin_sensor import ObjRef
    from mjlab.tasks.registry import load_env_cfg

    from robotwright.sensors import LivoxPatternCfg
    from robotwright.sensors.mjlab import (
        SemanticLidarSensorCfg,
        lidar_semantic_obs,
        mjlab_class_mapping,
    )

    cfg = load_env_cfg(TASK)
    cfg.scene.num_envs = num_envs
    cfg.scene.env_spacing = 0.0
    props = {"furniture": EntityCfg(spec_fn=furniture_spec)}
    for name, pos in CRACKER_BOXES:
        props[name] = EntityCfg(
            spec_fn=functools.partial(cracker_box_spec, pos),
            init_state=EntityCfg.InitialStateCfg(pos=pos),
        )
    cfg.scene.entities = {**cfg.scene.entities, **props}
    lidar = SemanticLidarSensorCfg(
        name="lidar",
        frame=ObjRef(type="body", name="trunk", entity="robot"),
        pattern=LivoxPatternCfg(sensor_type="mid360"),
        offset_pos=(0.0, 0.0, 0.1),
        max_distance=MAX_DISTANCE,
        semantic_class_mapping=mjlab_class_mapping(),
    )
    cfg.scene.sensors = (*(cfg.scene.sensors or ()), lidar)
    cfg.observations["actor"].terms["lidar"] = ObservationTermCfg(
        func=lidar_semantic_obs, params={"sensor_name": "lidar"}
    )
    env = ManagerBasedRlEnv(cfg, device=device)
    env.reset()
    return env


def run(
    out_dir: Path | None,
    num_envs: int = 4,
    steps: int = 200,
    device: str | None = None,
    actions: str = "zero",
) -> dict[str, Any]:
    """Step the task; returns a summary and writes the picture into ``out_dir``."""
    import torch

    from robotwright.sensors.plot import plot_scan

    device = device or ("cuda" if torch.cuda.is_available() else "cpu")
    env = make_env(num_envs, device)
    sensor = env.scene["lidar"]
    shape = (env.num_envs, env.action_manager.total_action_dim)
    generator = torch.Generator(device=env.device).manual_seed(0)
    obs: dict[str, torch.Tensor] = {}
    t0 = time.perf_counter()
    for _ in range(steps):
        if actions == "random":
            action = torch.rand(shape, generator=generator, device=env.device) * 2.0 - 1.0
        else:
            action = torch.zeros(shape, device=env.device)
        obs, *_ = env.step(action)
    if env.device.startswith("cuda"):
        torch.cuda.synchronize()
    elapsed = time.perf_counter() - t0
    data = sensor.data
    labels = data.semantic_labels.cpu().numpy()
    hits = data.hit_mask.cpu().numpy()
    counts = {n: int(((labels == i) & hits).sum()) for i, n in enumerate(sensor.class_names)}
    summary: dict[str, Any] = {
        "envs": env.num_envs,
        "rays": int(labels.shape[1]),
        "steps": steps,
        "steps_per_s": steps / elapsed,
        "env_steps_per_s": steps * env.num_envs / elapsed,
        "hits_per_class": counts,
        "misses": int((~hits).sum()),
        "actor_obs": tuple(obs["actor"].shape) if obs else None,
        "device": env.device,
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
            title=f"Go1 in mjlab: Mid-360 frame after {steps} steps (env 0)",
            view_radius=6.0,
        )
        summary["png"] = str(png)
    env.close()
    return summary


def main(argv: list[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("out_dir", nargs="?", type=Path, default=None, help="output folder")
    ap.add_argument("--envs", type=int, default=4, help="number of environments (default 4)")
    ap.add_argument("--steps", type=int, default=200, help="environment steps (default 200)")
    ap.add_argument("--device", default=None, help="cpu or cuda (default: cuda if available)")
    ap.add_argument("--actions", choices=("zero", "random"), default="zero")
    args = ap.parse_args(argv)
    s = run(args.out_dir, args.envs, args.steps, args.device, args.actions)
    print(
        f"{s['envs']} envs x {s['rays']} rays on {s['device']}: {s['steps']} steps, "
        f"{s['steps_per_s']:.1f} steps/s ({s['env_steps_per_s']:.1f} env steps/s, "
        f"{s['env_steps_per_s'] * s['rays']:.3g} rays/s including physics)"
    )
    hits = ", ".join(f"{k}={v}" for k, v in s["hits_per_class"].items())
    print(f"hits per class (all envs, last step): {hits}; misses={s['misses']}")
    print(f"actor observation {s['actor_obs']}" + (f"; picture: {s['png']}" if s["png"] else ""))
    return s


if __name__ == "__main__":
    main()
