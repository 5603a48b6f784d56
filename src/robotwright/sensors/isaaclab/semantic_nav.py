"""Isaac Lab task ``Robotwright-Isaac-SemanticNav-Go2-v0`` (and ``...-PointNet-v0``): the
seed's Go2 among labelled clutter (:mod:`robotwright.sensors.semantic_nav` says what the
task is; this module wires it into Isaac Lab 3, kit-less on Newton).

Isaac Lab's own Go2 rough-terrain velocity task (``UnitreeGo2RoughEnvCfg``: its terrain
generator and curriculum, twist commands, rewards, height scanner, contact sensor) with

* the robot replaced by example-robot-data's Go2 as ``robotwright isaaclab-cfg`` makes
  it (flat USD layout, position drives kp 50 / kv 1, the standing pose; the USD is
  written once per process into a private temporary folder), so no Nucleus asset is
  needed; the terrain's Nucleus material and the sky texture are left out;
* the clutter (:func:`~robotwright.sensors.isaaclab.semantic_scene.add_semantic_scene`,
  the obstacles' count following the terrain level);
* the semantic LiDAR on ``{ENV_REGEX_NS}/Robot/base`` at the position of the Go2's LiDAR
  body (``radar``) with the base's axes, seeing the terrain and the objects (the robot
  itself is see-through);
* the valuable/obstacle rewards, and the scan in the policy's view (range image with
  class channels for the MLP, or a ``points`` group for PointNet).

Registered with gym when this module is imported (``import
robotwright.sensors.isaaclab.semantic_nav``); ``robotwright isaaclab-train TASK`` trains
it with rsl_rl (:mod:`robotwright.sensors.isaaclab.train`).
"""

from __future__ import annotations

import atexit
import functools
import shutil
import tempfile
from pathlib import Path
from typing import Any

import gymnasium as gym
import isaaclab.sim as sim_utils
import torch
from isaaclab.actuators import ImplicitActuatorCfg
from isaaclab.assets import ArticulationCfg
from isaaclab.managers import ObservationGroupCfg, ObservationTermCfg, SceneEntityCfg
from isaaclab.managers import RewardTermCfg as RewTerm
from isaaclab.utils import configclass
from isaaclab_newton.sim.schemas import NewtonArticulationCfg
from isaaclab_tasks.core.velocity.config.go2.agents.rsl_rl_ppo_cfg import (
    UnitreeGo2RoughPPORunnerCfg,
)
from isaaclab_tasks.core.velocity.config.go2.rough_env_cfg import UnitreeGo2RoughEnvCfg

from robotwright.sensors.isaaclab.config import SemanticLidarCfg
from robotwright.sensors.isaaclab.observations import lidar_point_cloud, lidar_range_image
from robotwright.sensors.isaaclab.semantic_scene import (
    OBJECT_PRIM_PATHS,
    add_semantic_scene,
    object_distances,
)
from robotwright.sensors.semantic_nav import (
    GO2_JOINT_POS,
    IMAGE_HEIGHT,
    IMAGE_WIDTH,
    LIDAR_RANGE,
    MAX_POINTS,
    NEAR_OBSTACLE,
    NEAR_VALUABLE,
    OBSTACLE_WEIGHT,
    POINTNET_MODEL,
    VALUABLE_WEIGHT,
    go2_robot,
    lidar_mount,
    lidar_pattern,
)
from robotwright.sensors.semantic_scene import SemanticSceneCfg

__all__ = [
    "POINTNET_TASK_ID",
    "TASK_ID",
    "SemanticNavGo2EnvCfg",
    "SemanticNavGo2PointNetEnvCfg",
    "go2_articulation_cfg",
]

TASK_ID = "Robotwright-Isaac-SemanticNav-Go2-v0"
POINTNET_TASK_ID = "Robotwright-Isaac-SemanticNav-Go2-PointNet-v0"


@functools.cache
def _go2_usd() -> tuple[str, tuple[float, ...], dict[str, float], tuple[float, float, float]]:
    """The Go2's USD (flat layout, root at its prim's origin) in a private temporary
    folder removed at exit; its standing base position [m], joint positions [rad], and
    the LiDAR's position in the base frame [m] (:func:`lidar_mount`)."""
    from robotwright._temporaries import prefix
    from robotwright.generators.isaaclab_cfg import initial_state
    from robotwright.generators.usd import to_usd

    folder = Path(tempfile.mkdtemp(prefix=prefix("semantic-nav")))
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    done = to_usd(
        go2_robot(), folder / "go2.usd", layout="flat", root_at_origin=True, geometry=True
    )
    pos, joint_pos, _ = initial_state(done.mjcf_model, GO2_JOINT_POS)
    return str(done.path), tuple(pos), dict(joint_pos), lidar_mount(done.mjcf_model)


def go2_articulation_cfg() -> ArticulationCfg:
    """The Go2 as ``robotwright isaaclab-cfg go2`` with the task's options writes it: its
    USD, standing pose, and one implicit actuator group per set of equal drive values;
    contact reports on and self-collisions off, as Isaac Lab's own Go2 has them."""
    from robotwright.generators.isaaclab_cfg import actuator_groups

    usd, pos, joint_pos, _ = _go2_usd()
    actuators = {}
    for k, (values, joints) in enumerate(actuator_groups(go2_robot())):
        actuators[f"group_{k}"] = ImplicitActuatorCfg(
            joint_names_expr=list(joints),
            stiffness=values.get("stiffness"),
            damping=values.get("damping"),
            **{
                key: values[key]
                for key in ("joint_effort_limit", "joint_velocity_limit")
                if key in values
            },
        )
    return ArticulationCfg(
        prim_path="{ENV_REGEX_NS}/Robot",
        # As Isaac Lab's own Go2: contact reports on (its contact sensor needs them) and
        # no collisions between the robot's own bodies (the rotor shapes sit inside the
        # base and the hips).
        spawn=sim_utils.UsdFileCfg(
            usd_path=usd,
            activate_contact_sensors=True,
            articulation_props=NewtonArticulationCfg(self_collision_enabled=False),
        ),
        init_state=ArticulationCfg.InitialStateCfg(pos=pos, joint_pos=joint_pos),
        actuators=actuators,
    )


