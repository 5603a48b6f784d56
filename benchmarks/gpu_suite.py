"""The GPU figures in one run: LiDAR throughput, the seed's task's steps per second, and a
short training run with its reward curve, in each framework this Python has.

    python benchmarks/gpu_suite.py --device cuda:0 --envs 4096 --out gpu_suite.json
    python benchmarks/gpu_suite.py --device cpu --envs 4 --iterations 3   # the CPU check

Sections (each in a subprocess of its own with a time limit, so that one failing or
running out of memory leaves the others' figures; a framework that is not installed is
skipped with the reason):

  lidar_mjlab      mjlab's Go1 rough task + our 20 000-ray semantic Mid-360 vs mjlab's
                   RayCastSensor casting the same directions: rays/s added and the ratio
  lidar_isaaclab   Isaac Lab's NewtonRaycastSensor vs our LiDAR on the same rays
                   (benchmarks/isaaclab_lidar.py), rays/s and the ratio to the stock cast
  nav_mjlab        steps/s of Robotwright-Mjlab-SemanticNav-Go2 (benchmarks/semantic_nav.py)
  nav_isaaclab     steps/s of Robotwright-Isaac-SemanticNav-Go2-v0
  train_mjlab      N iterations of mjlab's train on the task: losses and mean reward per
                   iteration
  train_isaaclab   N iterations of `robotwright isaaclab-train` on the Isaac Lab task

Writes one JSON summary (machine, versions, each section's figures or its error) to
``--out`` and prints it. Needs no network.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _machine import machine, print_machine  # noqa: E402

SECTIONS = (
    "lidar_mjlab",
    "lidar_isaaclab",
    "nav_mjlab",
    "nav_isaaclab",
    "train_mjlab",
    "train_isaaclab",
)
LIDAR_RAYS = 20_000


def _framework(section: str) -> str:
    return section.rsplit("_", 1)[1]


def missing(section: str) -> str | None:
    """Why ``section`` cannot run in this Python, or ``None``."""
    module = {"mjlab": "mjlab", "isaaclab": "isaaclab_newton"}[_framework(section)]
    if importlib.util.find_spec(module) is None:
        return f"{module} is not installed in this Python"
    return None


def lidar_mjlab(envs: int, device: str, steps: int) -> dict[str, Any]:
    """Added step cost of our sensor and of mjlab's cast of the same 20 000 directions."""
    from lidar_mjlab_step import make_env, mjlab_same_rays, time_steps
    from mjlab.sensor.builtin_sensor import ObjRef

    from robotwright.sensors import LivoxPatternCfg
    from robotwright.sensors.mjlab import SemanticLidarSensorCfg

    pattern = LivoxPatternCfg(num_rays=LIDAR_RAYS)
    ours_cfg = SemanticLidarSensorCfg(
        name="lidar",
        frame=ObjRef(type="body", name="trunk", entity="robot"),
        pattern=pattern,
        max_distance=40.0,
    )
    times = {}
    for name, extra in (
        ("task", []),
        ("stock", [mjlab_same_rays(pattern.rays(0)[1])]),
        ("ours", [ours_cfg]),
    ):
        env = make_env(envs, device, extra)
        times[name] = time_steps(env, steps)
        env.close()
    rays = envs * LIDAR_RAYS
    added = {k: max(times[k] - times["task"], 1e-9) for k in ("stock", "ours")}
    return {
        "rays_per_step": rays,
        "step_s": times,
        "stock_rays_per_s": rays / added["stock"],
        "ours_rays_per_s": rays / added["ours"],
        "ours_over_stock": added["ours"] / added["stock"],
    }


def lidar_isaaclab(envs: int, device: str, steps: int) -> dict[str, Any]:
    from isaaclab_lidar import bench

    return bench(envs, device, steps)


def nav(framework: str, envs: int, device: str, steps: int) -> dict[str, Any]:
    from semantic_nav import measure

    step = measure(framework, envs, device, steps, lidar=True)
    bare = measure(framework, envs, device, steps, lidar=False)
    return {
        "step_s": step,
        "env_steps_per_s": envs / step,
        "step_without_lidar_s": bare,
        "lidar_share": 1.0 - bare / step,
    }


def _per_iteration(stdout: str) -> dict[str, list[float]]:
    """rsl_rl's printed losses, mean episode reward and length, one value per iteration."""
    out: dict[str, list[float]] = {}
    for key, pattern in (
        ("value_loss", r"Mean value loss:\s*(\S+)"),
        ("surrogate_loss", r"Mean surrogate loss:\s*(\S+)"),
        ("mean_reward", r"Mean reward:\s*(\S+)"),
        ("mean_episode_length", r"Mean episode length:\s*(\S+)"),
        ("iteration_s", r"Iteration time:\s*([\d.]+)s"),
    ):
        out[key] = [float(v) for v in re.findall(pattern, stdout)]
    return out


