"""mjlab tasks (loaded by mjlab's ``mjlab.tasks`` entry point, so ``train`` / ``play``
list them): ``Mjlab-Velocity-Rough-Unitree-Go1-SemanticLidar``, below, the semantic
seeker ``Mjlab-Semantic-Seeker-PointMass`` (and ``-NoLabels``), :mod:`.seeker`, and the
seed's task ``Robotwright-Mjlab-SemanticNav-Go2`` (and ``-PointNet``), :mod:`.semantic_nav`.

mjlab's rough-terrain Go1 velocity task, plus obstacles of the three default classes on
the terrain around every robot, and a semantic Mid-360 on the trunk whose range image
(:func:`~robotwright.sensors.mjlab.observations.lidar_range_image`, flattened) the actor
reads:

* terrain: mjlab's generated rough terrain (class ``terrain`` by default in mjlab);
* ``valuable``: a sofa, an armchair and a dining table (one static, mocap-placed entity
  put near each environment's origin at reset);
* ``dynamic_obstacle``: two free cracker boxes dropped near each robot at reset.

Modules under ``robotwright.sensors.mjlab`` are imported by name here (not through the
package), because mjlab loads this module while ``import mjlab`` is still running.
"""

from __future__ import annotations

import functools

import mujoco
from mjlab.entity import EntityCfg
from mjlab.envs import ManagerBasedRlEnvCfg
from mjlab.envs import mdp as envs_mdp
from mjlab.managers.event_manager import EventTermCfg
from mjlab.managers.observation_manager import ObservationTermCfg
from mjlab.managers.scene_entity_config import SceneEntityCfg
from mjlab.sensor.builtin_sensor import ObjRef
from mjlab.tasks.registry import list_tasks, register_mjlab_task
from mjlab.tasks.velocity.config.go1.env_cfgs import unitree_go1_rough_env_cfg
from mjlab.tasks.velocity.config.go1.rl_cfg import unitree_go1_ppo_runner_cfg
from mjlab.tasks.velocity.rl import VelocityOnPolicyRunner

from robotwright.sensors.mjlab.config import SemanticLidarSensorCfg
from robotwright.sensors.mjlab.observations import lidar_range_image
from robotwright.sensors.mjlab.seeker import register as register_seeker
from robotwright.sensors.mjlab.semantic_nav import register as register_semantic_nav
from robotwright.sensors.patterns import LivoxPatternCfg

__all__ = ["TASK_ID", "semantic_lidar_go1_rough_env_cfg"]

TASK_ID = "Mjlab-Velocity-Rough-Unitree-Go1-SemanticLidar"

#: Range image the actor reads: width (azimuth) x height (elevation) cells.
IMAGE_WIDTH, IMAGE_HEIGHT = 32, 8
#: Static furniture of the "valuable" class: (geom name, box half-sizes [m], position [m]
#: relative to the entity's root, placed near the environment origin at reset).
FURNITURE = (
    ("sofa", (0.9, 0.4, 0.4), (2.5, 1.5, 0.4)),
    ("dining_table", (0.8, 0.5, 0.4), (-2.0, -2.0, 0.4)),
    ("armchair", (0.4, 0.4, 0.45), (-2.5, 2.0, 0.45)),
)
#: Free cracker boxes ("dynamic_obstacle"): entity name, offset from the env origin [m].
CRACKER_BOXES = (("cracker_box_0", (1.5, -1.0, 0.6)), ("cracker_box_1", (-1.2, 1.8, 0.6)))
CRACKER_BOX = (0.08, 0.03, 0.11)  # half-sizes [m]


def _furniture_spec() -> mujoco.MjSpec:
    """One body (made a mocap body by mjlab) holding the furniture boxes, geom group 0."""
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="furniture")
    for name, size, pos in FURNITURE:
        body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX, size=size, pos=pos)
    return spec


def _cracker_box_spec() -> mujoco.MjSpec:
    """One free cracker box (0.41 kg), named like the seed's YCB object."""
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="box")
    body.add_freejoint()
    body.add_geom(
        name="_03_cracker_box", type=mujoco.mjtGeom.mjGEOM_BOX, size=CRACKER_BOX, mass=0.41
    )
    return spec


def semantic_lidar_go1_rough_env_cfg(play: bool = False) -> ManagerBasedRlEnvCfg:
    """mjlab's rough Go1 velocity task with obstacles and the semantic LiDAR ``"lidar"``."""
    cfg = unitree_go1_rough_env_cfg(play=play)
    # The furniture and boxes touch the terrain too: room for their contacts per world.
    cfg.sim.nconmax = max(cfg.sim.nconmax or 0, 35) + 150
    entities = {"furniture": EntityCfg(spec_fn=_furniture_spec)}
    yaw = {"yaw": (-3.14159, 3.14159)}
    cfg.events["reset_furniture"] = EventTermCfg(
        func=envs_mdp.reset_root_state_uniform,
        mode="reset",
        params={
            "pose_range": {"x": (-0.5, 0.5), "y": (-0.5, 0.5), **yaw},
            "asset_cfg": SceneEntityCfg("furniture"),
        },
    )
    for name, (x, y, z) in CRACKER_BOXES:
        entities[name] = EntityCfg(
            spec_fn=functools.partial(_cracker_box_spec),
            init_state=EntityCfg.InitialStateCfg(pos=(x, y, z)),
        )
        cfg.events[f"reset_{name}"] = EventTermCfg(
            func=envs_mdp.reset_root_state_uniform,
            mode="reset",
            params={
                "pose_range": {"x": (-0.3, 0.3), "y": (-0.3, 0.3), **yaw},
                "velocity_range": {},
                "asset_cfg": SceneEntityCfg(name),
            },
        )
    cfg.scene.entities = {**cfg.scene.entities, **entities}
    lidar = SemanticLidarSensorCfg(
        name="lidar",
        frame=ObjRef(type="body", name="trunk", entity="robot"),
        pattern=LivoxPatternCfg(sensor_type="mid360", num_rays=4000),
        offset_pos=(0.0, 0.0, 0.1),
        max_distance=10.0,
    )
    cfg.scene.sensors = (*(cfg.scene.sensors or ()), lidar)
    cfg.observations["actor"].terms["lidar"] = ObservationTermCfg(
        func=lidar_range_image,
        params={
            "sensor_name": "lidar",
            "width": IMAGE_WIDTH,
            "height": IMAGE_HEIGHT,
            "flatten": True,
        },
    )
    return cfg


def _runner_cfg():  # noqa: ANN202 - mjlab's RslRlOnPolicyRunnerCfg
    cfg = unitree_go1_ppo_runner_cfg()
    cfg.experiment_name = "go1_velocity_semantic_lidar"
    cfg.logger = "tensorboard"  # offline by default (mjlab's Go1 logs to wandb)
    return cfg


if TASK_ID not in list_tasks():  # importing twice (entry point, then by name) is fine
    register_mjlab_task(
        task_id=TASK_ID,
        env_cfg=semantic_lidar_go1_rough_env_cfg(),
        play_env_cfg=semantic_lidar_go1_rough_env_cfg(play=True),
        rl_cfg=_runner_cfg(),
        runner_cls=VelocityOnPolicyRunner,
    )

register_seeker()
register_semantic_nav()
