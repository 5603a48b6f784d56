"""mjlab task ``Robotwright-Mjlab-SemanticNav-Go2`` (and ``...-PointNet``): the seed's
Go2 among labelled clutter (:mod:`robotwright.sensors.semantic_nav` says what the task
is; this module wires it into mjlab).

mjlab's velocity task (``make_velocity_env_cfg``: rough terrain with its curriculum,
twist commands, the locomotion rewards) on the Go2 of example-robot-data, instrumented
the way mjlab's Go1 is: an IMU site with gyro, velocimeter and angular-momentum sensors
on the base, a site and a named collision geom per foot. Added: the clutter
(:func:`~robotwright.sensors.mjlab.semantic_scene.add_semantic_scene`, the obstacles'
count following the terrain level), the semantic LiDAR where the Go2's LiDAR (``radar``)
is, with the base's axes, the
valuable/obstacle rewards and their metrics, and the policy's view of the scan.

The Go2 is read when a task config is first copied (mjlab's ``train``/``play`` do that
for the task they run), not when mjlab starts: reading it takes about a second.
"""

from __future__ import annotations

import copy
import functools
import math
from typing import Any

import mujoco
import torch
from mjlab.actuator import XmlActuatorCfg
from mjlab.entity import EntityArticulationInfoCfg, EntityCfg
from mjlab.envs import ManagerBasedRlEnvCfg
from mjlab.envs.mdp.actions import JointPositionActionCfg
from mjlab.managers import TerminationTermCfg
from mjlab.managers.metrics_manager import MetricsTermCfg
from mjlab.managers.observation_manager import ObservationGroupCfg, ObservationTermCfg
from mjlab.managers.reward_manager import RewardTermCfg
from mjlab.rl import RslRlOnPolicyRunnerCfg
from mjlab.sensor import ContactMatch, ContactSensorCfg, ObjRef, RingPatternCfg
from mjlab.tasks.velocity import mdp
from mjlab.tasks.velocity.velocity_env_cfg import make_velocity_env_cfg

from robotwright.sensors.mjlab.config import SemanticLidarSensorCfg
from robotwright.sensors.mjlab.observations import lidar_point_cloud, lidar_range_image
from robotwright.sensors.mjlab.rl import ppo_runner_cfg
from robotwright.sensors.mjlab.semantic_scene import add_semantic_scene, object_distances
from robotwright.sensors.semantic_nav import (
    FEET,
    GO2_JOINT_POS,
    IMAGE_HEIGHT,
    IMAGE_WIDTH,
    LIDAR_RANGE,
    MAX_POINTS,
    NEAR_OBSTACLE,
    NEAR_VALUABLE,
    OBSTACLE_WEIGHT,
    VALUABLE_WEIGHT,
    check_policy,
    go2_mjcf,
    lidar_mount,
    lidar_pattern,
)
from robotwright.sensors.semantic_scene import SemanticSceneCfg

__all__ = [
    "POINTNET_TASK_ID",
    "TASK_ID",
    "go2_entity_cfg",
    "register",
    "semantic_nav_env_cfg",
    "semantic_nav_runner_cfg",
]

TASK_ID = "Robotwright-Mjlab-SemanticNav-Go2"
POINTNET_TASK_ID = "Robotwright-Mjlab-SemanticNav-Go2-PointNet"
#: Joint-position action scale [rad per unit action] (Isaac Lab's for its Go2).
ACTION_SCALE = 0.25
_LEGS = ("FL", "FR", "RL", "RR")


@functools.cache
def _go2_mjcf() -> tuple[
    str, tuple[float, float, float], dict[str, float], tuple[float, float, float]
]:
    """The Go2's MJCF text (meshes by absolute path, no floor), its standing base
    position [m], joint positions [rad] and the LiDAR's position on the base [m]."""
    from robotwright.generators.isaaclab_cfg import initial_state

    text = go2_mjcf()
    model = mujoco.MjSpec.from_string(text).compile()
    pos, joint_pos, _ = initial_state(model, GO2_JOINT_POS)
    return text, tuple(pos), dict(joint_pos), lidar_mount(model)