def mjlab_gpu_ids(device: str) -> str:
    """``device`` as mjlab's train takes ``--gpu-ids``: ``None`` for the CPU, else a list
    in Python syntax (``cuda:1`` -> ``[1]``; ``cuda`` is the first GPU)."""
    if device == "cpu":
        return "None"
    return f"[{device.partition(':')[2] or 0}]"


def train(framework: str, envs: int, device: str, iterations: int, limit: float) -> dict[str, Any]:
    """``iterations`` of the framework's train command; the per-iteration figures."""
    with tempfile.TemporaryDirectory(prefix="robotwright-gpu-suite-") as logs:
        if framework == "mjlab":
            code = (
                "import sys; from mjlab.scripts.train import main; "
                "sys.argv = ['train'] + sys.argv[1:]; main()"
            )
            gpu = ["--gpu-ids", mjlab_gpu_ids(device)]
            cmd = [sys.executable, "-c", code, "Robotwright-Mjlab-SemanticNav-Go2"]
            cmd += ["--env.scene.num-envs", str(envs), "--agent.max-iterations", str(iterations)]
            cmd += [*gpu, "--log-root", logs]
        else:
            cmd = [sys.executable, "-m", "robotwright", "isaaclab-train"]
            cmd += ["Robotwright-Isaac-SemanticNav-Go2-v0", "--num-envs", str(envs)]
            cmd += ["--max-iterations", str(iterations), "--device", device, "--log-root", logs]
        t0 = time.perf_counter()
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=limit, cwd=logs)
        if done.returncode != 0:
            raise RuntimeError(done.stderr[-2000:])
        figures = _per_iteration(done.stdout)
    figures["wall_s"] = time.perf_counter() - t0
    figures["envs"] = envs
    return figures


def run_section(args: argparse.Namespace) -> dict[str, Any]:
    section, envs, device = args.section, args.envs, args.device
    if section == "lidar_mjlab":
        return lidar_mjlab(envs, device, args.steps)
    if section == "lidar_isaaclab":
        return lidar_isaaclab(envs, device, args.steps)
    if section.startswith("nav_"):
        return nav(_framework(section), envs, device, args.steps)
    return train(_framework(section), envs, device, args.iterations, args.section_timeout)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--device", default="cuda:0")
    ap.add_argument("--envs", type=int, default=4096)
    ap.add_argument("--steps", type=int, default=20, help="timed steps per measurement")
    ap.add_argument("--iterations", type=int, default=10, help="training iterations")
    ap.add_argument("--sections", nargs="+", choices=SECTIONS, default=list(SECTIONS))
    ap.add_argument("--section-timeout", type=float, default=900.0, help="seconds per section")
    ap.add_argument("--out", type=Path, default=Path("gpu_suite.json"))
    ap.add_argument("--section", choices=SECTIONS, help=argparse.SUPPRESS)  # one, in a child
    args = ap.parse_args(argv)
    if args.section:
        print("RESULT " + json.dumps(run_section(args)), flush=True)
        return 0
    info = machine(("mjlab", "isaaclab", "mujoco", "mujoco-warp", "warp-lang", "newton", "torch"))
    print_machine(info)
    summary: dict[str, Any] = {"machine": info, "device": args.device, "envs": args.envs}
    for section in args.sections:
        reason = missing(section)
        if reason:
            summary[section] = {"skipped": reason}
            print(f"{section}: skipped ({reason})", flush=True)
            continue
        cmd = [sys.executable, __file__, "--section", section, "--device", args.device]
        cmd += ["--envs", str(args.envs), "--steps", str(args.steps)]
        cmd += ["--iterations", str(args.iterations)]
        cmd += ["--section-timeout", str(args.section_timeout)]
        t0 = time.perf_counter()
        try:
            done = subprocess.run(
                cmd, capture_output=True, text=True, timeout=args.section_timeout + 60
            )
        except subprocess.TimeoutExpired:
            summary[section] = {"error": f"ran past {args.section_timeout:g} s"}
            print(f"{section}: ran past its time limit", flush=True)
            continue
        found = [ln for ln in done.stdout.splitlines() if ln.startswith("RESULT ")]
        if done.returncode == 0 and found:
            summary[section] = json.loads(found[-1][len("RESULT ") :])
            summary[section]["section_s"] = round(time.perf_counter() - t0, 1)
            print(f"{section}: {json.dumps(summary[section])}", flush=True)
        else:
            summary[section] = {"error": (done.stderr or done.stdout)[-1500:]}
            print(f"{section}: failed (exit {done.returncode})", flush=True)
    summary["load_average_after"] = machine()["load_average"]
    print(f"load average after: {summary['load_average_after']}")
    args.out.write_text(json.dumps(summary, indent=1))
    print(f"wrote {args.out}")
    return 0 if all("error" not in v for k, v in summary.items() if k in SECTIONS) else 1


if __name__ == "__main__":
    sys.exit(main())
