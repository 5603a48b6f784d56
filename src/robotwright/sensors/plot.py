"""Pictures of a scan: point cloud coloured by semantic class, top and side views (PNG)."""

from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from robotwright._atomic import atomic_open

__all__ = ["CLASS_COLORS", "class_color", "plot_scan", "upside_down"]

#: Colours (hex) by semantic class id, fixed so that a class looks the same in every
#: scan picture, rendered picture and the browser viewer (class 0 = unknown, grey).
CLASS_COLORS: tuple[str, ...] = (
    "#9e9e9e",
    "#8c6d31",
    "#d62728",
    "#1f77b4",
    "#2ca02c",
    "#9467bd",
    "#ff7f0e",
    "#17becf",
    "#e377c2",
)
#: Characters per line of a legend label (two columns fit the 13-inch-wide figure).
_LEGEND_CHARS = 70


def class_color(cls_id: int) -> str:
    """The colour (hex) of semantic class ``cls_id`` in every scan picture."""
    return CLASS_COLORS[cls_id % len(CLASS_COLORS)]


def upside_down(sensor_quat: np.ndarray | Sequence[float] | None) -> bool:
    """Whether a sensor with world orientation ``sensor_quat`` (w, x, y, z) is mounted
    upside down: its z axis (the scan's up) points below the horizon."""
    if sensor_quat is None:
        return False
    w, x, y, z = np.asarray(sensor_quat, dtype=np.float64).reshape(4)
    n = w * w + x * x + y * y + z * z
    if not np.isfinite(n) or n == 0:
        return False
    # World z component of the sensor's z axis: R[2, 2] of the unit quaternion.
    return bool(1.0 - 2.0 * (x * x + y * y) / n < 0.0)


def tilt_deg(sensor_quat: np.ndarray | Sequence[float]) -> float:
    """Angle [deg] between a sensor's z axis (orientation ``sensor_quat``, w, x, y, z, in
    the world frame) and the world's up."""
    w, x, y, z = np.asarray(sensor_quat, dtype=np.float64).reshape(4)
    n = w * w + x * x + y * y + z * z
    cos = float(np.clip(1.0 - 2.0 * (x * x + y * y) / n, -1.0, 1.0))
    return float(np.degrees(np.arccos(cos)))


#: Widest a view is drawn at equal scales (width / height); a flatter one is stretched.
MAX_VIEW_RATIO = 4.0


def view_stretch(xlim: tuple[float, float], ylim: tuple[float, float]) -> float:
    """How much a view's vertical scale is stretched: 1 (equal scales) unless the view
    is more than :data:`MAX_VIEW_RATIO` times wider than high (a ground seen from 0.3 m
    out to 30 m: a strip no one can read at equal scales); then to that ratio."""
    flat = (xlim[1] - xlim[0]) / (ylim[1] - ylim[0])
    return max(1.0, flat / MAX_VIEW_RATIO)


def _limits(values: np.ndarray, extra: float | None) -> tuple[float, float]:
    """Axis range covering ``values`` (and ``extra``) with a 4 % margin."""
    lo, hi = float(values.min()), float(values.max())
    if extra is not None and np.isfinite(extra):
        lo, hi = min(lo, extra), max(hi, extra)
    pad = max(hi - lo, 0.2) * 0.04
    return lo - pad, hi + pad


