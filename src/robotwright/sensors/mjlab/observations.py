"""Observation terms of the semantic LiDAR for mjlab's observation manager.

Use them as ``ObservationTermCfg(func=term, params={"sensor_name": "lidar", ...})``.
Shapes use ``E`` environments, ``N`` rays per step and ``C = len(sensor.class_names)``
classes (``"unknown"`` included, and the robot's own class when the sensor has one).
Memory figures are float32 per step for 4096 environments; PPO keeps
``num_steps_per_env`` (24 in mjlab's velocity tasks) steps of each actor observation.

Which to use:
  * :func:`lidar_range_image` for any pattern, rosettes (Mid-360, Avia) included: every
    cell means the same direction every step, so a CNN or a flattened MLP can learn it.
  * :func:`lidar_point_cloud` for point-cloud encoders (PointNet, PVCNN-style).
  * :func:`lidar_semantic_obs` and the per-ray terms only for fixed patterns (grid,
    spinning, pinhole, file), where ray ``i`` always points the same way.
"""

from __future__ import annotations

from typing import Any, Literal

import torch

from robotwright.errors import SensorError
from robotwright.sensors import learning_obs
from robotwright.sensors.mjlab.sensor import MjlabSemanticLidarSensor

__all__ = [
    "lidar_class_ids",
    "lidar_distances_normalized",
    "lidar_one_hot_classes",
    "lidar_point_cloud",
    "lidar_range_image",
    "lidar_semantic_obs",
]


def _sensor(env: Any, sensor_name: str) -> MjlabSemanticLidarSensor:
    sensor = env.scene[sensor_name]
    if not isinstance(sensor, MjlabSemanticLidarSensor):
        raise SensorError(
            f"{sensor_name!r} is a {type(sensor).__name__}, not a robotwright "
            "SemanticLidarSensorCfg sensor"
        )
    return sensor


def lidar_distances_normalized(env: Any, sensor_name: str) -> torch.Tensor:
    """``(E, N)`` distance / ``max_distance``: in [0, 1] for hits; misses read
    ``miss_distance / max_distance`` (1 by default). Fixed patterns only (see
    :func:`lidar_semantic_obs`)."""
    s = _sensor(env, sensor_name)
    return s.get_distances() / float(s.cfg.max_distance)


def lidar_class_ids(env: Any, sensor_name: str) -> torch.Tensor:
    """``(E, N)`` class ids as floats (0 = miss/unknown). Fixed patterns only."""
    return _sensor(env, sensor_name).data.semantic_labels.float()


def lidar_one_hot_classes(env: Any, sensor_name: str) -> torch.Tensor:
    """``(E, N * C)`` one-hot classes, ray-major, class 0 included. Fixed patterns only."""
    s = _sensor(env, sensor_name)
    labels = s.data.semantic_labels
    return learning_obs.one_hot_classes(labels, len(s.class_names)).reshape(labels.shape[0], -1)


def lidar_semantic_obs(env: Any, sensor_name: str) -> torch.Tensor:
    """The seed's stacked observation: ``(E, N * 2)``, per ray (distance [m], class id).

    Suits fixed patterns only (grid, spinning, pinhole, file patterns, mjlab's grid and
    ring): the value at index ``2 i`` means ray ``i``'s direction only when ray ``i``
    points the same way every step. A Livox rosette's window advances every step (ray
    ``i`` of a 20 000-ray Mid-360 turns about 16 degrees per step), so the same index
    means a different direction each step and a policy cannot learn from it; use
    :func:`lidar_range_image` or :func:`lidar_point_cloud` there. Size: 2 N floats per
    env (20 000 rays: 40 000, 625 MiB per step for 4096 envs, 15 GiB of PPO rollout).
    Misses read ``miss_distance`` (default ``max_distance``).
    """
    s = _sensor(env, sensor_name)
    return learning_obs.semantic_obs(s.get_distances(), s.get_semantic_labels())


def lidar_point_cloud(
    env: Any,
    sensor_name: str,
    max_points: int,
    frame: Literal["sensor", "base", "world"] = "sensor",
    accumulate: int = 1,
) -> torch.Tensor:
    """``(E, max_points, 3 + C)`` a fixed-size sample of the hit points, with one-hot classes.

    Per env, the hits (ray order) are sampled evenly: all of them when there are at most
    ``max_points``, else hit ``floor(j * hits / max_points)`` for slot ``j``; the same
    scan gives the same sample (no randomness). Columns 0..2 are the point [m] in the
    ``frame``: ``"sensor"`` (the LiDAR, offset included), ``"base"`` (the frame object
    carrying it) or ``"world"``; columns 3.. the one-hot class. Slots past the hits are
    zero (their one-hot sums to 0: that is the padding mask).

    For point-cloud encoders (PointNet, PVCNN-style). Size per env: ``max_points * (3 +
    C)`` floats; 1024 points with 5 classes: 32 KiB, 128 MiB per step for 4096 envs
    (3 GiB of PPO rollout at 24 steps); flattened into an MLP it is as hard to learn as
    per-ray terms (slot ``j`` is not a direction), so pair it with an encoder.
    ``accumulate=k`` samples the hits of the last ``k`` steps' scans (kept in the world
    frame, shown in this step's ``frame``: a static scene stays in place as the robot
    moves; hits from before an environment's reset are left out).
    """
    learning_obs.check_point_cloud_args(max_points, frame, ("sensor", "base", "world"))
    s = _sensor(env, sensor_name)
    data = s.data
    origin = rot = None
    if frame == "sensor":
        origin, rot = data.sensor_pos_w, s._sensor_mat
    elif frame == "base":
        origin, rot = data.pos_w, s._frame_mat
    hit, points, labels = data.hit_mask, data.hit_pos_w, data.semantic_labels
    if accumulate != 1:
        rays = _accumulated(
            s,
            ("point_cloud",),
            accumulate,
            "lidar_point_cloud",
            hit=hit,
            points=points,
            labels=labels,
        )
        hit, points, labels = rays["hit"] & rays["valid"], rays["points"], rays["labels"]
    return learning_obs.point_cloud(
        hit,
        points,
        labels,
        len(s.class_names),
        max_points,
        origin,
        rot,
    )


