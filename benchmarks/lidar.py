"""LiDAR throughput: robotwright vs mjlab's RayCastSensor vs mujoco-lidar vs raw ``mj_multiRay``.

Scenes (built here with MjSpec): a ground plane, 20 primitives (sphere, box, capsule,
cylinder, ellipsoid) and one 5120-triangle mesh, plus a robot carrying the sensor; the
"hfield" variant replaces the plane with a 256x256 heightfield. One frame = 20 000 rays
(Mid-360-like pattern) per environment, for 1, 16, 256 (and on CUDA 4096) environments,
each environment with its own robot pose.

Contenders, timed per frame on the same poses and the same ray directions:
  raw mj_multiRay        one mj_multiRay call per environment, one thread, no labels
  robotwright mujoco     SemanticLidarSensor.update() (labels on), engine "mujoco", host
                         numpy: 1 thread with the raw call's fixed directions, 1 thread
                         and every core with the Mid-360 window advancing each frame
  robotwright warp       engine "warp", output "torch", reading a mujoco_warp.Data in
                         place: the RL training path (labels on, nothing leaves the device)
  mjlab RayCastSensor    mjlab's own ray cast (prepare -> refit BVH + rays -> finalize),
                         same directions, no labels (when mjlab is installed: the
                         MuJoCo 3.11 environment of .ci/run)
  mujoco-lidar warp/cpu  MjLidarWrapper backends (no labels; `pip install --no-deps mujoco-lidar==0.3.5`)

Contenders run interleaved (one frame each, in turn) so load from other processes hits
them alike, for at least --repeats rounds and --min-seconds of raw frames; prints median
frame times, rays per second, the ratio to raw mj_multiRay and the fraction of rays that
hit something within 40 m (a check that all do the same work). Slow CPU contenders are
left out above 16 environments (raw mj_multiRay stays as the reference).
Run: python benchmarks/lidar.py [--device cpu|cuda] [--envs 1 16 256] [--scenes plane hfield]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

import mujoco
import numpy as np
import trimesh
from _machine import measured

from robotwright.sensors import (
    FilePatternCfg,
    LivoxPatternCfg,
    SemanticLidarCfg,
    SemanticLidarSensor,
    warp_available,
)

#: Above this many environments the host-side contenders (threads, mujoco-lidar cpu)
#: take seconds per frame and are left out; raw mj_multiRay stays as the reference.
MAX_HOST_ENVS = 16

NUM_RAYS = 20_000


class Contender(NamedTuple):
    """One way to cast a frame: ``run`` is timed, ``hits`` (fraction of rays that hit,
    read from the last frame) is not."""

    label: str
    run: Callable[[], None]
    hits: Callable[[], float]


def build_scene(kind: str) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    world = spec.worldbody
    rng = np.random.default_rng(0)
    if kind == "hfield":
        n = 256
        hf = spec.add_hfield(name="terrain_hf", nrow=n, ncol=n, size=[20.0, 20.0, 1.0, 0.2])
        x = np.linspace(0, 6 * math.pi, n)
        elev = (
            0.5 + 0.25 * np.sin(x)[:, None] * np.cos(0.7 * x)[None, :] + 0.05 * rng.random((n, n))
        )
        hf.userdata = (elev / elev.max()).ravel().tolist()
        world.add_geom(
            name="ground_hf",
            type=mujoco.mjtGeom.mjGEOM_HFIELD,
            hfieldname="terrain_hf",
            pos=[0, 0, -1.0],
        )
    else:
        world.add_geom(name="ground", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[50, 50, 0.1])
    types = [
        (mujoco.mjtGeom.mjGEOM_SPHERE, [0.4, 0, 0]),
        (mujoco.mjtGeom.mjGEOM_BOX, [0.3, 0.4, 0.5]),
        (mujoco.mjtGeom.mjGEOM_CAPSULE, [0.2, 0.5, 0]),
        (mujoco.mjtGeom.mjGEOM_CYLINDER, [0.3, 0.4, 0]),
        (mujoco.mjtGeom.mjGEOM_ELLIPSOID, [0.3, 0.5, 0.4]),
    ]
    names = ["cracker_box", "sugar_box", "chair", "table", "crate"]
    for i in range(20):
        ang = 2 * math.pi * i / 20
        r = 4.0 + 4.0 * (i % 3)
        body = world.add_body(
            name=f"{names[i % 5]}_{i}", pos=[r * math.cos(ang), r * math.sin(ang), 0.6]
        )
        gtype, size = types[i % 5]
        body.add_geom(type=gtype, size=size)
    ico = trimesh.creation.icosphere(subdivisions=4, radius=1.0)  # 5120 triangles
    spec.add_mesh(
        name="SM_Sofa", uservert=ico.vertices.ravel().tolist(), userface=ico.faces.ravel().tolist()
    )
    sofa = world.add_body(name="sofa", pos=[6.0, -2.0, 1.0])
    sofa.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="SM_Sofa")
    robot = world.add_body(name="robot", pos=[0, 0, 0.5])
    robot.add_freejoint()
    robot.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.3, 0.15, 0.1])
    robot.add_site(name="lidar", pos=[0.2, 0, 0.15])
    model = spec.compile()
    assert model.nmeshface == 5120, model.nmeshface
    return model


def make_envs(model: mujoco.MjModel, n: int) -> list[mujoco.MjData]:
    rng = np.random.default_rng(1)
    datas = []
    for _ in range(n):
        d = mujoco.MjData(model)
        d.qpos[:2] = rng.uniform(-1, 1, 2)
        yaw = rng.uniform(-math.pi, math.pi)
        d.qpos[3:7] = [math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)]
        mujoco.mj_forward(model, d)
        datas.append(d)
    return datas


def device_contenders(
    model: mujoco.MjModel,
    datas: list[mujoco.MjData],
    device: str,
    pattern: LivoxPatternCfg,
    dirs_s: np.ndarray,
    robot: int,
) -> list[Contender]:
    """Contenders that run on a warp device and read a mujoco_warp.Data in place."""
    import mujoco_warp as mjw
    import warp as wp

    wp.config.quiet = True
    out = []
    n = len(datas)
    with wp.ScopedDevice(device):
        mw = mjw.put_model(model)
        dw = mjw.put_data(model, datas[0], nworld=n)
        dw.qpos.assign(np.stack([d.qpos for d in datas]).astype(np.float32))
        mjw.kinematics(mw, dw)
    cfg = SemanticLidarCfg(
        prim_path="lidar",
        max_distance=40.0,
        pattern_cfg=pattern,
        engine="warp",
        device=device,
        output="torch",
    )
    sensor = SemanticLidarSensor(cfg, model, dw)

    def ours() -> None:
        sensor.update()
        wp.synchronize_device(device)

    out.append(
        Contender(
            f"robotwright warp ({device}), labels, torch out",
            ours,
            lambda: float(sensor.data.hit_mask.float().mean()),
        )
    )
    mjlab = mjlab_contender(model, mw, dw, device, dirs_s)
    if mjlab is not None:
        out.append(mjlab)
    try:
        from mujoco_lidar import MjLidarWrapper
    except ImportError:
        print("  (mujoco-lidar not installed: skipped; pip install --no-deps mujoco-lidar==0.3.5)")
        return out
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "lidar")
    theta = np.arctan2(dirs_s[:, 1], dirs_s[:, 0])
    phi = np.arcsin(np.clip(dirs_s[:, 2], -1, 1))
    args = {"bodyexclude": robot, "device": device}
    wrp = MjLidarWrapper(model, "lidar", backend="warp", cutoff_dist=40.0, args=args)
    # mujoco-lidar takes host arrays of poses (its API), so they are made once here.
    xpos = np.stack([d.geom_xpos for d in datas])
    xmat = np.stack([d.geom_xmat for d in datas])
    spos = np.stack([d.site_xpos[site] for d in datas])
    srot = np.stack([d.site_xmat[site].reshape(3, 3) for d in datas])

    last: dict[str, np.ndarray] = {}

    def ml_warp() -> None:
        last["dist"], _ = wrp.trace_rays_batch(xpos, xmat, spos, srot, theta, phi)

    def ml_warp_hits() -> float:
        dist = np.asarray(last["dist"])
        return float(((dist > 0) & (dist < 40.0)).mean())

    out.append(Contender(f"mujoco-lidar warp ({device}, no labels)", ml_warp, ml_warp_hits))
    return out


def mujoco_lidar_cpu(
    model: mujoco.MjModel, datas: list[mujoco.MjData], dirs_s: np.ndarray, robot: int
) -> list[Contender]:
    try:
        from mujoco_lidar import MjLidarWrapper
    except ImportError:
        return []
    theta = np.arctan2(dirs_s[:, 1], dirs_s[:, 0])
    phi = np.arcsin(np.clip(dirs_s[:, 2], -1, 1))
    # Same hittable set as the others: everything but the robot body.
    cpu = MjLidarWrapper(
        model, "lidar", backend="cpu", cutoff_dist=40.0, args={"bodyexclude": robot}
    )

    last: list[np.ndarray] = []

    def ml_cpu() -> None:
        last[:] = [cpu.trace_rays(d, theta, phi) for d in datas]

    return [
        Contender(
            "mujoco-lidar cpu (no labels)",
            ml_cpu,
            lambda: float(np.mean([dist >= 0 for dist in last])),
        )
    ]


def mjlab_contender(model, mw, dw, device: str, dirs_s: np.ndarray):
    """mjlab's RayCastSensor on the same model, data and directions (None without mjlab)."""
    try:
        import torch
        from mjlab.sensor.builtin_sensor import ObjRef
        from mjlab.sensor.raycast_sensor import RayCastSensorCfg
        from mjlab.sensor.sensor_context import SensorContext
        from mjlab.sim.sim_data import WarpBridge
    except ImportError:
        print("  (mjlab not installed: skipped; it runs in the MuJoCo 3.11 environment)")
        return None
    import mujoco_warp as mjw
    import warp as wp

    class SameRays:
        """An mjlab pattern that casts our frame-0 Mid-360 directions."""

        def generate_rays(self, mj_model, dev):
            d = torch.as_tensor(dirs_s, dtype=torch.float32, device=dev)
            return torch.zeros_like(d), d

    cfg = RayCastSensorCfg(
        name="bench",
        frame=ObjRef(type="site", name="lidar"),
        pattern=SameRays(),  # type: ignore[arg-type]
        max_distance=40.0,
        include_geom_groups=None,
    )
    sensor = cfg.build()
    # As mjlab's Simulation does: the sensor sees the warp model/data through torch bridges.
    mb, db = WarpBridge(mw, nworld=dw.nworld), WarpBridge(dw)
    sensor.initialize(model, mb, db, device)
    ctx = SensorContext(model, mb, db, [], [sensor], device)

    def run() -> None:
        ctx.prepare()
        with wp.ScopedDevice(device):
            mjw.refit_bvh(mw, dw, ctx.render_context)
            sensor.raycast_kernel(rc=ctx.render_context)
        ctx.finalize()
        wp.synchronize_device(device)

    return Contender(
        f"mjlab RayCastSensor ({device}, no labels)",
        run,
        lambda: float((sensor.data.distances >= 0).float().mean()),
    )


