"""mjlab tasks ``Mjlab-Semantic-Seeker-PointMass`` and ``...-NoLabels``: a task small
enough to train on a CPU in minutes whose only way to succeed is the LiDAR's labels.

A point mass (x/y slide joints driven by motors) on a plane among three solid,
identical upright cylinders (radius :data:`CYLINDER_RADIUS`), placed at random in the
arena at every reset:

* the target, a geom named ``armchair``: class ``valuable``;
* two obstacles, geoms named ``cracker_box``: class ``dynamic_obstacle``.

The agent sees them only through the semantic LiDAR, a horizontal ring of
:data:`RING_RAYS` rays at its own height (:data:`LIDAR_RANGE` m): normalised distances,
one-hot classes per ray, and its own velocity. It is rewarded for closing in on the
target, for time near it and penalised for time near an obstacle. The cylinders are the
same shape and size: the ``-NoLabels`` variant, which drops the class channels and
nothing else (same network, same budget), cannot tell the target from an obstacle.

Metrics (mjlab's ``Episode_Metrics/...``, the share of an episode's steps):
``at_target`` (centre within :data:`NEAR` m of the target's) and ``near_obstacle``.
``benchmarks/semantic_seeker.py`` trains both variants and compares ``at_target``.

Modules under ``robotwright.sensors.mjlab`` are imported by name (see :mod:`.tasks`).
"""

from __future__ import annotations

import math
from typing import Any

import mujoco
import torch
from mjlab.actuator.xml_actuator import XmlActuatorCfg
from mjlab.entity import EntityArticulationInfoCfg, EntityCfg
from mjlab.envs import ManagerBasedRlEnvCfg
from mjlab.envs.mdp import joint_vel_rel, time_out
from mjlab.envs.mdp.actions import JointEffortActionCfg
from mjlab.managers.event_manager import EventTermCfg
from mjlab.managers.metrics_manager import MetricsTermCfg
from mjlab.managers.observation_manager import ObservationGroupCfg, ObservationTermCfg
from mjlab.managers.reward_manager import RewardTermCfg
from mjlab.managers.scene_entity_config import SceneEntityCfg
from mjlab.managers.termination_manager import TerminationTermCfg
from mjlab.rl import RslRlOnPolicyRunnerCfg
from mjlab.scene import SceneCfg
from mjlab.sensor.builtin_sensor import ObjRef
from mjlab.sim import MujocoCfg, SimulationCfg
from mjlab.terrains import TerrainEntityCfg

from robotwright.sensors.mjlab.config import SemanticLidarSensorCfg
from robotwright.sensors.mjlab.observations import (
    lidar_distances_normalized,
    lidar_one_hot_classes,
    lidar_point_cloud,
)
from robotwright.sensors.mjlab.rl import POLICIES, ppo_runner_cfg
from robotwright.sensors.patterns import SpinningLidarPatternCfg

__all__ = [
    "NO_LABELS_TASK_ID",
    "POINTNET_TASK_ID",
    "TASK_ID",
    "seeker_env_cfg",
    "seeker_runner_cfg",
]

TASK_ID = "Mjlab-Semantic-Seeker-PointMass"
NO_LABELS_TASK_ID = "Mjlab-Semantic-Seeker-PointMass-NoLabels"
POINTNET_TASK_ID = "Mjlab-Semantic-Seeker-PointMass-PointNet"

#: Half side of the square arena the cylinders and the agent are placed in [m].
ARENA_HALF = 2.5
#: Radius and half-height of the three cylinders [m].
CYLINDER_RADIUS, CYLINDER_HALF_HEIGHT = 0.25, 0.25
#: Smallest distance between the centres of any two of the agent and the cylinders at a
#: reset [m].
MIN_SEPARATION = 1.0
#: "Near" a cylinder: centre-to-centre distance below this [m].
NEAR = 0.5
#: The LiDAR ring: rays, range [m], height of the agent (and of the ring) [m].
RING_RAYS, LIDAR_RANGE, AGENT_HEIGHT = 32, 6.0, 0.25
#: Motor force at full action [N], slide damping [N s/m] (top speed 2 m/s), mass [kg].
MOTOR_FORCE, DAMPING, MASS = 4.0, 2.0, 1.0
#: Physics step [s] and policy decimation: a 10 Hz policy; 8 s episodes.
TIMESTEP, DECIMATION, EPISODE_S = 0.02, 5, 8.0
#: Environments and PPO steps per iteration a CPU trains in minutes.
NUM_ENVS, STEPS_PER_ENV = 64, 32

_AGENT = SceneEntityCfg("agent", joint_names=("x", "y"))
_OBSTACLES = ("obstacle_a", "obstacle_b")


def _agent_spec() -> mujoco.MjSpec:
    """The point mass: a sphere on two horizontal slides, a motor on each."""
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="agent", pos=(0.0, 0.0, AGENT_HEIGHT))
    for name, axis in (("x", (1.0, 0.0, 0.0)), ("y", (0.0, 1.0, 0.0))):
        body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=axis, damping=DAMPING)
        spec.add_actuator(
            name=name,
            target=name,
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            gear=(MOTOR_FORCE, 0, 0, 0, 0, 0),
            ctrllimited=True,
            ctrlrange=(-1.0, 1.0),
        )
    body.add_geom(name="agent", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=(0.1, 0, 0), mass=MASS)
    return spec


