"""Write a :class:`~robotwright.render.core.Picture` as a PNG of exactly its size,
optionally with a title and a legend drawn over it (matplotlib, no display needed)."""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from robotwright._atomic import write_bytes_atomic
from robotwright.render.core import Picture

__all__ = ["save_png"]

#: Pixels per inch used to lay out text; the PNG has the picture's own pixel size.
_DPI = 100


def save_png(
    picture: Picture,
    path: str | os.PathLike[str],
    *,
    title: str | None = None,
    legend: Sequence[tuple[str, tuple[float, float, float]]] = (),
) -> Path:
    """Write ``picture`` to ``path`` (PNG, ``width`` x ``height`` pixels), through a
    temporary file so that a failed write leaves no partial file.

    Args:
        picture: what :func:`~robotwright.render.render_model` returned.
        path: the PNG file to write (its folder is created when missing).
        title: a line of text at the top of the picture.
        legend: ``(label, (r, g, b))`` entries in [0, 1], drawn as a box of markers.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)  # files only; never open a window
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    h, w = picture.image.shape[:2]
    fig = Figure(figsize=(w / _DPI, h / _DPI), dpi=_DPI)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.imshow(np.asarray(picture.image), interpolation="nearest")
    ax.set_axis_off()
    # Text size [pt] follows the picture: 1/45 of its smaller side (about 10 pt at 600 px).
    size = max(6.0, min(w, h) / 45 * 72 / _DPI)
    if title:
        # Top left: a free camera centres the robot, so the corner is the emptiest place.
        fig.text(
            0.012,
            1.0 - 0.012,
            title,
            ha="left",
            va="top",
            fontsize=size * 1.15,
            bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 3},
        )
    if legend:
        handles = [
            Line2D([], [], marker="o", linestyle="", markersize=size * 0.8, color=tuple(rgb))
            for _, rgb in legend
        ]
        # Along the bottom edge, two columns: it hides the least of the picture.
        ax.legend(
            handles,
            [label for label, _ in legend],
            loc="lower center",
            ncol=2 if len(legend) > 2 else 1,
            fontsize=size * 0.8,
            columnspacing=1.0,
            framealpha=0.85,
            borderpad=0.5,
            handletextpad=0.3,
        )
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=_DPI)
    path = Path(path)
    write_bytes_atomic(path, buffer.getvalue())  # a missing folder is made
    return path
