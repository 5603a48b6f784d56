"""Ray engines: cast world-frame rays against a MuJoCo scene, return distance and geom id.

The engines take the geom poses that MuJoCo computed (``MjData.geom_xpos`` /
``geom_xmat``) for each environment and return, per ray, the distance along the unit
direction [m] (``-1`` when nothing is hit) and the id of the hit geom (``-1`` on a miss).

* :class:`MujocoRayEngine`: ``mujoco.mj_multiRay`` (float64, the reference), run on a
  pool of threads over environments or ray chunks (MuJoCo releases the GIL).
* the warp engine is a whole device-resident pipeline, in
  :mod:`robotwright.sensors.device` (``mujoco_warp.rays`` over MuJoCo Warp's BVH).

Which geoms are hittable is decided once, in :func:`make_ray_model`: the engines work on
a private copy of the model where hittable geoms sit in group 0 and are opaque, and all
others in group 1, so MuJoCo's own geom-group filter does the selection at no cost.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor

import mujoco
import numpy as np

from robotwright.errors import SensorError

__all__ = ["make_ray_model", "MujocoRayEngine", "warp_available"]

#: mj_multiRay's geomgroup filter: only group 0 (the hittable geoms of the ray model).
_GEOMGROUP = np.array([1, 0, 0, 0, 0, 0], dtype=np.uint8)


def make_ray_model(model: mujoco.MjModel, hittable: np.ndarray) -> mujoco.MjModel:
    """A copy of ``model`` in which exactly the geoms flagged in ``hittable`` can be hit.

    MuJoCo's ray functions skip transparent geoms (alpha 0, from rgba or material) and
    filter by geom group; the copy makes hittable geoms opaque and puts them in group 0,
    everything else in group 1. The user's model is not touched.
    """
    hittable = np.asarray(hittable, dtype=bool)
    if hittable.shape != (model.ngeom,):
        raise SensorError(f"hittable mask: expected shape ({model.ngeom},), got {hittable.shape}")
    ray_model = copy.deepcopy(model)
    ray_model.geom_group[:] = np.where(hittable, 0, 1)
    ray_model.geom_matid[hittable] = -1
    ray_model.geom_rgba[hittable, 3] = 1.0
    return ray_model


def split_ranges(n: int, parts: int) -> list[tuple[int, int]]:
    """``parts`` contiguous near-equal ranges covering ``range(n)`` (empty ones dropped)."""
    bounds = [n * k // parts for k in range(parts + 1)]
    return [(a, b) for a, b in zip(bounds[:-1], bounds[1:], strict=True) if b > a]


class MujocoRayEngine:
    """``mj_multiRay`` on CPU threads (reference engine, float64).

    Each worker thread owns a scratch ``MjData`` of the ray model into which the geom
    poses of the environment it works on are copied, so the user's ``MjData`` are only
    read and threads never share MuJoCo's stack.
    """

    name = "mujoco"

    def __init__(self, ray_model: mujoco.MjModel, num_threads: int | None = None) -> None:
        self.model = ray_model
        self.num_threads = max(1, int(num_threads or os.cpu_count() or 1))
        self._scratch = [mujoco.MjData(ray_model) for _ in range(self.num_threads)]
        # What mj_multiRay reads from MjData: geom poses, and body inertial frames for
        # its per-body culling (measured: without xipos/ximat it culls wrongly).
        self._pose_fields = ("geom_xpos", "geom_xmat", "xipos", "ximat")
        if ray_model.nflex:
            self._pose_fields += ("flexvert_xpos",)
        self._pool = ThreadPoolExecutor(self.num_threads) if self.num_threads > 1 else None

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=False)
            self._pool = None

    def __del__(self) -> None:  # pragma: no cover - best effort at interpreter teardown
        self.close()

    def cast(
        self,
        datas: Sequence[mujoco.MjData],
        origins_s: np.ndarray,
        directions_s: np.ndarray,
        rot: np.ndarray,
        pos: np.ndarray,
        cutoff: float,
        single_origin: bool,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Cast one pattern from every environment's sensor pose.

        World rays of environment ``e``: origin ``pos[e] + rot[e] @ origins_s[i]``,
        direction ``rot[e] @ directions_s[i]``.

        Args:
            datas: one ``MjData`` per environment holding the current poses (only read).
            origins_s: ``(N, 3)`` ray origins in the sensor frame [m].
            directions_s: ``(N, 3)`` unit ray directions in the sensor frame.
            rot: ``(E, 3, 3)`` rotation of the rays of each environment (world frame).
            pos: ``(E, 3)`` sensor position of each environment (world frame) [m].
            cutoff: geoms further than this are skipped [m] (a speed hint only).
            single_origin: ``origins_s`` is all zero, so every ray of an environment
                starts at ``pos[e]`` (one ``mj_multiRay`` call shares its culling).

        Returns:
            distances ``(E, N)`` float64 (-1 on a miss) and geom ids ``(E, N)`` int32.
        """
        num_envs, num_rays = rot.shape[0], directions_s.shape[0]
        dist = np.empty((num_envs, num_rays), dtype=np.float64)
        geomid = np.empty((num_envs, num_rays), dtype=np.int32)
        directions_s = np.asarray(directions_s, dtype=np.float64)
        origins_s = np.asarray(origins_s, dtype=np.float64)
        # Enough chunks to keep every thread busy, whole environments when there are many.
        per_env = max(1, -(-self.num_threads // num_envs))
        tasks = [(e, a, b) for e in range(num_envs) for a, b in split_ranges(num_rays, per_env)]
        groups = [tasks[i :: self.num_threads] for i in range(self.num_threads)]

        def run(worker: int) -> None:
            scratch = self._scratch[worker]
            last_env = -1
            for e, a, b in groups[worker]:
                if e != last_env:
                    for name in self._pose_fields:
                        getattr(scratch, name)[:] = getattr(datas[e], name)
                    last_env = e
                # World directions of this chunk, computed in the worker (numpy releases the
                # GIL); a contiguous R^T makes this (n, 3) @ (3, 3) product ~3x faster.
                rot_t = np.ascontiguousarray(rot[e].T)
                vec = directions_s[a:b] @ rot_t
                if single_origin:
                    mujoco.mj_multiRay(
                        self.model,
                        scratch,
                        pos[e],
                        vec.ravel(),
                        _GEOMGROUP,
                        1,
                        -1,
                        geomid[e, a:b],
                        dist[e, a:b],
                        None,
                        b - a,
                        cutoff,
                    )
                else:
                    pnt = origins_s[a:b] @ rot_t + pos[e]
                    gid = np.empty(1, dtype=np.int32)
                    for i in range(b - a):
                        dist[e, a + i] = mujoco.mj_ray(
                            self.model, scratch, pnt[i], vec[i], _GEOMGROUP, 1, -1, gid
                        )
                        geomid[e, a + i] = gid[0]

        busy = [w for w in range(self.num_threads) if groups[w]]
        if self._pool is None or len(busy) == 1:
            for w in busy:
                run(w)
        else:
            list(self._pool.map(run, busy))
        return dist, geomid


def warp_available() -> bool:
    """True when ``warp`` and ``mujoco_warp`` import (the ``robotwright[warp]`` extra)."""
    try:
        import mujoco_warp  # noqa: F401
        import warp  # noqa: F401
    except ImportError:
        return False
    return True