def _cylinder_spec(geom_name: str, rgba: tuple[float, float, float, float]) -> Any:
    """A spec function: one upright cylinder standing on the plane, named ``geom_name``
    (its name decides its class; a fixed body, which mjlab makes a mocap body)."""

    def spec_fn() -> mujoco.MjSpec:
        spec = mujoco.MjSpec()
        body = spec.worldbody.add_body(name="cylinder")
        body.add_geom(
            name=geom_name,
            type=mujoco.mjtGeom.mjGEOM_CYLINDER,
            size=(CYLINDER_RADIUS, CYLINDER_HALF_HEIGHT, 0),
            pos=(0.0, 0.0, CYLINDER_HALF_HEIGHT),
            rgba=rgba,
        )
        return spec

    return spec_fn


def _positions(env: Any) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(agent ``(E, 2)``, target ``(E, 2)``, obstacles ``(E, 2, 2)``) positions [m]."""
    agent = env.scene["agent"].data.joint_pos[:, :2]
    target = env.scene["target"].data.root_link_pos_w[:, :2]
    obstacles = torch.stack([env.scene[n].data.root_link_pos_w[:, :2] for n in _OBSTACLES], 1)
    return agent, target, obstacles


def reset_layout(env: Any, env_ids: torch.Tensor | None) -> None:
    """Place the agent (at rest) and the three cylinders uniformly in the arena, every
    two centres at least :data:`MIN_SEPARATION` apart (16 tries per env; the last is
    kept when none succeeds)."""
    if env_ids is None:
        env_ids = torch.arange(env.num_envs, device=env.device)
    n = len(env_ids)
    if n == 0:
        return
    tries = 16
    xy = (torch.rand(n, tries, 4, 2, device=env.device) * 2.0 - 1.0) * ARENA_HALF
    gaps = torch.cdist(xy.view(n * tries, 4, 2), xy.view(n * tries, 4, 2)).view(n, tries, 4, 4)
    gaps = gaps + torch.eye(4, device=env.device) * 1e3
    ok = gaps.amin(dim=(2, 3)) >= MIN_SEPARATION
    pick = torch.where(
        ok.any(1), ok.float().argmax(1), torch.full_like(ok[:, 0], tries - 1, dtype=torch.long)
    )
    place_layout(env, env_ids, xy[torch.arange(n, device=env.device), pick])


def place_layout(env: Any, env_ids: torch.Tensor, xy: torch.Tensor) -> None:
    """Put the agent (at rest), the target and the two obstacles of ``env_ids`` at the
    ``(n, 4, 2)`` world x/y positions ``xy`` [m], in that order."""
    n = len(env_ids)
    agent = env.scene["agent"]
    agent.write_joint_state_to_sim(xy[:, 0], torch.zeros_like(xy[:, 0]), env_ids=env_ids)
    quat = torch.tensor([1.0, 0.0, 0.0, 0.0], device=env.device).expand(n, 4)
    for k, name in enumerate(("target", *_OBSTACLES), start=1):
        pos = torch.cat([xy[:, k], torch.zeros(n, 1, device=env.device)], dim=1)
        env.scene[name].write_mocap_pose_to_sim(torch.cat([pos, quat], dim=1), env_ids=env_ids)


def progress_to_target(env: Any) -> torch.Tensor:
    """``(E,)`` speed toward the target's centre [m/s] (mjlab multiplies by the step)."""
    agent, target, _ = _positions(env)
    to_target = target - agent
    unit = to_target / to_target.norm(dim=1, keepdim=True).clamp(min=1e-6)
    return (env.scene["agent"].data.joint_vel[:, :2] * unit).sum(dim=1)


def near_target(env: Any) -> torch.Tensor:
    """``(E,)`` 1 where the agent's centre is within :data:`NEAR` m of the target's."""
    agent, target, _ = _positions(env)
    return ((agent - target).norm(dim=1) < NEAR).float()


def near_obstacle(env: Any) -> torch.Tensor:
    """``(E,)`` 1 where the agent's centre is within :data:`NEAR` m of an obstacle's."""
    agent, _, obstacles = _positions(env)
    return ((agent[:, None] - obstacles).norm(dim=2).amin(dim=1) < NEAR).float()


