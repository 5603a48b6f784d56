"""The semantic LiDAR as an mjlab ``RayCastSensor`` whose data is a ``RayCastData``.

The sensor *is* an mjlab ``RayCastSensor``, so the scene wires it to the shared
``SensorContext`` (one BVH for every ray sensor and camera) and casts inside mjlab's sense
graph (a CUDA graph on GPU). Inside that graph, per step, it launches robotwright's
kernels around mjlab's ray cast: ``advance_frame`` (the pattern window, counter on the
device), ``sensor_pose`` (sensor and carrier frame poses), ``world_rays`` (the window of
the pattern table), MuJoCo Warp ``rays`` (the call of mjlab's ``RayCastSensor`` with its
arguments: BVH, parent-body exclusion, geom-group filter) and ``finish_rays_mjlab``
(float64 refinement of curved hits, range model, labels, points and mjlab's miss
values in one pass; with realism options or held scans, ``finish_rays`` then
``mjlab_finish``). On warp's CPU device the per-ray kernels run in column blocks on
parallel threads, each a thread per environment looping over its rays (a 2-D launch's
index costs more there than their work); on CUDA a thread a ray. Nothing runs on the
host per step and nothing is copied: mjlab's
``prepare_rays`` (host, before the graph) is replaced by the in-graph kernels and
``postprocess_rays`` (host, after it) only marks the data fresh.

``env.scene["lidar"].data`` is a :class:`MjlabSemanticLidarData`, a ``RayCastData`` with
mjlab's meanings (so ``height_scan``, ``terrain_normal_from_sensors`` and the ``upright``
reward read it as they read mjlab's sensor) plus the semantic fields.
"""

from __future__ import annotations

import copy
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, Literal

import mujoco
import mujoco_warp as mjw
import numpy as np
import torch
import warp as wp  # no global warp setting is changed here: mjlab configures warp
from mjlab.sensor.raycast_sensor import RayCastData, RayCastSensor

from robotwright.errors import SensorError
from robotwright.sensors import _warp_kernels as kernels
from robotwright.sensors.device import ray_blocks
from robotwright.sensors.lidar import geom_paths
from robotwright.sensors.mjlab import _kernels as mjlab_kernels
from robotwright.sensors.mjlab.config import (
    MJLAB_TERRAIN_KEYWORD,
    ResolvedLidarCfg,
    SemanticLidarSensorCfg,
    resolve,
)
from robotwright.sensors.patterns import PatternCfg, RayTable
from robotwright.sensors.semantic import classify_path, geom_class_table

__all__ = ["CLASS_COLORS", "MjlabSemanticLidarData", "MjlabSemanticLidarSensor"]

_ALIGN = {"base": kernels.ALIGN_BASE, "yaw": kernels.ALIGN_YAW, "world": kernels.ALIGN_WORLD}

#: RGBA of the class ids drawn by ``debug_vis`` (id modulo the length; 0 = unknown).
CLASS_COLORS: tuple[tuple[float, float, float, float], ...] = (
    (0.5, 0.5, 0.5, 1.0),
    (0.55, 0.35, 0.15, 1.0),
    (0.9, 0.1, 0.1, 1.0),
    (0.1, 0.4, 0.95, 1.0),
    (0.1, 0.8, 0.2, 1.0),
    (0.9, 0.7, 0.1, 1.0),
    (0.7, 0.2, 0.8, 1.0),
)

EnvIds = torch.Tensor | np.ndarray | list[int] | slice | None

#: The arrays each scan publishes, in the order of ``mjlab_finish``'s outputs.
_PUBLISHED = ("distances", "hit_mask", "geom_ids", "labels", "points", "normals", "pnt", "vec")


def _table_of(pattern: Any, mj_model: mujoco.MjModel) -> RayTable:
    """The ray table of a robotwright pattern, or one frame of an mjlab pattern."""
    if isinstance(pattern, PatternCfg):
        return pattern.ray_table()
    origins, dirs = pattern.generate_rays(mj_model, "cpu")
    o = np.ascontiguousarray(torch.as_tensor(origins).cpu().numpy(), dtype=np.float64)
    d = np.ascontiguousarray(torch.as_tensor(dirs).cpu().numpy(), dtype=np.float64)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return RayTable(o, d, int(d.shape[0]))