def bench_scene(
    kind: str, num_envs: int, repeats: int, min_seconds: float, device: str
) -> list[tuple[str, float, float]]:
    """(label, median seconds per frame, fraction of rays that hit) for every contender."""
    model = build_scene(kind)
    datas = make_envs(model, num_envs)
    pattern = LivoxPatternCfg(num_rays=NUM_RAYS)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "lidar")
    robot = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "robot")
    dirs_s = pattern.rays(0)[1]
    world_dirs = [
        np.ascontiguousarray(dirs_s @ d.site_xmat[site].reshape(3, 3).T).ravel() for d in datas
    ]
    raw_ids = np.empty((num_envs, NUM_RAYS), dtype=np.int32)
    raw_dist = np.empty((num_envs, NUM_RAYS))

    def raw() -> None:
        for e, (d, v) in enumerate(zip(datas, world_dirs, strict=True)):
            mujoco.mj_multiRay(
                model,
                d,
                d.site_xpos[site],
                v,
                None,
                1,
                robot,
                raw_ids[e],
                raw_dist[e],
                None,
                NUM_RAYS,
                40.0,
            )

    contenders = [
        Contender(
            "raw mj_multiRay (1 thread, no labels)",
            raw,
            lambda: float(((raw_ids >= 0) & (raw_dist <= 40.0)).mean()),
        )
    ]
    common = dict(prim_path="lidar", max_distance=40.0, return_mesh_ids=True)
    # The same 20k directions every frame, as the raw call uses (read from a file of
    # angles), and the Mid-360 pattern advancing every frame (non-repetitive).
    angles = np.stack(
        [np.arctan2(dirs_s[:, 1], dirs_s[:, 0]), np.arcsin(np.clip(dirs_s[:, 2], -1, 1))], 1
    )
    fixed_file = Path(tempfile.mkdtemp()) / "mid360_frame0.npy"
    np.save(fixed_file, angles)
    fixed = FilePatternCfg(path=fixed_file)
    ncpu = os.cpu_count() or 1
    engines = [
        ("mujoco, 1 thread, fixed rays", dict(engine="mujoco", num_threads=1, pattern_cfg=fixed)),
        ("mujoco, 1 thread", dict(engine="mujoco", num_threads=1, pattern_cfg=pattern)),
    ]
    if num_envs <= MAX_HOST_ENVS:
        engines.append(
            (
                f"mujoco, {ncpu} threads",
                dict(engine="mujoco", num_threads=ncpu, pattern_cfg=pattern),
            )
        )
    for label, extra in engines:
        sensor = SemanticLidarSensor(SemanticLidarCfg(**common, **extra), model, datas)

        def ours(sensor: SemanticLidarSensor = sensor) -> None:
            sensor.update()
            sensor.get_semantic_labels()

        contenders.append(
            Contender(
                f"robotwright {label}, labels",
                ours,
                lambda sensor=sensor: float(sensor.data.hit_mask.mean()),
            )
        )
    if warp_available():
        contenders += device_contenders(model, datas, device, pattern, dirs_s, robot)
    if num_envs <= MAX_HOST_ENVS:
        contenders += mujoco_lidar_cpu(model, datas, dirs_s, robot)
    hits = {}
    for c in contenders:  # warm-up: JIT compile, caches
        c.run()
        c.run()
        hits[c.label] = c.hits()
    # Short frames get more rounds (at least min_seconds of raw frames, at most 300).
    t0 = time.perf_counter()
    raw()
    rounds = max(repeats, min(300, math.ceil(min_seconds / (time.perf_counter() - t0))))
    # Interleave the contenders so that load from other processes hits them alike.
    # Only the casts are timed: the hit-fraction checks (a torch reduction, say) would
    # add their own cost and, through torch's spinning worker threads, slow the next
    # contender's threads.
    times: dict[str, list[float]] = {c.label: [] for c in contenders}
    for _ in range(rounds):
        for c in contenders:
            t0 = time.perf_counter()
            c.run()
            times[c.label].append(time.perf_counter() - t0)
    print(f"  ({rounds} interleaved rounds)")
    return [(c.label, statistics.median(times[c.label]), hits[c.label]) for c in contenders]


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--repeats", type=int, default=7, help="minimum rounds per case")
    ap.add_argument("--min-seconds", type=float, default=1.0, help="minimum raw time per case")
    ap.add_argument("--envs", type=int, nargs="+", default=[1, 16, 256])
    ap.add_argument("--device", default="cpu", help="warp device of the device contenders")
    ap.add_argument("--scenes", nargs="+", default=["plane", "hfield"], choices=["plane", "hfield"])
    args = ap.parse_args()
    print(f"mujoco {mujoco.__version__}, {os.cpu_count()} CPU cores, {NUM_RAYS} rays/frame/env")
    for kind in args.scenes:
        for n in args.envs:
            print(f"\nscene={kind} envs={n}  (median frame time)")
            results = bench_scene(kind, n, args.repeats, args.min_seconds, args.device)
            base = results[0][1]
            for label, t, hit in results:
                mrays = n * NUM_RAYS / t / 1e6
                print(
                    f"  {label:48s} {t * 1e3:9.2f} ms/frame {mrays:7.2f} Mrays/s"
                    f"  x{base / t:6.2f} vs raw  hits {hit:6.1%}"
                )


if __name__ == "__main__":
    with measured(("mujoco-warp", "warp-lang", "mjlab", "mujoco-lidar")):
        main()
