"""The semantic LiDAR as a native mjlab sensor (``pip install 'robotwright[mjlab]'``).

* :class:`SemanticLidarSensorCfg` goes into ``SceneCfg.sensors`` like mjlab's own
  ``RayCastSensorCfg``; it builds a :class:`MjlabSemanticLidarSensor` (an mjlab
  ``RayCastSensor``) whose data is a ``RayCastData`` plus labels
  (:class:`MjlabSemanticLidarData`): module :mod:`.sensor`, config :mod:`.config`.
* Observation terms, among them the range image and point cloud a policy can learn
  from: :mod:`.observations`.
* The task ``Mjlab-Velocity-Rough-Unitree-Go1-SemanticLidar``: :mod:`.tasks`, loaded by
  mjlab through the ``mjlab.tasks`` entry point.

This package imports mjlab; ``robotwright.sensors`` never imports it.
"""

from __future__ import annotations

# mjlab first: importing it loads the "mjlab.tasks" entry points, among them .tasks,
# which imports the modules below by name; started from here, they import cleanly.
import mjlab  # noqa: F401

from robotwright.sensors.mjlab.config import (
    MJLAB_TERRAIN_KEYWORD,
    ResolvedLidarCfg,
    SemanticLidarSensorCfg,
    mjlab_class_mapping,
    resolve,
)
from robotwright.sensors.mjlab.observations import (
    lidar_class_ids,
    lidar_distances_normalized,
    lidar_one_hot_classes,
    lidar_point_cloud,
    lidar_range_image,
    lidar_semantic_obs,
)
from robotwright.sensors.mjlab.sensor import (
    CLASS_COLORS,
    MjlabSemanticLidarData,
    MjlabSemanticLidarSensor,
)

__all__ = [
    "CLASS_COLORS",
    "MJLAB_TERRAIN_KEYWORD",
    "MjlabSemanticLidarData",
    "MjlabSemanticLidarSensor",
    "ResolvedLidarCfg",
    "SemanticLidarSensorCfg",
    "lidar_class_ids",
    "lidar_distances_normalized",
    "lidar_one_hot_classes",
    "lidar_point_cloud",
    "lidar_range_image",
    "lidar_semantic_obs",
    "mjlab_class_mapping",
    "resolve",
]
