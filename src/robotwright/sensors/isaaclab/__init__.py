"""The semantic LiDAR as an Isaac Lab 3 sensor (``pip install 'robotwright[isaaclab]'``).

The seed's classes in Isaac Lab's idiom, on Isaac Lab's Newton ray caster (kit-less,
warp's CPU device or CUDA):

* :class:`LidarCfg` / :class:`LidarSensor`: distances, point cloud, per-ray shape ids;
* :class:`SemanticLidarCfg` / :class:`SemanticLidarSensor` / :class:`SemanticLidarData`:
  plus a class per ray from keywords in the hit shape's prim path;
* observation terms (``ObservationTermCfg(func=..., params={"sensor_cfg": ...})``):
  :mod:`.observations`.

The seed's configuration works as written with this import path::

    from robotwright.sensors.isaaclab import SemanticLidarCfg, LivoxPatternCfg

This package imports Isaac Lab; ``robotwright.sensors`` never imports it.
"""

from __future__ import annotations

from robotwright.sensors.isaaclab.config import (
    LidarCfg,
    ResolvedLidarCfg,
    SemanticLidarCfg,
    resolve,
)
from robotwright.sensors.isaaclab.sensor import (
    LidarSensor,
    LidarSensorData,
    SemanticLidarData,
    SemanticLidarSensor,
)
from robotwright.sensors.patterns import (
    FilePatternCfg,
    LivoxPatternCfg,
    PinholeCameraPatternCfg,
    SpinningLidarPatternCfg,
)

__all__ = [
    "FilePatternCfg",
    "LidarCfg",
    "LidarSensor",
    "LidarSensorData",
    "LivoxPatternCfg",
    "PinholeCameraPatternCfg",
    "ResolvedLidarCfg",
    "SemanticLidarCfg",
    "SemanticLidarData",
    "SemanticLidarSensor",
    "SpinningLidarPatternCfg",
    "resolve",
]
