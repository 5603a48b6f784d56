"""The semantic LiDAR as an mjlab sensor, with observation terms (``robotwright[mjlab]``).

:class:`SemanticLidarSensorCfg` goes into ``SceneCfg.sensors`` like mjlab's own
``RayCastSensorCfg``; the sensor it builds *is* an mjlab ``RayCastSensor``, so the scene
wires it to the shared ``SensorContext`` (one BVH for every ray sensor and camera) and
casts inside mjlab's sense graph (a CUDA graph on GPU). Inside that graph, per step, it
launches robotwright's kernels around mjlab's ray cast: ``advance_frame`` (the pattern
window, counter on the device), ``sensor_pose``, ``world_rays`` (the window of the
pattern table), MuJoCo Warp ``rays`` (the call of mjlab's ``RayCastSensor`` with its
arguments: BVH, parent-body exclusion, geom-group filter), then ``finish_rays`` (float64
refinement of curved hits, range model, labels, points); on warp's CPU device the last
three run in column blocks on parallel threads. Nothing runs on the host per step and
nothing is copied:
mjlab's ``prepare_rays`` (host, before the graph) is replaced by the in-graph kernels and
``postprocess_rays`` (host, after it) only marks the data fresh.

``env.scene["lidar"].data`` is a :class:`MjlabSemanticLidarData` of torch tensors on the
environment's device, views of the device buffers (the same tensors every step):
``distances``, ``semantic_labels``, ``geom_ids``, ``hit_mask`` ``(num_envs, num_rays)``
and ``hit_pos_w`` ``(num_envs, num_rays, 3)`` (world frame [m], NaN for misses).

Which geoms rays see (the robot's own geoms included or not): mjlab's
``include_geom_groups``, here ``(0,)`` by default (mjlab's robots keep their visual
meshes in group 2 and collision geoms in group 3, terrain and plain props sit in group
0, so the robot does not see itself), and ``exclude_parent_body`` (the carrier body).
:meth:`MjlabSemanticLidarSensor.initialize` warns when geoms of the carrier's own robot
are left in an included group.

Terrain: mjlab names its terrain geoms ``terrain`` (plane) or ``terrain_<n>`` (boxes and
heightfields of generated terrain), under the terrain entity's body: their paths are
``/world/terrain/terrain[_<n>]``, which none of the default mapping's terrain keywords
("ground", "wall", "floor", "plane") matches. The default mapping is kept as
is; :func:`mjlab_class_mapping` adds the keyword ``/world/terrain/`` to the
terrain class, and the sensor warns when the terrain would read class 0.

This module imports mjlab; ``robotwright.sensors`` never imports it.
"""

from __future__ import annotations

import copy
import math
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np
import torch

from robotwright.errors import SensorError
from robotwright.sensors.device import import_warp, ray_blocks

# Before mjlab initialises warp: warp quiet, as the core's warp engine keeps it.
wp, mjw = import_warp()

from mjlab.sensor.builtin_sensor import ObjRef  # noqa: E402
from mjlab.sensor.raycast_sensor import RayCastSensor, RayCastSensorCfg  # noqa: E402

from robotwright.sensors import _warp_kernels as kernels  # noqa: E402
from robotwright.sensors.config import (  # noqa: E402
    DEFAULT_SEMANTIC_CLASS_MAPPING,
    SemanticLidarCfg,
)
from robotwright.sensors.lidar import geom_paths  # noqa: E402
from robotwright.sensors.patterns import (  # noqa: E402
    GridPatternCfg,
    LivoxPatternCfg,
    PatternCfg,
    RayTable,
)
from robotwright.sensors.semantic import classify_path, geom_class_table  # noqa: E402

__all__ = [
    "MJLAB_TERRAIN_KEYWORD",
    "MjlabSemanticLidarData",
    "MjlabSemanticLidarSensor",
    "SemanticLidarSensorCfg",
    "lidar_class_ids",
    "lidar_distances_normalized",
    "lidar_one_hot_classes",
    "lidar_semantic_obs",
    "mjlab_class_mapping",
]