class _TablePattern:
    """mjlab's pattern protocol over the first ``rays`` rays of our table: mjlab sizes
    its own buffers from it, so the sensor hands it one ray and allocates the buffers
    it uses itself (mjlab's per-ray output tensors, 28 B a ray, would go unused)."""

    def __init__(self, table: RayTable, rays: int) -> None:
        self.table = table
        self.rays = rays

    def generate_rays(self, mj_model: Any, device: str) -> tuple[torch.Tensor, torch.Tensor]:
        o, d = self.table.origins[: self.rays], self.table.directions[: self.rays]
        return (
            torch.as_tensor(o, dtype=torch.float32, device=device),
            torch.as_tensor(d, dtype=torch.float32, device=device),
        )


@dataclass
class MjlabSemanticLidarData(RayCastData):
    """mjlab's ``RayCastData`` (``E`` envs, ``N`` rays, one frame ``F = 1``) plus labels.

    Torch views of the device buffers, overwritten in place by every ``sim.sense()``;
    the same tensor objects every step. mjlab's fields keep mjlab's meanings:

    Attributes:
        distances: ``(E, N)`` float32 range [m]; -1 for a miss (nothing hit, out of
            ``[min_distance, max_distance]``, or dropped).
        normals_w: ``(E, N, 3)`` unit surface normal at the hit (world frame, computed by
            MuJoCo Warp); zero for a miss.
        hit_pos_w: ``(E, N, 3)`` hit point [m] (world); the ray origin for a miss.
        pos_w: ``(E, 3)`` position of the frame object [m]; quat_w: ``(E, 4)`` its
            orientation (w, x, y, z) (``frame_*[:, 0]``, as mjlab's).
        frame_pos_w: ``(E, 1, 3)``; frame_quat_w: ``(E, 1, 4)``: the frame object's pose.
        hit_mask: ``(E, N)`` bool, True where the ray returned a point.
        semantic_labels: ``(E, N)`` int32 class id (1..K in mapping order, the robot's
            own class after them, 0 miss/unknown).
        geom_ids: ``(E, N)`` int32 MuJoCo geom id of the hit, -1 on a miss.
        ray_origins_w: ``(E, N, 3)`` this step's ray origins [m].
        ray_directions_w: ``(E, N, 3)`` this step's unit ray directions.
        sensor_pos_w: ``(E, 3)`` the LiDAR's position (``offset_pos`` applied) [m];
            sensor_quat_w: ``(E, 4)`` its orientation (w, x, y, z).
        frame: ``(1,)`` int32 count of scans cast since the start, less one.
        window_start: ``(E,)`` int32 first row, in the pattern table, of the window of
            the scan the data hold (its rays are rows ``window_start + i``, wrapping;
            a held scan keeps its own window while the live one moves on).
        scan_due: ``(E,)`` int32, 1 where this step published a new scan (always, with
            ``update_period`` 0), 0 where the data hold an earlier one.
    """

    hit_mask: torch.Tensor
    semantic_labels: torch.Tensor
    geom_ids: torch.Tensor
    ray_origins_w: torch.Tensor
    ray_directions_w: torch.Tensor
    sensor_pos_w: torch.Tensor
    sensor_quat_w: torch.Tensor
    frame: torch.Tensor
    window_start: torch.Tensor
    scan_due: torch.Tensor

    @property
    def mesh_ids(self) -> torch.Tensor:
        """The seed's name of :attr:`geom_ids`."""
        return self.geom_ids


def _draw_spheres(
    scene: mujoco.MjvScene, points: np.ndarray, colours: np.ndarray, radius: float
) -> None:
    """Append spheres to a MuJoCo scene as decorations, as many as it has room for."""
    first = scene.ngeom
    count = min(len(points), scene.maxgeom - first)
    geoms = scene.geoms  # a new tuple on every access: read once
    size = np.array([radius, 0.0, 0.0])
    eye = np.eye(3).ravel()
    colours = np.asarray(colours, dtype=np.float32)
    sphere = int(mujoco.mjtGeom.mjGEOM_SPHERE)
    for j in range(count):
        g = geoms[first + j]
        mujoco.mjv_initGeom(g, sphere, size, points[j], eye, colours[j])
        g.category = mujoco.mjtCatBit.mjCAT_DECOR
    scene.ngeom = first + count


def _rows(tensor: torch.Tensor, env_ids: EnvIds) -> torch.Tensor:
    if env_ids is None:
        return tensor
    if isinstance(env_ids, slice):
        return tensor[env_ids]
    return tensor[torch.as_tensor(env_ids, dtype=torch.long, device=tensor.device)]


