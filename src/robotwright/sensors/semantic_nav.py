"""The seed's task, framework-free parts: a Go2 walking among labelled clutter.

Both registered tasks, ``Robotwright-Mjlab-SemanticNav-Go2``
(:mod:`robotwright.sensors.mjlab.semantic_nav`) and ``Robotwright-Isaac-SemanticNav-Go2-v0``
(:mod:`robotwright.sensors.isaaclab.semantic_nav`), are the framework's velocity-tracking
locomotion task on the Go2 of example-robot-data plus

* the clutter of :class:`~robotwright.sensors.semantic_scene.SemanticSceneCfg` (three
  moving YCB obstacles and three pieces of furniture per environment);
* the semantic LiDAR where the Go2 carries its own (the ``radar`` body, at the front of
  the head), its axes the base's (:func:`lidar_mount`: the ``radar`` frame itself is
  pitched 165 degrees, upside down): :data:`LIDAR_CHANNELS` x :data:`LIDAR_COLUMNS` rays
  from :data:`LIDAR_ELEVATION` above the base's horizontal, range :data:`LIDAR_RANGE`;
* rewards for standing near a valuable and penalties for coming near a dynamic obstacle
  (the seeker's idea on legs): :data:`NEAR_VALUABLE`, :data:`NEAR_OBSTACLE`;
* the policy reads the scan either as a range image with class channels through an MLP
  (``policy="mlp"``) or as a point cloud with one-hot classes through PointNet
  (``policy="pointnet"``, :class:`~robotwright.sensors.pointnet.PointNetModel`).

The Go2 is read the way ``robotwright mjlab-cfg`` / ``isaaclab-cfg`` read it, with the
options of :data:`GO2_OPTIONS` and the standing pose of :data:`GO2_JOINT_POS` (Isaac
Lab's Go2 pose; the base height follows from the model): :func:`go2_robot`.
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING

import mujoco

from robotwright.sensors.patterns import SpinningLidarPatternCfg

if TYPE_CHECKING:
    from robotwright.hrdf.model import HRDF

__all__ = [
    "GO2_JOINT_POS",
    "GO2_OPTIONS",
    "POLICIES",
    "go2_mjcf",
    "go2_robot",
    "lidar_mount",
    "lidar_pattern",
]

#: The robot, as the catalog names it (example-robot-data's Go2 URDF).
GO2_SOURCE = "go2"
#: How the URDF is read: a floating base, position actuators with kp 50 N m/rad and
#: kv 1 N m s/rad on every joint (the gains the standing tests hold the pose with).
GO2_OPTIONS = {
    "floating_base": True,
    "actuators": "position",
    "actuator_gains": {"*": (50.0, 1.0)},
}
#: Isaac Lab's Go2 standing pose [rad], as ``--joint-pos`` patterns (first match wins).
GO2_JOINT_POS = (
    ("*L_hip_joint", 0.1),
    ("*R_hip_joint", -0.1),
    ("F?_thigh_joint", 0.8),
    ("R?_thigh_joint", 1.0),
    ("*calf_joint", -1.5),
)
#: The Go2's LiDAR body and the feet.
LIDAR_BODY, FEET = "radar", ("FL_foot", "FR_foot", "RL_foot", "RR_foot")
#: The scan: channels between the elevations [rad], columns over the full circle, range
#: [m]. Tilted down so that the YCB objects a few metres away are hit from 0.3 m up
#: (2 deg between columns: a 16 cm box subtends 4.6 deg at 2 m).
LIDAR_CHANNELS, LIDAR_COLUMNS = 16, 180
LIDAR_ELEVATION = (math.radians(-35.0), math.radians(15.0))
LIDAR_RANGE = 6.0
#: Range image the MLP reads: columns x rows.
IMAGE_WIDTH, IMAGE_HEIGHT = 32, 8
#: Points the PointNet reads.
MAX_POINTS = 256
#: "Near": base within this of a valuable's / an obstacle's footprint [m].
NEAR_VALUABLE, NEAR_OBSTACLE = 0.5, 0.4
#: Reward weights: per second near a valuable, near an obstacle.
VALUABLE_WEIGHT, OBSTACLE_WEIGHT = 1.0, -2.0
#: Policies: an MLP on the flat observations (a range image), or PointNet on the points.
POLICIES = ("mlp", "pointnet")
#: rsl_rl's name of the point-cloud model (resolved by rsl_rl when the runner starts).
POINTNET_MODEL = "robotwright.sensors.pointnet:PointNetModel"


def lidar_pattern() -> SpinningLidarPatternCfg:
    """The task's scan pattern (see :data:`LIDAR_CHANNELS`)."""
    low, high = LIDAR_ELEVATION
    step = (high - low) / (LIDAR_CHANNELS - 1)
    return SpinningLidarPatternCfg(
        vertical_angles=tuple(low + i * step for i in range(LIDAR_CHANNELS)),
        horizontal_resolution=2.0 * math.pi / LIDAR_COLUMNS,
    )


def lidar_mount(model: mujoco.MjModel) -> tuple[float, float, float]:
    """Position [m] of the LiDAR body (:data:`LIDAR_BODY`) in the ``base`` body's frame,
    from the compiled robot at its reference pose: the sensor sits there with the
    base's axes."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    base, radar = model.body("base").id, model.body(LIDAR_BODY).id
    offset = data.xmat[base].reshape(3, 3).T @ (data.xpos[radar] - data.xpos[base])
    return (float(offset[0]), float(offset[1]), float(offset[2]))


def check_policy(policy: str) -> None:
    """Raise ``ValueError`` unless ``policy`` is one of :data:`POLICIES`."""
    if policy not in POLICIES:
        raise ValueError(f"policy {policy!r}: expected one of {', '.join(POLICIES)}")


@functools.cache
def go2_robot() -> HRDF:
    """The Go2 read with :data:`GO2_OPTIONS` (once per process: its meshes stay staged
    while the process runs).

    Raises:
        SourceNotFoundError: example-robot-data is not installed.
    """
    import warnings

    from robotwright.errors import ConversionWarning
    from robotwright.sources import load_robot

    with warnings.catch_warnings():
        # The visual meshes' materials are not kept (said once in the docs); every other
        # note is shown.
        warnings.filterwarnings("ignore", r".*\(cosmetic\)", ConversionWarning)
        return load_robot(GO2_SOURCE, **GO2_OPTIONS)


@functools.cache
def go2_mjcf() -> str:
    """The MJCF text of :func:`go2_robot` (meshes by absolute path, no floor)."""
    from robotwright.generators.mjcf import MJCFHumanoidGenerator

    return MJCFHumanoidGenerator.from_hrdf(go2_robot()).export(None, add_scene=False)
