"""Observations a policy can learn from a LiDAR, as torch functions of the scan.

Framework-free (torch only): the mjlab and Isaac Lab observation terms
(:mod:`robotwright.sensors.mjlab.observations`,
:mod:`robotwright.sensors.isaaclab.observations`) gather the tensors from their sensor and
call these. Shapes use ``E`` environments, ``N`` rays and ``C`` classes (class 0,
"unknown", included).
"""

from __future__ import annotations

import math

import torch

from robotwright.errors import SensorError

__all__ = [
    "ScanHistory",
    "check_image_size",
    "check_point_cloud_args",
    "direction_bounds",
    "one_hot_classes",
    "point_cloud",
    "range_image",
    "ray_cells",
    "semantic_obs",
]


def semantic_obs(distances: torch.Tensor, labels: torch.Tensor) -> torch.Tensor:
    """The seed's stacked observation ``(E, 2 N)``: per ray (distance [m], class id)."""
    obs = torch.stack([distances, labels.float()], dim=-1)
    return obs.reshape(distances.shape[0], -1)


def one_hot_classes(labels: torch.Tensor, classes: int) -> torch.Tensor:
    """``(..., C)`` one-hot of class ids (ids outside ``[0, C)`` clamped)."""
    return torch.nn.functional.one_hot(labels.long().clamp(0, classes - 1), classes).float()


def check_point_cloud_args(max_points: object, frame: object, frames: tuple[str, ...]) -> None:
    """Refuse a bad ``max_points`` or ``frame`` of a point-cloud term, naming it."""
    if not isinstance(max_points, int) or isinstance(max_points, bool) or max_points < 1:
        raise SensorError(
            f"lidar_point_cloud: max_points must be an integer >= 1, got {max_points!r}"
        )
    if frame not in frames:
        raise SensorError(
            f"lidar_point_cloud: frame must be one of {', '.join(map(repr, frames))}, got {frame!r}"
        )