def plot_scan(
    points: np.ndarray,
    labels: np.ndarray,
    class_names: Sequence[str],
    path: str | Path,
    sensor_pos: np.ndarray | None = None,
    title: str | None = None,
    view_radius: float | None = None,
    *,
    class_keywords: Mapping[str, Sequence[str]] | None = None,
    sensor_quat: np.ndarray | Sequence[float] | None = None,
    side_slice: float | None = 1.0,
) -> Path:
    """Draw hit points (world frame [m]) coloured by class id into a PNG file: a top
    view, and a side view of a slice through the sensor (walls in front of and behind
    the furniture would otherwise cover it).

    Both views are cropped to the drawn hits (and the sensor), with equal scales, except
    that a view wider than :data:`MAX_VIEW_RATIO` times its height has its height
    stretched (said in its title).

    Args:
        points: ``(N, 3)`` points; rows with NaN (misses) are skipped.
        labels: ``(N,)`` class ids indexing ``class_names`` (0 = unknown).
        class_names: names by class id.
        path: the PNG to write (written to a temporary file first, then renamed).
        sensor_pos: sensor position [m], drawn as a black cross.
        title: figure title.
        view_radius: show only points within this horizontal distance [m] of the sensor
            (of the origin without ``sensor_pos``); ``None`` shows every point. Legend
            counts always cover every point.
        class_keywords: class name -> keywords that define it (the sensor's
            ``semantic_class_mapping``): the legend says ``valuable: sofa, table, ...``.
        sensor_quat: sensor orientation (w, x, y, z) in the world frame; a sensor whose
            z axis points below the horizon has its tilt said in the title (the
            pattern's elevations are measured in the sensor's frame).
        side_slice: the side view shows points with ``|y - y_sensor|`` at most this
            [m] (y of the origin without ``sensor_pos``); ``None`` shows every point.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    labels = np.asarray(labels).reshape(-1)
    keep = np.isfinite(points).all(axis=1)
    points, labels = points[keep], labels[keep]
    counts = [int((labels == i).sum()) for i in range(len(class_names))]
    centre = np.zeros(3) if sensor_pos is None else np.asarray(sensor_pos, dtype=np.float64)
    if view_radius is not None:
        near = np.hypot(points[:, 0] - centre[0], points[:, 1] - centre[1]) <= view_radius
        points, labels = points[near], labels[near]
    side = np.ones(len(points), dtype=bool)
    side_name = "side view"
    if side_slice is not None:
        side = np.abs(points[:, 1] - centre[1]) <= side_slice
        side_name = f"side view: slice |y - y_sensor| <= {side_slice:g} m"
    fig, axes = plt.subplots(1, 2, figsize=(13, 6.2))
    views = (
        ("top view", 0, 1, "x [m]", "y [m]", np.ones(len(points), dtype=bool)),
        (side_name, 0, 2, "x [m]", "z [m]", side),
    )
    for ax, (name, i, j, xl, yl, sel_view) in zip(axes, views, strict=True):
        shown = points[sel_view]
        # Terrain and unknown first, objects over them: class order puts classes the
        # user listed first (terrain, in the default mapping) below the others.
        for cls_id in range(len(class_names)):
            sel = sel_view & (labels == cls_id)
            if not sel.any():
                continue
            ax.scatter(points[sel, i], points[sel, j], s=1.5, c=class_color(cls_id), linewidths=0)
        if sensor_pos is not None:
            ax.plot(sensor_pos[i], sensor_pos[j], "kx", markersize=10, mew=2)
        stretch = 1.0
        if len(shown):
            extra_i = None if sensor_pos is None else float(sensor_pos[i])
            extra_j = None if sensor_pos is None else float(sensor_pos[j])
            xlim, ylim = _limits(shown[:, i], extra_i), _limits(shown[:, j], extra_j)
            ax.set_xlim(*xlim)
            ax.set_ylim(*ylim)
            stretch = view_stretch(xlim, ylim)
        ax.set_title(
            f"{name} ({len(shown)} points"
            + (f"; {yl[0]} stretched x{stretch:.3g})" if stretch > 1.0 else ")")
        )
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.set_aspect(stretch, adjustable="box")
        ax.grid(True, alpha=0.3)

    # Legend markers drawn at a readable size (the scatter dots themselves are tiny).
    # A class's keywords can be a long list (the default mapping's are): its label is
    # wrapped, so the legend's columns stay within the figure's width.
    handles = []
    for cls_id, cls_name in enumerate(class_names):
        words = list((class_keywords or {}).get(cls_name, ()))
        what = f"{cls_name}: {', '.join(words)}" if words else cls_name
        if cls_id == 0:
            what = f"{cls_name} (no keyword matched)"
        what = textwrap.fill(f"{what} ({counts[cls_id]} pts)", _LEGEND_CHARS)
        handles.append(
            Line2D(
                [],
                [],
                ls="",
                marker="o",
                ms=7,
                color=class_color(cls_id),
                label=what,
            )
        )
    if sensor_pos is not None:
        handles.append(Line2D([], [], ls="", marker="x", ms=9, mew=2, color="k", label="sensor"))
    legend = fig.legend(
        handles=handles, loc="lower center", ncol=min(len(handles), 2), frameon=False
    )
    heading = title or f"LiDAR scan: {len(points)} points"
    if upside_down(sensor_quat):
        heading += (
            f"\nthe sensor's z axis is tilted {tilt_deg(sensor_quat):.0f} deg from up: the "
            "pattern's elevations are measured in the sensor's frame"
        )
    fig.suptitle(heading)
    # The views get what the legend leaves: its height measured once drawn.
    fig.canvas.draw()
    below = legend.get_window_extent().height / fig.bbox.height
    fig.tight_layout(rect=(0, min(below + 0.05, 0.6), 1, 0.97))
    path = Path(path)
    try:
        with atomic_open(path, "wb") as fh:
            # "tight": the saved picture holds every drawn text, the whole legend too.
            fig.savefig(fh, format="png", dpi=110, bbox_inches="tight", pad_inches=0.15)
    finally:
        plt.close(fig)
    return path
