"""A Unitree Go2 in an Isaac Lab 3 scene with the seed's semantic LiDAR on its base.

Kit-less Isaac Lab (Newton with the MuJoCo Warp solver) on warp's CPU device:
  * a generated wave terrain at /World/ground (terrain), a sofa and a table shared by
    every environment (valuable), two kinematic cracker boxes per environment that
    slide to and fro (dynamic_obstacle) and a crate the mapping does not name;
  * the Go2 from example-robot-data, imported from its URDF by Isaac Lab's converter,
    with its base fixed 0.45 m above the terrain (the example shows the sensor, not a
    walking policy; a free base needs a trained policy or a stand-up controller);
  * robotwright's SemanticLidarCfg as the seed writes it, on the Go2's base
    (a 20 000-ray Mid-360 whose window advances with each environment's simulated
    time), the robot's own legs labelled "robot";
  * the seed's observation ``lidar_semantic_obs`` and a 64 x 16 range image, computed
    each step as an observation manager would.
Writes a labelled picture of environment 0's scan and prints rays, hits per class and
the cost of a step.

Needs Isaac Lab 3 (Python 3.12: pip install 'robotwright[isaaclab]' example-robot-data).
Run: python examples/isaaclab_semantic_lidar.py [OUT_DIR] [--envs 2] [--steps 50]
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

MAX_DISTANCE = 20.0  # [m]
FURNITURE = (  # (prim name, size [m], position [m]): global, static
    ("SM_Sofa_1", (0.9, 1.8, 0.8), (3.4, -2.4, 0.45)),
    ("SM_Table_1", (1.2, 0.8, 0.75), (2.4, 2.2, 0.42)),
)
CRACKER_BOXES = ((1.8, -0.8), (0.6, 1.6))  # (x, y) [m] of each environment's boxes
CRACKER_BOX = (0.16, 0.21, 0.07)  # [m], the YCB box lying down
PITCH_DOWN_20 = (0.0, math.sin(math.radians(10.0)), 0.0, math.cos(math.radians(10.0)))  # x, y, z, w


def go2_usd(folder: Path) -> Path:
    """The Go2 of example-robot-data as USD: its URDF converted by robotwright to MJCF
    (proven against the URDF), the MJCF by mujoco-usd-converter to USD (the library
    behind Isaac Lab's kit-less MJCF importer), the robot alone (no floor, no light)."""
    import mujoco
    import mujoco_usd_converter

    from robotwright.catalog import find_entry
    from robotwright.proof.convert import convert

    entry = find_entry("go2")
    if entry is None:
        raise SystemExit("the Go2 comes from example-robot-data: pip install example-robot-data")
    mjcf = folder / "go2_mjcf" / "go2.xml"
    convert(entry.path, mjcf, overwrite=True)
    spec = mujoco.MjSpec.from_file(str(mjcf))
    for geom in list(spec.worldbody.geoms):
        spec.delete(geom)  # the floor: the scene has its own terrain
    for light in list(spec.worldbody.lights):
        spec.delete(light)
    for body in spec.worldbody.bodies:  # the base fixed to the world (see the module doc)
        for joint in list(body.joints):
            if joint.type == mujoco.mjtJoint.mjJNT_FREE:
                spec.delete(joint)
    robot_only = folder / "go2_mjcf" / "go2_robot.xml"
    robot_only.write_text(spec.to_xml())
    asset = mujoco_usd_converter.Converter().convert(str(robot_only), str(folder / "go2_usd"))
    return Path(asset.path)


def scene_cfg(num_envs: int, robot_usd: Path):
    import isaaclab.sim as sim_utils
    import isaaclab.terrains as terrain_gen
    from isaaclab.assets import ArticulationCfg, AssetBaseCfg, RigidObjectCfg
    from isaaclab.scene import InteractiveSceneCfg
    from isaaclab.terrains import TerrainGeneratorCfg, TerrainImporterCfg
    from isaaclab.utils import configclass

    from robotwright.sensors.isaaclab import SemanticLidarCfg

    terrain = TerrainGeneratorCfg(
        size=(12.0, 12.0),
        border_width=1.0,
        num_rows=1,
        num_cols=1,
        use_cache=False,
        sub_terrains={
            "waves": terrain_gen.HfWaveTerrainCfg(amplitude_range=(0.04, 0.04), num_waves=2)
        },
    )

    def box(prim_path: str, size, pos, rigid: bool) -> AssetBaseCfg | RigidObjectCfg:
        spawn = sim_utils.CuboidCfg(
            size=size,
            collision_props=sim_utils.UsdPhysicsCollisionCfg(),
            rigid_props=sim_utils.UsdPhysicsRigidBodyCfg(kinematic_enabled=True) if rigid else None,
            mass_props=sim_utils.MassCfg(mass=0.41) if rigid else None,
        )
        if rigid:
            return RigidObjectCfg(
                prim_path=prim_path, spawn=spawn, init_state=RigidObjectCfg.InitialStateCfg(pos=pos)
            )
        return AssetBaseCfg(
            prim_path=prim_path, spawn=spawn, init_state=AssetBaseCfg.InitialStateCfg(pos=pos)
        )

    @configclass
    class Go2LidarSceneCfg(InteractiveSceneCfg):
        ground = TerrainImporterCfg(
            prim_path="/World/ground", terrain_type="generator", terrain_generator=terrain
        )
        robot = ArticulationCfg(
            prim_path="{ENV_REGEX_NS}/Robot",
            spawn=sim_utils.UsdFileCfg(usd_path=str(robot_usd)),
            init_state=ArticulationCfg.InitialStateCfg(
                pos=(0.0, 0.0, 0.45),
                joint_pos={".*_thigh_joint": 0.8, ".*_calf_joint": -1.5},  # standing pose [rad]
            ),
            actuators={},
        )
        crate = box("{ENV_REGEX_NS}/crate", (0.5, 0.5, 0.9), (0.0, -2.2, 0.5), rigid=True)
        lidar = SemanticLidarCfg(
            # mujoco-usd-converter puts the bodies under Geometry/, nested as in the MJCF.
            prim_path="{ENV_REGEX_NS}/Robot/Geometry/base",
            # On top of the base, pitched 20 degrees down so that the Mid-360's -7..52
            # degree field of view sees the ground around the robot.
            offset=SemanticLidarCfg.OffsetCfg(pos=(0.15, 0.0, 0.12), rot=PITCH_DOWN_20),
            mesh_prim_paths=[],  # every collision shape of the scene
            return_semantic_labels=True,
            max_distance=MAX_DISTANCE,
        )

    # Every environment at the origin, on the one terrain among the shared furniture:
    # each is its own Newton world, so the robots never meet.
    cfg = Go2LidarSceneCfg(num_envs=num_envs, env_spacing=0.0)
    for name, size, pos in FURNITURE:
        setattr(cfg, name.lower(), box(f"/World/{name}", size, pos, rigid=False))
    for i, (x, y) in enumerate(CRACKER_BOXES):
        z = CRACKER_BOX[2] / 2 + 0.06
        setattr(
            cfg,
            f"cracker_box_{i}",
            box(f"{{ENV_REGEX_NS}}/cracker_box_{i}", CRACKER_BOX, (x, y, z), rigid=True),
        )
    return cfg


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out_dir", nargs="?", default="isaaclab_semantic_lidar_out")
    parser.add_argument("--envs", type=int, default=2)
    parser.add_argument("--steps", type=int, default=50)
    parser.add_argument("--device", default="cpu")
    args = parser.parse_args()
    out = Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)

    import isaaclab.sim as sim_utils
    import torch
    from isaaclab.managers import SceneEntityCfg
    from isaaclab.scene import InteractiveScene
    from isaaclab.utils import math as math_utils
    from isaaclab_newton.physics import MJWarpSolverCfg, NewtonCfg

    from robotwright.sensors.isaaclab.observations import lidar_range_image, lidar_semantic_obs
    from robotwright.sensors.plot import plot_scan

    sim_cfg = sim_utils.SimulationCfg(
        dt=0.01,
        device=args.device,
        gravity=(0.0, 0.0, 0.0),  # no actuators hold the legs: they keep their pose
        physics=NewtonCfg(solver_cfg=MJWarpSolverCfg(), use_cuda_graph=False),
    )
    with sim_utils.build_simulation_context(sim_cfg=sim_cfg) as sim:
        sim._app_control_on_stop_handle = None
        scene = InteractiveScene(scene_cfg(args.envs, go2_usd(out)))
        sim.reset()
        lidar = scene["lidar"]
        boxes = [scene[f"cracker_box_{i}"] for i in range(len(CRACKER_BOXES))]
        env = argparse.Namespace(scene=scene)
        dt = sim.get_physics_dt()
        start = time.perf_counter()
        lidar_time = 0.0
        for step in range(args.steps):
            t = step * dt
            for i, box in enumerate(boxes):
                pos = scene.env_origins.clone()
                pos[:, 0] += CRACKER_BOXES[i][0] + 0.5 * math.sin(2.0 * t + i)
                pos[:, 1] += CRACKER_BOXES[i][1]
                pos[:, 2] += CRACKER_BOX[2] / 2 + 0.06
                zero = torch.zeros(scene.num_envs, device=pos.device)
                quat = math_utils.quat_from_euler_xyz(zero, zero, zero + t)
                box.write_root_pose_to_sim_index(root_pose=torch.cat([pos, quat], dim=-1))
            scene.write_data_to_sim()
            sim.step()
            scene.update(dt)
            tick = time.perf_counter()
            obs = lidar_semantic_obs(env, SceneEntityCfg("lidar"))  # casts the rays
            image = lidar_range_image(env, SceneEntityCfg("lidar"), width=64, height=16)
            lidar_time += time.perf_counter() - tick
        per_step = (time.perf_counter() - start) / args.steps

        labels = lidar.get_semantic_labels()[0].cpu().numpy()
        points = lidar.get_pointcloud()[0].cpu().numpy()
        hit = lidar.get_hit_mask()[0].cpu().numpy()
        points[~hit] = float("nan")
        sensor_pos, _ = lidar.sensor_pose_w()
        picture = plot_scan(
            points,
            labels,
            lidar.class_names,
            out / "scan_env0.png",
            sensor_pos=sensor_pos[0].cpu().numpy(),
            title=f"Go2 in Isaac Lab 3 (Newton, {args.device}): semantic Mid-360, environment 0",
            view_radius=MAX_DISTANCE,
            class_keywords=lidar.semantic_class_mapping,
        )
        print(f"rays per environment: {lidar.num_rays}; environments: {scene.num_envs}")
        counts = ", ".join(
            f"{name} {int((labels[hit] == i).sum())}" for i, name in enumerate(lidar.class_names)
        )
        print(f"hits of environment 0 by class: {counts}")
        print(
            f"observation lidar_semantic_obs: {tuple(obs.shape)}; range image: {tuple(image.shape)}"
        )
        print(
            f"{per_step * 1000:.1f} ms per step, of which LiDAR and observations "
            f"{lidar_time / args.steps * 1000:.1f} ms ({args.device}, {scene.num_envs} environments)"
        )
        print(f"wrote {picture}")


if __name__ == "__main__":
    main()
