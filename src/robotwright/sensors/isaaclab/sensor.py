"""``LidarSensor`` and ``SemanticLidarSensor``: Isaac Lab's Newton ray caster with per-ray
shape ids, robotwright patterns and classes.

The sensors subclass ``isaaclab_newton.sensors.NewtonRaycastSensor`` and keep its pose
tracking, drift, update timing and outputs (``ray_hits_w``, ``ray_distances``,
``ray_normals_w``, ``inf`` on a miss). What they replace is the cast itself
(``_launch_raycast``): per step,

1. ``pattern_window`` (windowed patterns only): each environment's window of the
   pattern table, chosen by its simulated time since reset;
2. Isaac Lab's ray transform (``_update_ray_infos``);
3. the nearest *seen* collision shape per ray: with ``pass_through="skip"`` (default)
   one cast whose walk of Newton's shape BVH leaves the see-through shapes out (outside
   ``mesh_prim_paths``, the carrier body, or the robot itself when ``self_class=None``;
   :mod:`._skip_cast`); with ``"recast"``, ``newton.intersect_ray`` with
   ``out_shape_id``, then the rays whose nearest shape is see-through re-cast just past
   it, only those rays, up to ``max_pass_through`` times;
4. ``finish_rays``: Isaac Lab's outputs plus the hit mask, shape ids and class ids.

Parts of the parent relied on (private in Isaac Lab, pinned by a test):
``_launch_raycast``, ``_update_ray_infos``, ``_initialize_rays_impl``,
``_ray_starts_w``, ``_ray_directions_w``, ``_ray_worlds``, ``_sensor_site_indices``,
``_is_outdated``, ``_timestamp``, ``backend``, and the data's ``_ray_hits_w``,
``_ray_distances``, ``_ray_normals_w``.
"""

from __future__ import annotations

import copy
import warnings
from collections.abc import Sequence
from typing import Any

import newton
import numpy as np
import torch
import warp as wp
from isaaclab.utils.math import matrix_from_quat
from isaaclab.utils.warp import ProxyArray
from isaaclab_newton.sensors import NewtonRaycastSensor, NewtonRaycastSensorData

from robotwright._rotations import quat_to_mat
from robotwright.errors import SensorError
from robotwright.sensors import learning_obs
from robotwright.sensors.isaaclab import _kernels as k
from robotwright.sensors.isaaclab._skip_cast import skip_cast_kernel
from robotwright.sensors.isaaclab.config import (
    LidarCfg,
    ResolvedLidarCfg,
    SemanticLidarCfg,
    resolve,
)
from robotwright.sensors.isaaclab.scene_shapes import SceneShapes, scene_shapes
from robotwright.sensors.patterns import PatternCfg
from robotwright.sensors.semantic import classify_path

__all__ = ["LidarSensor", "LidarSensorData", "SemanticLidarData", "SemanticLidarSensor"]

#: Casts between two looks at the count of hits lost to ``max_pass_through`` (each look
#: waits for the device once).
LOST_CHECK_EVERY = 100

EnvIds = torch.Tensor | Sequence[int] | slice | None


class LidarSensorData(NewtonRaycastSensorData):
    """Isaac Lab's Newton ray-cast data plus what the LiDAR knows per ray.

    Isaac Lab's fields keep Isaac Lab's meanings: ``ray_hits_w`` [m] and
    ``ray_distances`` [m] are ``inf`` on a miss, ``pos_w``/``quat_w`` are the carrier
    prim's pose (x, y, z, w; ``cfg.offset`` not applied). Like them, the fields below are
    ``ProxyArray`` (``.torch`` / ``.warp``).

    Attributes:
        hit_mask: ``(E, N)`` bool, True where the ray returned a point.
        shape_ids: ``(E, N)`` int32 Newton shape index of the hit, -1 on a miss.
        ray_directions_local: ``(E, N, 3)`` this step's ray directions in the sensor
            frame (``offset`` excluded): what a range image bins.
        frame: ``(E,)`` int32 index of each environment's pattern window.
    """

    def create_buffers(self, num_envs: int, num_rays: int, device: str) -> None:
        super().create_buffers(num_envs, num_rays, device)
        self._hit_mask = wp.zeros((num_envs, num_rays), dtype=wp.bool, device=device)
        self._shape_ids = wp.full((num_envs, num_rays), -1, dtype=wp.int32, device=device)
        self._labels = wp.zeros((num_envs, num_rays), dtype=wp.int32, device=device)
        self._local_dirs = wp.zeros((num_envs, num_rays), dtype=wp.vec3f, device=device)
        self._frame = wp.zeros(num_envs, dtype=wp.int32, device=device)
        self._hit_mask_ta = ProxyArray(self._hit_mask)
        self._shape_ids_ta = ProxyArray(self._shape_ids)
        self._labels_ta = ProxyArray(self._labels)
        self._local_dirs_ta = ProxyArray(self._local_dirs)
        self._frame_ta = ProxyArray(self._frame)

    @property
    def hit_mask(self) -> ProxyArray:
        return self._hit_mask_ta

    @property
    def shape_ids(self) -> ProxyArray:
        return self._shape_ids_ta

    @property
    def ray_directions_local(self) -> ProxyArray:
        return self._local_dirs_ta

    @property
    def frame(self) -> ProxyArray:
        return self._frame_ta