_ALIGN = {"base": kernels.ALIGN_BASE, "yaw": kernels.ALIGN_YAW, "world": kernels.ALIGN_WORLD}

#: Path prefix of the geoms of mjlab's terrain entity (plane, boxes, heightfields).
MJLAB_TERRAIN_KEYWORD = "/world/terrain/"


def mjlab_class_mapping(
    mapping: dict[str, list[str]] | None = None, terrain_class: str = "terrain"
) -> dict[str, list[str]]:
    """A class mapping under which mjlab's terrain geoms belong to ``terrain_class``.

    Returns a copy of ``mapping`` (``None``: the default mapping) with
    :data:`MJLAB_TERRAIN_KEYWORD` appended to the keywords of ``terrain_class`` (the class
    is added last when the mapping lacks it). Keyword matching stays the default
    case-insensitive substring rule, so nothing else changes class.
    """
    base = DEFAULT_SEMANTIC_CLASS_MAPPING if mapping is None else mapping
    out = {k: list(v) for k, v in base.items()}
    keywords = out.setdefault(terrain_class, [])
    if MJLAB_TERRAIN_KEYWORD not in keywords:
        keywords.append(MJLAB_TERRAIN_KEYWORD)
    return out


def _is_mjlab_pattern(pattern: object) -> bool:
    """mjlab's own patterns (grid, pinhole, ring) and anything with its protocol."""
    return not isinstance(pattern, PatternCfg) and callable(getattr(pattern, "generate_rays", None))


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


@dataclass(kw_only=True)
class SemanticLidarSensorCfg(RayCastSensorCfg):
    """mjlab config of a semantic LiDAR: the SemanticLidarCfg fields on mjlab's ray-cast sensor.

    Frames: the pattern is given in the sensor frame (+x forward, +z up), which sits at
    ``offset_pos``/``offset_rot`` in the ``frame`` object's frame; outputs are in the
    world frame; distances [m].

    Attributes:
        name: the sensor's key in ``env.scene``.
        frame: the body, site or geom carrying the sensor (one ``ObjRef``, e.g.
            ``ObjRef(type="body", name="trunk", entity="robot")``).
        pattern: any robotwright pattern (:class:`~robotwright.sensors.LivoxPatternCfg`
            Mid-360/Avia rosettes advance one window per step; spinning, grid, pinhole
            and file patterns repeat), or one of mjlab's own patterns (grid, pinhole,
            ring), cast as a repeating pattern. Default: a 20 000-ray Mid-360.
        offset_pos: sensor position in the frame object's frame [m] (default: at its
            origin, as mjlab's ray sensor).
        offset_rot: sensor orientation in that frame, quaternion (w, x, y, z).
        semantic_class_mapping: class -> keywords matched case-insensitively in geom
            paths (``/world/<bodies>/<geom>[/<mesh>]``); class ids 1..K in mapping
            order, 0 = miss/unknown. ``None``: the default mapping (see
            :func:`mjlab_class_mapping` for mjlab's terrain).
        min_distance, max_distance: hits nearer or further are misses [m].
        range_noise_std: Gaussian range noise on hits [m], clipped to the range.
        dropout_prob: probability that a hit is dropped (becomes a miss).
        seed: base seed of the per-environment noise streams (``None``: fresh entropy).
        miss_distance: distance of a miss [m]; ``None``: ``max_distance``.
        num_threads: on warp's CPU device, cast the rays in this many column blocks on
            parallel threads (``None``: one per core); CUDA always casts in one launch.
        refine_curved_hits: recompute hits on spheres, capsules, ellipsoids and cylinders
            in float64 from the compiled geom sizes (turn off when ``geom_size`` is
            randomised per environment).
        ray_alignment: ``"base"``, ``"yaw"`` or ``"world"`` (as mjlab's).
        exclude_parent_body: rays ignore the body carrying the sensor (as mjlab's).
        include_geom_groups: geom groups rays can hit (as mjlab's; here ``(0,)`` by
            default: terrain and props, not the robot's visual and collision groups).
    """

    frame: ObjRef
    pattern: Any = field(default_factory=LivoxPatternCfg)
    offset_pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    offset_rot: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    semantic_class_mapping: dict[str, list[str]] | None = None
    min_distance: float = 0.0
    max_distance: float = 40.0
    range_noise_std: float = 0.0
    dropout_prob: float = 0.0
    seed: int | None = 0
    miss_distance: float | None = None
    refine_curved_hits: bool = True
    num_threads: int | None = None
    include_geom_groups: tuple[int, ...] | None = (0,)

    def __post_init__(self) -> None:
        name = type(self).__name__
        if not isinstance(self.frame, ObjRef) or self.frame.type not in ("body", "site", "geom"):
            raise SensorError(
                f"{name}.frame: expected one ObjRef of a body, site or geom, got {self.frame!r}"
            )
        if not isinstance(self.pattern, PatternCfg) and not _is_mjlab_pattern(self.pattern):
            raise SensorError(
                f"{name}.pattern: expected a robotwright PatternCfg or an mjlab pattern, "
                f"got {type(self.pattern).__name__}"
            )
        if not isinstance(self.refine_curved_hits, bool):
            raise SensorError(f"{name}.refine_curved_hits: expected True or False")
        # The core config validates and normalises the shared fields (ranges, noise,
        # mapping, offsets, alignment, seed) with the same rules and messages.
        core = SemanticLidarCfg(
            prim_path=self.frame.prefixed_name(),
            pattern_cfg=self.pattern if isinstance(self.pattern, PatternCfg) else GridPatternCfg(),
            offset_pos=self.offset_pos,
            offset_rot=self.offset_rot,
            ray_alignment=self.ray_alignment,
            min_distance=self.min_distance,
            max_distance=self.max_distance,
            range_noise_std=self.range_noise_std,
            dropout_prob=self.dropout_prob,
            seed=self.seed,
            miss_distance=self.miss_distance,
            num_threads=self.num_threads,
            semantic_class_mapping=self.semantic_class_mapping,
        )
        self.offset_pos = core.offset_pos
        self.offset_rot = core.offset_rot
        self.miss_distance = float(core.miss_distance)  # type: ignore[arg-type]
        if not math.isfinite(self.miss_distance):
            raise SensorError(f"{name}.miss_distance: expected a finite number [m]")
        self.semantic_class_mapping = {
            k: list(v) for k, v in (core.semantic_class_mapping or {}).items()
        }

    def build(self) -> MjlabSemanticLidarSensor:
        return MjlabSemanticLidarSensor(self)


