"""The winners of a search, written to look at: ``OUT/best_1`` ... ``OUT/best_K``.

Each ``best_N`` is a design folder (as ``robotwright grammar export`` writes it: MJCF,
URDF, design text/JSON, tree, picture of the limb alone), readable by
``robotwright view OUT/best_N`` and ``robotwright render``, plus:

- ``values.json`` / ``values.txt``: every objective's value with its unit, the score,
  the rank and the design hash; for ``track`` and ``energy``, ``values.json`` also gives
  each tracking run (one per posture) as a designer checks it: the RMS and largest tool
  error (m), the largest joint speed over its rating, the share of steps touching
  anything and the first touch or overlap (``tracking_run``);
- ``on_carrier.png``: the limb worn by the task's carrier in its display pose, drawn by
  the ``draw_carrier`` function given (``robotwright grammar search -o`` passes
  :func:`robotwright.render.api.draw_pose`: OpenGL when available, else the software
  renderer; the grammar does not import the renderer, which reads design folders);
- ``track.png`` (objectives ``track`` and ``energy``): the tool path against the task's
  reference, seen from the front (y-z) and from above (x-y).

With a task of several carrier postures, each posture gets its pictures, numbered in the
task's order (``on_carrier.png``, ``on_carrier_2.png``, ...; ``track_2.png``, ...), and
``values.json`` lists the postures' names in that order and, under ``by_posture``, each
physics objective's value in every posture (the score is the worst of them).

``OUT/winners.txt`` lists the ranking. The whole folder is written at once (a failure
leaves the earlier output, or none). A Pareto search writes ``front_1`` ... instead, with
``front.json`` and ``pareto.png`` (:func:`write_front`).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from pathlib import Path

import mujoco
import numpy as np

from robotwright._atomic import atomic_dir
from robotwright.grammar.objectives import (
    EvalContext,
    Evaluation,
    Objective,
    Track,
    WorstPosture,
)
from robotwright.grammar.physics import TrackResult, display_pose
from robotwright.grammar.rules import Grammar
from robotwright.grammar.task import DEFAULT_TASK, Task

#: Draws a model at joint values ``qpos`` into a PNG at ``path`` under a ``title``.
DrawPose = Callable[[mujoco.MjModel, np.ndarray, Path, str], None]

#: Unit of each objective's value.
UNITS = {
    "reach": "m",
    "workspace": "m^3",
    "coverage": "share of the box",
    "mass": "kg",
    "dof": "DoF",
    "payload": "kg",
    "track": "m",
    "energy": "W",
}


def ranked(evaluations: Sequence[Evaluation], k: int) -> list[Evaluation]:
    """The ``k`` best feasible evaluations by score, then tie-break (earlier first on
    ties of both)."""
    feasible = [(i, e) for i, e in enumerate(evaluations) if e.feasible]
    feasible.sort(key=lambda t: (-t[1].score, -t[1].tiebreak, t[0]))
    return [e for _, e in feasible[:k]]


def write_winners(
    grammar: Grammar,
    evaluations: Sequence[Evaluation],
    objectives: Sequence[Objective],
    out: str | Path,
    *,
    k: int = 3,
    task: Task = DEFAULT_TASK,
    pictures: bool = True,
    draw_carrier: DrawPose | None = None,
) -> list[Path]:
    """Write the ``k`` best feasible designs of ``evaluations`` into ``out`` (a folder
    of designs; see the module docstring). Returns the ``best_N`` folders written.
    ``draw_carrier(model, qpos, path, title)`` draws ``on_carrier.png`` (with
    ``pictures``; none is drawn without it).

    Raises:
        OutputExistsError: ``out`` holds something other than an earlier folder of
            designs (callers check ``--overwrite`` before).
    """
    return _write_designs(
        grammar,
        ranked(evaluations, k),
        objectives,
        Path(out),
        "best",
        task=task,
        pictures=pictures,
        draw_carrier=draw_carrier,
    )


def write_front(
    grammar: Grammar,
    front: Sequence[Evaluation],
    objectives: Sequence[Objective],
    out: str | Path,
    *,
    evaluated: Sequence[Evaluation] = (),
    task: Task = DEFAULT_TASK,
    pictures: bool = True,
    draw_carrier: DrawPose | None = None,
) -> list[Path]:
    """Write a Pareto front into ``out``: ``front_1`` ... (design folders as
    :func:`write_winners` writes them, in the front's order), ``front.json`` (each
    design's values with units) and, with ``pictures`` and two objectives or more,
    ``pareto.png``: the first two objectives of every feasible design ``evaluated``
    (grey) and of the front (joined), numbered as the folders."""
    names = [o.name for o in objectives]

    def extra(tmp: Path) -> None:
        rows = [
            {
                "folder": f"front_{i}",
                "design_hash": ev.design.hash(),
                "values": {n: {"value": ev.values[n], "unit": UNITS.get(n, "")} for n in names},
            }
            for i, ev in enumerate(front, 1)
        ]
        (tmp / "front.json").write_text(json.dumps(rows, indent=2) + "\n", "utf-8")
        if pictures and len(objectives) >= 2:
            plot_front(front, evaluated, objectives, tmp / "pareto.png")

    return _write_designs(
        grammar,
        list(front),
        objectives,
        Path(out),
        "front",
        task=task,
        pictures=pictures,
        draw_carrier=draw_carrier,
        extra=extra,
    )


def _write_designs(
    grammar: Grammar,
    chosen: Sequence[Evaluation],
    objectives: Sequence[Objective],
    out: Path,
    prefix: str,
    *,
    task: Task,
    pictures: bool,
    draw_carrier: DrawPose | None,
    extra: Callable[[Path], None] | None = None,
) -> list[Path]:
    """``out/<prefix>_N`` for each of ``chosen`` (folder, values, pictures), the list
    ``winners.txt`` and whatever ``extra(tmp)`` adds, written at once."""
    from robotwright.grammar.export import export_design

    names = [o.name for o in objectives]
    lines = []
    written = []
    with atomic_dir(out, kind="designs") as tmp:
        for rank, ev in enumerate(chosen, 1):
            label = f"{prefix}_{rank}"
            folder = tmp / label
            export_design(grammar, ev.design, folder, picture=pictures, overwrite=True)
            values = {
                "rank": rank,
                "design_hash": ev.design.hash(),
                "score": ev.score,
                "objectives": {n: {"value": ev.values[n], "unit": UNITS.get(n, "")} for n in names},
                "values": dict(ev.values),
            }
            # One context per winner: the values by posture, the drawings and the track
            # plots share its limb, mounted models and tracking runs.
            ctx = EvalContext(grammar, ev.design)
            if task.postures:
                values["postures"] = [name for name, _ in task.postures]
                # Each physics objective's value in every posture (its score is the worst).
                values["by_posture"] = {
                    o.name: o.by_posture(ctx) for o in objectives if isinstance(o, WorstPosture)
                }
            if {"track", "energy"} & set(names):
                values["tracking_run"] = _tracking_runs(ctx, task)
            (folder / "values.json").write_text(json.dumps(values, indent=2) + "\n", "utf-8")
            text = "".join(
                f"{n}: {ev.values[n]:.6g} {UNITS.get(n, '')}\n".replace(" \n", "\n")
                for n in ev.values
            )
            (folder / "values.txt").write_text(
                f"rank {rank}, design {ev.design.hash()}\n{text}", "utf-8"
            )
            summary = ", ".join(f"{n} {ev.values[n]:.4g} {UNITS.get(n, '')}" for n in names)
            lines.append(f"{label}: {ev.design.hash()}  {summary.strip()}\n")
            if pictures:
                limb = ctx.limb
                carriers = task.carriers()
                for i, carrier in enumerate(carriers, 1):
                    m = ctx.mounted(carrier)
                    # Numbered, not named: a posture's name comes from the task file.
                    suffix = "" if i == 1 else f"_{i}"
                    of = f", posture {i} of {len(carriers)}" if len(carriers) > 1 else ""
                    if draw_carrier is not None:
                        title = f"{label} on its carrier{of}"
                        png = folder / f"on_carrier{suffix}.png"
                        draw_carrier(m.model, display_pose(limb), png, title)
                    if {"track", "energy"} & set(names):
                        run = Track(carrier=carrier, **task.track).run(ctx)
                        title = f"{label} ({ev.design.hash()}){of}"
                        plot_track(run, folder / f"track{suffix}.png", title)
            written.append(out / label)
        (tmp / "winners.txt").write_text("".join(lines) or "no feasible design\n", encoding="utf-8")
        if extra is not None:
            extra(tmp)
    return written


def _tracking_runs(ctx: EvalContext, task: Task) -> list[dict]:
    """What a designer checks of each tracking run (one per posture): the largest tool
    error (m), the largest joint speed over its rating, the share of steps touching
    anything and the first touch or overlap."""
    names = [n for n, _ in task.postures] or ["carrier"]
    out = []
    for name, carrier in zip(names, task.carriers()):
        run = Track(carrier=carrier, **task.track).run(ctx)
        out.append(
            {
                "posture": name,
                "rms_error_m": run.error,
                "largest_error_m": float(np.linalg.norm(run.path - run.reference, axis=1).max()),
                "speed_over_rating": run.speed_ratio,
                "contact_share": run.contact_share,
                "first_contact": list(run.first_contact) if run.first_contact else None,
                "first_overlap": list(run.first_overlap) if run.first_overlap else None,
            }
        )
    return out


def plot_front(
    front: Sequence[Evaluation],
    evaluated: Sequence[Evaluation],
    objectives: Sequence[Objective],
    path: Path,
) -> None:
    """The first two objectives (with units) of every feasible design evaluated and of
    the Pareto front, the front's designs numbered as their folders."""
    import matplotlib

    matplotlib.use("Agg")  # files only; never open a window
    import matplotlib.pyplot as plt

    from robotwright._atomic import atomic_open

    a, b = objectives[0], objectives[1]

    def label(o: Objective) -> str:
        unit = UNITS.get(o.name, "")
        better = "larger" if o.maximize else "smaller"
        return f"{o.name}" + (f" [{unit}]" if unit else "") + f" ({better} is better)"

    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    rest = [e for e in evaluated if e.feasible]
    if rest:
        ax.scatter(
            [e.values[a.name] for e in rest],
            [e.values[b.name] for e in rest],
            s=10,
            c="0.7",
            label=f"feasible designs evaluated ({len(rest)})",
        )
    xs = [e.values[a.name] for e in front]
    ys = [e.values[b.name] for e in front]
    order = sorted(range(len(front)), key=lambda i: xs[i])
    ax.plot(
        [xs[i] for i in order],
        [ys[i] for i in order],
        "-o",
        color="tab:red",
        ms=6,
        lw=1.2,
        label=f"Pareto front ({len(front)})",
    )
    for i, (x, y) in enumerate(zip(xs, ys, strict=True), 1):
        ax.annotate(str(i), (x, y), textcoords="offset points", xytext=(5, 4), fontsize=8)
    ax.set_xlabel(label(a))
    ax.set_ylabel(label(b))
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title("Pareto front (numbers: front_N folders)")
    fig.tight_layout()
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=90)
    plt.close(fig)


def plot_track(run: TrackResult, path: Path, title: str) -> None:
    """Tool path against reference (m), front view (y-z) and top view (x-y)."""
    import matplotlib

    matplotlib.use("Agg")  # files only; never open a window
    import matplotlib.pyplot as plt

    from robotwright._atomic import atomic_open

    fig, axes = plt.subplots(1, 2, figsize=(8, 4))
    for ax, (i, j), label in zip(axes, ((1, 2), (0, 1)), ("front (y-z)", "top (x-y)")):
        ax.plot(run.reference[:, i], run.reference[:, j], "k--", lw=1, label="reference")
        ax.plot(run.path[:, i], run.path[:, j], "r-", lw=1.2, label="tool point")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(label)
        ax.set_xlabel("xyz"[i] + " [m]")
        ax.set_ylabel("xyz"[j] + " [m]")
    axes[0].legend(loc="best", fontsize=8)
    fig.suptitle(f"{title}: RMS error {run.error * 1000:.1f} mm, mean power {run.power:.1f} W")
    fig.tight_layout()
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=80)
    plt.close(fig)