class SemanticLidarData(LidarSensorData):
    """:class:`LidarSensorData` plus the seed's semantic fields.

    Attributes:
        semantic_labels: ``(E, N)`` int32 class id per ray (0 = miss/unknown); ``None``
            when ``return_semantic_labels`` is False.
        mesh_ids: ``(E, N)`` int32 hit Newton shape index (-1 = miss); ``None`` unless
            ``return_mesh_ids``.
    """

    semantic_enabled: bool = True
    mesh_ids_enabled: bool = False

    @property
    def semantic_labels(self) -> ProxyArray | None:
        return self._labels_ta if self.semantic_enabled else None

    @property
    def mesh_ids(self) -> ProxyArray | None:
        return self._shape_ids_ta if self.mesh_ids_enabled else None


class _FirstFrame:
    """Hands the parent's ray initialisation frame 0 of a robotwright pattern table."""

    def __init__(self, starts: np.ndarray, dirs: np.ndarray) -> None:
        self._starts, self._dirs = starts, dirs

    def func(self, _cfg: Any, device: str) -> tuple[torch.Tensor, torch.Tensor]:
        return (
            torch.tensor(self._starts, dtype=torch.float32, device=device),
            torch.tensor(self._dirs, dtype=torch.float32, device=device),
        )


def _pattern_table(pattern: Any) -> tuple[np.ndarray, np.ndarray, int, float | None]:
    """Every ray of ``pattern`` in the sensor frame: starts, directions ``(F*N, 3)``,
    rays per frame ``N`` and the frame period [s] (``None`` for a repeating pattern)."""
    if isinstance(pattern, PatternCfg):
        table = pattern.ray_table()
        rate = pattern.firing_rate()
        period = None
        if table.num_frames > 1 and rate:
            period = table.rays_per_frame / rate
        return table.origins, table.directions, table.rays_per_frame, period
    starts, dirs = pattern.func(pattern, "cpu")
    starts = starts.detach().cpu().double().numpy()
    dirs = dirs.detach().cpu().double().numpy()
    return starts, dirs, int(dirs.shape[0]), None


def _rotate_xyzw(quat: Sequence[float], v: np.ndarray) -> np.ndarray:
    """Rotate rows of ``v`` by the quaternion (x, y, z, w), Isaac Lab's order."""
    x, y, z, w = quat
    return v @ quat_to_mat((w, x, y, z)).T


def _rows(tensor: torch.Tensor, env_ids: EnvIds) -> torch.Tensor:
    if env_ids is None:
        return tensor
    if isinstance(env_ids, slice):
        return tensor[env_ids]
    return tensor[torch.as_tensor(env_ids, device=tensor.device, dtype=torch.long)]


