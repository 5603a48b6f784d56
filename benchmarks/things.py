"""Benchmark: build a 30-body chain (hinge, capsule, site, motor, 2 sensors per body),
compile it and export it to MJCF text, with Things vs directly with ``mujoco.MjSpec``.

Both sides do the same work in the same run: build the description, compile an
``MjModel``, produce the MJCF string. Prints medians (ms) and the ratio ours/MjSpec.

Run: ``python benchmarks/things.py [--bodies 30] [--repeats 50]``
"""

from __future__ import annotations

import argparse
import statistics
import time

import mujoco
from _machine import measured

from robotwright.things import Body, Capsule, Gyro, Hinge, JointPos, Motor, Site, World


def build_things(n: int) -> World:
    world = World("chain")
    parent: World | Body = world
    for i in range(n):
        body = Body(f"link{i}", pos=[0, 0, 0.1] if i else [0, 0, 1])
        joint = Hinge(f"joint{i}", axis=[0, 1, 0], range=[-1, 1], damping=[0.1])
        joint.attach(Motor(f"motor{i}", gear=[10], ctrlrange=[-1, 1]), JointPos(f"jpos{i}"))
        site = Site(f"site{i}", pos=[0, 0, 0.05])
        site.attach(Gyro(f"gyro{i}"))
        body.attach(
            joint, Capsule(f"geom{i}", radius=0.02, half_length=0.05, pos=[0, 0, 0.05]), site
        )
        parent.attach(body)
        parent = body
    return world


def things_run(n: int) -> tuple[mujoco.MjModel, str]:
    world = build_things(n)
    model = world.model
    return model, world.to_xml_string()


def mjspec_run(n: int) -> tuple[mujoco.MjModel, str]:
    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    parent = spec.worldbody
    for i in range(n):
        body = parent.add_body(name=f"link{i}", pos=[0, 0, 0.1] if i else [0, 0, 1])
        body.add_joint(
            name=f"joint{i}",
            type=mujoco.mjtJoint.mjJNT_HINGE,
            axis=[0, 1, 0],
            range=[-1, 1],
            damping=[0.1, 0, 0],
        )
        body.add_geom(
            name=f"geom{i}",
            type=mujoco.mjtGeom.mjGEOM_CAPSULE,
            size=[0.02, 0.05, 0],
            pos=[0, 0, 0.05],
        )
        body.add_site(name=f"site{i}", pos=[0, 0, 0.05])
        spec.add_actuator(
            name=f"motor{i}",
            target=f"joint{i}",
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            gear=[10, 0, 0, 0, 0, 0],
            ctrlrange=[-1, 1],
        )
        spec.add_sensor(
            name=f"jpos{i}",
            type=mujoco.mjtSensor.mjSENS_JOINTPOS,
            objtype=mujoco.mjtObj.mjOBJ_JOINT,
            objname=f"joint{i}",
        )
        spec.add_sensor(
            name=f"gyro{i}",
            type=mujoco.mjtSensor.mjSENS_GYRO,
            objtype=mujoco.mjtObj.mjOBJ_SITE,
            objname=f"site{i}",
        )
        parent = body
    model = spec.compile()
    return model, spec.to_xml()


def _median_ms(fn, n: int, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn(n)
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bodies", type=int, default=30)
    parser.add_argument("--repeats", type=int, default=50)
    args = parser.parse_args()
    ours_model, _ = things_run(args.bodies)
    ref_model, _ = mjspec_run(args.bodies)
    # Same model on both sides, or the timing means nothing.
    assert (ours_model.nbody, ours_model.nu, ours_model.nsensor) == (
        ref_model.nbody,
        ref_model.nu,
        ref_model.nsensor,
    )
    assert abs(ours_model.body_mass.sum() - ref_model.body_mass.sum()) < 1e-9
    for fn in (things_run, mjspec_run):  # warm-up
        fn(args.bodies)
    ours = _median_ms(things_run, args.bodies, args.repeats)
    ref = _median_ms(mjspec_run, args.bodies, args.repeats)
    build = _median_ms(build_things, args.bodies, args.repeats)
    print(f"{args.bodies}-body chain, build + compile + export to MJCF, median of {args.repeats}:")
    print(f"  robotwright.things : {ours:8.2f} ms   (of which building Things: {build:.2f} ms)")
    print(f"  mujoco.MjSpec      : {ref:8.2f} ms")
    print(f"  ratio things/MjSpec: {ours / ref:8.2f}x  (target <= 3x)")


if __name__ == "__main__":
    with measured(()):
        main()