def _base_xy(env: Any) -> torch.Tensor:
    return env.scene["robot"].data.root_pos_w.torch[:, :2]


def near_valuable(env: Any) -> torch.Tensor:
    """``(E,)`` 1 where the base is within :data:`NEAR_VALUABLE` m of a valuable."""
    return (object_distances(env, _base_xy(env), dynamic=False) < NEAR_VALUABLE).float()


def near_obstacle(env: Any) -> torch.Tensor:
    """``(E,)`` 1 where the base is within :data:`NEAR_OBSTACLE` m of a dynamic obstacle."""
    return (object_distances(env, _base_xy(env), dynamic=True) < NEAR_OBSTACLE).float()


@configclass
class PointsCfg(ObservationGroupCfg):
    """The scan as points with one-hot classes (base frame), for PointNet."""

    points = ObservationTermCfg(
        func=lidar_point_cloud,
        params={"sensor_cfg": SceneEntityCfg("lidar"), "max_points": MAX_POINTS, "frame": "base"},
    )


@configclass
class SemanticNavGo2EnvCfg(UnitreeGo2RoughEnvCfg):
    """The task (see the module), policy reading a range image through an MLP."""

    semantic_scene: SemanticSceneCfg = SemanticSceneCfg()

    def __post_init__(self) -> None:
        super().__post_init__()
        # The LiDAR casts with Newton: its MuJoCo Warp preset, not a backend choice.
        self.sim.physics = getattr(self.sim.physics, "newton_mjwarp", self.sim.physics)
        self.commands.base_velocity.debug_vis = False  # its arrows are Nucleus assets
        self.scene.robot = go2_articulation_cfg()
        self.scene.terrain.visual_material = None  # a Nucleus material
        self.scene.sky_light = None  # a Nucleus texture
        offset = _go2_usd()[3]
        self.scene.lidar = SemanticLidarCfg(
            prim_path="{ENV_REGEX_NS}/Robot/base",
            offset=SemanticLidarCfg.OffsetCfg(pos=offset),  # the base's axes
            pattern_cfg=lidar_pattern(),
            max_distance=LIDAR_RANGE,
            mesh_prim_paths=["/World/ground", *OBJECT_PRIM_PATHS],
            self_class=None,
            update_period=self.decimation * self.sim.dt,
        )
        add_semantic_scene(self, self.semantic_scene, clutter_curriculum=True)
        self.rewards.near_valuable = RewTerm(func=near_valuable, weight=VALUABLE_WEIGHT)
        self.rewards.near_obstacle = RewTerm(func=near_obstacle, weight=OBSTACLE_WEIGHT)
        self.add_scan_observation()

    def add_scan_observation(self) -> None:
        """The range image with class channels, flattened, in the policy group."""
        self.observations.policy.lidar = ObservationTermCfg(
            func=lidar_range_image,
            params={
                "sensor_cfg": SceneEntityCfg("lidar"),
                "width": IMAGE_WIDTH,
                "height": IMAGE_HEIGHT,
                "flatten": True,
            },
        )


@configclass
class SemanticNavGo2PointNetEnvCfg(SemanticNavGo2EnvCfg):
    """The task with the scan as a ``points`` group, for PointNet."""

    def add_scan_observation(self) -> None:
        self.observations.points = PointsCfg()


@configclass
class SemanticNavGo2PPORunnerCfg(UnitreeGo2RoughPPORunnerCfg):
    """Isaac Lab's Go2 rough PPO (MLP 512-256-128, 24 steps per env)."""

    experiment_name = "go2_semantic_nav"


@configclass
class SemanticNavGo2PointNetPPORunnerCfg(SemanticNavGo2PPORunnerCfg):
    """PointNet on the ``points`` group before the MLP head, actor and critic alike."""

    experiment_name = "go2_semantic_nav_pointnet"
    obs_groups = {"actor": ["policy", "points"], "critic": ["policy", "points"]}

    def __post_init__(self) -> None:
        super().__post_init__()
        for model in (self.actor, self.critic):
            model.class_name = POINTNET_MODEL


def _register() -> None:
    for task_id, env_cfg, runner in (
        (TASK_ID, "SemanticNavGo2EnvCfg", "SemanticNavGo2PPORunnerCfg"),
        (POINTNET_TASK_ID, "SemanticNavGo2PointNetEnvCfg", "SemanticNavGo2PointNetPPORunnerCfg"),
    ):
        if task_id in gym.registry:
            continue
        gym.register(
            id=task_id,
            entry_point="isaaclab.envs:ManagerBasedRLEnv",
            disable_env_checker=True,
            kwargs={
                "env_cfg_entry_point": f"{__name__}:{env_cfg}",
                "rsl_rl_cfg_entry_point": f"{__name__}:{runner}",
                "default_agent": "rsl_rl",
            },
        )


_register()
