"""Ray engines: cast world-frame rays against a MuJoCo scene, return distance and geom id.

Both engines take the geom poses that MuJoCo computed (``MjData.geom_xpos`` /
``geom_xmat``) for each environment and return, per ray, the distance along the unit
direction [m] (``-1`` when nothing is hit) and the id of the hit geom (``-1`` on a miss).

* :class:`MujocoRayEngine`: ``mujoco.mj_multiRay`` (float64, the reference), run on a
  pool of threads over environments or ray chunks (MuJoCo releases the GIL).
* :class:`WarpRayEngine`: ``mujoco_warp.rays`` with MuJoCo Warp's scene BVH, every
  environment in one kernel launch, on warp's CPU device or on CUDA (float32).

Which geoms are hittable is decided once, in :func:`make_ray_model`: the engines work on
a private copy of the model where hittable geoms sit in group 0 and are opaque, and all
others in group 1, so MuJoCo's own geom-group filter does the selection at no cost.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import mujoco
import numpy as np

from robotwright.errors import SensorError

__all__ = [
    "make_ray_model",
    "MujocoRayEngine",
    "WarpRayEngine",
    "refine_curved_hits",
    "warp_available",
]

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


def _split(n: int, parts: int) -> list[tuple[int, int]]:
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
        tasks = [(e, a, b) for e in range(num_envs) for a, b in _split(num_rays, per_env)]
        groups = [tasks[i :: self.num_threads] for i in range(self.num_threads)]

        def run(worker: int) -> None:
            scratch = self._scratch[worker]
            last_env = -1
            for e, a, b in groups[worker]:
                if e != last_env:
                    for name in self._pose_fields:
                        getattr(scratch, name)[:] = getattr(datas[e], name)
                    last_env = e
                # World directions of this chunk, computed in the worker (numpy releases the GIL).
                vec = directions_s[a:b] @ rot[e].T
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
                    pnt = origins_s[a:b] @ rot[e].T + pos[e]
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


_SPHERE, _CAPSULE, _ELLIPSOID, _CYLINDER = (
    int(mujoco.mjtGeom.mjGEOM_SPHERE),
    int(mujoco.mjtGeom.mjGEOM_CAPSULE),
    int(mujoco.mjtGeom.mjGEOM_ELLIPSOID),
    int(mujoco.mjtGeom.mjGEOM_CYLINDER),
)


def _quadric_roots(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Both roots of a t^2 + 2 b t + c = 0 (NaN where none), numerically stable."""
    disc = b * b - a * c
    ok = (disc >= 0) & (a > 0)
    sq = np.sqrt(np.where(ok, disc, 0.0))
    q = -(b + np.copysign(sq, b))
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = np.where(ok, q / a, np.nan)
        t2 = np.where(ok & (q != 0), c / q, np.where(ok, -b / np.where(a > 0, a, 1.0), np.nan))
    return t1, t2