def _go2_spec() -> mujoco.MjSpec:
    """The Go2 instrumented like mjlab's Go1: IMU site and sensors on the base, a site
    and a named collision geom (``FL_foot_collision``, ...) per foot; self-collisions off."""
    spec = mujoco.MjSpec.from_string(_go2_mjcf()[0])
    base = spec.body("base")
    base.add_site(name="imu", pos=(0.0, 0.0, 0.0), group=5)
    for kind, name in (
        (mujoco.mjtSensor.mjSENS_GYRO, "imu_ang_vel"),
        (mujoco.mjtSensor.mjSENS_VELOCIMETER, "imu_lin_vel"),
    ):
        spec.add_sensor(name=name, type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname="imu")
    spec.add_sensor(
        name="root_angmom",
        type=mujoco.mjtSensor.mjSENS_SUBTREEANGMOM,
        objtype=mujoco.mjtObj.mjOBJ_BODY,
        objname="base",
    )
    # No collisions between the robot's own bodies (as Isaac Lab's Go2; the base and the
    # front thighs touch in the standing pose): its shapes collide with what has
    # contype 1 (terrain, objects), not with each other.
    for geom in spec.geoms:
        if geom.contype or geom.conaffinity:
            geom.contype, geom.conaffinity = 2, 1
    for leg, foot in zip(_LEGS, FEET, strict=True):
        body = spec.body(foot)
        body.add_site(name=leg, pos=(0.0, 0.0, 0.0), group=5)
        colliding = [g for g in body.geoms if g.contype or g.conaffinity]
        if len(colliding) != 1:
            raise RuntimeError(f"Go2 {foot}: expected one collision geom, found {len(colliding)}")
        colliding[0].name = f"{leg}_foot_collision"
    return spec


def go2_entity_cfg() -> EntityCfg:
    """The Go2 entity: its MJCF's position actuators (kp 50, kv 1), standing pose."""
    _, pos, joint_pos, _ = _go2_mjcf()
    return EntityCfg(
        spec_fn=_go2_spec,
        init_state=EntityCfg.InitialStateCfg(pos=pos, joint_pos=joint_pos, joint_vel={".*": 0.0}),
        articulation=EntityArticulationInfoCfg(
            actuators=(XmlActuatorCfg(target_names_expr=(".*_joint",)),)
        ),
    )


def _base_xy(env: Any) -> torch.Tensor:
    return env.scene["robot"].data.root_link_pos_w[:, :2]


def near_valuable(env: Any) -> torch.Tensor:
    """``(E,)`` 1 where the base is within :data:`NEAR_VALUABLE` m of a valuable."""
    return (object_distances(env, _base_xy(env), dynamic=False) < NEAR_VALUABLE).float()


def near_obstacle(env: Any) -> torch.Tensor:
    """``(E,)`` 1 where the base is within :data:`NEAR_OBSTACLE` m of a dynamic obstacle."""
    return (object_distances(env, _base_xy(env), dynamic=True) < NEAR_OBSTACLE).float()


def semantic_nav_env_cfg(
    play: bool = False,
    policy: str = "mlp",
    scene: SemanticSceneCfg | None = None,
    flat: bool = False,
) -> ManagerBasedRlEnvCfg:
    """The task's environment config (see the module); ``play``: endless episodes, no
    pushes; ``policy``: ``"mlp"`` (range image with class channels) or ``"pointnet"``
    (a ``"points"`` group of :data:`MAX_POINTS` hits with one-hot classes); ``flat``: a
    plane instead of the generated terrain (no terrain curriculum: every obstacle out)."""
    check_policy(policy)
    scene = scene or SemanticSceneCfg()
    scene.check()  # before the robot is read
    cfg = make_velocity_env_cfg()
    cfg.sim.mujoco.ccd_iterations = 50
    cfg.sim.nconmax = 300  # the robot starts inside the terrain before its first reset
    cfg.sim.contact_sensor_maxmatch = 64
    cfg.scene.entities = {"robot": go2_entity_cfg()}
    geom_names = tuple(f"{leg}_foot_collision" for leg in _LEGS)
    for sensor in cfg.scene.sensors or ():
        if sensor.name == "terrain_scan":
            sensor.frame.name = "base"
        if sensor.name == "foot_height_scan":
            sensor.frame = tuple(ObjRef(type="site", name=s, entity="robot") for s in _LEGS)
            sensor.pattern = RingPatternCfg.single_ring(radius=0.03, num_samples=4)
    feet = ContactSensorCfg(
        name="feet_ground_contact",
        primary=ContactMatch(mode="geom", pattern=geom_names, entity="robot"),
        secondary=ContactMatch(mode="body", pattern="terrain"),
        fields=("found", "force"),
        reduce="netforce",
        num_slots=1,
        track_air_time=True,
    )
    lidar = SemanticLidarSensorCfg(
        name="lidar",
        frame=ObjRef(type="body", name="base", entity="robot"),
        offset_pos=_go2_mjcf()[3],  # where the Go2's LiDAR is, the base's axes
        pattern=lidar_pattern(),
        max_distance=LIDAR_RANGE,
    )
    cfg.scene.sensors = (*(cfg.scene.sensors or ()), feet, lidar)
    cfg.scene.terrain.terrain_generator.curriculum = True
    add_semantic_scene(cfg, scene, clutter_curriculum=True)

    action = cfg.actions["joint_pos"]
    assert isinstance(action, JointPositionActionCfg)
    action.scale = ACTION_SCALE
    cfg.viewer.body_name = "base"
    cfg.events["foot_friction"].params["asset_cfg"].geom_names = geom_names
    cfg.events["base_com"].params["asset_cfg"].body_names = ("base",)
    legs = r".*(FR|FL|RR|RL)_"
    cfg.rewards["pose"].params["std_standing"] = {
        legs + "(hip|thigh)_joint": 0.05,
        legs + "calf_joint": 0.1,
    }
    for gait in ("std_walking", "std_running"):
        cfg.rewards["pose"].params[gait] = {
            legs + "(hip|thigh)_joint": 0.3,
            legs + "calf_joint": 0.6,
        }
    cfg.rewards["upright"].params["asset_cfg"].body_names = ("base",)
    cfg.rewards["upright"].params["terrain_sensor_names"] = ("terrain_scan",)
    cfg.rewards["body_ang_vel"].params["asset_cfg"].body_names = ("base",)
    for name in ("foot_clearance", "foot_slip"):
        cfg.rewards[name].params["asset_cfg"].site_names = _LEGS
    for name in ("body_ang_vel", "angular_momentum", "air_time"):
        cfg.rewards[name].weight = 0.0
    cfg.rewards["near_valuable"] = RewardTermCfg(func=near_valuable, weight=VALUABLE_WEIGHT)
    cfg.rewards["near_obstacle"] = RewardTermCfg(func=near_obstacle, weight=OBSTACLE_WEIGHT)
    cfg.metrics["near_valuable"] = MetricsTermCfg(func=near_valuable)
    cfg.metrics["near_obstacle"] = MetricsTermCfg(func=near_obstacle)
    cfg.terminations["fell_over"] = TerminationTermCfg(
        func=mdp.bad_orientation, params={"limit_angle": math.radians(70.0)}
    )
    _add_scan_observations(cfg, policy)
    if flat:
        cfg.scene.terrain.terrain_type = "plane"
        cfg.scene.terrain.terrain_generator = None
        cfg.curriculum.pop("terrain_levels", None)
        cfg.terminations.pop("out_of_terrain_bounds", None)
    if play:
        cfg.episode_length_s = int(1e9)
        cfg.observations["actor"].enable_corruption = False
        cfg.events.pop("push_robot", None)
        cfg.terminations.pop("out_of_terrain_bounds", None)
        cfg.curriculum = {}
    return cfg


