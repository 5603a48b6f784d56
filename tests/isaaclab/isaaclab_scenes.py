"""Isaac Lab scenes for the LiDAR tests: terrain, a small robot, boxes and a sofa.

The robot and the cracker box are written as USD with usd-core's physics schemas so that
their prims carry the names the seed's configuration uses (``Robot/base``,
``cracker_box_0/_03_cracker_box``); the sofa sits outside the environments, at the
seed's ``/World/SM_Sofa_1``.
"""

from __future__ import annotations

from pathlib import Path

import isaaclab.sim as sim_utils
import isaaclab.terrains as terrain_gen
from isaaclab.assets import ArticulationCfg, AssetBaseCfg, RigidObjectCfg
from isaaclab.scene import InteractiveSceneCfg
from isaaclab.terrains import TerrainGeneratorCfg, TerrainImporterCfg
from isaaclab.utils import configclass
from pxr import Gf, Usd, UsdGeom, UsdPhysics

#: The seed's configuration (specification 004), with only the import path changed.
SEED_MESH_PRIM_PATHS = [
    "/World/ground",
    "/world/SM_sofa_1",
    "{ENV_REGEX_NS}/cracker_box_0/_03_cracker_box",
]
SEED_MAPPING = {
    "terrain": ["ground", "wall", "floor"],
    "dynamic_obstacle": ["cracker_box", "sugar_box", "tomato_soup_can"],
    "valuable": ["sofa", "armchair", "table"],
}

WAVE_TERRAIN = TerrainGeneratorCfg(
    size=(12.0, 12.0),
    border_width=1.0,
    num_rows=1,
    num_cols=1,
    use_cache=False,
    sub_terrains={"waves": terrain_gen.HfWaveTerrainCfg(amplitude_range=(0.05, 0.05), num_waves=2)},
)

BASE_HEIGHT = 0.8
BOX_START = (1.6, 0.0, 0.5)


def _collider(stage: Usd.Stage, path: str, kind: str, size: tuple[float, ...], pos=(0, 0, 0)):
    if kind == "box":
        geom = UsdGeom.Cube.Define(stage, path)
        geom.CreateSizeAttr(1.0)
        xf = UsdGeom.Xformable(geom)
        xf.AddTranslateOp().Set(Gf.Vec3d(*pos))
        xf.AddScaleOp().Set(Gf.Vec3f(*size))
    else:
        geom = UsdGeom.Capsule.Define(stage, path)
        geom.CreateRadiusAttr(size[0])
        geom.CreateHeightAttr(size[1])
        geom.CreateAxisAttr("Z")
        UsdGeom.Xformable(geom).AddTranslateOp().Set(Gf.Vec3d(*pos))
    UsdPhysics.CollisionAPI.Apply(geom.GetPrim())
    return geom


def _body(stage: Usd.Stage, path: str, mass: float, pos=(0, 0, 0)) -> Usd.Prim:
    xf = UsdGeom.Xform.Define(stage, path)
    if any(pos):
        xf.AddTranslateOp().Set(Gf.Vec3d(*pos))
    prim = xf.GetPrim()
    UsdPhysics.RigidBodyAPI.Apply(prim)
    UsdPhysics.MassAPI.Apply(prim).CreateMassAttr(mass)
    return prim


def write_robot_usd(path: Path) -> Path:
    """A two-link robot: ``Robot/base`` (a 0.4 x 0.3 x 0.1 m box) and ``Robot/leg`` (a
    capsule hanging under the base's front), a hinge between them, fixed to the world."""
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, "/Robot")
    stage.SetDefaultPrim(root.GetPrim())
    UsdPhysics.ArticulationRootAPI.Apply(root.GetPrim())
    _body(stage, "/Robot/base", 5.0)
    _collider(stage, "/Robot/base/collision", "box", (0.4, 0.3, 0.1))
    _body(stage, "/Robot/leg", 0.5, pos=(0.3, 0.0, -0.25))
    _collider(stage, "/Robot/leg/collision", "capsule", (0.04, 0.3))
    hinge = UsdPhysics.RevoluteJoint.Define(stage, "/Robot/hip")
    hinge.CreateBody0Rel().SetTargets(["/Robot/base"])
    hinge.CreateBody1Rel().SetTargets(["/Robot/leg"])
    hinge.CreateAxisAttr("Y")
    hinge.CreateLocalPos0Attr(Gf.Vec3f(0.3, 0.0, -0.05))
    hinge.CreateLocalPos1Attr(Gf.Vec3f(0.0, 0.0, 0.2))
    hinge.CreateLowerLimitAttr(-45.0)
    hinge.CreateUpperLimitAttr(45.0)
    anchor = UsdPhysics.FixedJoint.Define(stage, "/Robot/anchor")
    anchor.CreateBody1Rel().SetTargets(["/Robot/base"])
    stage.GetRootLayer().Save()
    return path