class MjlabSemanticLidarSensor(RayCastSensor):
    """mjlab ``RayCastSensor`` whose rays follow a robotwright pattern and carry labels.

    Attributes (after ``initialize``):
        resolved: the checked values of the config (:class:`ResolvedLidarCfg`).
        table: the pattern's :class:`~robotwright.sensors.RayTable` (sensor frame).
        class_names: ``("unknown", *classes[, self_class])``, indexed by class id.
        geom_paths: classification path of every geom of the compiled scene.
        geom_semantic_class: ``(ngeom,)`` class id of every geom (0 where not hittable).
        hittable_geom_mask: ``(ngeom,)`` geoms the rays can hit (included groups, minus
            the excluded parent body).
    """

    cfg: SemanticLidarSensorCfg

    def __init__(self, cfg: SemanticLidarSensorCfg) -> None:
        self.resolved: ResolvedLidarCfg = resolve(cfg)
        super().__init__(cfg)
        self._buffers: dict[str, Any] = {}
        self._pool: ThreadPoolExecutor | None = None
        self._blocks: list[tuple[int, int]] = []
        self._elapsed = 0.0  # simulated seconds since the last sense
        self._casts = 0

    @property
    def class_names(self) -> tuple[str, ...]:
        return self.resolved.class_names

    @property
    def semantic_class_mapping(self) -> dict[str, list[str]]:
        return self.resolved.mapping

    def initialize(self, mj_model: mujoco.MjModel, model: Any, data: Any, device: str) -> None:
        cfg = self.cfg
        # Fields may have changed since build(): check and derive again.
        self.resolved = res = resolve(cfg)
        self.table = _table_of(cfg.pattern, mj_model)
        # mjlab's own initialisation resolves the frame: hand it one ray of the table
        # (the buffers it would size from the pattern are allocated below, those it
        # does not need not at all), then restore the user's config.
        mjlab_cfg = copy.copy(cfg)
        mjlab_cfg.pattern = _TablePattern(self.table, 1)
        self.cfg = mjlab_cfg
        try:
            super().initialize(mj_model, model, data, device)
        finally:
            self.cfg = cfg
        kind, obj, body = self._frame_infos[0]
        if self._num_frames != 1:
            raise SensorError(f"{cfg.name}: expected one frame object, got {self._num_frames}")
        self._carrier, self._kind = obj, kind
        self.geom_paths = geom_paths(mj_model)
        self.hittable_geom_mask = self._hittable(mj_model, body)
        lut = geom_class_table(self.geom_paths, res.mapping, self.hittable_geom_mask)
        own = self._own_geoms(mj_model, body) & self.hittable_geom_mask
        if res.self_class_id:
            lut[:-1][own] = res.self_class_id
        self.geom_semantic_class = lut[:-1]
        self._check_scene(own)
        e, n = int(data.nworld), int(self.table.rays_per_frame)
        rows = int(self.table.directions.shape[0])
        self._num_rays_per_frame = self._num_rays = n
        self._distances = self._normals_w = self._hit_pos_w = None  # mjlab's, unused
        seeds = np.random.SeedSequence(cfg.seed).generate_state(e).astype(np.uint32)
        self._rng = np.random.default_rng(np.random.SeedSequence(cfg.seed).spawn(1)[0])
        rate = cfg.pattern.firing_rate() if isinstance(cfg.pattern, PatternCfg) else None
        self._rate = float(rate or 0.0)
        self._hold = res.update_period > 0.0
        dev = self._wp_device
        # Load the kernels now: mjlab captures its sense graph later, and no module may
        # be compiled or loaded during a CUDA graph capture.
        wp.load_module(kernels, device=dev)
        wp.load_module(mjlab_kernels, device=dev)
        identity = np.tile(np.eye(3, dtype=np.float32), (e, 1, 1))
        with wp.ScopedDevice(dev):
            b = {
                "table_o": wp.array(self.table.origins.astype(np.float32), dtype=wp.vec3),
                "table_d": wp.array(self.table.directions.astype(np.float32), dtype=wp.vec3),
                "lut": wp.array(lut, dtype=wp.int32),
                "class_drop": wp.array(np.asarray(res.class_dropout, np.float32), dtype=float),
                "geom_type": wp.array(mj_model.geom_type.astype(np.int32), dtype=wp.int32),
                "geom_size": wp.array(mj_model.geom_size, dtype=wp.vec3d),
                "env_seed": wp.array(seeds.view(np.int32), dtype=wp.int32),
                "frame": wp.array(np.array([-1], dtype=np.int32), dtype=wp.int32),
                "window": wp.zeros(1, dtype=wp.int32),
                "elapsed": wp.zeros(1, dtype=wp.float64),
                "start": wp.zeros(e, dtype=wp.int32),
                "carry": wp.zeros(e, dtype=wp.float64),
                "timer": wp.zeros(e, dtype=wp.float64),
                "fresh": wp.ones(e, dtype=wp.int32),
                "due": wp.ones(e, dtype=wp.int32),
                "published": wp.zeros(e, dtype=wp.int32),
                "mount_pos": wp.array(
                    np.tile(np.asarray(res.offset_pos, np.float32), (e, 1)), dtype=wp.vec3
                ),
                "mount_mat": wp.array(identity, dtype=wp.mat33),
                "drift": wp.zeros(e, dtype=wp.vec3),
                "pos_w": wp.zeros(e, dtype=wp.vec3),
                "quat_w": wp.zeros(e, dtype=wp.vec4),
                "sensor_mat": wp.zeros(e, dtype=wp.mat33),
                "ray_rot": wp.zeros(e, dtype=wp.mat33),
                "frame_pos": wp.zeros(e, dtype=wp.vec3),
                "frame_quat": wp.zeros(e, dtype=wp.vec4),
                "frame_mat": wp.zeros(e, dtype=wp.mat33),
                "frame_rot": wp.zeros(e, dtype=wp.mat33),
            }
            # The rays mjlab's cast reads and writes (mjlab's own, at one ray, unused).
            self._ray_pnt = wp.zeros((e, n), dtype=wp.vec3)
            self._ray_vec = wp.zeros((e, n), dtype=wp.vec3)
            self._ray_dist = wp.zeros((e, n), dtype=float)
            self._ray_geomid = wp.zeros((e, n), dtype=int)
            self._ray_normal = wp.zeros((e, n), dtype=wp.vec3)
            exclude = int(body) if cfg.exclude_parent_body else -1
            self._ray_bodyexclude = wp.array(np.full(n, exclude, np.int32), dtype=int)
            # What the range model writes, and what the data publish: the same arrays,
            # unless scans are held between updates (update_period > 0).
            work = {
                "distances": wp.full((e, n), -1.0, dtype=wp.float32),
                "hit_mask": wp.zeros((e, n), dtype=wp.bool),
                "geom_ids": wp.full((e, n), -1, dtype=wp.int32),
                "labels": wp.zeros((e, n), dtype=wp.int32),
                "points": wp.zeros((e, n), dtype=wp.vec3),
            }
            if self._hold:
                out = {key: wp.zeros_like(arr) for key, arr in work.items()}
                out["distances"].fill_(-1.0)
                out["geom_ids"].fill_(-1)
                out |= {
                    "normals": wp.zeros((e, n), dtype=wp.vec3),
                    "pnt": wp.zeros((e, n), dtype=wp.vec3),
                    "vec": wp.zeros((e, n), dtype=wp.vec3),
                }
            else:
                out = dict(work)
                out |= {"normals": self._ray_normal, "pnt": self._ray_pnt, "vec": self._ray_vec}
        self._work, self._out = work, out
        b |= {k: out[k] for k in ("distances", "hit_mask", "geom_ids", "labels", "points")}
        self._table_rows = rows
        self._origins = int(bool(np.any(self.table.origins)))
        rot = np.empty(9)
        mujoco.mju_quat2Mat(rot, np.asarray(res.offset_rot, dtype=np.float64))
        self._offset_pos = wp.vec3(*np.asarray(res.offset_pos, dtype=np.float32))
        self._offset_mat = wp.mat33(*rot.astype(np.float32))
        self._zero_pos = wp.vec3(0.0, 0.0, 0.0)
        self._identity = wp.mat33(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
        self._buffers = b
        self._elapsed = 0.0
        self._casts = 0
        self._blocks = ray_blocks(n, dev, cfg.num_threads)
        self._pool = ThreadPoolExecutor(len(self._blocks)) if len(self._blocks) > 1 else None
        t = wp.to_torch
        frame_pos, frame_quat = t(b["frame_pos"]), t(b["frame_quat"])
        self._lidar_data = MjlabSemanticLidarData(
            distances=t(out["distances"]),
            normals_w=t(out["normals"]),
            hit_pos_w=t(out["points"]),
            pos_w=frame_pos,
            quat_w=frame_quat,
            frame_pos_w=frame_pos.view(e, 1, 3),
            frame_quat_w=frame_quat.view(e, 1, 4),
            hit_mask=t(out["hit_mask"]),
            semantic_labels=t(out["labels"]),
            geom_ids=t(out["geom_ids"]),
            ray_origins_w=t(out["pnt"]),
            ray_directions_w=t(out["vec"]),
            sensor_pos_w=t(b["pos_w"]),
            sensor_quat_w=t(b["quat_w"]),
            frame=t(b["frame"]),
            window_start=t(b["published"]),
            scan_due=t(b["due"]),
        )
        self._sensor_mat = t(b["sensor_mat"])
        self._ray_rot = t(b["ray_rot"])
        self._frame_mat = t(b["frame_mat"])
        self._obs_cache: dict[Any, Any] = {}
        self._place(None)

    def _env_index(self, env_ids: EnvIds) -> torch.Tensor:
        """``env_ids`` as a long tensor of environment indices on the sensor's device."""
        e = int(self._data.nworld)
        device = self._lidar_data.window_start.device
        if env_ids is None:
            return torch.arange(e, device=device)
        if isinstance(env_ids, slice):
            return torch.arange(e, device=device)[env_ids]
        return torch.as_tensor(env_ids, dtype=torch.long, device=device).reshape(-1)

    def _place(self, env_ids: EnvIds) -> None:
        """Start the scans of ``env_ids`` (all: ``None``) afresh: their phase, and their
        mount offset and drift drawn anew where those are randomised. Other
        environments are not touched."""
        res, b = self.resolved, self._buffers
        idx = self._env_index(env_ids)
        k = int(idx.numel())
        if k == 0:
            return
        t = wp.to_torch
        rows, n = self._table_rows, int(self.table.rays_per_frame)
        start = np.zeros(k, dtype=np.int64)
        if res.random_phase:
            if self._rate > 0.0:  # any ray of the stream
                start = self._rng.integers(0, rows, size=k)
            else:  # any frame
                start = self._rng.integers(0, max(rows // n, 1), size=k) * n
        dev = idx.device
        t(b["start"])[idx] = torch.as_tensor(start, dtype=torch.int32, device=dev)
        t(b["carry"])[idx] = 0.0
        t(b["fresh"])[idx] = 1
        if not res.randomised_mount:
            return
        lo_hi = np.asarray(res.mount_pos_range)
        pos = np.asarray(res.offset_pos) + self._rng.uniform(-lo_hi, lo_hi, size=(k, 3))
        rpy = self._rng.uniform(-np.asarray(res.mount_rot_range), res.mount_rot_range, (k, 3))
        base = np.empty(9)
        mujoco.mju_quat2Mat(base, np.asarray(res.offset_rot, dtype=np.float64))
        mats = np.empty((k, 3, 3))
        for j, (roll, pitch, yaw) in enumerate(rpy):
            q, extra = np.empty(4), np.empty(9)
            mujoco.mju_euler2Quat(q, np.array([roll, pitch, yaw]), "XYZ")
            mujoco.mju_quat2Mat(extra, q)
            mats[j] = base.reshape(3, 3) @ extra.reshape(3, 3)
        drift = self._rng.uniform(res.drift_range[0], res.drift_range[1], size=(k, 3))
        t(b["mount_pos"])[idx] = torch.as_tensor(pos, dtype=torch.float32, device=dev)
        t(b["mount_mat"])[idx] = torch.as_tensor(mats, dtype=torch.float32, device=dev)
        t(b["drift"])[idx] = torch.as_tensor(drift, dtype=torch.float32, device=dev)

    def reset(self, env_ids: torch.Tensor | slice | None = None) -> None:
        """Reset only ``env_ids`` (all: ``None``): their scan starts again at its phase,
        their mount and drift are drawn anew, their accumulated observations cleared."""
        super().reset(env_ids)
        if not self._buffers:
            return
        self._place(env_ids)
        histories = [v for v in self._obs_cache.values() if hasattr(v, "clear_envs")]
        if histories:
            idx = self._env_index(env_ids)
            for history in histories:
                history.clear_envs(idx)

    def update(self, dt: float) -> None:
        """Count the simulated time [s] that passes (mjlab calls this every physics step)."""
        super().update(dt)
        self._elapsed += float(dt)

    def __del__(self) -> None:  # pragma: no cover - best effort at teardown
        if getattr(self, "_pool", None) is not None:
            self._pool.shutdown(wait=False)

    def _hittable(self, mj_model: mujoco.MjModel, parent_body: int) -> np.ndarray:
        """Geoms mjlab's ``rays`` call can hit: included groups, minus the parent body."""
        groups = self.cfg.include_geom_groups
        mask = np.ones(mj_model.ngeom, dtype=bool)
        if groups is not None:
            mask &= np.isin(mj_model.geom_group, list(groups))
        if self.cfg.exclude_parent_body:
            mask &= mj_model.geom_bodyid != parent_body
        return mask

    @staticmethod
    def _own_geoms(mj_model: mujoco.MjModel, parent_body: int) -> np.ndarray:
        """Geoms of the robot (kinematic tree under the world) carrying the sensor."""
        root = int(mj_model.body_rootid[parent_body])
        if root == 0:
            return np.zeros(mj_model.ngeom, dtype=bool)
        return mj_model.body_rootid[mj_model.geom_bodyid] == root

    def _check_scene(self, own: np.ndarray) -> None:
        """Warn about unlabelled self-hits and unclassified terrain (both silent otherwise)."""
        name = self.cfg.name
        if own.any() and not self.resolved.self_class_id:
            first = self.geom_paths[int(np.flatnonzero(own)[0])]
            warnings.warn(
                f"{name}: {int(own.sum())} geoms of the robot carrying the sensor are in "
                f"include_geom_groups={self.cfg.include_geom_groups} (e.g. {first}): the "
                "LiDAR will see its own robot and, with self_class=None, label it by path; "
                "set self_class, move them to another geom group or narrow "
                "include_geom_groups",
                stacklevel=3,
            )
        terrain = [
            g
            for g, p in enumerate(self.geom_paths)
            if p.startswith(MJLAB_TERRAIN_KEYWORD) and self.hittable_geom_mask[g]
        ]
        if terrain and not any(self.geom_semantic_class[g] for g in terrain):
            warnings.warn(
                f"{name}: mjlab's terrain geoms ({self.geom_paths[terrain[0]]}, ...) match no "
                "class of semantic_class_mapping and read class 0; use "
                "robotwright.sensors.mjlab.mjlab_class_mapping() to class them as terrain",
                stacklevel=3,
            )

    # mjlab's pipeline: prepare (host, before the graph) -> raycast_kernel (in the graph)
    # -> postprocess (host, after). Everything per ray happens in the graph.
    def prepare_rays(self) -> None:
        """Host, before the graph: hand it the simulated time since the last sense."""
        if self._buffers:
            self._buffers["elapsed"].fill_(self._elapsed)
            self._elapsed = 0.0

    def raycast_kernel(self, rc: Any) -> None:
        """IN-GRAPH: pattern window, poses, world rays, mjlab's cast, range model, labels.

        On CUDA every step is one launch (captured in mjlab's sense graph). On warp's CPU
        device, which runs a kernel on one core, the rays are cast in column blocks by
        parallel launches (warp releases the GIL), as the core's warp pipeline does.
        """
        b, cfg = self._buffers, self.cfg
        d = self._data.struct
        e, n = int(d.nworld), int(self.table.rays_per_frame)
        if self._kind == "body":
            cpos, cmat = d.xpos, d.xmat
        elif self._kind == "site":
            cpos, cmat = d.site_xpos, d.site_xmat
        else:
            cpos, cmat = d.geom_xpos, d.geom_xmat
        dev = self._wp_device
        res = self.resolved
        wp.launch(
            kernels.advance_frame,
            dim=1,
            inputs=[b["frame"], self.table.num_frames, n],
            outputs=[b["window"]],
            device=dev,
        )
        wp.launch(
            mjlab_kernels.advance_scan,
            dim=e,
            inputs=[
                b["elapsed"],
                self._rate,
                self._table_rows,
                n,
                float(res.update_period),
                b["fresh"],
            ],
            outputs=[b["start"], b["carry"], b["timer"], b["due"], b["published"]],
            device=dev,
        )
        align = _ALIGN[cfg.ray_alignment]
        if res.randomised_mount:
            wp.launch(
                kernels.sensor_pose_per_env,
                dim=e,
                inputs=[cpos, cmat, self._carrier, b["mount_pos"], b["mount_mat"], align],
                outputs=[b["pos_w"], b["quat_w"], b["sensor_mat"], b["ray_rot"]],
                device=dev,
            )
        else:
            wp.launch(
                kernels.sensor_pose,
                dim=e,
                inputs=[cpos, cmat, self._carrier, self._offset_pos, self._offset_mat, align],
                outputs=[b["pos_w"], b["quat_w"], b["sensor_mat"], b["ray_rot"]],
                device=dev,
            )
        # The frame object's own pose (mjlab's pos_w / frame_pos_w): no offset.
        wp.launch(
            kernels.sensor_pose,
            dim=e,
            inputs=[
                cpos,
                cmat,
                self._carrier,
                self._zero_pos,
                self._identity,
                align,
            ],
            outputs=[b["frame_pos"], b["frame_quat"], b["frame_mat"], b["frame_rot"]],
            device=dev,
        )
        # Off CUDA nothing is captured: when no environment publishes a scan this step
        # (update_period), the cast is skipped (the held scans stay as they are).
        if self._hold and not dev.is_cuda and not wp.to_torch(b["due"]).any():
            return
        if self._pool is None:
            self._cast_block(rc, 0, n)
        else:
            list(self._pool.map(lambda ab: self._cast_block(rc, *ab), self._blocks))

    def _cast_block(self, rc: Any, a: int, b_: int) -> None:
        """World rays, mjlab's cast and finishing of the rays ``[a, b_)`` of every env."""
        b, cfg = self._buffers, self.cfg
        d = self._data.struct
        e = int(d.nworld)
        whole = (a, b_) == (0, int(self.table.rays_per_frame))

        def cols(array: Any) -> Any:
            return array if whole else array[:, a:b_]

        pnt, vec = cols(self._ray_pnt), cols(self._ray_vec)
        dist, geomid = cols(self._ray_dist), cols(self._ray_geomid)
        res, work, out = self.resolved, self._work, self._out
        self._per_ray(
            mjlab_kernels.world_rays_windowed,
            (e, b_ - a),
            [
                b["table_o"],
                b["table_d"],
                b["start"],
                self._table_rows,
                a,
                b["pos_w"],
                b["ray_rot"],
                b["drift"],
                float(res.angular_jitter_std),
                b["env_seed"],
                b["frame"],
                int(self._hold),
                b["due"],
                self._origins,
            ],
            [pnt, vec],
        )
        # mjlab's own call (RayCastSensor.raycast_kernel): its BVH, geom groups and
        # parent-body exclusion, on this block of columns.
        mjw.rays(
            m=self._model.struct,
            d=d,
            pnt=pnt,
            vec=vec,
            geomgroup=self._geomgroup,
            flg_static=True,
            bodyexclude=self._ray_bodyexclude if whole else self._ray_bodyexclude[a:b_],
            dist=dist,
            geomid=geomid,
            normal=cols(self._ray_normal),
            rc=rc,
        )
        range_model = [
            dist,
            geomid,
            pnt,
            vec,
            d.geom_xpos,
            d.geom_xmat,
            b["geom_type"],
            b["geom_size"],
            int(cfg.refine_curved_hits),
            float(cfg.min_distance),
            float(cfg.max_distance),
            float(cfg.range_noise_std),
            float(cfg.dropout_prob),
        ]
        labelled = [cols(work[k]) for k in ("distances", "hit_mask", "geom_ids", "labels")]
        if not (self._hold or res.range_noise_per_meter or any(res.class_dropout)):
            # The plain case: one pass writes the published arrays with mjlab's misses.
            self._per_ray(
                mjlab_kernels.finish_rays_mjlab,
                (e, b_ - a),
                [*range_model, b["env_seed"], b["frame"], b["lut"], a],
                [*labelled, cols(work["points"]), cols(self._ray_normal)],
            )
            return
        self._per_ray(
            kernels.finish_rays,
            (e, b_ - a),
            [
                *range_model,
                -1.0,  # mjlab's miss value; get_distances() applies miss_distance
                b["env_seed"],
                b["frame"],
                b["lut"],
                a,
            ],
            [*labelled, cols(work["points"])],
        )
        self._per_ray(
            mjlab_kernels.mjlab_finish,
            (e, b_ - a),
            [
                cols(work["distances"]),
                cols(work["hit_mask"]),
                cols(work["geom_ids"]),
                cols(work["labels"]),
                cols(work["points"]),
                cols(self._ray_normal),
                pnt,
                vec,
                float(res.range_noise_per_meter),
                b["class_drop"],
                float(cfg.min_distance),
                float(cfg.max_distance),
                b["env_seed"],
                b["frame"],
                a,
                int(self._hold),
                b["due"],
            ],
            [cols(out[k]) for k in _PUBLISHED],
        )

    def _per_ray(self, kernel: Any, dim: tuple[int, int], inputs: list, outputs: list) -> None:
        kernels.launch_per_ray(kernel, dim, inputs, outputs, self._wp_device)

    def postprocess_rays(self) -> None:
        """Fresh results: drop data cached before this step's cast (nothing per ray),
        and count the scan (on the host: on CUDA the cast is a replayed graph)."""
        self._invalidate_cache()
        self._casts += 1

    def _compute_data(self) -> MjlabSemanticLidarData:  # type: ignore[override]
        if not self._buffers:
            raise SensorError(f"{self.cfg.name}: the sensor is not initialised (no scene yet)")
        return self._lidar_data

    def debug_vis(self, visualizer: Any) -> None:
        """Hit points coloured by class (:data:`CLASS_COLORS`), at most
        ``debug_vis_max_points`` evenly spaced hits per drawn environment.

        MuJoCo's native viewer gets the spheres written into its scene in one pass (2 000
        points in 2-3 ms); other viewers (viser) through ``add_sphere``, each call
        with prepared arrays."""
        if not self.cfg.debug_vis or not self._debug_vis_enabled or not self._buffers:
            return
        data = self.data
        envs = list(visualizer.get_env_indices(data.distances.shape[0]))
        if not envs:
            return
        points, colours = self._debug_points(envs)
        radius = 0.2 * float(visualizer.meansize)
        scene = getattr(visualizer, "_mjv_scene", None)
        if isinstance(scene, mujoco.MjvScene):
            _draw_spheres(scene, points, colours, radius)
            return
        add = visualizer.add_sphere
        for p, c in zip(points, map(tuple, colours.tolist()), strict=True):
            add(center=p, radius=radius, color=c)

    def _debug_points(self, envs: list[int]) -> tuple[np.ndarray, np.ndarray]:
        """``(M, 3)`` hit points [m] of ``envs`` (at most ``debug_vis_max_points`` each,
        evenly spaced) and their ``(M, 4)`` class colours."""
        data = self.data
        points = data.hit_pos_w[envs].cpu().numpy()
        labels = data.semantic_labels[envs].cpu().numpy()
        hits = data.hit_mask[envs].cpu().numpy()
        limit = self.cfg.debug_vis_max_points
        chosen_p, chosen_l = [], []
        for k in range(len(envs)):
            idx = np.flatnonzero(hits[k])
            if idx.size > limit:
                idx = idx[np.linspace(0, idx.size - 1, limit).astype(np.int64)]
            chosen_p.append(points[k, idx])
            chosen_l.append(labels[k, idx])
        palette = np.asarray(CLASS_COLORS, dtype=np.float64)
        lab = np.concatenate(chosen_l) if chosen_l else np.zeros(0, np.int64)
        pts = np.concatenate(chosen_p) if chosen_p else np.zeros((0, 3))
        return pts, palette[lab % len(palette)]

    # The seed's getters (Isaac Lab style), so such observation code runs as written.
    def get_distances(self, env_ids: EnvIds = None) -> torch.Tensor:
        """``(E, N)`` ranges [m]; misses hold ``miss_distance`` (default ``max_distance``)."""
        data = self.data
        miss = torch.full((), self.resolved.miss_distance, device=data.distances.device)
        return _rows(torch.where(data.hit_mask, data.distances, miss), env_ids)

    def get_semantic_labels(self, env_ids: EnvIds = None) -> torch.Tensor:
        """``(E, N)`` int32 class ids (0 = miss/unknown)."""
        return _rows(self.data.semantic_labels, env_ids)

    def get_mesh_ids(self, env_ids: EnvIds = None) -> torch.Tensor:
        """``(E, N)`` int32 hit geom ids (-1 = miss)."""
        return _rows(self.data.geom_ids, env_ids)

    def get_hit_mask(self, env_ids: EnvIds = None) -> torch.Tensor:
        """``(E, N)`` bool, True where a ray returned a point."""
        return _rows(self.data.hit_mask, env_ids)

    @property
    def mesh_ids(self) -> torch.Tensor:
        """The seed's name of ``data.geom_ids``."""
        return self.data.geom_ids

    def get_pointcloud(
        self, env_ids: EnvIds = None, frame: Literal["world", "sensor"] = "world"
    ) -> torch.Tensor:
        """``(E, N, 3)`` hit points [m], NaN for misses (as the core sensor).

        Args:
            env_ids: environments (``None``: all).
            frame: ``"world"``, or ``"sensor"`` (the LiDAR's own frame, offset included).
        """
        if frame not in ("world", "sensor"):
            raise SensorError(f"get_pointcloud: frame must be 'world' or 'sensor', got {frame!r}")
        data = self.data
        points = _rows(data.hit_pos_w, env_ids)
        if frame == "sensor":
            rot = _rows(self._sensor_mat, env_ids)
            points = torch.einsum(
                "eji,enj->eni", rot, points - _rows(data.sensor_pos_w, env_ids)[:, None]
            )
        nan = torch.full((), float("nan"), device=points.device)
        return torch.where(_rows(data.hit_mask, env_ids)[..., None], points, nan)

    def classify_geom(self, geom_id: int) -> int:
        """Class id of a geom under this sensor's mapping (the robot's own class included)."""
        if (
            self.resolved.self_class_id
            and self.geom_semantic_class[geom_id] == self.resolved.self_class_id
        ):
            return self.resolved.self_class_id
        return classify_path(self.geom_paths[geom_id], self.resolved.mapping)
