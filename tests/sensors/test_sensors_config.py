"""Config validation: clear errors for bad sensor configs."""

from __future__ import annotations

import math

import pytest

from robotwright.errors import SensorError
from robotwright.sensors import (
    DEFAULT_SEMANTIC_CLASS_MAPPING,
    GridPatternCfg,
    LidarCfg,
    LidarSensor,
    LivoxPatternCfg,
    PinholeCameraPatternCfg,
    SemanticLidarCfg,
    SpinningLidarPatternCfg,
)


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
        ({"num_threads": 0}, "num_threads: expected an integer in \\[1, 256\\]"),
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


@pytest.mark.parametrize(
    ("pattern", "match"),
    [
        (lambda: PinholeCameraPatternCfg(width=100_000, height=100_000), "at most 10,000,000"),
        (lambda: GridPatternCfg(resolution=1e-9), "at most 10,000,000"),
        (lambda: LivoxPatternCfg(num_rays=2_000_000, table_frames=20), "table rows"),
        (
            lambda: SpinningLidarPatternCfg(
                vertical_angles=(0.1, math.nan), horizontal_resolution=0.01
            ),
            "vertical_angles",
        ),
        (
            lambda: SpinningLidarPatternCfg(vertical_angles=(0.1,), horizontal_resolution=1e-9),
            "at most",
        ),
    ],
)
def test_huge_or_nan_patterns_are_refused_before_allocating(pattern, match):
    with pytest.raises(SensorError, match=match):
        pattern()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"seed": -1}, "seed: expected an integer >= 0"),
        ({"num_threads": 10_000}, "num_threads: expected an integer in"),
        ({"offset_pos": None}, "offset_pos: expected 3 finite numbers"),
        ({"offset_rot": "abcd"}, "offset_rot: expected a non-zero quaternion"),
        ({"dropout_prob": "0.5"}, "dropout_prob: expected a probability"),
        ({"max_distance": "40"}, "max_distance: expected a non-negative number"),
        ({"miss_distance": math.nan}, "miss_distance: expected a number"),
        ({"exclude_robot": "no"}, "exclude_robot: expected True or False"),
    ],
)
def test_wrong_types_are_clear_errors(kwargs, match):
    with pytest.raises(SensorError, match=match):
        LidarCfg(prim_path="lidar", **kwargs)


def test_nan_sensor_pose_is_an_error_not_all_misses(analytic_model):
    import mujoco
    from lidar_scenes import forward

    data = forward(analytic_model)[0]
    s = LidarSensor(LidarCfg(prim_path="lidar_site"), analytic_model, data)
    s.update()
    site = mujoco.mj_name2id(analytic_model, mujoco.mjtObj.mjOBJ_SITE, "lidar_site")
    data.site_xpos[site, 0] = math.nan
    with pytest.raises(SensorError, match="environment 0: the pose of 'lidar_site' is not finite"):
        s.update()
