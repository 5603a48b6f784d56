"""Draw the seed's task as a framework simulated it: the Go2 among its labelled objects,
its semantic scan coloured by class (docs/images/semantic_nav_<framework>.png).

    python tools/picture_semantic_nav.py mjlab -o docs/images/semantic_nav_mjlab.png
    python tools/picture_semantic_nav.py isaaclab -o docs/images/semantic_nav_isaaclab.png

mjlab runs in the MuJoCo 3.11 environment, Isaac Lab in its own (``.ci/run``); both on
warp's CPU device. One environment on flat ground; the robot stands (zero actions hold
its default pose) for ``--steps`` policy steps while the obstacles move, then the last
scan is drawn by :func:`robotwright.render.nav_scene.draw_nav_scene`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np


def _mjlab_state(steps: int, seed: int) -> dict:
    import mjlab  # noqa: F401 - loads the tasks
    import torch
    from mjlab.envs import ManagerBasedRlEnv

    from robotwright.sensors.mjlab.semantic_nav import semantic_nav_env_cfg
    from robotwright.sensors.semantic_nav import go2_mjcf

    cfg = semantic_nav_env_cfg(play=True, flat=True)
    cfg.scene.num_envs = 1
    cfg.seed = seed
    env = ManagerBasedRlEnv(cfg=cfg, device="cpu")
    env.reset()
    action = torch.zeros(1, env.action_manager.total_action_dim)
    for _ in range(steps):
        env.step(action)
    robot, lidar = env.scene["robot"], env.scene["lidar"]
    term = env.event_manager.get_term_cfg("semantic_scene").func.state
    names = robot.joint_names
    state = {
        "xml": go2_mjcf(),
        "root": robot.data.root_link_pose_w[0].tolist(),
        "joints": dict(zip(names, robot.data.joint_pos[0].tolist(), strict=True)),
        "objects": [
            (s.asset, env.scene[s.name].data.root_link_pose_w[0].tolist()) for s in term.slots
        ],
        "points": np.where(
            lidar.data.hit_mask[0, :, None].numpy(), lidar.data.hit_pos_w[0].numpy(), np.nan
        ),
        "labels": lidar.data.semantic_labels[0].numpy(),
        "class_names": lidar.class_names,
        "mapping": lidar.semantic_class_mapping,
        "framework": "mjlab 1.6 (MuJoCo Warp, CPU)",
    }
    env.close()
    return state


def _isaaclab_state(steps: int, seed: int) -> dict:
    """One environment on nearly flat ground (height noise of at most 5 mm): the same
    state as :func:`_mjlab_state`, read from Isaac Lab."""
    import gymnasium as gym
    import isaaclab.terrains as terrain_gen
    import torch
    from isaaclab_tasks.utils.hydra import resolve_presets

    from robotwright.sensors.isaaclab.semantic_nav import TASK_ID, SemanticNavGo2EnvCfg
    from robotwright.sensors.semantic_nav import go2_mjcf

    cfg = resolve_presets(SemanticNavGo2EnvCfg())
    cfg.scene.num_envs = 1
    cfg.sim.device = "cpu"
    cfg.seed = seed
    generator = cfg.scene.terrain.terrain_generator
    generator.num_rows = generator.num_cols = 1
    generator.curriculum = False
    generator.sub_terrains = {
        "flat": terrain_gen.HfRandomUniformTerrainCfg(
            proportion=1.0, noise_range=(0.0, 0.005), noise_step=0.005
        )
    }
    cfg.curriculum.terrain_levels = None
    env = gym.make(TASK_ID, cfg=cfg).unwrapped
    try:
        env.reset()
        action = torch.zeros(1, env.action_manager.total_action_dim)
        for _ in range(steps):
            env.step(action)
        robot, lidar = env.scene["robot"], env.scene["lidar"]
        term = env.event_manager.get_term_cfg("semantic_scene").func

        def pose(asset) -> list[float]:  # Isaac Lab: x y z qx qy qz qw
            p = asset.data.root_pose_w.torch[0].tolist()
            return [*p[:3], p[6], *p[3:6]]

        hit = lidar.data.hit_mask.torch[0].numpy()
        return {
            "xml": go2_mjcf(),
            "root": pose(robot),
            "joints": dict(
                zip(robot.joint_names, robot.data.joint_pos.torch[0].tolist(), strict=True)
            ),
            "objects": [(s.asset, pose(env.scene[s.name])) for s in term.state.slots],
            "points": np.where(hit[:, None], lidar.data.ray_hits_w.torch[0].numpy(), np.nan),
            "labels": lidar.data.semantic_labels.torch[0].numpy(),
            "class_names": lidar.class_names,
            "mapping": lidar.semantic_class_mapping,
            "framework": "Isaac Lab 3 (Newton, CPU)",
        }
    finally:
        env.close()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("framework", choices=("mjlab", "isaaclab"))
    p.add_argument("-o", "--output", required=True, type=Path)
    p.add_argument("--steps", type=int, default=25, help="policy steps before the picture")
    p.add_argument("--seed", type=int, default=2)
    p.add_argument("--camera", default="135,-40,7", help="AZIMUTH,ELEVATION,DISTANCE")
    args = p.parse_args(argv)
    if args.framework == "mjlab":
        state = _mjlab_state(args.steps, args.seed)
    else:
        state = _isaaclab_state(args.steps, args.seed)
    from robotwright.render.nav_scene import draw_nav_scene

    hits = int(np.isfinite(state["points"]).all(axis=1).sum())
    draw_nav_scene(
        state["xml"],
        state["root"],
        state["joints"],
        state["objects"],
        state["points"],
        state["labels"],
        state["class_names"],
        args.output,
        mapping=state["mapping"],
        camera=args.camera,
        title=f"Go2 among labelled objects, {state['framework']}: {hits} hits by class",
    )
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
