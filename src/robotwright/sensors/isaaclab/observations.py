"""Observation terms of the Isaac Lab LiDAR, in Isaac Lab's ``ObservationTermCfg`` style.

Use them as ``ObsTerm(func=lidar_semantic_obs, params={"sensor_cfg":
SceneEntityCfg("lidar")})``. The arithmetic is shared with the mjlab terms
(:mod:`robotwright.sensors.learning_obs`); which term suits which pattern is said
there and in :mod:`robotwright.sensors.mjlab.observations`: per-ray terms only for
fixed patterns, a range image or a point cloud for rosettes (Mid-360, Avia).
"""

from __future__ import annotations

from typing import Any, Literal

import torch
from isaaclab.managers import SceneEntityCfg

from robotwright.errors import SensorError
from robotwright.sensors import learning_obs
from robotwright.sensors.isaaclab.sensor import LidarSensor, SemanticLidarSensor

__all__ = [
    "lidar_distances_normalized",
    "lidar_point_cloud",
    "lidar_range_image",
    "lidar_semantic_obs",
]


def _sensor(env: Any, sensor_cfg: SceneEntityCfg, semantic: bool = True) -> Any:
    sensor = env.scene.sensors[sensor_cfg.name]
    wanted = SemanticLidarSensor if semantic else LidarSensor
    if not isinstance(sensor, wanted):
        raise SensorError(
            f"{sensor_cfg.name!r} is a {type(sensor).__name__}, not a robotwright "
            f"{wanted.__name__} (robotwright.sensors.isaaclab)"
        )
    return sensor


def _labels(sensor: Any) -> torch.Tensor:
    labels = sensor.data.semantic_labels
    if labels is None:
        raise SensorError(
            f"{type(sensor.cfg).__name__}.return_semantic_labels is False: this observation "
            "needs the labels"
        )
    return labels.torch


def lidar_semantic_obs(env: Any, sensor_cfg: SceneEntityCfg) -> torch.Tensor:
    """The seed's observation ``(E, 2 N)``: per ray (distance [m], class id).

    Misses read ``miss_distance`` (default ``max_distance``), never ``inf``. Fixed
    patterns only: with a Livox window the same index means another direction each
    step (see :mod:`robotwright.sensors.mjlab.observations`).
    """
    s = _sensor(env, sensor_cfg)
    return learning_obs.semantic_obs(s.get_distances(), _labels(s))


def lidar_distances_normalized(env: Any, sensor_cfg: SceneEntityCfg) -> torch.Tensor:
    """``(E, N)`` distance / ``max_distance`` (misses: ``miss_distance / max_distance``)."""
    s = _sensor(env, sensor_cfg, semantic=False)
    return s.get_distances() / float(s.cfg.max_distance)


def lidar_point_cloud(
    env: Any,
    sensor_cfg: SceneEntityCfg,
    max_points: int,
    frame: Literal["sensor", "base", "world"] = "sensor",
) -> torch.Tensor:
    """``(E, max_points, 3 + C)`` an even sample of the hit points with one-hot classes,
    in the LiDAR's frame (``"sensor"``, offset included), the carrier prim's
    (``"base"``) or the world's; padding slots are zero (see
    :func:`robotwright.sensors.learning_obs.point_cloud`)."""
    learning_obs.check_point_cloud_args(max_points, frame, ("sensor", "base", "world"))
    s = _sensor(env, sensor_cfg)
    data = s.data
    origin = rot = None
    if frame == "sensor":
        origin, rot = s.sensor_pose_w()
    elif frame == "base":
        origin, rot = s.carrier_pose_w()
    return learning_obs.point_cloud(
        data.hit_mask.torch,
        data.ray_hits_w.torch,
        _labels(s),
        len(s.class_names),
        max_points,
        origin,
        rot,
    )


def _window_cells(s: Any, width: int, height: int) -> torch.Tensor:
    """``(E, N)`` range-image cells of each environment's window: the cells of every row
    of the pattern table are computed once per image size (a row's direction in the
    sensor frame never changes) and only looked up each step at ``data.frame``."""
    cache = s.__dict__.setdefault("_robotwright_cells", {})
    key = (width, height)
    if key not in cache:
        local = torch.as_tensor(s._table_local.numpy(), dtype=torch.float32)
        cells = learning_obs.ray_cells(local, s.direction_bounds(), width, height)
        cache[key] = cells.view(int(s.num_frames), -1).to(s.data.hit_mask.torch.device)
    return cache[key][s.data.frame.torch.long()]


def lidar_range_image(
    env: Any,
    sensor_cfg: SceneEntityCfg,
    width: int,
    height: int,
    flatten: bool = False,
    scanned: bool = False,
) -> torch.Tensor:
    """``(E, 1 + C, height, width)`` nearest distance and class occupancy per direction
    cell of the sensor frame, over the pattern's whole field of view (every window);
    ``scanned=True`` adds a last channel saying which cells this step's rays scanned;
    the cells of the pattern's rays are computed once and looked up each step;
    ``flatten=True`` gives ``(E, channels * height * width)`` for an MLP. See
    :func:`robotwright.sensors.learning_obs.range_image`."""
    learning_obs.check_image_size(width, height)
    s = _sensor(env, sensor_cfg)
    data = s.data
    out = learning_obs.range_image(
        None,
        data.hit_mask.torch,
        data.ray_distances.torch,
        float(s.cfg.max_distance),
        _labels(s),
        len(s.class_names),
        s.direction_bounds(),
        width,
        height,
        cells=_window_cells(s, width, height),
        scanned=scanned,
    )
    return out.reshape(out.shape[0], -1) if flatten else out
