"""Isaac Lab 3 LiDAR cost per update: robotwright's sensors vs Isaac Lab's NewtonRaycastSensor.

One kit-less Isaac Lab scene (Newton, MuJoCo Warp solver): a generated wave terrain, a
sensor carrier (a kinematic box) and four boxes per environment. On the same carrier,
with the same rays (Isaac Lab's LidarPatternCfg, 16 channels x 1 degree = 5 760 rays),
the contenders are:

  Isaac Lab NewtonRaycastSensor    the stock sensor (distances, hit points, normals)
  robotwright LidarSensor          the same cast plus per-ray shape ids and hit mask
  robotwright SemanticLidarSensor  plus a class per ray
  robotwright Semantic, Mid-360    20 000 rays per step, the window following each
                                   environment's simulated time
  robotwright Semantic, see-through  the sensor inside its carrier's box: every ray
                                   passes it (pass_through="skip": one cast whose BVH
                                   walk leaves the box out)
    the same, re-cast              pass_through="recast": a second cast of every ray

Each update is forced (``update(dt, force_recompute=True)``) in turn, one contender after
the other, so load from other processes hits them alike; prints the median time per
update and the ratio to the stock sensor. Needs Isaac Lab 3 (Python 3.12).
Run: python benchmarks/isaaclab_lidar.py [--device cpu|cuda:0] [--envs 4 64] [--rounds 20]
"""

from __future__ import annotations

import argparse
import statistics
import time

from _machine import measured


def scene_cfg(num_envs: int):
    import isaaclab.sim as sim_utils
    import isaaclab.terrains as terrain_gen
    from isaaclab.assets import RigidObjectCfg
    from isaaclab.scene import InteractiveSceneCfg
    from isaaclab.sensors.ray_caster.patterns import LidarPatternCfg
    from isaaclab.terrains import TerrainGeneratorCfg, TerrainImporterCfg
    from isaaclab.utils import configclass
    from isaaclab_newton.sensors import NewtonRaycastSensorCfg

    from robotwright.sensors.isaaclab import LidarCfg, LivoxPatternCfg, SemanticLidarCfg

    pattern = LidarPatternCfg(
        channels=16,
        vertical_fov_range=(-30.0, 10.0),
        horizontal_fov_range=(-180.0, 180.0),
        horizontal_res=1.0,
    )
    above = NewtonRaycastSensorCfg.OffsetCfg(pos=(0.0, 0.0, 0.2))  # outside the carrier
    common = dict(prim_path="{ENV_REGEX_NS}/Carrier", max_distance=20.0)

    def cube(path: str, size, pos) -> RigidObjectCfg:
        return RigidObjectCfg(
            prim_path=path,
            spawn=sim_utils.CuboidCfg(
                size=size,
                rigid_props=sim_utils.UsdPhysicsRigidBodyCfg(kinematic_enabled=True),
                mass_props=sim_utils.MassCfg(mass=1.0),
                collision_props=sim_utils.UsdPhysicsCollisionCfg(),
            ),
            init_state=RigidObjectCfg.InitialStateCfg(pos=pos),
        )

    @configclass
    class BenchSceneCfg(InteractiveSceneCfg):
        terrain = TerrainImporterCfg(
            prim_path="/World/ground",
            terrain_type="generator",
            terrain_generator=TerrainGeneratorCfg(
                size=(16.0, 16.0),
                border_width=1.0,
                num_rows=1,
                num_cols=1,
                use_cache=False,
                sub_terrains={
                    "w": terrain_gen.HfWaveTerrainCfg(amplitude_range=(0.05, 0.05), num_waves=2)
                },
            ),
        )
        carrier = cube("{ENV_REGEX_NS}/Carrier", (0.4, 0.3, 0.1), (0.0, 0.0, 0.6))
        box_0 = cube("{ENV_REGEX_NS}/cracker_box_0", (0.4, 0.4, 0.6), (2.0, 0.0, 0.45))
        box_1 = cube("{ENV_REGEX_NS}/cracker_box_1", (0.4, 0.4, 0.6), (-2.0, 1.0, 0.45))
        sofa_0 = cube("{ENV_REGEX_NS}/sofa_0", (0.8, 1.6, 0.7), (0.0, 3.0, 0.5))
        table_0 = cube("{ENV_REGEX_NS}/table_0", (1.2, 0.8, 0.8), (0.0, -3.0, 0.55))
        stock = NewtonRaycastSensorCfg(pattern_cfg=pattern, offset=above, **common)
        plain = LidarCfg(pattern_cfg=pattern, offset=above, **common)
        semantic = SemanticLidarCfg(pattern_cfg=pattern, offset=above, **common)
        mid360 = SemanticLidarCfg(pattern_cfg=LivoxPatternCfg(), offset=above, **common)
        see_through = SemanticLidarCfg(pattern_cfg=pattern, **common)
        see_through_recast = SemanticLidarCfg(pattern_cfg=pattern, pass_through="recast", **common)

    return BenchSceneCfg(num_envs=num_envs, env_spacing=0.0)


LABELS = {
    "stock": "Isaac Lab NewtonRaycastSensor",
    "plain": "robotwright LidarSensor",
    "semantic": "robotwright SemanticLidarSensor",
    "mid360": "robotwright Semantic, Mid-360 20k",
    "see_through": "robotwright Semantic, see-through",
    "see_through_recast": "  the same, re-cast past the carrier",
}


def bench(num_envs: int, device: str, rounds: int) -> dict[str, dict[str, float]]:
    """Print and return, per contender: rays, median seconds per update, ratio to stock."""
    import isaaclab.sim as sim_utils
    from isaaclab.scene import InteractiveScene
    from isaaclab_newton.physics import MJWarpSolverCfg, NewtonCfg

    cfg = sim_utils.SimulationCfg(
        dt=0.01,
        device=device,
        physics=NewtonCfg(solver_cfg=MJWarpSolverCfg(), use_cuda_graph=False),
    )
    with sim_utils.build_simulation_context(sim_cfg=cfg) as sim:
        sim._app_control_on_stop_handle = None
        scene = InteractiveScene(scene_cfg(num_envs))
        sim.reset()
        dt = sim.get_physics_dt()
        times: dict[str, list[float]] = {name: [] for name in LABELS}
        for r in range(rounds + 2):  # two warm-up rounds (kernel loading)
            sim.step()
            for name in LABELS:
                sensor = scene[name]
                tick = time.perf_counter()
                sensor.update(dt, force_recompute=True)
                _ = sensor.data.ray_hits_w.torch.sum().item()  # wait for the device
                if r >= 2:
                    times[name].append(time.perf_counter() - tick)
        stock = statistics.median(times["stock"])
        print(f"\n{num_envs} environments, {device}:")
        out: dict[str, dict[str, float]] = {}
        for name, label in LABELS.items():
            sensor = scene[name]
            med = statistics.median(times[name])
            rays = sensor.num_rays * num_envs
            print(
                f"  {label:36s} {rays:9d} rays {med * 1e3:8.2f} ms  "
                f"{rays / med / 1e6:7.2f} Mrays/s  x{med / stock:5.2f} of stock"
            )
            out[name] = {
                "rays": rays,
                "seconds": med,
                "rays_per_s": rays / med,
                "x_stock": med / stock,
            }
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", default="cpu")
    parser.add_argument("--envs", type=int, nargs="+", default=[4, 64])
    parser.add_argument("--rounds", type=int, default=20)
    args = parser.parse_args()
    for n in args.envs:
        bench(n, args.device, args.rounds)


if __name__ == "__main__":
    with measured(("isaaclab", "newton", "warp-lang", "torch")):
        main()