def seeker_env_cfg(
    labels: bool = True, play: bool = False, solid: bool = True, policy: str = "mlp"
) -> ManagerBasedRlEnvCfg:
    """The seeker task; ``labels=False`` drops the class channels from the observations
    (the ``-NoLabels`` variant), ``play`` makes episodes endless. The cylinders are
    solid (the agent stops at their surface); ``solid=False`` turns contacts off and
    lets it pass through them. ``policy="pointnet"`` observes the scan as a point cloud
    (a ``"points"`` group: :func:`lidar_point_cloud`, the hits in the agent's sensor
    frame with their one-hot classes) beside the velocity, for
    :class:`~robotwright.sensors.pointnet.PointNetModel`."""
    if policy not in POLICIES:
        raise ValueError(f"policy {policy!r}: expected one of {', '.join(POLICIES)}")
    lidar = SemanticLidarSensorCfg(
        name="lidar",
        frame=ObjRef(type="body", name="agent", entity="agent"),
        pattern=SpinningLidarPatternCfg(
            vertical_angles=(0.0,), horizontal_resolution=2.0 * math.pi / RING_RAYS
        ),
        max_distance=LIDAR_RANGE,
    )
    terms = {
        "lidar_distances": ObservationTermCfg(
            func=lidar_distances_normalized, params={"sensor_name": "lidar"}
        ),
    }
    if labels:
        terms["lidar_classes"] = ObservationTermCfg(
            func=lidar_one_hot_classes, params={"sensor_name": "lidar"}
        )
    terms["velocity"] = ObservationTermCfg(func=joint_vel_rel, params={"asset_cfg": _AGENT})
    groups = {"actor": ObservationGroupCfg(terms), "critic": ObservationGroupCfg(dict(terms))}
    if policy == "pointnet":
        if not labels:
            raise ValueError("policy 'pointnet' reads the labels: expected labels=True")
        velocity = {"velocity": terms["velocity"]}
        points = ObservationTermCfg(
            func=lidar_point_cloud, params={"sensor_name": "lidar", "max_points": RING_RAYS}
        )
        groups = {
            "actor": ObservationGroupCfg(velocity),
            "critic": ObservationGroupCfg(dict(velocity)),
            "points": ObservationGroupCfg({"points": points}),
        }
    entities = {
        "agent": EntityCfg(
            spec_fn=_agent_spec,
            articulation=EntityArticulationInfoCfg(
                actuators=(XmlActuatorCfg(target_names_expr=("x", "y")),)
            ),
        ),
        "target": EntityCfg(spec_fn=_cylinder_spec("armchair", (0.9, 0.7, 0.1, 1.0))),
        **{
            name: EntityCfg(spec_fn=_cylinder_spec("cracker_box", (0.8, 0.2, 0.2, 1.0)))
            for name in _OBSTACLES
        },
    }
    return ManagerBasedRlEnvCfg(
        scene=SceneCfg(
            terrain=TerrainEntityCfg(terrain_type="plane"),
            entities=entities,
            sensors=(lidar,),
            num_envs=NUM_ENVS,
            env_spacing=2.0 * ARENA_HALF + 1.0,
        ),
        observations=groups,
        actions={"force": JointEffortActionCfg(entity_name="agent", actuator_names=("x", "y"))},
        events={"reset_layout": EventTermCfg(func=reset_layout, mode="reset")},
        rewards={
            "progress": RewardTermCfg(func=progress_to_target, weight=10.0),
            "at_target": RewardTermCfg(func=near_target, weight=2.0),
            "near_obstacle": RewardTermCfg(func=near_obstacle, weight=-2.0),
        },
        metrics={
            "at_target": MetricsTermCfg(func=near_target),
            "near_obstacle": MetricsTermCfg(func=near_obstacle),
        },
        terminations={"time_out": TerminationTermCfg(func=time_out, time_out=True)},
        sim=SimulationCfg(
            mujoco=MujocoCfg(timestep=TIMESTEP, disableflags=() if solid else ("contact",)),
            nconmax=8 if solid else None,
        ),
        decimation=DECIMATION,
        episode_length_s=1e10 if play else EPISODE_S,
    )


def seeker_runner_cfg(labels: bool = True, policy: str = "mlp") -> RslRlOnPolicyRunnerCfg:
    """PPO for the seeker (every variant alike): MLP head 128-64, 32 steps per env;
    ``policy="pointnet"``: a PointNet encoder (shared point MLP 64-128, max-pooled) on
    the ``"points"`` group before the head, actor and critic alike."""
    name = "semantic_seeker" if labels else "semantic_seeker_no_labels"
    return ppo_runner_cfg(
        policy=policy,
        hidden_dims=(128, 64),
        obs_normalization=False,
        entropy_coef=0.005,
        experiment_name=f"semantic_seeker_{policy}" if policy != "mlp" else name,
        num_steps_per_env=STEPS_PER_ENV,
        max_iterations=150,
    )


def register() -> None:
    """Register the variants with mjlab (once per process): labels, no labels, and
    labels read as a point cloud by PointNet."""
    from mjlab.tasks.registry import list_tasks, register_mjlab_task

    variants = ((TASK_ID, True, "mlp"), (NO_LABELS_TASK_ID, False, "mlp"))
    variants += ((POINTNET_TASK_ID, True, "pointnet"),)
    for task_id, labels, policy in variants:
        if task_id not in list_tasks():
            register_mjlab_task(
                task_id=task_id,
                env_cfg=seeker_env_cfg(labels, policy=policy),
                play_env_cfg=seeker_env_cfg(labels, play=True, policy=policy),
                rl_cfg=seeker_runner_cfg(labels, policy=policy),
            )