def refine_curved_hits(
    model: mujoco.MjModel,
    geom_xpos: np.ndarray,
    geom_xmat: np.ndarray,
    origins_s: np.ndarray,
    directions_s: np.ndarray,
    rot: np.ndarray,
    pos: np.ndarray,
    dist: np.ndarray,
    geomid: np.ndarray,
) -> None:
    """Recompute, in float64, the distance of hits on spheres, capsules, ellipsoids and cylinders.

    A float32 quadratic solve loses about ``sqrt(eps32) * radius`` (up to ~1e-4 m)
    on grazing rays; box, plane, mesh and heightfield hits only lose ``eps32 * t``.
    The engine already found which geom each ray hits, so the exact float64 root is
    the candidate surface intersection nearest to the float32 distance.

    Args:
        geom_xpos, geom_xmat: ``(E, ngeom, 3)`` and ``(E, ngeom, 9)`` geom poses.
        origins_s, directions_s, rot, pos: the rays, as in :meth:`MujocoRayEngine.cast`.
        dist, geomid: ``(E, N)`` engine results, refined in place.
    """
    gtype = model.geom_type
    curved = np.zeros(model.ngeom + 1, dtype=bool)
    curved[1:] = np.isin(gtype, (_SPHERE, _CAPSULE, _ELLIPSOID, _CYLINDER))
    e_idx, r_idx = np.nonzero(curved[geomid + 1])
    if e_idx.size == 0:
        return
    g = geomid[e_idx, r_idx]
    gpos = geom_xpos[e_idx, g]
    mat = geom_xmat[e_idx, g].reshape(-1, 3, 3)
    # World rays of the selected hits only, then in the geom frame: p = R^T (o - x), v = R^T d.
    ray_rot = rot[e_idx]
    origin_w = np.einsum("kij,kj->ki", ray_rot, origins_s[r_idx]) + pos[e_idx]
    dir_w = np.einsum("kij,kj->ki", ray_rot, directions_s[r_idx])
    p = np.einsum("kji,kj->ki", mat, origin_w - gpos)
    v = np.einsum("kji,kj->ki", mat, dir_w)
    size = model.geom_size[g]
    kind = gtype[g]
    t0 = dist[e_idx, r_idx]
    refined = t0.copy()
    # Each geom type only evaluates its own surfaces (few array passes per subset).
    for kinds, candidates in (
        ((_SPHERE, _ELLIPSOID), _ellipsoid_candidates),
        ((_CAPSULE,), _capsule_candidates),
        ((_CYLINDER,), _cylinder_candidates),
    ):
        sel = np.flatnonzero(np.isin(kind, kinds))
        if sel.size == 0:
            continue
        sz = size[sel]
        if kinds[0] == _SPHERE:
            sz = np.where((kind[sel] == _ELLIPSOID)[:, None], sz, sz[:, :1])
        with np.errstate(divide="ignore", invalid="ignore"):
            stack = np.stack(candidates(p[sel], v[sel], sz), axis=1)
        err = np.abs(stack - t0[sel, None])
        err[~(stack >= 0)] = np.inf  # NaN (no root) and roots behind the origin
        best = np.argmin(err, axis=1)
        rows = np.arange(sel.size)
        ok = np.isfinite(err[rows, best])
        refined[sel[ok]] = stack[rows, best][ok]
    dist[e_idx, r_idx] = refined


def _ellipsoid_candidates(p: np.ndarray, v: np.ndarray, radii: np.ndarray) -> list[np.ndarray]:
    ps, vs = p / radii, v / radii
    return list(_quadric_roots((vs * vs).sum(1), (ps * vs).sum(1), (ps * ps).sum(1) - 1.0))


def _side_candidates(
    p: np.ndarray, v: np.ndarray, r: np.ndarray, h: np.ndarray
) -> list[np.ndarray]:
    """Infinite cylinder x^2 + y^2 = r^2 restricted to |z| <= h."""
    out = []
    for t in _quadric_roots(
        v[:, 0] ** 2 + v[:, 1] ** 2,
        p[:, 0] * v[:, 0] + p[:, 1] * v[:, 1],
        p[:, 0] ** 2 + p[:, 1] ** 2 - r * r,
    ):
        out.append(np.where(np.abs(p[:, 2] + t * v[:, 2]) <= h, t, np.nan))
    return out


def _capsule_candidates(p: np.ndarray, v: np.ndarray, size: np.ndarray) -> list[np.ndarray]:
    r, h = size[:, 0], size[:, 1]
    out = _side_candidates(p, v, r, h)
    vv = (v * v).sum(1)
    for sign in (-1.0, 1.0):  # hemispherical caps: spheres of radius r at z = +-h
        pc = p.copy()
        pc[:, 2] -= sign * h
        for t in _quadric_roots(vv, (pc * v).sum(1), (pc * pc).sum(1) - r * r):
            out.append(np.where(sign * (p[:, 2] + t * v[:, 2]) >= h, t, np.nan))
    return out


