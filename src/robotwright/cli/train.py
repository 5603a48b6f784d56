"""``robotwright isaaclab-train``: train an Isaac Lab task (the seed's among them) with
rsl_rl, kit-less on Newton (:mod:`robotwright.sensors.isaaclab.train`)."""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Any

__all__ = ["register", "run"]


def _whole(low: int, high: int) -> Any:
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not low <= value <= high:
            raise argparse.ArgumentTypeError(
                f"{text!r}: expected a whole number in [{low}, {high}]"
            )
        return value

    return parse


def _device(text: str) -> str:
    if not re.fullmatch(r"cpu|cuda(:\d{1,2})?", text):
        raise argparse.ArgumentTypeError(f"{text!r}: expected cpu, cuda or cuda:N")
    return text


#: Most environments, iterations and terrain rows or columns a run may ask for.
MAX_ENVS, MAX_ITERATIONS, MAX_TERRAIN_CELLS = 1 << 20, 10**7, 100


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "isaaclab-train",
        help="train an Isaac Lab task with rsl_rl, kit-less (Isaac Lab 3 environment)",
        description=(
            "Train a gym-registered Isaac Lab task (e.g. Robotwright-Isaac-SemanticNav-Go2-v0) "
            "with rsl_rl on Newton, without Isaac Sim's app; logs and checkpoints under "
            "LOG_ROOT/<experiment>/<date-time>/."
        ),
    )
    p.add_argument("task", help="gym id, e.g. Robotwright-Isaac-SemanticNav-Go2-v0")
    p.add_argument("--num-envs", type=_whole(1, MAX_ENVS), help="environments (task's own)")
    p.add_argument("--max-iterations", type=_whole(1, MAX_ITERATIONS), help="PPO iterations")
    p.add_argument("--device", type=_device, default="cpu", help="cpu or cuda:N (default cpu)")
    p.add_argument("--seed", type=_whole(0, 2**31 - 1), help="runner seed (task's own)")
    p.add_argument("--log-root", type=Path, default=Path("logs/rsl_rl"), help="log folder")
    cells = _whole(1, MAX_TERRAIN_CELLS)
    p.add_argument("--terrain-rows", type=cells, help="terrain generator rows (task's own)")
    p.add_argument("--terrain-cols", type=cells, help="terrain generator columns (task's own)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import importlib.util

    from robotwright.errors import SensorError

    if importlib.util.find_spec("isaaclab_newton") is None:
        raise SensorError(
            "isaaclab-train needs Isaac Lab 3 (Python 3.12: pip install 'isaaclab==3.0.0' "
            "'robotwright[isaaclab]' example-robot-data); isaaclab_newton is not installed"
        )
    from robotwright.sensors.isaaclab.train import train

    log_dir = train(
        args.task,
        num_envs=args.num_envs,
        max_iterations=args.max_iterations,
        device=args.device,
        seed=args.seed,
        log_root=args.log_root,
        terrain_rows=args.terrain_rows,
        terrain_cols=args.terrain_cols,
    )
    print(f"logs and checkpoints: {log_dir}")
    return 0
