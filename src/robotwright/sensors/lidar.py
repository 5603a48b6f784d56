"""``LidarSensor``: a LiDAR carried by a body or site of a MuJoCo model, over 1..N envs.

Frames: ray origins, directions and hit points are in the world frame unless stated;
distances in metres along unit ray directions; quaternions (w, x, y, z).

What a miss returns: ``distance = cfg.miss_distance`` (``max_distance`` by default, so
observations stay finite), the point is ``(nan, nan, nan)``, ``data.hit_mask`` is False
(and, for the semantic sensor, label 0 and mesh id -1). A ray is a miss when it hits nothing hittable, when its hit is nearer
than ``min_distance`` or further than ``max_distance``, or when dropout removes it.
Noise is added to hits only and the noisy range is clipped to
``[min_distance, max_distance]``, so a hit never turns into a miss by noise.

Two pipelines: ``engine="mujoco"`` works on the host in numpy (float64, the reference);
``engine="warp"`` keeps every step of a frame on the warp device
(:class:`~robotwright.sensors.device.WarpLidarPipeline`) and hands out its buffers as
numpy copies, zero-copy torch tensors or warp arrays (``cfg.output``).
"""

from __future__ import annotations

import fnmatch
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from robotwright._suggest import did_you_mean
from robotwright.errors import SensorError
from robotwright.sensors.config import LidarCfg
from robotwright.sensors.device import RangeModel, WarpLidarPipeline
from robotwright.sensors.raycast import MujocoRayEngine, make_ray_model

if TYPE_CHECKING:  # the warp extra is optional
    from mujoco_warp import Data as WarpData

__all__ = ["LidarSensor", "LidarSensorData", "geom_paths", "prim_path_candidates"]

#: Environment namespaces of Isaac Lab style paths; each MuJoCo world is one environment,
#: so they are dropped from ``prim_path`` and stand for "any prefix" in ``mesh_prim_paths``.
_ENV_NAMESPACES = ("{ENV_REGEX_NS}", "/World/envs/env_.*", "/World/envs/env_*")


@dataclass
class LidarSensorData:
    """Buffers of the last :meth:`LidarSensor.update`, one row per environment.

    With ``cfg.output="numpy"`` every field is a numpy array (float64). With ``"torch"``
    or ``"warp"`` (warp engine) every field is a zero-copy view of the device buffers
    (float32, labels int32, mask bool): the same objects after every update, overwritten
    in place, like mjlab's sensor data.

    Attributes:
        pos_w: ``(E, 3)`` sensor position, world frame [m].
        quat_w: ``(E, 4)`` sensor orientation (w, x, y, z), world frame (offset included).
        distances: ``(E, N)`` range along each ray [m] (noise applied; misses
            ``cfg.miss_distance``).
        hit_mask: ``(E, N)`` True where the ray returned a point.
        frame: index of the scan frame (0 for the first update).
        ray_rot_w: ``(E, 3, 3)`` rotation applied to the pattern (set by ``ray_alignment``).
        pattern_origins, pattern_directions: ``(N, 3)`` the pattern's rays in the sensor
            frame for this frame [m].
        ray_origins_w, ray_directions_w, hit_points_w: ``(E, N, 3)`` world-frame ray
            origins [m], unit directions and hit points [m] (NaN for misses), computed
            on first access after each update.
    """

    pos_w: np.ndarray
    quat_w: np.ndarray
    distances: np.ndarray
    hit_mask: np.ndarray
    ray_rot_w: np.ndarray
    pattern_origins: np.ndarray
    pattern_directions: np.ndarray
    frame: int = -1
    _cache: dict[str, np.ndarray] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    @property
    def ray_directions_w(self) -> np.ndarray:
        if "dirs" not in self._cache:
            self._cache["dirs"] = np.matmul(
                self.pattern_directions[None], self.ray_rot_w.transpose(0, 2, 1)
            )
        return self._cache["dirs"]

    @property
    def ray_origins_w(self) -> np.ndarray:
        if "origins" not in self._cache:
            rotated = np.matmul(self.pattern_origins[None], self.ray_rot_w.transpose(0, 2, 1))
            self._cache["origins"] = rotated + self.pos_w[:, None, :]
        return self._cache["origins"]

    @property
    def hit_points_w(self) -> np.ndarray:
        if "points" not in self._cache:
            # Misses carry the miss distance (inf by default): use 0, then NaN them.
            dist = np.where(self.hit_mask, self.distances, 0.0)
            pts = np.multiply(self.ray_directions_w, dist[..., None])
            pts += self.ray_origins_w
            np.copyto(pts, np.nan, where=~self.hit_mask[..., None])
            self._cache["points"] = pts
        return self._cache["points"]

    def _invalidate(self) -> None:
        if not self._cache.get("device_views", False):
            self._cache.clear()

    def _set_device_views(self, origins: Any, directions: Any, points: Any) -> None:
        """Device outputs: world rays and points are buffers too, not host computations."""
        self._cache.update(origins=origins, dirs=directions, points=points, device_views=True)