@dataclass
class MjlabSemanticLidarData:
    """Torch views of the device buffers (``E`` envs, ``N`` rays), world frame.

    Overwritten in place by every ``sim.sense()``; the same tensor objects every step.

    Attributes:
        distances: ``(E, N)`` float32 range [m]; misses hold ``miss_distance``.
        hit_mask: ``(E, N)`` bool, True where the ray returned a point.
        semantic_labels: ``(E, N)`` int32 class id (1..K in mapping order, 0 miss/unknown).
        geom_ids: ``(E, N)`` int32 MuJoCo geom id of the hit, -1 on a miss.
        hit_pos_w: ``(E, N, 3)`` float32 hit points [m], NaN on a miss.
        ray_origins_w: ``(E, N, 3)`` this step's ray origins [m].
        ray_directions_w: ``(E, N, 3)`` this step's unit ray directions.
        pos_w: ``(E, 3)`` sensor position [m]; quat_w: ``(E, 4)`` orientation (w, x, y, z).
        frame: ``(1,)`` int32 index of the last cast pattern frame (0 for the first).
    """

    distances: torch.Tensor
    hit_mask: torch.Tensor
    semantic_labels: torch.Tensor
    geom_ids: torch.Tensor
    hit_pos_w: torch.Tensor
    ray_origins_w: torch.Tensor
    ray_directions_w: torch.Tensor
    pos_w: torch.Tensor
    quat_w: torch.Tensor
    frame: torch.Tensor


