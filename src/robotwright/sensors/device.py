"""The device-resident LiDAR pipeline behind ``engine="warp"`` (MuJoCo Warp, CPU or CUDA).

Everything a frame needs lives on the warp device: the pattern table, the label lookup
table, the per-environment seeds, the frame counter and every output buffer. An update
launches five kernels (see :mod:`robotwright.sensors._warp_kernels`) and copies nothing
to the host, so the outputs can be handed out as zero-copy torch tensors or warp arrays
that keep their identity across updates. Given a ``mujoco_warp.Data`` the pipeline reads
the simulation's arrays in place; given host ``MjData`` it uploads their geom poses
(work proportional to geoms, not rays).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from robotwright.errors import SensorError
from robotwright.sensors.patterns import RayTable
from robotwright.sensors.raycast import split_ranges

__all__ = ["WarpLidarPipeline", "RangeModel", "import_warp", "ray_blocks"]

_ALIGN = {"base": 0, "yaw": 1, "world": 2}


def import_warp() -> tuple[Any, Any]:
    """``(warp, mujoco_warp)``, or a :class:`SensorError` naming the extra to install."""
    try:
        from robotwright._warp import quiet_warp

        wp = quiet_warp()  # before mujoco_warp initialises warp
        import mujoco_warp as mjw
    except ImportError as exc:
        raise SensorError(
            "engine='warp' needs the optional warp extra: pip install 'robotwright[warp]' "
            f"(import failed: {exc})"
        ) from exc
    return wp, mjw


def ray_blocks(num_rays: int, device: Any, num_threads: int | None) -> list[tuple[int, int]]:
    """Column blocks ``[a, b)`` of a frame's rays cast by parallel launches: one on CUDA;
    ``num_threads`` (default one per core) on warp's CPU device, which runs a kernel on one
    core (warp releases the GIL while it runs)."""
    threads = 1 if device.is_cuda else max(1, int(num_threads or os.cpu_count() or 1))
    return split_ranges(num_rays, threads)


@dataclass(frozen=True)
class RangeModel:
    """What turns a raw cast into a reading (all lengths in metres).

    Attributes:
        min_distance, max_distance: hits outside ``[min, max]`` are misses.
        noise_std: Gaussian range noise on hits, clipped to ``[min, max]``.
        dropout_prob: probability that a hit is dropped (becomes a miss).
        miss_distance: distance written for a miss.
        seed: base seed; each environment gets its own stream.
    """

    min_distance: float
    max_distance: float
    noise_std: float
    dropout_prob: float
    miss_distance: float
    seed: int


class WarpLidarPipeline:
    """Cast one frame of a pattern for ``num_envs`` worlds on a warp device.

    Args:
        ray_model: model whose group-0 geoms are the hittable ones (see
            :func:`~robotwright.sensors.raycast.make_ray_model`).
        num_envs: number of worlds.
        device: warp device name; ``None`` picks CUDA when present, else the CPU.
        table: the pattern's rays (sensor frame), uploaded once.
        carrier: ``("body" | "site", id)`` that carries the sensor.
        offset_pos, offset_mat: sensor pose in the carrier frame [m].
        alignment: ``"base"``, ``"yaw"`` or ``"world"``.
        range_model: ranges, noise, dropout, miss value, seed.
        label_lut: ``(ngeom + 1,)`` class id per geom, last entry for a miss; ``None``:
            every label is 0.
        refine: recompute curved-primitive hits in float64 (default True).
        num_threads: on warp's CPU device, which runs a kernel on one core, the rays are
            split into this many column blocks cast by parallel launches (warp releases
            the GIL while a CPU kernel runs); ``None``: one per core. CUDA: one launch.

    Attributes (device arrays, shapes ``E`` = envs, ``N`` = rays per frame):
        distances ``(E, N)`` float32, hit_mask ``(E, N)`` bool, geom_ids and labels
        ``(E, N)`` int32, points, ray_origins, ray_directions ``(E, N, 3)`` float32,
        pos_w ``(E, 3)``, quat_w ``(E, 4)`` (w, x, y, z), sensor_mat and ray_rot
        ``(E, 3, 3)``; ``table_o``/``table_d`` the pattern table.
    """

    def __init__(
        self,
        ray_model: mujoco.MjModel,
        num_envs: int,
        device: str | None,
        table: RayTable,
        carrier: tuple[str, int],
        offset_pos: np.ndarray,
        offset_mat: np.ndarray,
        alignment: str,
        range_model: RangeModel,
        label_lut: np.ndarray | None,
        refine: bool = True,
        num_threads: int | None = None,
    ) -> None:
        wp, mjw = import_warp()
        self._wp, self._mjw = wp, mjw
        wp.init()
        from robotwright.sensors import _warp_kernels

        self._k = _warp_kernels
        if device is None:
            device = "cuda" if wp.get_cuda_device_count() > 0 else "cpu"
        try:
            self.device = wp.get_device(device)
        except Exception as exc:  # warp raises a bare RuntimeError for unknown devices
            raise SensorError(f"warp device {device!r} is not available: {exc}") from exc
        self.model = ray_model
        self.num_envs = int(num_envs)
        self.num_rays = int(table.rays_per_frame)
        self._num_frames = int(table.num_frames)
        self._carrier_kind, self._carrier_id = carrier
        self._offset_pos = wp.vec3(*np.asarray(offset_pos, dtype=np.float32))
        self._offset_mat = wp.mat33(*np.asarray(offset_mat, dtype=np.float32).ravel())
        self._alignment = _ALIGN[alignment]
        self.range_model = range_model
        self._refine = int(bool(refine))
        # mujoco_warp.rays takes a 6-vector geom-group filter: only group 0 (hittable).
        self._geomgroup = wp.types.vector(length=6, dtype=float)(1, 0, 0, 0, 0, 0)
        lut = np.zeros(ray_model.ngeom + 1, dtype=np.int32) if label_lut is None else label_lut
        seeds = np.random.SeedSequence(range_model.seed).generate_state(self.num_envs)
        e, n = self.num_envs, self.num_rays
        with wp.ScopedDevice(self.device):
            self._m = mjw.put_model(ray_model)
            self._rc = mjw.create_render_context(
                ray_model,
                nworld=e,
                cam_res=(1, 1),
                render_rgb=False,
                render_depth=False,
                use_textures=False,
                enabled_geom_groups=[0],
            )
            self._host_data: Any = None  # device copy of host poses, made on first use
            self.table_o = wp.array(table.origins.astype(np.float32), dtype=wp.vec3)
            self.table_d = wp.array(table.directions.astype(np.float32), dtype=wp.vec3)
            self.label_lut = wp.array(np.asarray(lut, dtype=np.int32), dtype=wp.int32)
            self.geom_type = wp.array(ray_model.geom_type.astype(np.int32), dtype=wp.int32)
            self.geom_size = wp.array(ray_model.geom_size, dtype=wp.vec3d)
            self.env_seed = wp.array(seeds.astype(np.uint32).view(np.int32), dtype=wp.int32)
            # The frame counter lives on the device so a whole frame is graph-capturable;
            # it starts at -1 (the first update casts frame 0).
            self.frame = wp.array(np.array([-1], dtype=np.int32), dtype=wp.int32)
            self.window = wp.zeros(1, dtype=wp.int32)
            self.pos_w = wp.zeros(e, dtype=wp.vec3)
            self.quat_w = wp.zeros(e, dtype=wp.vec4)
            self.sensor_mat = wp.zeros(e, dtype=wp.mat33)
            self.ray_rot = wp.zeros(e, dtype=wp.mat33)
            self.ray_origins = wp.zeros((e, n), dtype=wp.vec3)
            self.ray_directions = wp.zeros((e, n), dtype=wp.vec3)
            self._raw_dist = wp.zeros((e, n), dtype=wp.float32)
            self._raw_geom = wp.zeros((e, n), dtype=wp.int32)
            self._normal = wp.zeros((e, n), dtype=wp.vec3)
            self._bodyexclude = wp.full(n, -1, dtype=wp.int32)
            self.distances = wp.full((e, n), range_model.miss_distance, dtype=wp.float32)
            self.hit_mask = wp.zeros((e, n), dtype=wp.bool)
            self.geom_ids = wp.full((e, n), -1, dtype=wp.int32)
            self.labels = wp.zeros((e, n), dtype=wp.int32)
            self.points = wp.full((e, n), wp.vec3(np.nan, np.nan, np.nan), dtype=wp.vec3)
            self._carrier_pos = wp.zeros((e, 1), dtype=wp.vec3)
            self._carrier_mat = wp.zeros((e, 1), dtype=wp.mat33)
        self._blocks = ray_blocks(n, self.device, num_threads)
        self._pool = ThreadPoolExecutor(len(self._blocks)) if len(self._blocks) > 1 else None

    def close(self) -> None:
        # getattr: __del__ runs this on a pipeline whose __init__ raised before the pool.
        pool = getattr(self, "_pool", None)
        if pool is not None:
            pool.shutdown(wait=False)
            self._pool = None

    def __del__(self) -> None:  # pragma: no cover - best effort at interpreter teardown
        self.close()

    # ------------------------------------------------------------------ inputs
    def check_data(self, data: Any) -> None:
        """Refuse a ``mujoco_warp.Data`` of another model size or on another device."""
        if tuple(data.geom_xpos.shape) != (self.num_envs, self.model.ngeom):
            raise SensorError(
                f"data: expected a mujoco_warp.Data of this model ({self.model.ngeom} geoms, "
                f"{self.num_envs} worlds), got geom_xpos of shape {tuple(data.geom_xpos.shape)}"
            )
        if data.geom_xpos.device != self.device:
            raise SensorError(
                f"mujoco_warp.Data is on {data.geom_xpos.device}, the sensor on {self.device}: "
                "set LidarCfg.device to match"
            )

    def _upload_host(self, datas: Sequence[mujoco.MjData]) -> tuple[Any, Any, Any, int]:
        """Copy geom poses and the carrier pose of host ``MjData`` to the device."""
        wp, mjw = self._wp, self._mjw
        if self._host_data is None:
            with wp.ScopedDevice(self.device):
                self._host_data = mjw.make_data(self.model, nworld=self.num_envs)
        dev = self._host_data
        e = self.num_envs
        dev.geom_xpos.assign(np.stack([d.geom_xpos for d in datas]).astype(np.float32))
        dev.geom_xmat.assign(
            np.stack([d.geom_xmat for d in datas]).astype(np.float32).reshape(e, -1, 3, 3)
        )
        i = self._carrier_id
        if self._carrier_kind == "body":
            pos = np.stack([d.xpos[i] for d in datas])
            mat = np.stack([d.xmat[i] for d in datas])
        else:
            pos = np.stack([d.site_xpos[i] for d in datas])
            mat = np.stack([d.site_xmat[i] for d in datas])
        self._carrier_pos.assign(pos.astype(np.float32).reshape(e, 1, 3))
        self._carrier_mat.assign(mat.astype(np.float32).reshape(e, 1, 3, 3))
        return dev, self._carrier_pos, self._carrier_mat, 0

    # ------------------------------------------------------------------ one frame
    def update(self, data: Any) -> None:
        """Cast the next frame from ``data``: a ``mujoco_warp.Data`` or a list of ``MjData``.

        Only kernel launches when ``data`` is a ``mujoco_warp.Data`` (graph-capturable).
        """
        wp, mjw, k = self._wp, self._mjw, self._k
        e, n = self.num_envs, self.num_rays
        if isinstance(data, (list, tuple)):
            dev, cpos, cmat, idx = self._upload_host(data)
        else:
            dev, idx = data, self._carrier_id
            if self._carrier_kind == "body":
                cpos, cmat = dev.xpos, dev.xmat
            else:
                cpos, cmat = dev.site_xpos, dev.site_xmat
        with wp.ScopedDevice(self.device):
            wp.launch(
                k.advance_frame,
                dim=1,
                inputs=[self.frame, self._num_frames, n],
                outputs=[self.window],
            )
            wp.launch(
                k.sensor_pose,
                dim=e,
                inputs=[cpos, cmat, idx, self._offset_pos, self._offset_mat, self._alignment],
                outputs=[self.pos_w, self.quat_w, self.sensor_mat, self.ray_rot],
            )
            mjw.refit_bvh(self._m, dev, self._rc)
        blocks = [(a, b, dev) for a, b in self._blocks]
        if self._pool is None:
            for block in blocks:
                self._cast_block(block)
        else:
            list(self._pool.map(self._cast_block, blocks))

    def _cast_block(self, block: tuple[int, int, Any]) -> None:
        """World rays, casting and finishing of the rays ``[a, b)`` of every environment."""
        wp, mjw, k = self._wp, self._mjw, self._k
        a, b, dev = block
        e, rm = self.num_envs, self.range_model
        whole = (a, b) == (0, self.num_rays)

        def cols(array: Any) -> Any:
            return array if whole else array[:, a:b]

        pnt, vec = cols(self.ray_origins), cols(self.ray_directions)
        raw_dist, raw_geom = cols(self._raw_dist), cols(self._raw_geom)
        with wp.ScopedDevice(self.device):
            k.launch_per_ray(
                k.world_rays,
                (e, b - a),
                [self.table_o, self.table_d, self.window, a, self.pos_w, self.ray_rot],
                [pnt, vec],
                pnt.device,
            )
            mjw.rays(
                self._m,
                dev,
                pnt,
                vec,
                self._geomgroup,
                True,
                self._bodyexclude if whole else self._bodyexclude[: b - a],
                raw_dist,
                raw_geom,
                cols(self._normal),
                self._rc,
            )
            k.launch_per_ray(
                k.finish_rays,
                (e, b - a),
                [
                    raw_dist,
                    raw_geom,
                    pnt,
                    vec,
                    dev.geom_xpos,
                    dev.geom_xmat,
                    self.geom_type,
                    self.geom_size,
                    self._refine,
                    rm.min_distance,
                    rm.max_distance,
                    rm.noise_std,
                    rm.dropout_prob,
                    rm.miss_distance,
                    self.env_seed,
                    self.frame,
                    self.label_lut,
                    a,
                ],
                [
                    cols(self.distances),
                    cols(self.hit_mask),
                    cols(self.geom_ids),
                    cols(self.labels),
                    cols(self.points),
                ],
                pnt.device,
            )