def _name(model: mujoco.MjModel, obj: mujoco.mjtObj, idx: int, fallback: str) -> str:
    return mujoco.mj_id2name(model, obj, idx) or f"{fallback}{idx}"


def _body_chain(model: mujoco.MjModel, body: int) -> list[int]:
    chain = []
    while body != 0:
        chain.append(body)
        body = int(model.body_parentid[body])
    return chain[::-1]


def _geom_name(model: mujoco.MjModel, g: int) -> str:
    """A geom's name; an unnamed one is ``geom<id>_<type>`` (e.g. ``geom0_plane``)."""
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g)
    if name:
        return name
    kind = mujoco.mjtGeom(int(model.geom_type[g])).name.removeprefix("mjGEOM_").lower()
    return f"geom{g}_{kind}"


def geom_paths(model: mujoco.MjModel, with_mesh: bool = True) -> list[str]:
    """Path of every geom: ``/world/<body>/.../<geom>`` (``+ /<mesh>`` for mesh geoms).

    Unnamed bodies appear as ``body<id>``; unnamed geoms as ``geom<id>_<type>``, so an
    unnamed ``<geom type="plane">`` is classified as terrain by the default mapping.
    """
    paths = []
    for g in range(model.ngeom):
        parts = ["", "world"]
        parts += [
            _name(model, mujoco.mjtObj.mjOBJ_BODY, b, "body")
            for b in _body_chain(model, int(model.geom_bodyid[g]))
        ]
        parts.append(_geom_name(model, g))
        if (
            with_mesh
            and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH
            and model.geom_dataid[g] >= 0
        ):
            parts.append(_name(model, mujoco.mjtObj.mjOBJ_MESH, int(model.geom_dataid[g]), "mesh"))
        paths.append("/".join(parts))
    return paths


def prim_path_candidates(prim_path: str) -> list[str]:
    """Names a (possibly Isaac Lab style) ``prim_path`` may stand for, most specific first.

    ``"{ENV_REGEX_NS}/Robot/base"`` gives ``["Robot/base", "base"]``: the environment
    namespace is dropped (each MuJoCo world is one environment), then the path itself is
    tried (mjlab names bodies ``<entity>/<body>``), then ever shorter tails of it.
    """
    path = prim_path
    for ns in _ENV_NAMESPACES:
        if path.startswith(ns):
            path = path[len(ns) :]
            break
    if path.lower().startswith("/world/"):
        path = path[len("/world/") :]
    parts = [p for p in path.split("/") if p]
    if not parts:
        return [prim_path]
    out = [prim_path] if prim_path != "/".join(parts) else []
    out += ["/".join(parts[k:]) for k in range(len(parts))]
    return out


def _mesh_pattern(pattern: str) -> str:
    """A ``mesh_prim_paths`` entry as a lower-case ``fnmatch`` pattern over geom paths."""
    for ns in _ENV_NAMESPACES:
        if pattern.startswith(ns):
            return ("/world*" + pattern[len(ns) :]).lower()
    return pattern.lower()


