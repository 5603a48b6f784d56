"""Pictures of a scan: point cloud coloured by semantic class, top and side views (PNG)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from robotwright._atomic import atomic_open

__all__ = ["class_color", "plot_scan"]

# Fixed colours so the same class looks the same in every picture (class 0 = unknown).
_COLORS = [
    "#9e9e9e",
    "#8c6d31",
    "#d62728",
    "#1f77b4",
    "#2ca02c",
    "#9467bd",
    "#ff7f0e",
    "#17becf",
    "#e377c2",
]


def class_color(cls_id: int) -> str:
    """The colour (hex) of semantic class ``cls_id`` in every scan picture."""
    return _COLORS[cls_id % len(_COLORS)]


def plot_scan(
    points: np.ndarray,
    labels: np.ndarray,
    class_names: Sequence[str],
    path: str | Path,
    sensor_pos: np.ndarray | None = None,
    title: str | None = None,
    view_radius: float | None = None,
) -> Path:
    """Draw hit points (world frame [m]) coloured by class id into a PNG file.

    Args:
        points: ``(N, 3)`` points; rows with NaN (misses) are skipped.
        labels: ``(N,)`` class ids indexing ``class_names`` (0 = unknown).
        class_names: names by class id.
        path: the PNG to write (written to a temporary file first, then renamed).
        sensor_pos: sensor position, drawn as a black cross.
        title: figure title.
        view_radius: show only points within this horizontal distance [m] of the sensor
            (of the origin without ``sensor_pos``); ``None`` shows every point. Legend
            counts always cover every point.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    labels = np.asarray(labels).reshape(-1)
    keep = np.isfinite(points).all(axis=1)
    points, labels = points[keep], labels[keep]
    counts = [int((labels == i).sum()) for i in range(len(class_names))]
    if view_radius is not None:
        centre = np.zeros(3) if sensor_pos is None else np.asarray(sensor_pos, dtype=np.float64)
        near = np.hypot(points[:, 0] - centre[0], points[:, 1] - centre[1]) <= view_radius
        points, labels = points[near], labels[near]
    fig, axes = plt.subplots(1, 2, figsize=(13, 6), gridspec_kw={"width_ratios": [1, 1]})
    views = (("top view", 0, 1, "x [m]", "y [m]"), ("side view", 0, 2, "x [m]", "z [m]"))
    for ax, (name, i, j, xl, yl) in zip(axes, views, strict=True):
        for cls_id in range(len(class_names)):
            sel = labels == cls_id
            if not sel.any():
                continue
            color = _COLORS[cls_id % len(_COLORS)]
            ax.scatter(points[sel, i], points[sel, j], s=1.5, c=color, linewidths=0)
        if sensor_pos is not None:
            ax.plot(sensor_pos[i], sensor_pos[j], "kx", markersize=10, mew=2)
        ax.set_title(name)
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
    from matplotlib.lines import Line2D

    # Legend markers drawn at a readable size (the scatter dots themselves are tiny).
    handles = []
    for cls_id, cls_name in enumerate(class_names):
        n = counts[cls_id]
        color = _COLORS[cls_id % len(_COLORS)]
        handles.append(
            Line2D(
                [], [], ls="", marker="o", ms=7, color=color, label=f"{cls_id} {cls_name} ({n} pts)"
            )
        )
    if sensor_pos is not None:
        handles.append(Line2D([], [], ls="", marker="x", ms=9, mew=2, color="k", label="sensor"))
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 5), frameon=False)
    fig.suptitle(title or f"LiDAR scan: {len(points)} points")
    fig.tight_layout(rect=(0, 0.07, 1, 0.97))
    path = Path(path)
    try:
        with atomic_open(path, "wb") as fh:
            fig.savefig(fh, format="png", dpi=110)
    finally:
        plt.close(fig)
    return path
