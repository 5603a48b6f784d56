"""A picture of a scene with the points of a LiDAR scan drawn in it."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import mujoco
import numpy as np

from robotwright.render.core import Picture, RenderOptions, render_model
from robotwright.render.png import save_png

__all__ = ["class_legend", "render_scan"]


def class_legend(
    class_names: Sequence[str],
    counts: Sequence[int],
    mapping: Mapping[str, Sequence[str]] | None = None,
) -> list[tuple[str, tuple[float, float, float]]]:
    """Legend entries ``(label, rgb)`` for the classes that have points: the class,
    the keywords that put a geom in it (``valuable: sofa, table, chair``) and the count."""
    from matplotlib.colors import to_rgb

    from robotwright.sensors.plot import class_color

    entries = []
    for cls_id, name in enumerate(class_names):
        if not counts[cls_id]:
            continue
        words = list((mapping or {}).get(name, ()))
        what = f"{name}: {', '.join(words)}" if words else name
        entries.append((f"{what} ({counts[cls_id]} pts)", to_rgb(class_color(cls_id))))
    return entries


def render_scan(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    points: np.ndarray,
    labels: np.ndarray,
    class_names: Sequence[str],
    output: str | os.PathLike[str] | None = None,
    options: RenderOptions | None = None,
    *,
    mapping: Mapping[str, Sequence[str]] | None = None,
    title: str | None = None,
) -> Picture:
    """Draw the scene of ``model`` in state ``data`` with scan ``points`` ``(N, 3)``
    (world frame [m], NaN rows = misses, skipped) coloured by class id ``labels``.

    Points behind a surface are hidden, as the eye would see them. With ``output`` a
    PNG is written, with a legend naming each class (and its keywords from
    ``mapping``) and its number of points.
    """
    from matplotlib.colors import to_rgb

    from robotwright.sensors.plot import class_color

    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    lab = np.asarray(labels).reshape(-1)
    keep = np.isfinite(pts).all(axis=1)
    pts, lab = pts[keep], lab[keep]
    palette = np.array([to_rgb(class_color(i)) for i in range(len(class_names))])
    colours = palette[np.clip(lab, 0, len(class_names) - 1)]
    picture = render_model(model, data, options, points=pts, point_colors=colours)
    if output is not None:
        counts = [int((lab == i).sum()) for i in range(len(class_names))]
        legend = class_legend(class_names, counts, mapping)
        save_png(picture, Path(output), title=title, legend=legend)
    return picture