def _is_warp_data(data: object) -> bool:
    """True for a ``mujoco_warp.Data`` (checked by type, without importing warp)."""
    cls = type(data)
    return cls.__name__ == "Data" and cls.__module__.startswith("mujoco_warp")


def _quat_to_mat(q: Sequence[float]) -> np.ndarray:
    mat = np.empty(9)
    mujoco.mju_quat2Mat(mat, np.asarray(q, dtype=np.float64))
    return mat.reshape(3, 3)


class LidarSensor:
    """A LiDAR on a compiled MuJoCo model, for one or many environments.

    Args:
        cfg: the sensor configuration.
        model: the compiled model (shared by every environment).
        data: one ``MjData`` or a list of them, one per environment, or a
            ``mujoco_warp.Data`` holding every environment on the warp device (with
            ``engine="warp"``; then it is read in place and nothing leaves the device).
            :meth:`update` reads the poses they hold (as left by ``mj_step``/
            ``mj_forward`` or ``mujoco_warp.step``/``kinematics``); it never writes them.

    Example:
        >>> sensor = LidarSensor(LidarCfg(prim_path="lidar_site"), model, data)
        >>> sensor.update()
        >>> sensor.get_distances().shape  # (num_envs, num_rays)
    """

    cfg: LidarCfg

    def __init__(
        self,
        cfg: LidarCfg,
        model: mujoco.MjModel,
        data: mujoco.MjData | Sequence[mujoco.MjData] | WarpData,
    ) -> None:
        if not isinstance(cfg, LidarCfg):
            raise SensorError(f"cfg: expected a LidarCfg, got {type(cfg).__name__}")
        if not isinstance(model, mujoco.MjModel):
            raise SensorError(f"model: expected a mujoco.MjModel, got {type(model).__name__}")
        self.cfg = cfg
        self.model = model
        # A mujoco_warp.Data (all worlds on the warp device) or host MjData, one per env.
        self._warp_data = data if _is_warp_data(data) else None
        if self._warp_data is not None:
            self._datas: list[mujoco.MjData] = []
            self._num_envs = int(data.nworld)
            if cfg.engine != "warp":
                raise SensorError(
                    "data is a mujoco_warp.Data: set engine='warp' (the mujoco engine needs MjData)"
                )
        else:
            self._datas = [data] if isinstance(data, mujoco.MjData) else list(data)
            self._num_envs = len(self._datas)
        if self._num_envs == 0:
            raise SensorError(
                "data: expected one MjData or a non-empty list of them (one per environment)"
            )
        for i, d in enumerate(self._datas):
            if (
                not isinstance(d, mujoco.MjData)
                or d.xpos.shape[0] != model.nbody
                or d.geom_xpos.shape[0] != model.ngeom
            ):
                raise SensorError(
                    f"data[{i}]: expected an MjData of this model ({model.nbody} bodies, {model.ngeom} geoms)"
                )
        self._carrier_kind, self._carrier_id, self._carrier_body = self._resolve_carrier(
            cfg.prim_path
        )
        self._geom_paths = geom_paths(model)
        self.hittable_geom_mask = self._select_geoms()
        self._ray_model = make_ray_model(model, self.hittable_geom_mask)
        self._table = cfg.pattern_cfg.ray_table()
        self._single_origin = self._table.single_origin
        self.num_rays = int(self._table.rays_per_frame)
        self._offset_mat = _quat_to_mat(cfg.offset_rot)
        self._offset_pos = np.asarray(cfg.offset_pos, dtype=np.float64)
        self._frame = -1
        self._label_lut: np.ndarray | None = None
        self._initialize_warp_meshes()
        self._pipeline: WarpLidarPipeline | None = None
        self._engine: MujocoRayEngine | None = None
        if cfg.engine == "warp":
            self._pipeline = WarpLidarPipeline(
                self._ray_model,
                self.num_envs,
                cfg.device,
                self._table,
                (self._carrier_kind, self._carrier_id),
                self._offset_pos,
                self._offset_mat,
                cfg.ray_alignment,
                RangeModel(
                    min_distance=float(cfg.min_distance),
                    max_distance=float(cfg.max_distance),
                    noise_std=float(cfg.range_noise_std),
                    dropout_prob=float(cfg.dropout_prob),
                    miss_distance=float(cfg.miss_distance),
                    seed=cfg.seed,
                ),
                self._label_lut,
                num_threads=cfg.num_threads,
            )
            if self._warp_data is not None:
                self._pipeline.check_data(self._warp_data)
        else:
            self._engine = MujocoRayEngine(self._ray_model, cfg.num_threads)
            self._rng = np.random.default_rng(cfg.seed)
        self._raw_geom_ids = np.full((self.num_envs, self.num_rays), -1, dtype=np.int32)
        self._data = self._make_data()

    # ------------------------------------------------------------------ set-up
    @property
    def num_envs(self) -> int:
        return self._num_envs

    @property
    def max_distance(self) -> float:
        """Maximum range [m] (seed name)."""
        return float(self.cfg.max_distance)

    @property
    def data(self) -> LidarSensorData:
        """The buffers of the last :meth:`update`."""
        return self._data

    @property
    def engine_name(self) -> str:
        return self.cfg.engine

    @property
    def device(self) -> str:
        """Where the sensor computes: ``"cpu"`` for the mujoco engine, else the warp device."""
        return "cpu" if self._pipeline is None else str(self._pipeline.device)

    def _resolve_carrier(self, name: str) -> tuple[str, int, int]:
        m = self.model
        for candidate in prim_path_candidates(name):
            body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, candidate)
            if body >= 0:
                return "body", body, body
            site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, candidate)
            if site >= 0:
                return "site", site, int(m.site_bodyid[site])
        names = [_name(m, mujoco.mjtObj.mjOBJ_BODY, i, "") for i in range(m.nbody)]
        names += [_name(m, mujoco.mjtObj.mjOBJ_SITE, i, "") for i in range(m.nsite)]
        # Case-insensitive, as Isaac Lab users write "Robot/base" for a body "base".
        lowered = {n.lower(): n for n in names if n}
        for candidate in prim_path_candidates(name):
            if candidate.lower() in lowered:
                return self._resolve_carrier(lowered[candidate.lower()])
        hint = did_you_mean(name, names)
        raise SensorError(
            f"{type(self.cfg).__name__}.prim_path: no body or site named {name!r} in the model{hint}"
        )

    def robot_body_ids(self) -> np.ndarray:
        """Bodies of the robot that carries the sensor (same root body; none on the world)."""
        root = int(self.model.body_rootid[self._carrier_body])
        if root == 0:
            return np.zeros(0, dtype=int)
        return np.flatnonzero(self.model.body_rootid == root)

    def _select_geoms(self) -> np.ndarray:
        m = self.model
        cfg = self.cfg
        if cfg.mesh_prim_paths:
            selected = np.zeros(m.ngeom, dtype=bool)
            # Candidate names of a geom: its own name and path, and every ancestor body's
            # name and path, so a body pattern selects that body's whole subtree. Matched
            # case-insensitively, like classification ("/World/ground" finds "ground").
            candidates = []
            for g in range(m.ngeom):
                chain = _body_chain(m, int(m.geom_bodyid[g]))
                names = [_geom_name(m, g), self._geom_paths[g]]
                prefix = "/world"
                names.append(prefix)
                for b in chain:
                    bname = _name(m, mujoco.mjtObj.mjOBJ_BODY, b, "body")
                    prefix = f"{prefix}/{bname}"
                    names += [bname, prefix]
                if not chain:
                    names.append("world")
                candidates.append([n.lower() for n in names])
            for pattern in cfg.mesh_prim_paths:
                key = _mesh_pattern(pattern)
                hits = [
                    g
                    for g in range(m.ngeom)
                    if any(fnmatch.fnmatchcase(c, key) for c in candidates[g])
                ]
                if not hits:
                    raise SensorError(
                        f"{type(cfg).__name__}.mesh_prim_paths: {pattern!r} matches no geom or body of the model"
                    )
                selected[hits] = True
        else:
            selected = np.ones(m.ngeom, dtype=bool)
        if cfg.exclude_robot:
            robot = self.robot_body_ids()
            selected &= ~np.isin(m.geom_bodyid, robot)
        if not selected.any():
            raise SensorError(
                f"{type(cfg).__name__}: no geom is left for rays to hit (mesh_prim_paths={cfg.mesh_prim_paths}, "
                f"exclude_robot={cfg.exclude_robot})"
            )
        return selected

    def _initialize_warp_meshes(self) -> None:
        """Seed hook run before the engine is built; the semantic sensor classifies geoms here."""

    def _make_data(self) -> LidarSensorData:
        e, n = self.num_envs, self.num_rays
        origins, dirs = self._table.window(0)
        data = LidarSensorData(
            pos_w=np.zeros((e, 3)),
            quat_w=np.tile([1.0, 0.0, 0.0, 0.0], (e, 1)),
            distances=np.full((e, n), self.cfg.miss_distance),
            hit_mask=np.zeros((e, n), dtype=bool),
            ray_rot_w=np.tile(np.eye(3), (e, 1, 1)),
            pattern_origins=origins,
            pattern_directions=dirs,
        )
        if self.cfg.output != "numpy":
            p = self._pipeline
            assert p is not None  # LidarCfg refuses device outputs without the warp engine
            view = self._device_view
            data.pos_w, data.quat_w = view(p.pos_w), view(p.quat_w)
            data.distances, data.hit_mask = view(p.distances), view(p.hit_mask)
            data.ray_rot_w = view(p.ray_rot)
            data.pattern_origins, data.pattern_directions = self._device_window(0)
            data._set_device_views(view(p.ray_origins), view(p.ray_directions), view(p.points))
        return data

    def _device_view(self, array: Any) -> Any:
        """A warp array as the configured output: itself, or a zero-copy torch tensor."""
        if self.cfg.output == "warp":
            return array
        import warp as wp

        return wp.to_torch(array)

    def _device_window(self, frame: int) -> tuple[Any, Any]:
        """The pattern rows of ``frame`` as views of the device table."""
        p = self._pipeline
        assert p is not None
        start = (frame % self._table.num_frames) * self.num_rays
        o, d = self._device_view(p.table_o), self._device_view(p.table_d)
        return o[start : start + self.num_rays], d[start : start + self.num_rays]

    # ------------------------------------------------------------------ update
    def sensor_poses(self) -> tuple[np.ndarray, np.ndarray]:
        """Sensor positions ``(E, 3)`` [m] and rotation matrices ``(E, 3, 3)``, world frame.

        With the warp engine these are the poses of the last update, copied to the host.
        """
        if self._pipeline is not None:
            return (
                self._pipeline.pos_w.numpy().astype(np.float64),
                self._pipeline.sensor_mat.numpy().astype(np.float64),
            )
        pos = np.empty((self.num_envs, 3))
        mat = np.empty((self.num_envs, 3, 3))
        for e, d in enumerate(self._datas):
            if self._carrier_kind == "body":
                p, r = d.xpos[self._carrier_id], d.xmat[self._carrier_id].reshape(3, 3)
            else:
                p, r = d.site_xpos[self._carrier_id], d.site_xmat[self._carrier_id].reshape(3, 3)
            pos[e] = p + r @ self._offset_pos
            mat[e] = r @ self._offset_mat
        return pos, mat

    def _ray_rotation(self, mat: np.ndarray) -> np.ndarray:
        align = self.cfg.ray_alignment
        if align == "base":
            return mat
        if align == "world":
            return np.broadcast_to(np.eye(3), mat.shape).copy()
        yaw = np.arctan2(mat[:, 1, 0], mat[:, 0, 0])
        c, s = np.cos(yaw), np.sin(yaw)
        rot = np.zeros_like(mat)
        rot[:, 0, 0], rot[:, 0, 1], rot[:, 1, 0], rot[:, 1, 1], rot[:, 2, 2] = c, -s, s, c, 1.0
        return rot

    def update(self) -> None:
        """Cast one frame of rays for every environment from the poses its data holds."""
        self._update_buffers_impl(None)

    def _update_buffers_impl(self, env_ids: Sequence[int] | np.ndarray | None) -> None:
        """Seed hook: cast and fill the buffers (every environment; ``env_ids`` kept for the API)."""
        self._frame += 1
        if self._pipeline is not None:
            self._update_device()
        else:
            self._update_host()

    def _update_device(self) -> None:
        """Warp engine: kernels only; numpy output then copies the results to the host."""
        p = self._pipeline
        assert p is not None
        p.update(self._warp_data if self._warp_data is not None else self._datas)
        d = self._data
        if self.cfg.output != "numpy":
            d.frame = self._frame
            d.pattern_origins, d.pattern_directions = self._device_window(self._frame)
            return
        d._invalidate()
        d.frame = self._frame
        d.pos_w = p.pos_w.numpy().astype(np.float64)
        d.quat_w = p.quat_w.numpy().astype(np.float64)
        d.ray_rot_w = p.ray_rot.numpy().astype(np.float64)
        d.pattern_origins, d.pattern_directions = self._table.window(self._frame)
        # .numpy() of a CPU-device array is a view of it: copy, numpy outputs are the host's.
        d.distances = p.distances.numpy().astype(np.float64)
        d.hit_mask = p.hit_mask.numpy().copy()
        self._raw_geom_ids = p.geom_ids.numpy().copy()

    def _update_host(self) -> None:
        """Mujoco engine: threaded ``mj_multiRay`` and the range model in numpy (float64)."""
        assert self._engine is not None
        origins_s, dirs_s = self._table.window(self._frame)
        pos, mat = self.sensor_poses()
        bad = np.flatnonzero(~(np.isfinite(pos).all(axis=1) & np.isfinite(mat).all(axis=(1, 2))))
        if bad.size:  # a diverged simulation: every ray would silently miss
            raise SensorError(
                f"environment {int(bad[0])}: the pose of {self.cfg.prim_path!r} is not finite "
                "(NaN or inf in MjData: has the simulation diverged?)"
            )
        rot = self._ray_rotation(mat)
        raw_dist, geom_ids = self._engine.cast(
            self._datas,
            origins_s,
            dirs_s,
            rot,
            pos,
            self.cfg.max_distance,
            self._single_origin,
        )
        self._apply_range_model(raw_dist, geom_ids)
        d = self._data
        d._invalidate()
        d.frame = self._frame
        d.pos_w[:] = pos
        for e in range(self.num_envs):
            mujoco.mju_mat2Quat(d.quat_w[e], mat[e].ravel())
        d.ray_rot_w = rot
        d.pattern_origins = origins_s
        d.pattern_directions = dirs_s

    def _apply_range_model(self, dist: np.ndarray, geom_ids: np.ndarray) -> None:
        """Ranges, noise and dropout on the engine output (both arrays are modified)."""
        cfg = self.cfg
        # The engine marks a miss with geom id -1; ``dropped`` collects the hits the range
        # model turns into misses. Each pass below is over every ray of every frame, so
        # the ones a configuration does not need are skipped.
        hit = geom_ids >= 0
        dropped = dist < cfg.min_distance if cfg.min_distance > 0 else None
        # mj_multiRay's cutoff culls whole geoms only, so a few hits may lie beyond it.
        far = dist > cfg.max_distance
        if far.any():
            dropped = far if dropped is None else dropped | far
        if cfg.range_noise_std > 0:
            dist = dist + self._rng.normal(0.0, cfg.range_noise_std, size=dist.shape)
            np.clip(dist, cfg.min_distance, cfg.max_distance, out=dist)
        if cfg.dropout_prob > 0:
            lost = self._rng.random(dist.shape) < cfg.dropout_prob
            dropped = lost if dropped is None else dropped | lost
        if dropped is not None:
            hit &= ~dropped
            np.copyto(geom_ids, -1, where=dropped)
        # copyto(where=) is several times faster than boolean-index assignment here.
        np.copyto(dist, cfg.miss_distance, where=~hit)
        self._data.hit_mask = hit
        self._data.distances = dist
        self._raw_geom_ids = geom_ids

    # ------------------------------------------------------------------ getters
    def _rows(self, env_ids: Sequence[int] | np.ndarray | None) -> Any:
        if env_ids is None:
            return slice(None)
        if self.cfg.output == "torch":
            import torch

            ids = torch.as_tensor(env_ids, dtype=torch.long).reshape(-1)
            lo, hi = (int(ids.min()), int(ids.max())) if ids.numel() else (0, 0)
            listed = ids.tolist()
        else:
            ids = np.asarray(env_ids, dtype=int).reshape(-1)
            lo, hi = (int(ids.min()), int(ids.max())) if ids.size else (0, 0)
            listed = ids.tolist()
        if lo < -self.num_envs or hi >= self.num_envs:
            raise SensorError(f"env_ids: expected indices in [0, {self.num_envs}), got {listed}")
        if self.cfg.output == "torch":
            return ids.to(self._data.distances.device)
        return ids

    def _take(self, array: Any, env_ids: Sequence[int] | np.ndarray | None) -> Any:
        """Rows of an output: a copy for numpy; for torch/warp the live buffer itself when
        ``env_ids`` is None (valid until the next update), else the selected rows."""
        if self.cfg.output == "numpy":
            return array[self._rows(env_ids)].copy()
        if env_ids is None:
            return array
        if self.cfg.output == "warp":
            raise SensorError(
                "env_ids: warp outputs are whole buffers; use output='torch' to index"
            )
        return array[self._rows(env_ids)]

    def get_distances(self, env_ids: Sequence[int] | np.ndarray | None = None) -> Any:
        """Ranges ``(num_envs, num_rays)`` [m]; misses hold ``cfg.miss_distance``."""
        return self._take(self._data.distances, env_ids)

    def get_pointcloud(
        self, env_ids: Sequence[int] | np.ndarray | None = None, frame: str = "world"
    ) -> Any:
        """Hit points ``(num_envs, num_rays, 3)`` [m], NaN for misses.

        Args:
            frame: ``"world"`` or ``"sensor"`` (the sensor's own frame, offset included).
        """
        if frame not in ("world", "sensor"):
            raise SensorError(f"frame: expected 'world' or 'sensor', got {frame!r}")
        pts = self._take(self._data.hit_points_w, env_ids)
        if frame == "world":
            return pts
        if self.cfg.output == "warp":
            raise SensorError("frame='sensor' needs output='numpy' or 'torch'")
        # The sensor pose at scan time (not the current one): p_s = R^T (p_w - pos).
        rows = self._rows(env_ids)
        pos = self._data.pos_w[rows]
        if self.cfg.output == "torch":
            assert self._pipeline is not None
            import warp as wp

            mat = wp.to_torch(self._pipeline.sensor_mat)[rows]
            import torch

            return torch.einsum("eji,enj->eni", mat, pts - pos[:, None, :])
        quat = self._data.quat_w[rows]
        mat = np.stack([_quat_to_mat(q) for q in quat]) if len(quat) else np.zeros((0, 3, 3))
        return np.einsum("eji,enj->eni", mat, pts - pos[:, None, :])

    def get_hit_mask(self, env_ids: Sequence[int] | np.ndarray | None = None) -> Any:
        """``(num_envs, num_rays)`` bool, True where a ray returned a point."""
        return self._take(self._data.hit_mask, env_ids)

    def __repr__(self) -> str:
        return (
            f"{type(self).__name__}(prim_path={self.cfg.prim_path!r}, num_envs={self.num_envs}, "
            f"num_rays={self.num_rays}, engine={self.engine_name!r}, device={self.device!r}, "
            f"output={self.cfg.output!r}, max_distance={self.max_distance})"
        )
