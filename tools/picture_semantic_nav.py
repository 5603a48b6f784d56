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

    from robotwright.sensors.mjlab.semantic_nav import _go2_mjcf, semantic_nav_env_cfg

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
        "xml": _go2_mjcf()[0],
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
        from robotwright.sensors.isaaclab.semantic_nav import picture_state

        state = picture_state(args.steps, args.seed)
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