def point_cloud(
    hit: torch.Tensor,
    points: torch.Tensor,
    labels: torch.Tensor,
    classes: int,
    max_points: int,
    origin: torch.Tensor | None = None,
    rot: torch.Tensor | None = None,
) -> torch.Tensor:
    """``(E, max_points, 3 + C)`` an even, deterministic sample of the hit points.

    Per env the hits (ray order) are sampled evenly: all of them when there are at most
    ``max_points``, else hit ``floor(j * hits / max_points)`` for slot ``j``. Columns
    0..2: the point [m], in the frame whose world position is ``origin`` ``(E, 3)`` and
    rotation ``rot`` ``(E, 3, 3)`` (both ``None``: the world frame); columns 3..: the
    one-hot class. Slots past the hits are zero (the padding mask: their one-hot sums
    to 0). ``points`` may hold anything (``inf``, NaN) where ``hit`` is False.
    """
    e, n = hit.shape
    dev = hit.device
    count = hit.sum(dim=1, keepdim=True)
    slots = torch.arange(max_points, device=dev).expand(e, max_points)
    rank = torch.where(count > max_points, (slots * count) // max_points, slots)
    valid = slots < count
    cumsum = hit.to(torch.int64).cumsum(dim=1)  # hits up to and including ray i
    idx = torch.searchsorted(cumsum, (rank + 1).contiguous()).clamp(max=n - 1)
    chosen = torch.gather(points, 1, idx[..., None].expand(e, max_points, 3))
    chosen = torch.where(valid[..., None], chosen, torch.zeros((), device=dev))
    if rot is not None and origin is not None:
        chosen = torch.einsum("eji,epj->epi", rot, chosen - origin[:, None])
    out = torch.cat([chosen, one_hot_classes(torch.gather(labels, 1, idx), classes)], dim=-1)
    return out * valid[..., None]


def direction_bounds(directions: torch.Tensor) -> tuple[float, float, float, float, bool]:
    """Azimuth and elevation bounds [rad] of a set of ray directions ``(M, 3)``; a set
    spanning nearly the full circle wraps at +-pi (the last value says so)."""
    d = directions.double()
    az = torch.atan2(d[:, 1], d[:, 0])
    el = torch.atan2(d[:, 2], torch.hypot(d[:, 0], d[:, 1]))
    az0, az1 = float(az.min()), float(az.max())
    full = az1 - az0 > 2 * math.pi * 0.95
    if full:
        az0, az1 = -math.pi, math.pi
    el0, el1 = float(el.min()), float(el.max())
    if el1 - el0 < 1e-6:  # one elevation: a one-row band around it
        el0, el1 = el0 - 1e-3, el1 + 1e-3
    if az1 - az0 < 1e-6:
        az0, az1 = az0 - 1e-3, az1 + 1e-3
    return az0, az1, el0, el1, full


def check_image_size(width: object, height: object) -> None:
    """Refuse a range-image width or height outside [1, 4096], naming it."""
    for what, v in (("width", width), ("height", height)):
        if not isinstance(v, int) or isinstance(v, bool) or not 1 <= v <= 4096:
            raise SensorError(
                f"lidar_range_image: {what} must be an integer in [1, 4096], got {v!r}"
            )


def ray_cells(
    local_dirs: torch.Tensor,
    bounds: tuple[float, float, float, float, bool],
    width: int,
    height: int,
) -> torch.Tensor:
    """The range-image cell (``row * width + col``) of each ray ``(..., 3)`` of the
    sensor's ray frame: columns by azimuth from the smallest of ``bounds``, rows by
    elevation from the highest. A pattern's rays keep their cells from step to step, so
    a sensor computes them once per pattern frame (see :func:`range_image`'s ``cells``)."""
    az0, az1, el0, el1, _ = bounds
    az = torch.atan2(local_dirs[..., 1], local_dirs[..., 0])
    el = torch.atan2(local_dirs[..., 2], torch.hypot(local_dirs[..., 0], local_dirs[..., 1]))
    col = ((az - az0) / (az1 - az0) * width).floor().long().clamp(0, width - 1)
    row = ((el1 - el) / (el1 - el0) * height).floor().long().clamp(0, height - 1)
    return row * width + col


def range_image(
    local_dirs: torch.Tensor | None,
    hit: torch.Tensor,
    distances: torch.Tensor,
    max_distance: float,
    labels: torch.Tensor,
    classes: int,
    bounds: tuple[float, float, float, float, bool],
    width: int,
    height: int,
    *,
    cells: torch.Tensor | None = None,
    scanned: bool = False,
    valid: torch.Tensor | None = None,
) -> torch.Tensor:
    """``(E, 1 + C, height, width)`` nearest distance and class occupancy per direction
    cell (``(E, 2 + C, height, width)`` with ``scanned``).

    Each ray falls in the cell of its azimuth (columns, left to right from the smallest
    azimuth of ``bounds``) and elevation (rows, top = highest), from ``local_dirs``
    ``(E, N, 3)`` in the sensor's ray frame, or given as ``cells`` ``(N,)`` or ``(E, N)``
    (:func:`ray_cells`, computed once; ``local_dirs`` is then not read). Channel 0: the
    nearest hit in the cell / ``max_distance``, 1 where the cell has no hit this step;
    channels 1..C: the fraction of the cell's rays this step that hit each class, 0 in a
    cell no ray fell in. Without ``scanned`` a cell no ray of this step fell in reads as
    one whose rays all missed (as a real range image with no return does); with it, a
    last channel says which cells this step's rays scanned (1) and which none did (0),
    so an obstacle in a pattern's blind part of this step is not free space.
    ``distances`` may hold anything where ``hit`` is False. ``valid`` ``(E, N)`` (bool)
    leaves out the rays where it is False altogether (not scanned, no distance, no class).
    """
    e = hit.shape[0]
    if cells is None:
        if local_dirs is None:
            raise SensorError("range_image: give the rays' directions or their cells")
        cells = ray_cells(local_dirs, bounds, width, height)
    cell = cells.expand(hit.shape)
    n_cells = height * width
    dev = hit.device
    if valid is not None:
        hit = hit & valid
    scaled = torch.where(hit, distances / float(max_distance), 1.0).clamp(0.0, 1.0)
    depth = torch.ones(e, n_cells, device=dev)
    depth.scatter_reduce_(1, cell, scaled, reduce="amin", include_self=True)
    rays = torch.zeros(e, n_cells, device=dev)
    rays.scatter_add_(1, cell, torch.ones_like(scaled) if valid is None else valid.float())
    per_class = torch.zeros(e, classes * n_cells, device=dev)
    slot = labels.long().clamp(0, classes - 1) * n_cells + cell
    per_class.scatter_add_(1, slot, hit.float())
    occupancy = per_class.view(e, classes, n_cells) / rays.clamp(min=1.0)[:, None]
    parts = [depth[:, None], occupancy]
    if scanned:
        parts.append((rays > 0).float()[:, None])
    return torch.cat(parts, dim=1).view(e, 1 + classes + int(scanned), height, width)


class ScanHistory:
    """The last ``k`` scans of every environment, for observations that accumulate
    frames (a rotating or rosette pattern fills a range image or a point cloud over
    several steps).

    Stores per scan the per-ray tensors it is given (``(E, N, ...)`` each, by name); a
    slot not filled since the environment's last reset is not valid (left out).
    """

    def __init__(self, k: int, what: str) -> None:
        if not isinstance(k, int) or isinstance(k, bool) or not 1 <= k <= 64:
            raise SensorError(f"{what}: accumulate must be an integer in [1, 64], got {k!r}")
        self.k = k
        self.arrays: dict[str, torch.Tensor] = {}
        self.filled: torch.Tensor | None = None
        self.scans = 0
        self.last_key: object = None

    def push(self, **rays: torch.Tensor) -> None:
        """Store this step's scan (each ``(E, N, ...)``) in place of the oldest."""
        if self.filled is None:
            first = next(iter(rays.values()))
            e = first.shape[0]
            self.arrays = {
                name: torch.zeros((e, self.k, *t.shape[1:]), dtype=t.dtype, device=t.device)
                for name, t in rays.items()
            }
            self.filled = torch.zeros(e, self.k, dtype=torch.bool, device=first.device)
        slot = self.scans % self.k
        for name, t in rays.items():
            self.arrays[name][:, slot] = t
        self.filled[:, slot] = True
        self.scans += 1

    def clear_envs(self, env_ids: torch.Tensor) -> None:
        """Forget the scans of ``env_ids`` (a reset): their slots become not valid."""
        if self.filled is not None:
            self.filled[env_ids] = False

    def flat(self) -> dict[str, torch.Tensor]:
        """Each stored tensor as ``(E, k * N, ...)``, and ``"valid"`` ``(E, k * N)``."""
        assert self.filled is not None, "push a scan first"
        out = {name: t.flatten(1, 2) for name, t in self.arrays.items()}
        first = next(iter(self.arrays.values()))
        valid = self.filled[:, :, None].expand(first.shape[:3])
        out["valid"] = valid.flatten(1, 2)
        return out
