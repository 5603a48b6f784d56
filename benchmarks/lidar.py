"""LiDAR throughput: robotwright's engines vs raw ``mj_multiRay`` vs mujoco-lidar, same scenes.

Scenes (built here with MjSpec): a ground plane, 20 primitives (sphere, box, capsule,
cylinder, ellipsoid) and one 5120-triangle mesh, plus a robot carrying the sensor; the
"hfield" variant replaces the plane with a 256x256 heightfield. One frame = 20 000 rays
(Mid-360-like pattern) per environment, for 1 and 16 environments (each environment has
its own robot pose).

Contenders, timed per frame on the same poses and directions:
  raw mj_multiRay       one mj_multiRay call per environment, one thread, no labels
  robotwright mujoco/1t SemanticLidarSensor.update() (labels on), engine "mujoco", 1 thread
  robotwright mujoco/Nt the same on every core
  robotwright warp      engine "warp" (mujoco-warp BVH; CPU device here, CUDA when present)
  mujoco-lidar cpu/warp MjLidarWrapper backends, when the package is installed (no labels)

Prints medians of --repeats frames and the ratios to raw mj_multiRay.
Run: python benchmarks/lidar.py [--repeats 7] [--envs 1 16] [--scenes plane hfield]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time

import mujoco
import numpy as np
import trimesh

from robotwright.sensors import (
    LivoxPatternCfg,
    SemanticLidarCfg,
    SemanticLidarSensor,
    warp_available,
)

NUM_RAYS = 20_000


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


def median_time(fn, repeats: int) -> float:
    fn()  # warm-up (JIT compile, caches)
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def bench_scene(kind: str, num_envs: int, repeats: int) -> list[tuple[str, float]]:
    model = build_scene(kind)
    datas = make_envs(model, num_envs)
    pattern = LivoxPatternCfg(num_rays=NUM_RAYS)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "lidar")
    robot = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "robot")
    dirs_s = pattern.rays(0)[1]
    world_dirs = [
        np.ascontiguousarray(dirs_s @ d.site_xmat[site].reshape(3, 3).T).ravel() for d in datas
    ]
    geomid = np.empty(NUM_RAYS, dtype=np.int32)
    dist = np.empty(NUM_RAYS)

    def raw() -> None:
        for d, v in zip(datas, world_dirs, strict=True):
            mujoco.mj_multiRay(
                model, d, d.site_xpos[site], v, None, 1, robot, geomid, dist, None, NUM_RAYS, 40.0
            )

    results = [("raw mj_multiRay (1 thread, no labels)", median_time(raw, repeats))]
    common = dict(prim_path="lidar", pattern_cfg=pattern, max_distance=40.0, return_mesh_ids=True)
    ncpu = os.cpu_count() or 1
    for label, extra in [
        ("robotwright mujoco, 1 thread, labels", dict(engine="mujoco", num_threads=1)),
        (f"robotwright mujoco, {ncpu} threads, labels", dict(engine="mujoco", num_threads=ncpu)),
    ]:
        sensor = SemanticLidarSensor(SemanticLidarCfg(**common, **extra), model, datas)
        results.append((label, median_time(sensor.update, repeats)))
    if warp_available():
        sensor = SemanticLidarSensor(SemanticLidarCfg(**common, engine="warp"), model, datas)
        dev = sensor._engine.device
        results.append((f"robotwright warp ({dev}), labels", median_time(sensor.update, repeats)))
    try:
        from mujoco_lidar import MjLidarWrapper
    except ImportError:
        print("  (mujoco-lidar not installed: skipped)")
    else:
        theta = np.arctan2(dirs_s[:, 1], dirs_s[:, 0])
        phi = np.arcsin(np.clip(dirs_s[:, 2], -1, 1))
        # Same hittable set as the others: everything but the robot body.
        cpu = MjLidarWrapper(
            model, "lidar", backend="cpu", cutoff_dist=40.0, args={"bodyexclude": robot}
        )

        def ml_cpu() -> None:
            for d in datas:
                cpu.trace_rays(d, theta, phi)

        results.append(("mujoco-lidar cpu (no labels)", median_time(ml_cpu, repeats)))
        if warp_available():
            wrp = MjLidarWrapper(
                model,
                "lidar",
                backend="warp",
                cutoff_dist=40.0,
                args={"bodyexclude": robot, "device": "cpu"},
            )
            xpos = np.stack([d.geom_xpos for d in datas])
            xmat = np.stack([d.geom_xmat for d in datas])
            spos = np.stack([d.site_xpos[site] for d in datas])
            srot = np.stack([d.site_xmat[site].reshape(3, 3) for d in datas])

            def ml_warp() -> None:
                wrp.trace_rays_batch(xpos, xmat, spos, srot, theta, phi)

            results.append(("mujoco-lidar warp (cpu, no labels)", median_time(ml_warp, repeats)))
    return results


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--envs", type=int, nargs="+", default=[1, 16])
    ap.add_argument("--scenes", nargs="+", default=["plane", "hfield"], choices=["plane", "hfield"])
    args = ap.parse_args()
    print(
        f"mujoco {mujoco.__version__}, {os.cpu_count()} CPU cores, {NUM_RAYS} rays per frame per env"
    )
    for kind in args.scenes:
        for n in args.envs:
            print(f"\nscene={kind} envs={n}  (median of {args.repeats} frames)")
            results = bench_scene(kind, n, args.repeats)
            base = results[0][1]
            for label, t in results:
                mrays = n * NUM_RAYS / t / 1e6
                print(
                    f"  {label:45s} {t * 1e3:9.2f} ms/frame {mrays:8.2f} Mrays/s  x{base / t:5.2f} vs raw"
                )


if __name__ == "__main__":
    main()
