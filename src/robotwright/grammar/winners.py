"""The winners of a search, written to look at: ``OUT/best_1`` ... ``OUT/best_K``.

Each ``best_N`` is a design folder (as ``robotwright grammar export`` writes it: MJCF,
URDF, design text/JSON, tree, picture of the limb alone), readable by
``robotwright view OUT/best_N`` and ``robotwright render``, plus:

- ``values.json`` / ``values.txt``: every objective's value with its unit, the score,
  the rank and the design hash;
- ``on_carrier.png``: the limb worn by its carrier in its display pose, drawn by the
  ``draw_carrier`` function given (``robotwright grammar search -o`` passes
  :func:`robotwright.render.api.draw_pose`: OpenGL when available, else the software
  renderer; the grammar does not import the renderer, which reads design folders);
- ``track.png`` (objectives ``track`` and ``energy``): the tool path against the
  reference, seen from the front (y-z) and from above (x-y).

``OUT/winners.txt`` lists the ranking. The whole folder is written at once (a failure
leaves the earlier output, or none).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from pathlib import Path

import mujoco
import numpy as np

from robotwright._atomic import atomic_dir
from robotwright.grammar.build import build
from robotwright.grammar.objectives import Evaluation, Objective
from robotwright.grammar.physics import (
    DEFAULT_CARRIER,
    Carrier,
    TrackResult,
    display_pose,
    mount,
    track,
)
from robotwright.grammar.rules import Grammar

#: Draws a model at joint values ``qpos`` into a PNG at ``path`` under a ``title``.
DrawPose = Callable[[mujoco.MjModel, np.ndarray, Path, str], None]

#: Unit of each objective's value.
UNITS = {
    "reach": "m",
    "workspace": "m^3",
    "mass": "kg",
    "dof": "DoF",
    "payload": "kg",
    "track": "m",
    "energy": "W",
}


def ranked(evaluations: Sequence[Evaluation], k: int) -> list[Evaluation]:
    """The ``k`` best feasible evaluations by score (earlier first on ties)."""
    feasible = [(i, e) for i, e in enumerate(evaluations) if e.feasible]
    feasible.sort(key=lambda t: (-t[1].score, t[0]))
    return [e for _, e in feasible[:k]]


def write_winners(
    grammar: Grammar,
    evaluations: Sequence[Evaluation],
    objectives: Sequence[Objective],
    out: str | Path,
    *,
    k: int = 3,
    carrier: Carrier = DEFAULT_CARRIER,
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
    from robotwright.grammar.export import export_design

    out = Path(out)
    best = ranked(evaluations, k)
    names = [o.name for o in objectives]
    lines = []
    written = []
    with atomic_dir(out, kind="designs") as tmp:
        for rank, ev in enumerate(best, 1):
            folder = tmp / f"best_{rank}"
            export_design(grammar, ev.design, folder, picture=pictures, overwrite=True)
            values = {
                "rank": rank,
                "design_hash": ev.design.hash(),
                "score": ev.score,
                "objectives": {n: {"value": ev.values[n], "unit": UNITS.get(n, "")} for n in names},
                "values": dict(ev.values),
            }
            (folder / "values.json").write_text(json.dumps(values, indent=2) + "\n", "utf-8")
            text = "".join(
                f"{n}: {ev.values[n]:.6g} {UNITS.get(n, '')}\n".replace(" \n", "\n")
                for n in ev.values
            )
            (folder / "values.txt").write_text(
                f"rank {rank}, design {ev.design.hash()}\n{text}", "utf-8"
            )
            summary = ", ".join(f"{n} {ev.values[n]:.4g} {UNITS.get(n, '')}" for n in names)
            lines.append(f"best_{rank}: {ev.design.hash()}  {summary.strip()}\n")
            if pictures:
                limb = build(grammar, ev.design)
                m = mount(limb, carrier)
                if draw_carrier is not None:
                    title = f"best_{rank} on its carrier"
                    draw_carrier(m.model, display_pose(limb), folder / "on_carrier.png", title)
                if {"track", "energy"} & set(names):
                    run = track(limb, carrier, mounted=m)
                    plot_track(run, folder / "track.png", f"best_{rank} ({ev.design.hash()})")
            written.append(out / f"best_{rank}")
        (tmp / "winners.txt").write_text("".join(lines) or "no feasible design\n", encoding="utf-8")
    return written


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
