"""The semantic LiDAR as an mjlab ``RayCastSensor`` whose data is a ``RayCastData``.

The sensor *is* an mjlab ``RayCastSensor``, so the scene wires it to the shared
``SensorContext`` (one BVH for every ray sensor and camera) and casts inside mjlab's sense
graph (a CUDA graph on GPU). Inside that graph, per step, it launches robotwright's
kernels around mjlab's ray cast: ``advance_frame`` (the pattern window, counter on the
device), ``sensor_pose`` (sensor and carrier frame poses), ``world_rays`` (the window of
the pattern table), MuJoCo Warp ``rays`` (the call of mjlab's ``RayCastSensor`` with its
arguments: BVH, parent-body exclusion, geom-group filter), ``finish_rays`` (float64
refinement of curved hits, range model, labels, points) and ``mjlab_misses`` (mjlab's
miss values); on warp's CPU device the last four run in column blocks on parallel
threads. Nothing runs on the host per step and nothing is copied: mjlab's
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
    """mjlab's pattern protocol over frame 0 of our table (mjlab sizes its buffers from it)."""

    def __init__(self, table: RayTable) -> None:
        self.table = table

    def generate_rays(self, mj_model: Any, device: str) -> tuple[torch.Tensor, torch.Tensor]:
        o, d = self.table.window(0)
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
        frame: ``(1,)`` int32 index of the last cast pattern frame (0 for the first).
    """

    hit_mask: torch.Tensor
    semantic_labels: torch.Tensor
    geom_ids: torch.Tensor
    ray_origins_w: torch.Tensor
    ray_directions_w: torch.Tensor
    sensor_pos_w: torch.Tensor
    sensor_quat_w: torch.Tensor
    frame: torch.Tensor

    @property
    def mesh_ids(self) -> torch.Tensor:
        """The seed's name of :attr:`geom_ids`."""
        return self.geom_ids


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
        # mjlab's own initialisation resolves the frame and sizes its ray buffers from
        # cfg.pattern: hand it frame 0 of the table, then restore the user's config.
        mjlab_cfg = copy.copy(cfg)
        mjlab_cfg.pattern = _TablePattern(self.table)
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
        seeds = np.random.SeedSequence(cfg.seed).generate_state(e).astype(np.uint32)
        dev = self._wp_device
        # Load the kernels now: mjlab captures its sense graph later, and no module may
        # be compiled or loaded during a CUDA graph capture.
        wp.load_module(kernels, device=dev)
        wp.load_module(mjlab_kernels, device=dev)
        with wp.ScopedDevice(dev):
            b = {
                "table_o": wp.array(self.table.origins.astype(np.float32), dtype=wp.vec3),
                "table_d": wp.array(self.table.directions.astype(np.float32), dtype=wp.vec3),
                "lut": wp.array(lut, dtype=wp.int32),
                "geom_type": wp.array(mj_model.geom_type.astype(np.int32), dtype=wp.int32),
                "geom_size": wp.array(mj_model.geom_size, dtype=wp.vec3d),
                "env_seed": wp.array(seeds.view(np.int32), dtype=wp.int32),
                "frame": wp.array(np.array([-1], dtype=np.int32), dtype=wp.int32),
                "window": wp.zeros(1, dtype=wp.int32),
                "pos_w": wp.zeros(e, dtype=wp.vec3),
                "quat_w": wp.zeros(e, dtype=wp.vec4),
                "sensor_mat": wp.zeros(e, dtype=wp.mat33),
                "ray_rot": wp.zeros(e, dtype=wp.mat33),
                "frame_pos": wp.zeros(e, dtype=wp.vec3),
                "frame_quat": wp.zeros(e, dtype=wp.vec4),
                "frame_mat": wp.zeros(e, dtype=wp.mat33),
                "frame_rot": wp.zeros(e, dtype=wp.mat33),
                "distances": wp.full((e, n), -1.0, dtype=wp.float32),
                "hit_mask": wp.zeros((e, n), dtype=wp.bool),
                "geom_ids": wp.full((e, n), -1, dtype=wp.int32),
                "labels": wp.zeros((e, n), dtype=wp.int32),
                "points": wp.zeros((e, n), dtype=wp.vec3),
            }
        rot = np.empty(9)
        mujoco.mju_quat2Mat(rot, np.asarray(res.offset_rot, dtype=np.float64))
        self._offset_pos = wp.vec3(*np.asarray(res.offset_pos, dtype=np.float32))
        self._offset_mat = wp.mat33(*rot.astype(np.float32))
        self._zero_pos = wp.vec3(0.0, 0.0, 0.0)
        self._identity = wp.mat33(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
        self._buffers = b
        self._blocks = ray_blocks(n, dev, cfg.num_threads)
        self._pool = ThreadPoolExecutor(len(self._blocks)) if len(self._blocks) > 1 else None
        t = wp.to_torch
        frame_pos, frame_quat = t(b["frame_pos"]), t(b["frame_quat"])
        self._lidar_data = MjlabSemanticLidarData(
            distances=t(b["distances"]),
            normals_w=t(self._ray_normal),
            hit_pos_w=t(b["points"]),
            pos_w=frame_pos,
            quat_w=frame_quat,
            frame_pos_w=frame_pos.view(e, 1, 3),
            frame_quat_w=frame_quat.view(e, 1, 4),
            hit_mask=t(b["hit_mask"]),
            semantic_labels=t(b["labels"]),
            geom_ids=t(b["geom_ids"]),
            ray_origins_w=t(self._ray_pnt),
            ray_directions_w=t(self._ray_vec),
            sensor_pos_w=t(b["pos_w"]),
            sensor_quat_w=t(b["quat_w"]),
            frame=t(b["frame"]),
        )
        self._sensor_mat = t(b["sensor_mat"])
        self._ray_rot = t(b["ray_rot"])
        self._frame_mat = t(b["frame_mat"])
        self._obs_cache: dict[Any, Any] = {}

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
        """Nothing to do on the host: the world rays are made in the graph."""

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
        wp.launch(
            kernels.advance_frame,
            dim=1,
            inputs=[b["frame"], self.table.num_frames, n],
            outputs=[b["window"]],
            device=dev,
        )
        align = _ALIGN[cfg.ray_alignment]
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
        if self._pool is None:
            self._cast_block(rc, 0, n)
        else:
            list(self._pool.map(lambda ab: self._cast_block(rc, *ab), self._blocks))

    def _cast_block(self, rc: Any, a: int, b_: int) -> None:
        """World rays, mjlab's cast and finishing of the rays ``[a, b_)`` of every env."""
        b, cfg = self._buffers, self.cfg
        d = self._data.struct
        e, dev = int(d.nworld), self._wp_device
        whole = (a, b_) == (0, int(self.table.rays_per_frame))

        def cols(array: Any) -> Any:
            return array if whole else array[:, a:b_]

        pnt, vec = cols(self._ray_pnt), cols(self._ray_vec)
        dist, geomid = cols(self._ray_dist), cols(self._ray_geomid)
        wp.launch(
            kernels.world_rays,
            dim=(e, b_ - a),
            inputs=[b["table_o"], b["table_d"], b["window"], a, b["pos_w"], b["ray_rot"]],
            outputs=[pnt, vec],
            device=dev,
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
        wp.launch(
            kernels.finish_rays,
            dim=(e, b_ - a),
            inputs=[
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
                -1.0,  # mjlab's miss value; get_distances() applies miss_distance
                b["env_seed"],
                b["frame"],
                b["lut"],
                a,
            ],
            outputs=[
                cols(b["distances"]),
                cols(b["hit_mask"]),
                cols(b["geom_ids"]),
                cols(b["labels"]),
                cols(b["points"]),
            ],
            device=dev,
        )
        wp.launch(
            mjlab_kernels.mjlab_misses,
            dim=(e, b_ - a),
            inputs=[cols(b["hit_mask"]), pnt],
            outputs=[cols(b["points"]), cols(self._ray_normal)],
            device=dev,
        )

    def postprocess_rays(self) -> None:
        """Fresh results: drop data cached before this step's cast (nothing per ray)."""
        self._invalidate_cache()

    def _compute_data(self) -> MjlabSemanticLidarData:  # type: ignore[override]
        if not self._buffers:
            raise SensorError(f"{self.cfg.name}: the sensor is not initialised (no scene yet)")
        return self._lidar_data

    def debug_vis(self, visualizer: Any) -> None:
        """Hit points coloured by class (:data:`CLASS_COLORS`), at most
        ``debug_vis_max_points`` evenly spaced hits per drawn environment."""
        if not self.cfg.debug_vis or not self._debug_vis_enabled or not self._buffers:
            return
        data = self.data
        envs = list(visualizer.get_env_indices(data.distances.shape[0]))
        if not envs:
            return
        points = data.hit_pos_w[envs].cpu().numpy()
        labels = data.semantic_labels[envs].cpu().numpy()
        hits = data.hit_mask[envs].cpu().numpy()
        radius = 0.2 * float(visualizer.meansize)
        limit = self.cfg.debug_vis_max_points
        name = self.cfg.name
        for k, env in enumerate(envs):
            idx = np.flatnonzero(hits[k])
            if idx.size > limit:
                idx = idx[np.linspace(0, idx.size - 1, limit).astype(np.int64)]
            for i in idx:
                visualizer.add_sphere(
                    center=points[k, i],
                    radius=radius,
                    color=CLASS_COLORS[int(labels[k, i]) % len(CLASS_COLORS)],
                    label=f"{name}_hit_{env}_{i}",
                )

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
