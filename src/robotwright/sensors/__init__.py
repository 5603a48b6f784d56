"""Semantic LiDAR on MuJoCo: scan patterns, batched ray casting, per-ray labels.

>>> from robotwright.sensors import SemanticLidarCfg, SemanticLidarSensor, LivoxPatternCfg
>>> cfg = SemanticLidarCfg(prim_path="base", pattern_cfg=LivoxPatternCfg(), max_distance=40.0)
>>> sensor = SemanticLidarSensor(cfg, model, data)   # data: one MjData or a list (one per env)
>>> sensor.update()
>>> sensor.get_distances(), sensor.get_pointcloud(), sensor.get_semantic_labels()
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.sensors.config import (
        DEFAULT_SEMANTIC_CLASS_MAPPING,
        LidarCfg,
        SemanticLidarCfg,
    )
    from robotwright.sensors.lidar import LidarSensor, LidarSensorData, geom_paths
    from robotwright.sensors.patterns import (
        PATTERN_NAMES,
        FilePatternCfg,
        GridPatternCfg,
        LivoxPatternCfg,
        PatternCfg,
        PinholeCameraPatternCfg,
        RayTable,
        SpinningLidarPatternCfg,
        pattern_from_name,
        ray_limit,
    )
    from robotwright.sensors.raycast import warp_available
    from robotwright.sensors.scan import scan_to_files
    from robotwright.sensors.semantic import (
        SemanticLidarData,
        SemanticLidarSensor,
        classify_path,
        geom_class_table,
    )

__all__ = [
    "DEFAULT_SEMANTIC_CLASS_MAPPING",
    "FilePatternCfg",
    "GridPatternCfg",
    "LidarCfg",
    "LidarSensor",
    "LidarSensorData",
    "LivoxPatternCfg",
    "PATTERN_NAMES",
    "PatternCfg",
    "PinholeCameraPatternCfg",
    "SemanticLidarCfg",
    "SemanticLidarData",
    "SemanticLidarSensor",
    "SpinningLidarPatternCfg",
    "RayTable",
    "classify_path",
    "geom_class_table",
    "geom_paths",
    "pattern_from_name",
    "ray_limit",
    "scan_to_files",
    "warp_available",
]

attach(__name__, __file__)