def _cylinder_candidates(p: np.ndarray, v: np.ndarray, size: np.ndarray) -> list[np.ndarray]:
    r, h = size[:, 0], size[:, 1]
    out = _side_candidates(p, v, r, h)
    for sign in (-1.0, 1.0):  # flat caps: discs at z = +-h
        t = (sign * h - p[:, 2]) / v[:, 2]
        x, y = p[:, 0] + t * v[:, 0], p[:, 1] + t * v[:, 1]
        out.append(np.where(x * x + y * y <= r * r, t, np.nan))
    return out


def warp_available() -> bool:
    """True when ``warp`` and ``mujoco_warp`` import (the ``robotwright[warp]`` extra)."""
    try:
        import mujoco_warp  # noqa: F401
        import warp  # noqa: F401
    except ImportError:
        return False
    return True


class WarpRayEngine:
    """Batched rays for ``num_envs`` worlds with MuJoCo Warp (scene BVH, float32).

    Runs on warp's CPU device or on CUDA. Only the hittable geoms (group 0 of the ray
    model) enter the BVH. Geom poses are uploaded from the ``MjData`` of each
    environment, the BVH is refit, and one kernel casts every ray of every world.
    With ``refine`` (default) hits on curved primitives get their distance recomputed
    in float64 on the host (:func:`refine_curved_hits`).

    Known difference from ``mj_multiRay`` (mujoco-warp 4.0): a heightfield is only its
    top surface, so rays that MuJoCo stops on a heightfield's vertical sides pass
    through here.
    """

    name = "warp"

    def __init__(
        self,
        ray_model: mujoco.MjModel,
        num_envs: int,
        device: str | None = None,
        refine: bool = True,
    ) -> None:
        self.refine = refine
        try:
            import warp as wp

            wp.config.quiet = True  # before mujoco_warp initialises warp: no banner on stdout
            import mujoco_warp as mjw
            from mujoco_warp._src.types import vec6
        except ImportError as exc:
            raise SensorError(
                "engine='warp' needs the optional warp extra: pip install 'robotwright[warp]' "
                f"(import failed: {exc})"
            ) from exc
        self._wp = wp
        self._mjw = mjw
        wp.init()
        if device is None:
            device = "cuda" if wp.get_cuda_device_count() > 0 else "cpu"
        try:
            self.device = wp.get_device(device)
        except Exception as exc:  # warp raises a bare RuntimeError for unknown devices
            raise SensorError(f"warp device {device!r} is not available: {exc}") from exc
        self.model = ray_model
        self.num_envs = int(num_envs)
        with wp.ScopedDevice(self.device):
            self._m = mjw.put_model(ray_model)
            self._d: Any = None  # device copy of host poses, made on first host-data cast
            self._rc = mjw.create_render_context(
                ray_model,
                nworld=self.num_envs,
                cam_res=(1, 1),
                render_rgb=False,
                render_depth=False,
                use_textures=False,
                enabled_geom_groups=[0],
            )
        self._geomgroup = vec6(1, 0, 0, 0, 0, 0)
        self._buffers: dict[str, Any] = {}
        from robotwright.sensors import _warp_kernels

        self._kernels = _warp_kernels

    def _alloc(self, num_rays: int) -> dict[str, Any]:
        if self._buffers.get("num_rays") != num_rays:
            wp = self._wp
            shape = (self.num_envs, num_rays)
            with wp.ScopedDevice(self.device):
                self._buffers = {
                    "num_rays": num_rays,
                    "pat_o": wp.empty(num_rays, dtype=wp.vec3),
                    "pat_d": wp.empty(num_rays, dtype=wp.vec3),
                    "rot": wp.empty(self.num_envs, dtype=wp.mat33),
                    "pos": wp.empty(self.num_envs, dtype=wp.vec3),
                    "pnt": wp.empty(shape, dtype=wp.vec3),
                    "vec": wp.empty(shape, dtype=wp.vec3),
                    "bodyexclude": wp.full(num_rays, -1, dtype=int),
                    "dist": wp.empty(shape, dtype=float),
                    "geomid": wp.empty(shape, dtype=int),
                    "normal": wp.empty(shape, dtype=wp.vec3),
                }
        return self._buffers

    def cast(
        self,
        datas: Sequence[mujoco.MjData] | Any,
        origins_s: np.ndarray,
        directions_s: np.ndarray,
        rot: np.ndarray,
        pos: np.ndarray,
        cutoff: float,
        single_origin: bool,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Same contract as :meth:`MujocoRayEngine.cast` (rays cast in float32).

        ``datas`` may also be a ``mujoco_warp.Data`` on this engine's device: its geom
        poses are used in place (nothing uploaded but the pattern and the sensor poses).

        Only the pattern (``N`` rays) and one pose per environment are uploaded; the
        world rays of every environment are made on the device.
        """
        wp, mjw = self._wp, self._mjw
        num_envs, num_rays = rot.shape[0], directions_s.shape[0]
        if num_envs != self.num_envs:
            raise SensorError(f"warp engine built for {self.num_envs} environments, got {num_envs}")
        buf = self._alloc(num_rays)
        on_device = not isinstance(datas, (list, tuple))
        if on_device:
            # A mujoco_warp.Data: its geom poses are already on the device.
            dev_data = datas
            if dev_data.geom_xpos.device != self.device:
                raise SensorError(
                    f"mujoco_warp.Data is on {dev_data.geom_xpos.device}, the sensor on {self.device}: "
                    "set LidarCfg.device to match"
                )
        else:
            if self._d is None:
                with wp.ScopedDevice(self.device):
                    self._d = mjw.make_data(self.model, nworld=self.num_envs)
            dev_data = self._d
            geom_xpos = np.stack([d.geom_xpos for d in datas])
            geom_xmat = np.stack([d.geom_xmat for d in datas])
        with wp.ScopedDevice(self.device):
            if not on_device:
                self._d.geom_xpos.assign(geom_xpos.astype(np.float32))
                self._d.geom_xmat.assign(geom_xmat.astype(np.float32).reshape(num_envs, -1, 3, 3))
            buf["pat_o"].assign(np.asarray(origins_s, dtype=np.float32))
            buf["pat_d"].assign(np.asarray(directions_s, dtype=np.float32))
            buf["rot"].assign(np.asarray(rot, dtype=np.float32))
            buf["pos"].assign(np.asarray(pos, dtype=np.float32))
            wp.launch(
                self._kernels.world_rays,
                dim=(num_envs, num_rays),
                inputs=[buf["pat_o"], buf["pat_d"], buf["rot"], buf["pos"]],
                outputs=[buf["pnt"], buf["vec"]],
            )
            mjw.refit_bvh(self._m, dev_data, self._rc)
            mjw.rays(
                self._m,
                dev_data,
                buf["pnt"],
                buf["vec"],
                self._geomgroup,
                True,
                buf["bodyexclude"],
                buf["dist"],
                buf["geomid"],
                buf["normal"],
                self._rc,
            )
            out_dist = buf["dist"].numpy().astype(np.float64)
            out_ids = buf["geomid"].numpy().astype(np.int32)
        if self.refine:
            if on_device:  # float32 poses from the device; the refinement is still float64
                geom_xpos = dev_data.geom_xpos.numpy().astype(np.float64)
                geom_xmat = dev_data.geom_xmat.numpy().astype(np.float64).reshape(num_envs, -1, 9)
            refine_curved_hits(
                self.model,
                geom_xpos,
                geom_xmat,
                origins_s,
                directions_s,
                rot,
                pos,
                out_dist,
                out_ids,
            )
        return out_dist, out_ids