def _accumulated(
    s: MjlabSemanticLidarSensor, key: tuple, k: int, what: str, **rays: torch.Tensor
) -> dict[str, torch.Tensor]:
    """The last ``k`` steps' values of ``rays`` (each ``(E, N, ...)``) as ``(E, k * N,
    ...)`` plus ``"valid"``: the sensor keeps them per observation term (``key``), adds
    this step's once however often the term is read, and forgets an environment's at its
    reset."""
    history = s._obs_cache.get(("history", *key, k))
    if history is None:
        history = learning_obs.ScanHistory(k, what)
        s._obs_cache[("history", *key, k)] = history
    if history.last_key != s._casts:
        history.push(**rays)
        history.last_key = s._casts
    return history.flat()


def _image_bounds(s: MjlabSemanticLidarSensor) -> tuple[float, float, float, float, bool]:
    """Azimuth and elevation bounds [rad] of every ray of the pattern (all frames), in the
    ray frame; a pattern spanning nearly the full circle wraps around at +-pi."""
    key = "range_image_bounds"
    if key not in s._obs_cache:
        s._obs_cache[key] = learning_obs.direction_bounds(torch.as_tensor(s.table.directions))
    return s._obs_cache[key]


def _frame_cells(s: MjlabSemanticLidarSensor, width: int, height: int) -> torch.Tensor:
    """Range-image cells of the rays each environment cast last: ``(N,)`` for a pattern
    of one frame, else ``(E, N)``. A table row has a fixed direction in the ray frame
    (whatever ``ray_alignment``), so the cells of all rows are computed once per image
    size and each step only looked up at the environments' windows (on the device)."""
    key = ("range_image_cells", width, height)
    data = s.data
    if key not in s._obs_cache:
        dirs = torch.as_tensor(s.table.directions)
        cells = learning_obs.ray_cells(dirs, _image_bounds(s), width, height)
        s._obs_cache[key] = cells.to(data.hit_mask.device)
    cells = s._obs_cache[key]
    n = int(s.table.rays_per_frame)
    if cells.numel() == n:
        return cells
    rays = torch.arange(n, device=cells.device)
    return cells[(data.window_start.long()[:, None] + rays) % cells.numel()]


def lidar_range_image(
    env: Any,
    sensor_name: str,
    width: int,
    height: int,
    flatten: bool = False,
    scanned: bool = False,
    accumulate: int = 1,
) -> torch.Tensor:
    """``(E, 1 + C, height, width)`` distances and class occupancy binned by direction
    (``(E, 2 + C, height, width)`` with ``scanned``).

    Each ray falls in the cell of its azimuth (columns, left to right from -pi, or from the
    pattern's smallest azimuth when it spans less than the full circle) and elevation
    (rows, top = highest elevation of the pattern), measured in the ray frame (the
    sensor frame under ``ray_alignment``). Channel 0: the nearest hit in the cell /
    ``max_distance`` (1 where the cell has no hit this step); channels 1..C: the
    fraction of the cell's rays this step that hit each class (class 0: unknown geoms).
    ``scanned=True`` adds a last channel: 1 where a ray of this step fell in the cell, 0
    where none did (a rotating pattern leaves cells unscanned each step; without this
    channel they read as free space). Every cell means the same direction every step,
    whatever the pattern, so a CNN or a flattened MLP can learn from it; a rosette fills
    different cells each step. The cells of the pattern's rays are computed once and
    looked up each step.

    ``accumulate=k`` bins the rays of the last ``k`` steps' scans together (a rosette or
    rotating pattern covers more cells over several steps; distance: the nearest of
    them, classes: their shares); scans from before an environment's reset are left
    out. The sensor keeps those ``k`` scans per environment (``k x N x 17`` bytes).

    Size per env: ``(1 + C) * height * width`` floats; 32 x 8 with 5 classes: 1 536
    floats (6 KiB), 24 MiB per step for 4096 envs (576 MiB of PPO rollout at 24 steps).
    ``flatten=True`` returns it as ``(E, channels * height * width)`` (channel-major), the
    form an MLP actor (rsl_rl's) and mjlab's term concatenation take.
    """
    learning_obs.check_image_size(width, height)
    s = _sensor(env, sensor_name)
    data = s.data
    cells = _frame_cells(s, width, height)
    hit, dist, labels, valid = data.hit_mask, data.distances, data.semantic_labels, None
    if accumulate != 1:
        rays = _accumulated(
            s,
            ("range_image", width, height),
            accumulate,
            "lidar_range_image",
            hit=hit,
            dist=dist,
            labels=labels,
            cells=cells.expand(hit.shape),
        )
        hit, dist, labels, cells, valid = (
            rays[k] for k in ("hit", "dist", "labels", "cells", "valid")
        )
    out = learning_obs.range_image(
        None,
        hit,
        dist,
        float(s.cfg.max_distance),
        labels,
        len(s.class_names),
        _image_bounds(s),
        width,
        height,
        cells=cells,
        scanned=scanned,
        valid=valid,
    )
    if flatten:
        return out.reshape(out.shape[0], -1)
    return out
