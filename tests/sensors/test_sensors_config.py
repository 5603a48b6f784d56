"""Config validation: clear errors for bad sensor configs."""

from __future__ import annotations

import math

import pytest

from robotwright.errors import SensorError
from robotwright.sensors import DEFAULT_SEMANTIC_CLASS_MAPPING, LidarCfg, SemanticLidarCfg


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"max_distance": -5.0}, "max_distance: expected a non-negative number"),
        ({"min_distance": -0.1}, "min_distance: expected a non-negative number"),
        ({"min_distance": 5.0, "max_distance": 5.0}, "expected min_distance < max_distance"),
        ({"max_distance": math.inf}, "expected min_distance < max_distance < inf"),
        ({"range_noise_std": -0.01}, "range_noise_std: expected a non-negative number"),
        ({"dropout_prob": 1.5}, "dropout_prob: expected a probability"),
        ({"ray_alignment": "roll"}, "ray_alignment: expected 'base', 'yaw' or 'world'"),
        ({"engine": "optix"}, "engine: expected 'mujoco' or 'warp'"),
        ({"offset_rot": (0, 0, 0, 0)}, "offset_rot: expected a non-zero quaternion"),
        ({"mesh_prim_paths": "floor"}, "mesh_prim_paths: expected a list"),
        ({"num_threads": 0}, "num_threads: expected an integer >= 1"),
        ({"prim_path": ""}, "prim_path: expected the name of a body or site"),
    ],
)
def test_bad_lidar_cfg(kwargs, message):
    args = {"prim_path": "base", **kwargs}
    with pytest.raises(SensorError, match=message):
        LidarCfg(**args)


def test_semantic_cfg_default_mapping_is_the_seeds():
    cfg = SemanticLidarCfg(prim_path="base")
    assert list(cfg.semantic_class_mapping) == ["terrain", "dynamic_obstacle", "valuable"]
    assert cfg.semantic_class_mapping == DEFAULT_SEMANTIC_CLASS_MAPPING
    assert cfg.semantic_class_mapping is not DEFAULT_SEMANTIC_CLASS_MAPPING  # no shared state
    assert cfg.return_semantic_labels and not cfg.return_mesh_ids


@pytest.mark.parametrize(
    ("mapping", "message"),
    [
        ({"terrain": []}, r"semantic_class_mapping\['terrain'\]: empty keyword list"),
        (
            {"terrain": "ground"},
            r"semantic_class_mapping\['terrain'\]: expected a list of keywords",
        ),
        ({"terrain": ["ground", ""]}, "keywords must be non-empty strings"),
        ({"": ["x"]}, "class names must be non-empty strings"),
    ],
)
def test_bad_semantic_mapping(mapping, message):
    with pytest.raises(SensorError, match=message):
        SemanticLidarCfg(prim_path="base", semantic_class_mapping=mapping)


def test_sensor_error_is_a_value_error():
    with pytest.raises(ValueError):
        LidarCfg(prim_path="base", max_distance=-1.0)
