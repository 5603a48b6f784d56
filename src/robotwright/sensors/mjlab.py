"""The semantic LiDAR as an mjlab sensor, with observation terms (``robotwright[mjlab]``).

:class:`SemanticLidarSensorCfg` goes into ``SceneCfg.sensors`` like mjlab's own
``RayCastSensorCfg``; the sensor it builds *is* an mjlab ``RayCastSensor``, so the scene
wires it to the shared ``SensorContext`` (one BVH for every ray sensor and camera) and
casts inside mjlab's sense graph (a CUDA graph on GPU). Inside that graph, per step, it
launches robotwright's kernels around mjlab's ray cast: ``advance_frame`` (the pattern
window, counter on the device), ``sensor_pose``, ``world_rays`` (the window of the
pattern table), MuJoCo Warp ``rays`` (mjlab's own call, its body exclusion and geom
groups), then ``finish_rays`` (float64 refinement of curved hits, range model, labels,
points). Nothing runs on the host per step and nothing is copied.

``env.scene["lidar"].data`` is a :class:`MjlabSemanticLidarData` of torch tensors on the
environment's device, views of the device buffers (the same tensors every step):
``distances`` and ``semantic_labels``/``geom_ids`` ``(num_envs, num_rays)``,
``hit_pos_w`` ``(num_envs, num_rays, 3)`` world frame [m] (NaN for misses), ``hit_mask``.

Which geoms rays see: mjlab's ``include_geom_groups`` (default ``(0,)``: in mjlab's
assets terrain and props sit in group 0 and robot collision/visual geoms in groups 2-3,
so the robot does not see itself) plus ``exclude_parent_body``.

This module imports mjlab; ``robotwright.sensors`` never imports it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np
import torch
import warp as wp
from mjlab.sensor.builtin_sensor import ObjRef
from mjlab.sensor.raycast_sensor import RayCastSensor, RayCastSensorCfg

from robotwright.errors import SensorError
from robotwright.sensors import _warp_kernels as kernels
from robotwright.sensors.config import DEFAULT_SEMANTIC_CLASS_MAPPING
from robotwright.sensors.lidar import geom_paths
from robotwright.sensors.patterns import LivoxPatternCfg, PatternCfg, RayTable
from robotwright.sensors.semantic import geom_class_table

__all__ = [
    "MjlabSemanticLidarData",
    "MjlabSemanticLidarSensor",
    "SemanticLidarSensorCfg",
    "lidar_class_ids",
    "lidar_distances_normalized",
    "lidar_one_hot_classes",
    "lidar_semantic_obs",
]

_ALIGN = {"base": kernels.ALIGN_BASE, "yaw": kernels.ALIGN_YAW, "world": kernels.ALIGN_WORLD}


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


@dataclass(kw_only=True)
class SemanticLidarSensorCfg(RayCastSensorCfg):
    """mjlab config of a semantic LiDAR (seed 004 fields on mjlab's ray-cast sensor).

    Attributes:
        name: the sensor's key in ``env.scene``.
        frame: the body or site carrying the sensor (one ``ObjRef``, e.g.
            ``ObjRef(type="body", name="trunk", entity="robot")``).
        lidar_pattern: any robotwright pattern (Livox Mid-360/Avia rosettes advance one
            window per step; spinning, grid, pinhole, file patterns repeat).
        semantic_class_mapping: class -> keywords matched case-insensitively in geom paths
            (``/world/<bodies>/<geom>[/<mesh>]``); ``None``: the seed's default mapping.
        min_distance, max_distance: readings outside are misses [m].
        range_noise_std: Gaussian range noise on hits [m]; dropout_prob: drop probability.
        seed: base seed of the per-environment noise streams.
        miss_distance: distance of a miss; ``None``: ``max_distance``.
        ray_alignment, exclude_parent_body, include_geom_groups: as mjlab's
            ``RayCastSensorCfg`` (default groups ``(0,)``: terrain and props).
    """

    frame: ObjRef
    lidar_pattern: PatternCfg = field(default_factory=LivoxPatternCfg)
    semantic_class_mapping: dict[str, list[str]] | None = None
    min_distance: float = 0.0
    max_distance: float = 40.0
    range_noise_std: float = 0.0
    dropout_prob: float = 0.0
    seed: int = 0
    miss_distance: float | None = None
    include_geom_groups: tuple[int, ...] | None = (0,)

    def __post_init__(self) -> None:
        if not isinstance(self.frame, ObjRef) or self.frame.type not in ("body", "site"):
            raise SensorError(
                f"SemanticLidarSensorCfg.frame: expected one ObjRef of a body or site, got {self.frame!r}"
            )
        if not isinstance(self.lidar_pattern, PatternCfg):
            raise SensorError(
                "SemanticLidarSensorCfg.lidar_pattern: expected a robotwright PatternCfg, "
                f"got {type(self.lidar_pattern).__name__}"
            )
        if not 0.0 <= self.min_distance < self.max_distance:
            raise SensorError(
                "SemanticLidarSensorCfg: expected 0 <= min_distance < max_distance, got "
                f"{self.min_distance}, {self.max_distance}"
            )
        if self.range_noise_std < 0 or not 0.0 <= self.dropout_prob <= 1.0:
            raise SensorError(
                "SemanticLidarSensorCfg: expected range_noise_std >= 0 and dropout_prob in [0, 1]"
            )
        if self.semantic_class_mapping is None:
            self.semantic_class_mapping = {
                k: list(v) for k, v in DEFAULT_SEMANTIC_CLASS_MAPPING.items()
            }
        if self.miss_distance is None:
            self.miss_distance = float(self.max_distance)

    def build(self) -> MjlabSemanticLidarSensor:
        return MjlabSemanticLidarSensor(self)


@dataclass
class MjlabSemanticLidarData:
    """Torch views of the device buffers (``E`` envs, ``N`` rays); see the module docstring.

    Attributes:
        distances: ``(E, N)`` float32 range [m]; misses hold ``miss_distance``.
        hit_mask: ``(E, N)`` bool.
        semantic_labels: ``(E, N)`` int32 class id (1..K in mapping order, 0 miss/unknown).
        geom_ids: ``(E, N)`` int32 MuJoCo geom id of the hit, -1 on a miss.
        hit_pos_w: ``(E, N, 3)`` float32 world-frame hit points [m], NaN on a miss.
        ray_directions_w: ``(E, N, 3)`` unit world directions of this step's rays.
        pos_w: ``(E, 3)`` sensor position [m]; quat_w: ``(E, 4)`` orientation (w, x, y, z).
    """

    distances: torch.Tensor
    hit_mask: torch.Tensor
    semantic_labels: torch.Tensor
    geom_ids: torch.Tensor
    hit_pos_w: torch.Tensor
    ray_directions_w: torch.Tensor
    pos_w: torch.Tensor
    quat_w: torch.Tensor


class MjlabSemanticLidarSensor(RayCastSensor):
    """mjlab ``RayCastSensor`` whose rays follow a robotwright pattern and carry labels."""

    cfg: SemanticLidarSensorCfg

    def __init__(self, cfg: SemanticLidarSensorCfg) -> None:
        self.table = cfg.lidar_pattern.ray_table()
        # mjlab's own initialisation sizes its ray buffers from cfg.pattern.
        super().__init__(dataclasses.replace(cfg, pattern=_TablePattern(self.table)))
        self.semantic_class_mapping = dict(cfg.semantic_class_mapping or {})
        self.class_names: tuple[str, ...] = ("unknown", *self.semantic_class_mapping)
        self._buffers: dict[str, Any] = {}

    def initialize(self, mj_model: mujoco.MjModel, model: Any, data: Any, device: str) -> None:
        super().initialize(mj_model, model, data, device)
        cfg = self.cfg
        kind, obj, _ = self._frame_infos[0]
        if self._num_frames != 1 or kind not in ("body", "site"):
            raise SensorError(f"{cfg.name}: expected one body or site frame")
        self._carrier = obj
        self._kind = kind
        self.geom_paths = geom_paths(mj_model)
        lut = geom_class_table(self.geom_paths, self.semantic_class_mapping)
        self.geom_semantic_class = lut[:-1]
        e, n = int(data.nworld), int(self.table.rays_per_frame)
        seeds = np.random.SeedSequence(cfg.seed).generate_state(e).astype(np.uint32)
        with wp.ScopedDevice(self._wp_device):
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
                "distances": wp.full((e, n), float(cfg.miss_distance), dtype=wp.float32),
                "hit_mask": wp.zeros((e, n), dtype=wp.bool),
                "geom_ids": wp.full((e, n), -1, dtype=wp.int32),
                "labels": wp.zeros((e, n), dtype=wp.int32),
                "points": wp.full((e, n), wp.vec3(np.nan, np.nan, np.nan), dtype=wp.vec3),
            }
        self._buffers = b
        t = wp.to_torch
        self._lidar_data = MjlabSemanticLidarData(
            distances=t(b["distances"]),
            hit_mask=t(b["hit_mask"]),
            semantic_labels=t(b["labels"]),
            geom_ids=t(b["geom_ids"]),
            hit_pos_w=t(b["points"]),
            ray_directions_w=t(self._ray_vec),
            pos_w=t(b["pos_w"]),
            quat_w=t(b["quat_w"]),
        )

    # mjlab's pipeline: prepare (host, before the graph) -> raycast_kernel (in the graph)
    # -> postprocess (host, after). Everything per ray happens in the graph.
    def prepare_rays(self) -> None:
        """Nothing to do on the host: the world rays are made in the graph."""

    def raycast_kernel(self, rc: Any) -> None:
        """IN-GRAPH: pattern window, sensor pose, world rays, mjlab's cast, labels."""
        b, cfg = self._buffers, self.cfg
        d = self._data.struct
        e, n = int(d.nworld), int(self.table.rays_per_frame)
        cpos, cmat = (d.xpos, d.xmat) if self._kind == "body" else (d.site_xpos, d.site_xmat)
        dev = self._wp_device
        wp.launch(
            kernels.advance_frame,
            dim=1,
            inputs=[b["frame"], self.table.num_frames, n],
            outputs=[b["window"]],
            device=dev,
        )
        wp.launch(
            kernels.sensor_pose,
            dim=e,
            inputs=[
                cpos,
                cmat,
                self._carrier,
                wp.vec3(0.0, 0.0, 0.0),
                wp.mat33(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
                _ALIGN[cfg.ray_alignment],
            ],
            outputs=[b["pos_w"], b["quat_w"], b["sensor_mat"], b["ray_rot"]],
            device=dev,
        )
        wp.launch(
            kernels.world_rays,
            dim=(e, n),
            inputs=[b["table_o"], b["table_d"], b["window"], 0, b["pos_w"], b["ray_rot"]],
            outputs=[self._ray_pnt, self._ray_vec],
            device=dev,
        )
        super().raycast_kernel(rc)
        wp.launch(
            kernels.finish_rays,
            dim=(e, n),
            inputs=[
                self._ray_dist,
                self._ray_geomid,
                self._ray_pnt,
                self._ray_vec,
                d.geom_xpos,
                d.geom_xmat,
                b["geom_type"],
                b["geom_size"],
                1,
                float(cfg.min_distance),
                float(cfg.max_distance),
                float(cfg.range_noise_std),
                float(cfg.dropout_prob),
                float(cfg.miss_distance),
                b["env_seed"],
                b["frame"],
                b["lut"],
                0,
            ],
            outputs=[b["distances"], b["hit_mask"], b["geom_ids"], b["labels"], b["points"]],
            device=dev,
        )

    def postprocess_rays(self) -> None:
        """Fresh results: drop data cached before this step's cast."""
        self._invalidate_cache()

    def _compute_data(self) -> MjlabSemanticLidarData:  # type: ignore[override]
        return self._lidar_data

    def debug_vis(self, visualizer: Any) -> None:
        """No ray drawing (mjlab's would loop over every ray on the host)."""


# ---------------------------------------------------------------------- observations
def _sensor(env: Any, sensor_name: str) -> MjlabSemanticLidarSensor:
    sensor = env.scene[sensor_name]
    if not isinstance(sensor, MjlabSemanticLidarSensor):
        raise SensorError(f"{sensor_name!r} is not a robotwright SemanticLidarSensor")
    return sensor


def lidar_distances_normalized(env: Any, sensor_name: str) -> torch.Tensor:
    """``(num_envs, num_rays)`` distances divided by ``max_distance`` (misses read 1)."""
    s = _sensor(env, sensor_name)
    return s.data.distances / s.cfg.max_distance


def lidar_class_ids(env: Any, sensor_name: str) -> torch.Tensor:
    """``(num_envs, num_rays)`` class ids as floats (0 = miss/unknown)."""
    return _sensor(env, sensor_name).data.semantic_labels.float()


def lidar_one_hot_classes(env: Any, sensor_name: str) -> torch.Tensor:
    """``(num_envs, num_rays * (K + 1))`` one-hot classes, class 0 (miss/unknown) included."""
    s = _sensor(env, sensor_name)
    labels = s.data.semantic_labels.long()
    one_hot = torch.nn.functional.one_hot(labels, num_classes=len(s.class_names))
    return one_hot.float().reshape(labels.shape[0], -1)


def lidar_semantic_obs(env: Any, sensor_name: str) -> torch.Tensor:
    """The seed's observation: distances and labels stacked, ``(num_envs, num_rays * 2)``."""
    s = _sensor(env, sensor_name)
    distances = s.data.distances
    semantic_labels = s.data.semantic_labels
    obs = torch.stack([distances, semantic_labels.float()], dim=-1)
    return obs.reshape(distances.shape[0], -1)
