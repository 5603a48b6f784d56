"""One-call scan of a scene to files: ``.npz`` data and a ``.png`` picture."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from robotwright._atomic import atomic_open
from robotwright.sensors.config import SemanticLidarCfg
from robotwright.sensors.patterns import pattern_from_name
from robotwright.sensors.plot import plot_scan
from robotwright.sensors.semantic import SemanticLidarSensor

__all__ = ["scan_to_files", "save_npz"]


def save_npz(path: str | Path, **arrays: np.ndarray) -> Path:
    """Write arrays to ``path`` (.npz) through a temporary file, so no partial file is left."""
    path = Path(path)
    with atomic_open(path, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    return path


def scan_to_files(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    sensor: str,
    pattern_name: str = "mid360",
    npz_path: str | Path | None = None,
    png_path: str | Path | None = None,
    *,
    semantic_class_mapping: Mapping[str, Sequence[str]] | None = None,
    max_distance: float = 40.0,
    offset_pos: tuple[float, float, float] = (0.0, 0.0, 0.0),
    mesh_prim_paths: Sequence[str] = (),
    exclude_robot: bool = True,
    engine: str = "mujoco",
    title: str | None = None,
    view_radius: float | None = None,
) -> dict[str, Any]:
    """Scan one environment with a :class:`SemanticLidarSensor` and save the result.

    ``data`` must hold current poses (call ``mj_forward`` first). The ``.npz`` holds
    ``distances`` (N,) [m] (inf = miss), ``hit_mask`` (N,) bool, ``points`` (N, 3) world frame [m] (NaN = miss),
    ``labels`` (N,) class ids, ``mesh_ids`` (N,) hit geom ids (-1 = miss),
    ``directions`` (N, 3), ``sensor_pos`` (3,), ``sensor_quat`` (4, w x y z),
    ``class_names`` and ``geom_paths`` (strings). ``view_radius`` [m] crops the picture
    (not the data) around the sensor; ``None`` draws every point.

    Returns:
        A summary: ``num_rays``, ``num_hits``, ``class_counts`` (name -> points),
        ``npz``/``png`` paths written (or None), ``sensor``, ``pattern``.
    """
    cfg = SemanticLidarCfg(
        prim_path=sensor,
        pattern_cfg=pattern_from_name(pattern_name),
        # Passed as given: the config refuses a keyword string ({"terrain": "floor"})
        # instead of splitting it into letters.
        semantic_class_mapping=dict(semantic_class_mapping)
        if isinstance(semantic_class_mapping, Mapping)
        else semantic_class_mapping,
        max_distance=max_distance,
        offset_pos=offset_pos,
        mesh_prim_paths=list(mesh_prim_paths),
        exclude_robot=exclude_robot,
        return_mesh_ids=True,
        engine=engine,  # type: ignore[arg-type]
        miss_distance=math.inf,  # a scan file marks misses unmistakably
    )
    lidar = SemanticLidarSensor(cfg, model, data)
    lidar.update()
    dist = lidar.get_distances()[0]
    points = lidar.get_pointcloud()[0]
    labels = lidar.get_semantic_labels()[0]
    mesh_ids = lidar.get_mesh_ids()[0]
    counts = {
        name: int((labels[lidar.get_hit_mask()[0]] == i).sum())
        for i, name in enumerate(lidar.class_names)
    }
    if npz_path is not None:
        save_npz(
            npz_path,
            distances=dist,
            hit_mask=lidar.get_hit_mask()[0],
            points=points,
            labels=labels,
            mesh_ids=mesh_ids,
            directions=lidar.data.ray_directions_w[0],
            sensor_pos=lidar.data.pos_w[0],
            sensor_quat=lidar.data.quat_w[0],
            class_names=np.asarray(lidar.class_names),
            geom_paths=np.asarray([lidar.geom_path(g) for g in range(model.ngeom)]),
        )
    if png_path is not None:
        plot_scan(
            points,
            labels,
            lidar.class_names,
            png_path,
            sensor_pos=lidar.data.pos_w[0],
            title=title
            or f"{pattern_name} scan from '{sensor}': {int(lidar.get_hit_mask().sum())} hits",
            view_radius=view_radius,
            class_keywords=lidar.semantic_class_mapping,
            sensor_quat=lidar.data.quat_w[0],
        )
    return {
        "sensor": sensor,
        "pattern": pattern_name,
        "num_rays": int(dist.shape[0]),
        "num_hits": int(lidar.get_hit_mask()[0].sum()),
        "class_counts": counts,
        "npz": str(npz_path) if npz_path is not None else None,
        "png": str(png_path) if png_path is not None else None,
    }