class LidarSensor(NewtonRaycastSensor):
    """A LiDAR in an Isaac Lab scene: distances, point cloud, per-ray shape ids.

    Attributes (after the scene starts):
        resolved: the checked config values (:class:`ResolvedLidarCfg`).
        shapes: the scene's collision shapes as this sensor sees them
            (:class:`~robotwright.sensors.isaaclab.scene_shapes.SceneShapes`).
        num_frames: windows in the pattern table (1 for a repeating pattern).
        frame_period: simulated time per window [s] (``None``: repeating pattern).
    """

    cfg: LidarCfg

    def __init__(self, cfg: LidarCfg) -> None:
        self.resolved: ResolvedLidarCfg = resolve(cfg)
        super().__init__(cfg)
        self._data = self._new_data()

    def _new_data(self) -> LidarSensorData:
        return LidarSensorData()

    @property
    def data(self) -> LidarSensorData:
        self._update_outdated_buffers()
        return self._data

    # -- initialisation ---------------------------------------------------------------
    def _initialize_impl(self) -> None:
        # Fields may have changed since construction (Isaac Lab and tyro allow it).
        self.resolved = resolve(self.cfg)
        global_world = not bool(self.cfg.global_world_only)
        self._skip_cast = None
        if self.cfg.pass_through == "skip":
            self._skip_cast = skip_cast_kernel(global_world)
            if self._skip_cast is None:
                warnings.warn(
                    f"{type(self.cfg).__name__}: this Newton lacks the ray-intersection "
                    "functions pass_through='skip' uses; re-casting past see-through "
                    "shapes instead (pass_through='recast')",
                    stacklevel=2,
                )
        recast = self._skip_cast is None
        if self.cfg.use_cuda_graph and recast and self.cfg.max_pass_through > 0:
            warnings.warn(
                f"{type(self.cfg).__name__}: use_cuda_graph=True needs pass_through='skip' "
                "or max_pass_through=0 (the re-cast loop reads its queue on the host); "
                "casting without a graph",
                stacklevel=2,
            )
            self.cfg.use_cuda_graph = False
        super()._initialize_impl()
        self._initialize_lidar()

    def _initialize_rays_impl(self) -> None:
        starts, dirs, n, period = _pattern_table(self.cfg.pattern_cfg)
        off_pos = np.asarray(self.cfg.offset.pos, dtype=np.float64)
        carrier_dirs = _rotate_xyzw(self.cfg.offset.rot, dirs)
        carrier_starts = _rotate_xyzw(self.cfg.offset.rot, starts) + off_pos
        cfg = self.cfg
        # The parent applies the offset to frame 0 itself: hand it the sensor-frame rays.
        swapped = copy.copy(cfg)
        swapped.pattern_cfg = _FirstFrame(starts[:n], dirs[:n])
        self.cfg = swapped
        try:
            super()._initialize_rays_impl()
        finally:
            self.cfg = cfg
        self.num_frames = starts.shape[0] // n
        self.frame_period = period
        dev = self._device
        self._table_starts = wp.array(carrier_starts.astype(np.float32), dtype=wp.vec3f, device=dev)
        self._table_dirs = wp.array(carrier_dirs.astype(np.float32), dtype=wp.vec3f, device=dev)
        self._table_local = wp.array(dirs.astype(np.float32), dtype=wp.vec3f, device=dev)
        self._bounds = learning_obs.direction_bounds(torch.as_tensor(dirs))
        first = np.broadcast_to(dirs[:n].astype(np.float32), (self._view_count, n, 3))
        wp.copy(
            self._data._local_dirs,
            wp.array(np.ascontiguousarray(first), dtype=wp.vec3f, device=dev),
        )

    def _initialize_lidar(self) -> None:
        model = self.backend.model
        dev = self._device
        site_shapes = self._sensor_site_indices.numpy()
        carriers = model.shape_body.numpy()[site_shapes]
        self.shapes: SceneShapes = scene_shapes(
            model, carriers, self.resolved, self.cfg.exclude_parent_body, self._classify
        )
        e, n = self._view_count, self.num_rays
        count = e * n
        self._shape_visible = wp.array(
            self.shapes.visible.astype(np.int32), dtype=wp.int32, device=dev
        )
        self._shape_class = wp.array(
            self.shapes.classes.astype(np.int32), dtype=wp.int32, device=dev
        )
        self._total = wp.empty(count, dtype=wp.float32, device=dev)
        self._final_shape = wp.empty(count, dtype=wp.int32, device=dev)
        self._final_normal = wp.empty(count, dtype=wp.vec3f, device=dev)
        # Hits lost when max_pass_through runs out, summed on the device since the
        # start; read on the host only every LOST_CHECK_EVERY casts (one warning).
        self._lost = wp.zeros(1, dtype=wp.int32, device=dev)
        self._casts = 0
        self._lost_warned = False
        if self._skip_cast is None:  # the re-casts' queues and sub-casts, ~50 B a ray
            self._hit_shape = wp.empty(count, dtype=wp.int32, device=dev)
            self._pending = [wp.empty(count, dtype=wp.int32, device=dev) for _ in range(2)]
            self._pending_count = [wp.zeros(1, dtype=wp.int32, device=dev) for _ in range(2)]
            self._sub = {
                "starts": wp.empty(count, dtype=wp.vec3f, device=dev),
                "dirs": wp.empty(count, dtype=wp.vec3f, device=dev),
                "worlds": wp.empty(count, dtype=wp.int32, device=dev),
                "dist": wp.empty(count, dtype=wp.float32, device=dev),
                "shape": wp.empty(count, dtype=wp.int32, device=dev),
                "normal": wp.empty(count, dtype=wp.vec3f, device=dev),
            }
        self._warn_scene()

    def _classify(self, path: str) -> int:
        """Class of a shape path; the plain LiDAR has no classes."""
        return 0

    @property
    def lost_pass_through_hits(self) -> int:
        """Rays, summed over every cast since the sensor started, that were still behind
        see-through shapes (the carrier, the robot, shapes outside ``mesh_prim_paths``)
        when ``max_pass_through`` ran out, and so read as misses. Reading it waits for the
        device."""
        return int(self._lost.numpy()[0])

    def _check_lost(self) -> None:
        """Warn once, naming the count, when hits were lost to ``max_pass_through``;
        looks every :data:`LOST_CHECK_EVERY` casts (a host read)."""
        self._casts += 1
        if self._lost_warned or (self._casts - 1) % LOST_CHECK_EVERY:
            return
        lost = self.lost_pass_through_hits
        if lost:
            self._lost_warned = True
            rays = self._casts * self._view_count * self.num_rays
            warnings.warn(
                f"{type(self.cfg).__name__}: {lost} of {rays} rays ({100 * lost / rays:.2g}%) "
                f"were still behind see-through shapes after max_pass_through="
                f"{self.cfg.max_pass_through} passes and read as misses; raise "
                "max_pass_through, or mount the sensor outside the robot "
                "(sensor.lost_pass_through_hits counts them)",
                stacklevel=3,
            )

    def _warn_scene(self) -> None:
        """Say what would otherwise go unnoticed: a pattern matching no shape."""
        for entry in self.shapes.unmatched_patterns:
            warnings.warn(
                f"{type(self.cfg).__name__}.mesh_prim_paths entry {entry!r} matches no "
                "collision shape of the scene (rays pass through what it was meant to name)",
                stacklevel=3,
            )
        if self.resolved.mesh_patterns and not self.shapes.visible.any():
            warnings.warn(
                f"{type(self.cfg).__name__}.mesh_prim_paths={self.cfg.mesh_prim_paths!r} match "
                "no collision shape of the scene: every ray will miss",
                stacklevel=3,
            )

    # -- the cast ---------------------------------------------------------------------
    def _launch_raycast(self) -> None:
        e, n = self._view_count, self.num_rays
        dev = self._device
        data = self._data
        if self.frame_period is not None:
            wp.launch(
                k.pattern_window,
                dim=(e, n),
                inputs=[
                    self._is_outdated,
                    self._timestamp,
                    float(self.frame_period),
                    int(self.num_frames),
                    self._table_starts,
                    self._table_dirs,
                    self._table_local,
                ],
                outputs=[
                    self.ray_starts.warp,
                    self.ray_directions.warp,
                    data._local_dirs,
                    data._frame,
                ],
                device=dev,
            )
        self._update_ray_infos(self._is_outdated)
        if self._skip_cast is not None:
            self._cast_skipping()
        else:
            self._cast_recasting()
        self._finish()

    def _cast_skipping(self) -> None:
        """One cast that leaves the see-through shapes out of its BVH walk."""
        model = self.backend.model
        wp.launch(
            self._skip_cast,
            dim=self._view_count * self.num_rays,
            inputs=[
                model.bvh_shapes.id,
                model.bvh_shapes_group_roots,
                model.bvh_shape_enabled,
                model.bvh_shape_world_transforms,
                model.shape_type,
                model.shape_scale,
                model.shape_source_ptr,
                self._shape_visible,
                self._is_outdated,
                self.num_rays,
                self._ray_starts_w_flat,
                self._ray_directions_w_flat,
                self._ray_worlds,
                float(self.cfg.max_distance),
            ],
            outputs=[self._total, self._final_shape, self._final_normal],
            device=self._device,
        )

    def _cast_recasting(self) -> None:
        """The stock cast, then re-casts past see-through shapes (host reads per pass)."""
        e, n = self._view_count, self.num_rays
        dev, model = self._device, self.backend.model
        global_world = not bool(self.cfg.global_world_only)
        newton.intersect_ray(
            model,
            ray_origins=self._ray_starts_w_flat,
            ray_directions=self._ray_directions_w_flat,
            ray_worlds=self._ray_worlds,
            enable_global_world=global_world,
            out_dist=self._hit_dist,
            out_shape_id=self._hit_shape,
            out_normal=self._hit_normal,
        )
        max_d = float(self.cfg.max_distance)
        queue, nxt = 0, 1
        self._pending_count[queue].zero_()
        wp.launch(
            k.first_pass,
            dim=e * n,
            inputs=[
                self._is_outdated,
                self._hit_dist,
                self._hit_shape,
                self._hit_normal,
                self._shape_visible,
                max_d,
                n,
            ],
            outputs=[
                self._total,
                self._final_shape,
                self._final_normal,
                self._pending[queue],
                self._pending_count[queue],
            ],
            device=dev,
        )
        passes = int(self.cfg.max_pass_through)
        sub = self._sub
        for p in range(passes):
            m = int(self._pending_count[queue].numpy()[0])
            if m == 0:
                break
            wp.launch(
                k.gather_pending,
                dim=m,
                inputs=[
                    self._pending[queue],
                    self._total,
                    self._ray_starts_w_flat,
                    self._ray_directions_w_flat,
                    self._ray_worlds,
                ],
                outputs=[sub["starts"], sub["dirs"], sub["worlds"]],
                device=dev,
            )
            newton.intersect_ray(
                model,
                ray_origins=sub["starts"][:m],
                ray_directions=sub["dirs"][:m],
                ray_worlds=sub["worlds"][:m],
                enable_global_world=global_world,
                out_dist=sub["dist"][:m],
                out_shape_id=sub["shape"][:m],
                out_normal=sub["normal"][:m],
            )
            self._pending_count[nxt].zero_()
            wp.launch(
                k.scatter_pass,
                dim=m,
                inputs=[
                    self._pending[queue],
                    sub["dist"],
                    sub["shape"],
                    sub["normal"],
                    self._shape_visible,
                    max_d,
                    int(p == passes - 1),
                ],
                outputs=[
                    self._total,
                    self._final_shape,
                    self._final_normal,
                    self._pending[nxt],
                    self._pending_count[nxt],
                    self._lost,
                ],
                device=dev,
            )
            queue, nxt = nxt, queue
        if passes == 0:  # every ray queued by the first pass is a lost hit
            wp.launch(k.add_count, dim=1, inputs=[self._pending_count[0], self._lost], device=dev)
        self._check_lost()  # only re-casts can lose hits

    def _finish(self) -> None:
        """Isaac Lab's outputs and ours from the final hits."""
        e, n, data = self._view_count, self.num_rays, self._data
        wp.launch(
            k.finish_rays,
            dim=(e, n),
            inputs=[
                self._is_outdated,
                self._ray_starts_w,
                self._ray_directions_w,
                self._total,
                self._final_shape,
                self._final_normal,
                self._shape_class,
                float(self.cfg.min_distance),
                float(self.cfg.max_distance),
                self.ray_cast_drift.warp,
            ],
            outputs=[
                data._ray_hits_w,
                data._ray_distances,
                data._ray_normals_w,
                data._hit_mask,
                data._shape_ids,
                data._labels,
            ],
            device=self._device,
        )

    def direction_bounds(self) -> tuple[float, float, float, float, bool]:
        """Azimuth and elevation bounds [rad] of every ray of the pattern (all windows),
        in the sensor frame, as :func:`~robotwright.sensors.learning_obs.direction_bounds`."""
        return self._bounds

    # -- the seed's getters -----------------------------------------------------------
    def get_distances(self, env_ids: EnvIds = None) -> torch.Tensor:
        """``(E, N)`` ranges [m]; misses hold ``miss_distance`` (default ``max_distance``),
        where ``data.ray_distances`` holds Isaac Lab's ``inf``."""
        data = self.data
        dist = data.ray_distances.torch
        miss = torch.full((), self.resolved.miss_distance, device=dist.device)
        return _rows(torch.where(data.hit_mask.torch, dist, miss), env_ids)

    def get_pointcloud(self, env_ids: EnvIds = None) -> torch.Tensor:
        """``(E, N, 3)`` hit points in the world frame [m]; ``inf`` on a miss (Isaac
        Lab's ``ray_hits_w``, ray-cast drift included)."""
        return _rows(self.data.ray_hits_w.torch, env_ids)

    def get_hit_mask(self, env_ids: EnvIds = None) -> torch.Tensor:
        """``(E, N)`` bool, True where a ray returned a point."""
        return _rows(self.data.hit_mask.torch, env_ids)

    def sensor_pose_w(self) -> tuple[torch.Tensor, torch.Tensor]:
        """The LiDAR's own pose (carrier pose with ``cfg.offset``): positions ``(E, 3)``
        [m] and rotation matrices ``(E, 3, 3)`` (columns: sensor axes in the world)."""
        data = self.data
        carrier_rot = matrix_from_quat(data.quat_w.torch)
        off_pos = torch.tensor(self.cfg.offset.pos, dtype=torch.float32, device=carrier_rot.device)
        off_rot = matrix_from_quat(
            torch.tensor(self.cfg.offset.rot, dtype=torch.float32, device=carrier_rot.device)[None]
        )[0]
        return data.pos_w.torch + carrier_rot @ off_pos, carrier_rot @ off_rot

    def carrier_pose_w(self) -> tuple[torch.Tensor, torch.Tensor]:
        """The carrier prim's pose: positions ``(E, 3)`` [m], rotations ``(E, 3, 3)``."""
        data = self.data
        return data.pos_w.torch, matrix_from_quat(data.quat_w.torch)