def _add_scan_observations(cfg: ManagerBasedRlEnvCfg, policy: str) -> None:
    """The scan in the actor's and critic's view: a flattened range image with class
    channels (MLP), or a ``"points"`` group both read (PointNet)."""
    if policy == "pointnet":
        points = ObservationTermCfg(
            func=lidar_point_cloud,
            params={"sensor_name": "lidar", "max_points": MAX_POINTS, "frame": "base"},
        )
        cfg.observations["points"] = ObservationGroupCfg({"points": points})
        return
    image = ObservationTermCfg(
        func=lidar_range_image,
        params={
            "sensor_name": "lidar",
            "width": IMAGE_WIDTH,
            "height": IMAGE_HEIGHT,
            "flatten": True,
        },
    )
    for group in ("actor", "critic"):
        cfg.observations[group].terms["lidar"] = copy.deepcopy(image)


def semantic_nav_runner_cfg(policy: str = "mlp") -> RslRlOnPolicyRunnerCfg:
    """PPO as mjlab's Go1 velocity task has it (MLP 512-256-128 with observation
    normalisation, 24 steps per env); ``policy="pointnet"`` puts the PointNet encoder on
    the ``"points"`` group before the head, actor and critic alike."""
    return ppo_runner_cfg(
        policy=policy,
        hidden_dims=(512, 256, 128),
        obs_normalization=True,
        entropy_coef=0.01,
        experiment_name="go2_semantic_nav" + ("_pointnet" if policy == "pointnet" else ""),
        num_steps_per_env=24,
        max_iterations=10_000,
    )


class _BuiltWhenCopied:
    """Stands in mjlab's registry for an env config that is built by ``build`` when the
    registry copies it (``load_env_cfg``), so that registering costs nothing."""

    def __init__(self, build: Any) -> None:
        self._build = build

    def __deepcopy__(self, memo: dict) -> ManagerBasedRlEnvCfg:
        return self._build()


def register() -> None:
    """Register the task (MLP) and its PointNet variant with mjlab, once per process.
    Their configs are built when a task is loaded; without example-robot-data loading
    one raises :class:`~robotwright.sources.SourceNotFoundError` naming the Go2."""
    from mjlab.tasks.registry import list_tasks, register_mjlab_task
    from mjlab.tasks.velocity.rl import VelocityOnPolicyRunner

    for task_id, policy in ((TASK_ID, "mlp"), (POINTNET_TASK_ID, "pointnet")):
        if task_id in list_tasks():
            continue
        register_mjlab_task(
            task_id=task_id,
            env_cfg=_BuiltWhenCopied(functools.partial(semantic_nav_env_cfg, policy=policy)),
            play_env_cfg=_BuiltWhenCopied(
                functools.partial(semantic_nav_env_cfg, play=True, policy=policy)
            ),
            rl_cfg=semantic_nav_runner_cfg(policy),
            runner_cls=VelocityOnPolicyRunner,
        )
