"""SemanticLidarSensor: labels from names, exact per ray; mesh ids; getters."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from lidar_scenes import RaysPattern, forward, geom_id, random_envs

from robotwright.errors import SensorError
from robotwright.sensors import (
    LivoxPatternCfg,
    SemanticLidarCfg,
    SemanticLidarData,
    SemanticLidarSensor,
)

AXES = [(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0), (0, 0, -1), (0, 0, 1)]


def test_labels_from_names_default_mapping(clutter_model):
    sensor = SemanticLidarSensor(
        SemanticLidarCfg(prim_path="lidar", return_mesh_ids=True),
        clutter_model,
        forward(clutter_model),
    )
    expect = {
        "ground": 1,
        "wall_north": 1,
        "rough_floor": 1,  # terrain
        "_03_cracker_box": 2,  # dynamic_obstacle by geom name
        "sofa_seat": 3,
        "top": 3,
        "leg_a": 3,  # valuable via body names sofa_1 / dining_table
        "lamp_shade": 0,  # unknown
    }
    for name, cls in expect.items():
        assert sensor.mesh_id_to_semantic_class[geom_id(clutter_model, name)] == cls, name
    # Unnamed geoms classified through their body path.
    body = mujoco.mj_name2id(clutter_model, mujoco.mjtObj.mjOBJ_BODY, "tomato_soup_can_1")
    g = int(np.flatnonzero(clutter_model.geom_bodyid == body)[0])
    assert sensor.geom_path(g) == f"/world/tomato_soup_can_1/geom{g}_cylinder"
    assert sensor.mesh_id_to_semantic_class[g] == 2
    # The robot's own geoms are not hittable, so not in the map.
    assert geom_id(clutter_model, "base") not in sensor.mesh_id_to_semantic_class
    assert sensor.class_names == ("unknown", "terrain", "dynamic_obstacle", "valuable")


def test_classify_mesh_path_rules(clutter_model):
    cfg = SemanticLidarCfg(
        prim_path="lidar", semantic_class_mapping={"terrain": ["floor"], "valuable": ["table"]}
    )
    s = SemanticLidarSensor(cfg, clutter_model, forward(clutter_model))
    assert s._classify_mesh_path("/world/SM_TABLE_1") == 2  # case-insensitive
    assert s._classify_mesh_path("/world/table_on_floor") == 1  # first class in mapping order wins
    assert s._classify_mesh_path("/world/lamp") == 0
    assert s.semantic_class_mapping == {"terrain": ["floor"], "valuable": ["table"]}
    # The mesh name is part of the path: the sofa is "valuable" through SM_Sofa_mesh too.
    default = SemanticLidarSensor(
        SemanticLidarCfg(prim_path="lidar"), clutter_model, forward(clutter_model)
    )
    assert (
        default.geom_path(geom_id(clutter_model, "sofa_seat"))
        == "/world/sofa_1/sofa_seat/SM_Sofa_mesh"
    )


def test_labels_exact_per_ray(analytic_model):
    mapping = {
        "terrain": ["floor"],
        "dynamic_obstacle": ["ball", "crate"],
        "valuable": ["cube_mesh"],
    }
    cfg = SemanticLidarCfg(
        prim_path="lidar_site",
        pattern_cfg=RaysPattern(AXES),
        semantic_class_mapping=mapping,
        return_mesh_ids=True,
    )
    s = SemanticLidarSensor(cfg, analytic_model, forward(analytic_model))
    s.update()
    # +x ball, +y crate, -x pillar (unknown), -y cube (mesh name), floor, miss.
    assert s.get_semantic_labels().tolist() == [[2, 2, 0, 3, 1, 0]]
    names = ["ball", "crate_geom", "pillar_geom", "cube", "floor"]
    assert s.get_mesh_ids().tolist() == [[geom_id(analytic_model, n) for n in names] + [-1]]
    assert isinstance(s.data, SemanticLidarData)
    assert s.data.semantic_labels.dtype == np.int32


def test_labels_match_mesh_ids_on_clutter(clutter_model):
    datas = random_envs(clutter_model, 3)
    cfg = SemanticLidarCfg(
        prim_path="lidar",
        pattern_cfg=LivoxPatternCfg(num_rays=4000),
        return_mesh_ids=True,
        max_distance=20.0,
    )
    s = SemanticLidarSensor(cfg, clutter_model, datas)
    s.update()
    labels, ids, hit = s.get_semantic_labels(), s.get_mesh_ids(), s.get_hit_mask()
    assert labels.shape == ids.shape == (3, 4000)
    np.testing.assert_array_equal(ids >= 0, hit)
    expected = np.array([s.mesh_id_to_semantic_class.get(int(g), 0) for g in ids.ravel()]).reshape(
        ids.shape
    )
    np.testing.assert_array_equal(labels, expected)
    # Every class shows up somewhere in this scene.
    assert set(np.unique(labels[hit])) >= {1, 2, 3}
    # Points of one class are points of the geoms of that class.
    pts = s.get_pointcloud()
    assert np.isfinite(pts[labels == 2]).all()


def test_getters_when_disabled(analytic_model):
    cfg = SemanticLidarCfg(
        prim_path="lidar_site", pattern_cfg=RaysPattern(AXES), return_semantic_labels=False
    )
    s = SemanticLidarSensor(cfg, analytic_model, forward(analytic_model))
    s.update()
    assert not s.return_semantic_labels and not s.return_mesh_ids
    assert s.data.semantic_labels is None and s.data.mesh_ids is None
    with pytest.raises(SensorError, match="return_semantic_labels=True"):
        s.get_semantic_labels()
    with pytest.raises(SensorError, match="return_mesh_ids=True"):
        s.get_mesh_ids()
    assert s.max_distance == 100.0