class SemanticLidarSensor(LidarSensor):
    """:class:`LidarSensor` with a class per ray from keywords in the hit shape's path.

    Attributes (after the scene starts):
        semantic_class_mapping: class -> keywords (the config's, or the default).
        class_names: ``("unknown", *classes[, terrain][, robot])``, indexed by class id.
        mesh_id_to_semantic_class: Newton shape index -> class id, for every shape the
            rays can see.
    """

    cfg: SemanticLidarCfg

    def _new_data(self) -> SemanticLidarData:
        data = SemanticLidarData()
        data.semantic_enabled = bool(self.cfg.return_semantic_labels)
        data.mesh_ids_enabled = bool(self.cfg.return_mesh_ids)
        return data

    @property
    def data(self) -> SemanticLidarData:
        self._update_outdated_buffers()
        return self._data  # type: ignore[return-value]

    @property
    def semantic_class_mapping(self) -> dict[str, list[str]]:
        return self.resolved.mapping

    @property
    def class_names(self) -> tuple[str, ...]:
        return self.resolved.class_names

    def _initialize_lidar(self) -> None:
        self._data.semantic_enabled = bool(self.cfg.return_semantic_labels)  # type: ignore[attr-defined]
        self._data.mesh_ids_enabled = bool(self.cfg.return_mesh_ids)  # type: ignore[attr-defined]
        super()._initialize_lidar()
        self.mesh_id_to_semantic_class: dict[int, int] = {
            int(s): int(self.shapes.classes[s]) for s in np.flatnonzero(self.shapes.visible)
        }

    def _initialize_warp_meshes(self) -> None:
        """The seed's hook: rays are cast on Newton's shape BVH, so there are no warp
        meshes to load; the shape -> class table is built when the scene starts."""

    def _classify_mesh_path(self, mesh_prim_path: str) -> int:
        """The seed's rule: the first class (mapping order, ids from 1) one of whose
        keywords occurs case-insensitively in ``mesh_prim_path``; 0 when none does."""
        return classify_path(mesh_prim_path, self.resolved.mapping)

    def _classify(self, path: str) -> int:
        return self._classify_mesh_path(path)

    def _warn_scene(self) -> None:
        super()._warn_scene()
        unknown = [
            self.shapes.labels[s]
            for s in np.flatnonzero(self.shapes.visible)
            if self.shapes.classes[s] == 0
        ]
        if unknown:
            warnings.warn(
                f"{type(self.cfg).__name__}: {len(unknown)} collision shapes the rays can see "
                f"match no class of semantic_class_mapping and read 0 (e.g. {unknown[0]})",
                stacklevel=3,
            )

    def get_semantic_labels(self, env_ids: EnvIds = None) -> torch.Tensor:
        """``(E, N)`` int32 class ids (0 = miss/unknown)."""
        labels = self.data.semantic_labels
        if labels is None:
            raise SensorError(
                f"{type(self.cfg).__name__}.return_semantic_labels is False: no labels"
            )
        return _rows(labels.torch, env_ids)

    def get_mesh_ids(self, env_ids: EnvIds = None) -> torch.Tensor:
        """``(E, N)`` int32 hit Newton shape indices (-1 = miss); needs ``return_mesh_ids``."""
        ids = self.data.mesh_ids
        if ids is None:
            raise SensorError(
                f"{type(self.cfg).__name__}.return_mesh_ids is False: set it to True to get "
                "mesh ids"
            )
        return _rows(ids.torch, env_ids)
