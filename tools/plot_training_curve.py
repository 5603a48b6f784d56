"""Plot an mjlab (rsl_rl) training run's curve from its TensorBoard event files.

Usage: ``python tools/plot_training_curve.py RUN_DIR OUT.png [--title TEXT] [--window N]``

``RUN_DIR`` is the run's folder under ``--log-root`` (``<experiment>/<date>``) holding
``events.out.tfevents.*``. Draws the mean episode reward and the mean episode length
(environment steps) per learning iteration, each with its moving average over
``--window`` iterations, and prints the first, last and best values. Needs tensorboard
and matplotlib (not robotwright dependencies; the mjlab environment has both).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

TAGS = (
    ("Train/mean_reward", "mean episode reward"),
    ("Train/mean_episode_length", "mean episode length [steps]"),
)


def _series(run_dir: Path) -> dict[str, tuple[list[int], list[float]]] | str:
    """Each tag's (iterations, values), or the error line naming the missing tag."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    acc = EventAccumulator(str(run_dir), size_guidance={"scalars": 0})
    acc.Reload()
    found = acc.Tags()["scalars"]
    out = {}
    for tag, _ in TAGS:
        if tag not in found or not acc.Scalars(tag):
            return f"error: {run_dir}: no scalar '{tag}' in the event files"
        out[tag] = ([e.step for e in acc.Scalars(tag)], [e.value for e in acc.Scalars(tag)])
    return out


def _moving_average(values: list[float], window: int) -> list[float]:
    out, total = [], 0.0
    for i, v in enumerate(values):
        total += v
        if i >= window:
            total -= values[i - window]
        out.append(total / min(i + 1, window))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--title", default="")
    parser.add_argument("--window", type=int, default=10)
    args = parser.parse_args(argv)
    if not args.run_dir.is_dir() or not list(args.run_dir.glob("events.out.tfevents.*")):
        print(f"error: {args.run_dir}: no events.out.tfevents.* file", file=sys.stderr)
        return 2
    series = _series(args.run_dir)
    if isinstance(series, str):
        print(series, file=sys.stderr)
        return 2

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(TAGS), figsize=(10, 3.6))
    for ax, (tag, label) in zip(axes, TAGS):
        steps, values = series[tag]
        ax.plot(steps, values, color="0.7", lw=0.8, label="per iteration")
        ax.plot(
            steps,
            _moving_average(values, args.window),
            color="C0",
            lw=1.6,
            label=f"mean of {args.window}",
        )
        ax.set_xlabel("learning iteration")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        print(
            f"{tag}: {len(values)} iterations, first {values[0]:.3f}, last {values[-1]:.3f}, "
            f"max {max(values):.3f} (iteration {steps[values.index(max(values))]}), "
            f"last-{args.window} mean {sum(values[-args.window :]) / min(args.window, len(values)):.3f}"
        )
    if args.title:
        fig.suptitle(args.title, fontsize=10)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main())
