"""Train the semantic seeker with and without the LiDAR's labels; compare time at target.

    python benchmarks/semantic_seeker.py --iterations 150 --seeds 1 [--jobs 2] [--out DIR]
        [--policy mlp|pointnet]

Runs mjlab's PPO (rsl_rl, the task's own runner config: 64 envs x 32 steps per
iteration, MLP 128-64) on ``Mjlab-Semantic-Seeker-PointMass`` and on its ``-NoLabels``
variant (the same task without the class channels), once per seed, on warp's CPU device
(or ``--device``). Each run is a fresh process. The measure is mjlab's episode metric
``at_target``: the share of an episode's steps the agent spends within 0.5 m of the
target, per iteration the mean over the episodes that ended in it. Prints per run the
first and last values and the seconds per iteration, writes ``DIR/seeker_runs.json``
and ``DIR/seeker_curves.png`` (needs matplotlib), and prints last:

    at target: labels X, no labels Y

With ``--policy pointnet`` the one variant is ``Mjlab-Semantic-Seeker-PointMass-PointNet``
(the labelled hits as a point cloud, :class:`robotwright.sensors.pointnet.PointNetModel`)
and the last line is ``at target: pointnet X``.

X and Y: ``at_target`` over the last 10 iterations (all of them when there are fewer),
mean over seeds. The cylinders are solid; ``--pass-through`` turns contacts off. Needs the mjlab
environment (``pip install 'robotwright[mjlab]'``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict
from pathlib import Path

from _machine import measured

VARIANTS = (("labels", True), ("no labels", False))
#: ``--policy pointnet``: the labels read as a point cloud by PointNet (no twin without
#: labels: the classes are what its points carry).
POINTNET_VARIANTS = (("pointnet", True),)
#: Iterations at the end whose ``at_target`` the summary averages.
LAST = 10


def train(
    labels: bool, seed: int, iterations: int, device: str, solid: bool = True, policy: str = "mlp"
) -> dict:
    """One training run in this process: per-iteration metrics and timing."""
    import torch
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.rl import MjlabOnPolicyRunner, RslRlVecEnvWrapper

    from robotwright.sensors.mjlab import seeker

    torch.manual_seed(seed)
    env_cfg = seeker.seeker_env_cfg(labels, solid=solid, policy=policy)
    env_cfg.seed = seed
    rl_cfg = seeker.seeker_runner_cfg(labels, policy=policy)
    rl_cfg.seed = seed
    steps = rl_cfg.num_steps_per_env
    sums: dict[str, list[float]] = {"at_target": [], "near_obstacle": []}
    counts: list[float] = []

    class Recording(RslRlVecEnvWrapper):
        """mjlab's wrapper, keeping the episode metrics of every step's ended episodes."""

        calls = 0

        def step(self, actions):  # noqa: ANN001, ANN202 - rsl_rl's VecEnv signature
            obs, rew, dones, extras = super().step(actions)
            it = Recording.calls // steps
            Recording.calls += 1
            while len(counts) <= it:
                counts.append(0.0)
                for v in sums.values():
                    v.append(0.0)
            ended = float(dones.sum())
            log = extras.get("log", {})
            if ended:
                counts[it] += ended
                for key, v in sums.items():
                    v[it] += float(log[f"Episode_Metrics/{key}"]) * ended
            return obs, rew, dones, extras

    env = Recording(ManagerBasedRlEnv(cfg=env_cfg, device=device), clip_actions=None)
    runner = MjlabOnPolicyRunner(env, asdict(rl_cfg), None, device)
    start = time.perf_counter()
    runner.learn(num_learning_iterations=iterations, init_at_random_ep_len=True)
    seconds = time.perf_counter() - start
    env.close()
    curves = {
        key: [s / c if c else math.nan for s, c in zip(v, counts, strict=True)]
        for key, v in sums.items()
    }
    return {
        "variant": "pointnet" if policy == "pointnet" else "labels" if labels else "no labels",
        "seed": seed,
        "iterations": iterations,
        "seconds": seconds,
        "episodes": counts,
        **curves,
    }


def tail_mean(values: list[float], last: int = LAST) -> float:
    """Mean of the last ``last`` values that are numbers (iterations where episodes ended)."""
    tail = [v for v in values[-last:] if not math.isnan(v)]
    return sum(tail) / len(tail) if tail else math.nan


def plot(runs: list[dict], path: Path) -> None:
    """Curves of ``at_target`` per iteration, one line per run, coloured by variant."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.2), dpi=120)
    colours = {"labels": "tab:blue", "no labels": "tab:orange", "pointnet": "tab:green"}
    seen: set[str] = set()
    for run in runs:
        v = run["variant"]
        ax.plot(
            range(1, len(run["at_target"]) + 1),
            run["at_target"],
            color=colours[v],
            alpha=0.8,
            lw=1.2,
            label=None if v in seen else f"{v}",
        )
        seen.add(v)
    ax.set_xlabel("PPO iteration (64 envs x 32 steps)")
    ax.set_ylabel("share of episode time at the target")
    ax.set_ylim(0.0, 1.0)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    ax.set_title("Semantic seeker: LiDAR labels as rays (MLP), points (PointNet), or none")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def _run_worker(labels: bool, seed: int, args: argparse.Namespace, out: Path) -> dict:
    name = "pointnet" if args.policy == "pointnet" else "labels" if labels else "nolabels"
    result = out / f"run_{name}_{seed}.json"
    cmd = [
        sys.executable,
        __file__,
        "--worker",
        "1" if labels else "0",
        str(seed),
        str(args.iterations),
        args.device,
        str(result),
        "0" if args.pass_through else "1",
        args.policy,
    ]
    env = dict(os.environ)
    if args.jobs > 1:  # share the cores between the runs
        env.setdefault("OMP_NUM_THREADS", "1")
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"training run {cmd[3:6]} failed:\n{done.stderr[-4000:]}")
    return json.loads(result.read_text(encoding="utf-8"))


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == "--worker":
        labels, seed, iterations, device, path, solid, policy = argv[1:8]
        if device == "cpu" and os.environ.get("OMP_NUM_THREADS") == "1":
            import torch

            torch.set_num_threads(1)
        result = train(labels == "1", int(seed), int(iterations), device, solid == "1", policy)
        Path(path).write_text(json.dumps(result), encoding="utf-8")
        return 0
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--iterations", type=int, default=150, help="PPO iterations per run")
    parser.add_argument("--seeds", type=int, default=1, help="runs per variant (seeds 0..S-1)")
    parser.add_argument("--jobs", type=int, default=1, help="runs at a time (processes)")
    parser.add_argument("--device", default="cpu", help="torch/warp device (cpu, cuda:0)")
    parser.add_argument("--out", type=Path, default=Path("seeker_out"), help="output folder")
    parser.add_argument(
        "--pass-through",
        action="store_true",
        help="contacts off: the agent passes through the cylinders (both variants alike)",
    )
    parser.add_argument(
        "--policy",
        choices=("mlp", "pointnet"),
        default="mlp",
        help="mlp: the labelled and unlabelled rays into an MLP (both variants); pointnet: "
        "the labelled hits as a point cloud into PointNet (robotwright.sensors.pointnet)",
    )
    args = parser.parse_args(argv)
    if args.iterations < 1 or args.seeds < 1 or args.jobs < 1:
        parser.error("expected --iterations, --seeds and --jobs >= 1")
    args.out.mkdir(parents=True, exist_ok=True)
    variants = POINTNET_VARIANTS if args.policy == "pointnet" else VARIANTS
    plan = [(labels, seed) for _, labels in variants for seed in range(args.seeds)]
    print(
        f"training {len(plan)} runs of {args.iterations} iterations on {args.device} "
        f"({args.jobs} at a time, "
        f"{'obstacles passed through' if args.pass_through else 'solid obstacles'}); "
        f"cores: {os.cpu_count()}",
        flush=True,
    )
    with ThreadPoolExecutor(args.jobs) as pool:
        runs = list(pool.map(lambda p: _run_worker(p[0], p[1], args, args.out), plan))
    print(f"{'variant':<10} {'seed':>4} {'first':>7} {f'last {LAST}':>8} {'s/iter':>7}")
    for run in runs:
        print(
            f"{run['variant']:<10} {run['seed']:>4} {tail_mean(run['at_target'][:LAST]):7.3f}"
            f" {tail_mean(run['at_target']):8.3f} {run['seconds'] / run['iterations']:7.2f}"
        )
    (args.out / "seeker_runs.json").write_text(json.dumps(runs, indent=1), encoding="utf-8")
    try:
        plot(runs, args.out / "seeker_curves.png")
        print(f"curves: {args.out / 'seeker_curves.png'}")
    except ImportError:
        print("note: matplotlib is not installed: no curve picture")
    means = {
        name: sum(tail_mean(r["at_target"]) for r in runs if r["variant"] == name) / args.seeds
        for name, _ in variants
    }
    print("at target: " + ", ".join(f"{name} {value:.3f}" for name, value in means.items()))
    return 0


if __name__ == "__main__":
    with measured(("mjlab", "torch", "rsl-rl-lib")):
        sys.exit(main())
