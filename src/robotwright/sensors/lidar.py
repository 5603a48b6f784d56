"""``LidarSensor``: a LiDAR carried by a body or site of a MuJoCo model, over 1..N envs.

Frames: ray origins, directions and hit points are in the world frame unless stated;
distances in metres along unit ray directions; quaternions (w, x, y, z).

What a miss returns: ``distance = cfg.miss_distance`` (``inf`` by default), the point is
``(nan, nan, nan)``, ``data.hit_mask`` is False (and, for the semantic sensor, label 0
and mesh id -1). A ray is a miss when it hits nothing hittable, when its hit is nearer
than ``min_distance`` or further than ``max_distance``, or when dropout removes it.
Noise is added to hits only and the noisy range is clipped to
``[min_distance, max_distance]``, so a hit never turns into a miss value by noise.
"""

from __future__ import annotations

import difflib
import fnmatch
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from robotwright.errors import SensorError
from robotwright.sensors.config import LidarCfg
from robotwright.sensors.raycast import MujocoRayEngine, WarpRayEngine, make_ray_model

if TYPE_CHECKING:  # the warp extra is optional
    from mujoco_warp import Data as WarpData

__all__ = ["LidarSensor", "LidarSensorData", "geom_paths"]


@dataclass
class LidarSensorData:
    """Buffers of the last :meth:`LidarSensor.update` (numpy, one row per environment).

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
        self._cache.clear()


def _name(model: mujoco.MjModel, obj: mujoco.mjtObj, idx: int, fallback: str) -> str:
    return mujoco.mj_id2name(model, obj, idx) or f"{fallback}{idx}"


def _body_chain(model: mujoco.MjModel, body: int) -> list[int]:
    chain = []
    while body != 0:
        chain.append(body)
        body = int(model.body_parentid[body])
    return chain[::-1]


def geom_paths(model: mujoco.MjModel, with_mesh: bool = True) -> list[str]:
    """Path of every geom: ``/world/<body>/.../<geom>`` (``+ /<mesh>`` for mesh geoms).

    Unnamed bodies and geoms appear as ``body<id>`` / ``geom<id>``.
    """
    paths = []
    for g in range(model.ngeom):
        parts = ["", "world"]
        parts += [
            _name(model, mujoco.mjtObj.mjOBJ_BODY, b, "body")
            for b in _body_chain(model, int(model.geom_bodyid[g]))
        ]
        parts.append(_name(model, mujoco.mjtObj.mjOBJ_GEOM, g, "geom"))
        if (
            with_mesh
            and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH
            and model.geom_dataid[g] >= 0
        ):
            parts.append(_name(model, mujoco.mjtObj.mjOBJ_MESH, int(model.geom_dataid[g]), "mesh"))
        paths.append("/".join(parts))
    return paths


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
            ``engine="warp"``; then geom poses never leave the device). :meth:`update`
            reads the poses they hold (as left by ``mj_step``/``mj_forward`` or
            ``mujoco_warp.step``/``kinematics``); it never writes to them.

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
            if tuple(data.geom_xpos.shape) != (self._num_envs, model.ngeom):
                raise SensorError(
                    f"data: expected a mujoco_warp.Data of this model ({model.ngeom} geoms), "
                    f"got geom_xpos of shape {tuple(data.geom_xpos.shape)}"
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
        if cfg.engine == "warp":
            self._engine: MujocoRayEngine | WarpRayEngine = WarpRayEngine(
                self._ray_model, self.num_envs, cfg.device
            )
        else:
            self._engine = MujocoRayEngine(self._ray_model, cfg.num_threads)
        self._offset_mat = _quat_to_mat(cfg.offset_rot)
        self._offset_pos = np.asarray(cfg.offset_pos, dtype=np.float64)
        self._rng = np.random.default_rng(cfg.seed)
        self._frame = -1
        self._pattern_cache: tuple[np.ndarray, np.ndarray] | None = None
        origins, _ = self._pattern(0)
        self._single_origin = bool(np.all(origins == 0.0))
        self.num_rays = int(origins.shape[0])
        if self.num_rays == 0:
            raise SensorError(f"{type(cfg.pattern_cfg).__name__}: empty pattern (0 rays)")
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
        return self._engine.name

    def _resolve_carrier(self, name: str) -> tuple[str, int, int]:
        m = self.model
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
        if body >= 0:
            return "body", body, body
        site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name)
        if site >= 0:
            return "site", site, int(m.site_bodyid[site])
        names = [_name(m, mujoco.mjtObj.mjOBJ_BODY, i, "") for i in range(m.nbody)]
        names += [_name(m, mujoco.mjtObj.mjOBJ_SITE, i, "") for i in range(m.nsite)]
        close = difflib.get_close_matches(name, [n for n in names if n], n=3)
        hint = f"; did you mean {', '.join(map(repr, close))}?" if close else ""
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
            # name and path, so a body pattern selects that body's whole subtree.
            candidates = []
            for g in range(m.ngeom):
                chain = _body_chain(m, int(m.geom_bodyid[g]))
                names = [_name(m, mujoco.mjtObj.mjOBJ_GEOM, g, "geom"), self._geom_paths[g]]
                prefix = "/world"
                names.append(prefix)
                for b in chain:
                    bname = _name(m, mujoco.mjtObj.mjOBJ_BODY, b, "body")
                    prefix = f"{prefix}/{bname}"
                    names += [bname, prefix]
                if not chain:
                    names.append("world")
                candidates.append(names)
            for pattern in cfg.mesh_prim_paths:
                hits = [
                    g
                    for g in range(m.ngeom)
                    if any(fnmatch.fnmatchcase(c, pattern) for c in candidates[g])
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

    def _make_data(self) -> LidarSensorData:
        e, n = self.num_envs, self.num_rays
        origins, dirs = self._pattern(0)
        return LidarSensorData(
            pos_w=np.zeros((e, 3)),
            quat_w=np.tile([1.0, 0.0, 0.0, 0.0], (e, 1)),
            distances=np.full((e, n), self.cfg.miss_distance),
            hit_mask=np.zeros((e, n), dtype=bool),
            ray_rot_w=np.tile(np.eye(3), (e, 1, 1)),
            pattern_origins=origins,
            pattern_directions=dirs,
        )

    def _pattern(self, frame: int) -> tuple[np.ndarray, np.ndarray]:
        pattern = self.cfg.pattern_cfg
        if pattern.repetitive:
            if self._pattern_cache is None:
                self._pattern_cache = pattern.rays(0)
            return self._pattern_cache
        return pattern.rays(frame)

    # ------------------------------------------------------------------ update
    def sensor_poses(self) -> tuple[np.ndarray, np.ndarray]:
        """Sensor positions ``(E, 3)`` [m] and rotation matrices ``(E, 3, 3)``, world frame."""
        if self._warp_data is not None:
            # Only the carrier's pose comes back from the device.
            wd, i = self._warp_data, self._carrier_id
            if self._carrier_kind == "body":
                p = wd.xpos.numpy()[:, i].astype(np.float64)
                r = wd.xmat.numpy()[:, i].astype(np.float64).reshape(-1, 3, 3)
            else:
                p = wd.site_xpos.numpy()[:, i].astype(np.float64)
                r = wd.site_xmat.numpy()[:, i].astype(np.float64).reshape(-1, 3, 3)
            return p + r @ self._offset_pos, r @ self._offset_mat
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
        """Cast one frame of rays for every environment from the poses in its ``MjData``."""
        self._update_buffers_impl(None)

    def _update_buffers_impl(self, env_ids: Sequence[int] | np.ndarray | None) -> None:
        """Seed hook: cast and fill the buffers (every environment; ``env_ids`` kept for the API)."""
        self._frame += 1
        origins_s, dirs_s = self._pattern(self._frame)
        pos, mat = self.sensor_poses()
        rot = self._ray_rotation(mat)
        raw_dist, geom_ids = self._engine.cast(
            self._warp_data if self._warp_data is not None else self._datas,
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
        hit = geom_ids >= 0
        if cfg.min_distance > 0:
            hit &= dist >= cfg.min_distance
        hit &= dist <= cfg.max_distance
        if cfg.range_noise_std > 0:
            dist = dist + self._rng.normal(0.0, cfg.range_noise_std, size=dist.shape)
            np.clip(dist, cfg.min_distance, cfg.max_distance, out=dist)
        if cfg.dropout_prob > 0:
            hit &= self._rng.random(dist.shape) >= cfg.dropout_prob
        miss = ~hit
        # copyto(where=) is several times faster than boolean-index assignment here.
        np.copyto(dist, cfg.miss_distance, where=miss)
        np.copyto(geom_ids, -1, where=miss)
        self._data.hit_mask = hit
        self._data.distances = dist
        self._raw_geom_ids = geom_ids

    # ------------------------------------------------------------------ getters
    def _rows(self, env_ids: Sequence[int] | np.ndarray | None) -> slice | np.ndarray:
        if env_ids is None:
            return slice(None)
        ids = np.asarray(env_ids, dtype=int).reshape(-1)
        if ids.size and (ids.min() < -self.num_envs or ids.max() >= self.num_envs):
            raise SensorError(
                f"env_ids: expected indices in [0, {self.num_envs}), got {ids.tolist()}"
            )
        return ids

    def get_distances(self, env_ids: Sequence[int] | np.ndarray | None = None) -> np.ndarray:
        """Ranges ``(num_envs, num_rays)`` [m]; misses are ``cfg.miss_distance`` (inf)."""
        return self._data.distances[self._rows(env_ids)].copy()

    def get_pointcloud(
        self, env_ids: Sequence[int] | np.ndarray | None = None, frame: str = "world"
    ) -> np.ndarray:
        """Hit points ``(num_envs, num_rays, 3)`` [m], NaN for misses.

        Args:
            frame: ``"world"`` or ``"sensor"`` (the sensor's own frame, offset included).
        """
        rows = self._rows(env_ids)
        pts = self._data.hit_points_w[rows]
        if frame == "world":
            return pts.copy()
        if frame != "sensor":
            raise SensorError(f"frame: expected 'world' or 'sensor', got {frame!r}")
        # The sensor pose at scan time (not the current one): p_s = R^T (p_w - pos).
        quat = self._data.quat_w[rows]
        mat = np.stack([_quat_to_mat(q) for q in quat]) if len(quat) else np.zeros((0, 3, 3))
        return np.einsum("eji,enj->eni", mat, pts - self._data.pos_w[rows][:, None, :])

    def get_hit_mask(self, env_ids: Sequence[int] | np.ndarray | None = None) -> np.ndarray:
        """``(num_envs, num_rays)`` bool, True where a ray returned a point."""
        return self._data.hit_mask[self._rows(env_ids)].copy()

    def __repr__(self) -> str:
        return (
            f"{type(self).__name__}(prim_path={self.cfg.prim_path!r}, num_envs={self.num_envs}, "
            f"num_rays={self.num_rays}, engine={self.engine_name!r}, max_distance={self.max_distance})"
        )