def write_cracker_box_usd(path: Path) -> Path:
    """A 0.3 m cube body whose collision prim is named as in the seed: ``_03_cracker_box``."""
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = _body(stage, "/cracker_box_0", 1.0)
    stage.SetDefaultPrim(root)
    UsdPhysics.RigidBodyAPI(root).CreateKinematicEnabledAttr(True)
    _collider(stage, "/cracker_box_0/_03_cracker_box", "box", (0.3, 0.3, 0.3))
    stage.GetRootLayer().Save()
    return path


def _cube(prim_path: str, size, pos) -> RigidObjectCfg:
    return RigidObjectCfg(
        prim_path=prim_path,
        spawn=sim_utils.CuboidCfg(
            size=size,
            rigid_props=sim_utils.UsdPhysicsRigidBodyCfg(kinematic_enabled=True),
            mass_props=sim_utils.MassCfg(mass=1.0),
            collision_props=sim_utils.UsdPhysicsCollisionCfg(),
        ),
        init_state=RigidObjectCfg.InitialStateCfg(pos=pos),
    )


def scene_cfg(folder: Path, sensors: dict, num_envs: int = 2) -> InteractiveSceneCfg:
    """The test scene with the given sensors (name -> sensor config)."""
    robot_usd = write_robot_usd(folder / "robot.usda")
    box_usd = write_cracker_box_usd(folder / "cracker_box.usda")

    @configclass
    class LidarTestSceneCfg(InteractiveSceneCfg):
        terrain = TerrainImporterCfg(
            prim_path="/World/ground", terrain_type="generator", terrain_generator=WAVE_TERRAIN
        )
        robot = ArticulationCfg(
            prim_path="{ENV_REGEX_NS}/Robot",
            spawn=sim_utils.UsdFileCfg(usd_path=str(robot_usd)),
            init_state=ArticulationCfg.InitialStateCfg(pos=(0.0, 0.0, BASE_HEIGHT)),
            actuators={},
        )
        cracker_box = RigidObjectCfg(
            prim_path="{ENV_REGEX_NS}/cracker_box_0",
            spawn=sim_utils.UsdFileCfg(usd_path=str(box_usd)),
            init_state=RigidObjectCfg.InitialStateCfg(pos=BOX_START),
        )
        # Global (shared by every environment) and static, like furniture of a level.
        sofa = AssetBaseCfg(
            prim_path="/World/SM_Sofa_1",
            spawn=sim_utils.CuboidCfg(
                size=(0.8, 1.6, 0.7), collision_props=sim_utils.UsdPhysicsCollisionCfg()
            ),
            init_state=AssetBaseCfg.InitialStateCfg(pos=(-2.5, 0.0, 0.45)),
        )
        crate = _cube("{ENV_REGEX_NS}/crate", (0.5, 0.5, 1.2), (0.0, 2.0, 0.7))

    cfg = LidarTestSceneCfg(num_envs=num_envs, env_spacing=20.0)
    for name, sensor in sensors.items():
        setattr(cfg, name, sensor)
    return cfg


def sim_context(device: str = "cpu"):
    """Isaac Lab's simulation context on Newton (MuJoCo Warp), no gravity, no CUDA graph."""
    from isaaclab_newton.physics import MJWarpSolverCfg, NewtonCfg

    cfg = sim_utils.SimulationCfg(
        dt=0.01,
        device=device,
        gravity=(0.0, 0.0, 0.0),
        physics=NewtonCfg(solver_cfg=MJWarpSolverCfg(), use_cuda_graph=False),
    )
    return sim_utils.build_simulation_context(sim_cfg=cfg)