class MjlabSemanticLidarSensor(RayCastSensor):
    """mjlab ``RayCastSensor`` whose rays follow a robotwright pattern and carry labels.

    Attributes (after ``initialize``):
        table: the pattern's :class:`~robotwright.sensors.RayTable` (sensor frame).
        class_names: ``("unknown", *classes)``, indexed by class id.
        geom_paths: classification path of every geom of the compiled scene.
        geom_semantic_class: ``(ngeom,)`` class id of every geom (0 where not hittable).
        hittable_geom_mask: ``(ngeom,)`` geoms the rays can hit (included groups, minus
            the excluded parent body).
    """

    cfg: SemanticLidarSensorCfg

    def __init__(self, cfg: SemanticLidarSensorCfg) -> None:
        super().__init__(cfg)
        self.semantic_class_mapping: dict[str, list[str]] = dict(cfg.semantic_class_mapping or {})
        self.class_names: tuple[str, ...] = ("unknown", *self.semantic_class_mapping)
        self._buffers: dict[str, Any] = {}
        self._pool: ThreadPoolExecutor | None = None
        self._blocks: list[tuple[int, int]] = []

    def initialize(self, mj_model: mujoco.MjModel, model: Any, data: Any, device: str) -> None:
        cfg = self.cfg
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
        lut = geom_class_table(
            self.geom_paths, self.semantic_class_mapping, self.hittable_geom_mask
        )
        self.geom_semantic_class = lut[:-1]
        self._check_scene(mj_model, body)
        e, n = int(data.nworld), int(self.table.rays_per_frame)
        seeds = np.random.SeedSequence(cfg.seed).generate_state(e).astype(np.uint32)
        dev = self._wp_device
        # Load the kernels now: mjlab captures its sense graph later, and no module may
        # be compiled or loaded during a CUDA graph capture.
        wp.load_module(kernels, device=dev)
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
                "distances": wp.full((e, n), float(cfg.miss_distance), dtype=wp.float32),
                "hit_mask": wp.zeros((e, n), dtype=wp.bool),
                "geom_ids": wp.full((e, n), -1, dtype=wp.int32),
                "labels": wp.zeros((e, n), dtype=wp.int32),
                "points": wp.full((e, n), wp.vec3(np.nan, np.nan, np.nan), dtype=wp.vec3),
            }
        rot = np.empty(9)
        mujoco.mju_quat2Mat(rot, np.asarray(cfg.offset_rot, dtype=np.float64))
        self._offset_pos = wp.vec3(*np.asarray(cfg.offset_pos, dtype=np.float32))
        self._offset_mat = wp.mat33(*rot.astype(np.float32))
        self._buffers = b
        self._blocks = ray_blocks(n, dev, cfg.num_threads)
        self._pool = ThreadPoolExecutor(len(self._blocks)) if len(self._blocks) > 1 else None
        t = wp.to_torch
        self._lidar_data = MjlabSemanticLidarData(
            distances=t(b["distances"]),
            hit_mask=t(b["hit_mask"]),
            semantic_labels=t(b["labels"]),
            geom_ids=t(b["geom_ids"]),
            hit_pos_w=t(b["points"]),
            ray_origins_w=t(self._ray_pnt),
            ray_directions_w=t(self._ray_vec),
            pos_w=t(b["pos_w"]),
            quat_w=t(b["quat_w"]),
            frame=t(b["frame"]),
        )

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

    def _check_scene(self, mj_model: mujoco.MjModel, parent_body: int) -> None:
        """Warn about self-hits and unclassified terrain (both silent otherwise)."""
        name = self.cfg.name
        root = int(mj_model.body_rootid[parent_body])
        if root != 0:
            own = self.hittable_geom_mask & (mj_model.body_rootid[mj_model.geom_bodyid] == root)
            if own.any():
                first = self.geom_paths[int(np.flatnonzero(own)[0])]
                warnings.warn(
                    f"{name}: {int(own.sum())} geoms of the robot carrying the sensor are in "
                    f"include_geom_groups={self.cfg.include_geom_groups} (e.g. {first}): the "
                    "LiDAR will see its own robot; move them to another geom group or "
                    "narrow include_geom_groups",
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
        """IN-GRAPH: pattern window, sensor pose, world rays, mjlab's cast, range model, labels.

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
        wp.launch(
            kernels.sensor_pose,
            dim=e,
            inputs=[
                cpos,
                cmat,
                self._carrier,
                self._offset_pos,
                self._offset_mat,
                _ALIGN[cfg.ray_alignment],
            ],
            outputs=[b["pos_w"], b["quat_w"], b["sensor_mat"], b["ray_rot"]],
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
                float(cfg.miss_distance),  # type: ignore[arg-type]
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

    def postprocess_rays(self) -> None:
        """Fresh results: drop data cached before this step's cast (nothing per ray)."""
        self._invalidate_cache()

    def _compute_data(self) -> MjlabSemanticLidarData:  # type: ignore[override]
        if not self._buffers:
            raise SensorError(f"{self.cfg.name}: the sensor is not initialised (no scene yet)")
        return self._lidar_data

    def debug_vis(self, visualizer: Any) -> None:
        """No ray drawing (mjlab's would loop over every ray on the host)."""

    # Isaac Lab-style getters, so such observation code runs on this sensor as written.
    def get_distances(self) -> torch.Tensor:
        """``(num_envs, num_rays)`` ranges [m]; misses hold ``miss_distance``."""
        return self.data.distances

    def get_semantic_labels(self) -> torch.Tensor:
        """``(num_envs, num_rays)`` int32 class ids (0 = miss/unknown)."""
        return self.data.semantic_labels

    def get_mesh_ids(self) -> torch.Tensor:
        """``(num_envs, num_rays)`` int32 hit geom ids (-1 = miss)."""
        return self.data.geom_ids

    def get_pointcloud(self) -> torch.Tensor:
        """``(num_envs, num_rays, 3)`` world-frame hit points [m], NaN for misses."""
        return self.data.hit_pos_w

    def classify_geom(self, geom_id: int) -> int:
        """Class id of a geom's path under this sensor's mapping (seed rule)."""
        return classify_path(self.geom_paths[geom_id], self.semantic_class_mapping)


# ---------------------------------------------------------------------- observations
def _sensor(env: Any, sensor_name: str) -> MjlabSemanticLidarSensor:
    sensor = env.scene[sensor_name]
    if not isinstance(sensor, MjlabSemanticLidarSensor):
        raise SensorError(
            f"{sensor_name!r} is a {type(sensor).__name__}, not a robotwright "
            "SemanticLidarSensorCfg sensor"
        )
    return sensor


def lidar_distances_normalized(env: Any, sensor_name: str) -> torch.Tensor:
    """``(num_envs, num_rays)`` distances divided by ``max_distance``, in [0, 1] for hits;
    misses read ``miss_distance / max_distance`` (1 by default)."""
    s = _sensor(env, sensor_name)
    return s.data.distances / s.cfg.max_distance


def lidar_class_ids(env: Any, sensor_name: str) -> torch.Tensor:
    """``(num_envs, num_rays)`` class ids as floats (0 = miss/unknown, 1..K classes)."""
    return _sensor(env, sensor_name).data.semantic_labels.float()


def lidar_one_hot_classes(env: Any, sensor_name: str) -> torch.Tensor:
    """``(num_envs, num_rays * (K + 1))`` one-hot classes, ray-major, class 0 included."""
    s = _sensor(env, sensor_name)
    labels = s.data.semantic_labels.long()
    one_hot = torch.nn.functional.one_hot(labels, num_classes=len(s.class_names))
    return one_hot.float().reshape(labels.shape[0], -1)


def lidar_semantic_obs(env: Any, sensor_name: str) -> torch.Tensor:
    """The stacked observation: ``(num_envs, num_rays * 2)``, per ray (distance [m], class id)."""
    s = _sensor(env, sensor_name)
    distances = s.get_distances()
    semantic_labels = s.get_semantic_labels()
    obs = torch.stack([distances, semantic_labels.float()], dim=-1)
    return obs.reshape(distances.shape[0], -1)
