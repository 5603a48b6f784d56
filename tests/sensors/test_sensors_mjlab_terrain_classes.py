"""A class per sub-terrain of mjlab's terrain generator (marked ``mjlab``):
``name_sub_terrains`` names each sub-terrain's geoms after its key, and a mapping that
lists a key as a class keyword labels every ray that hits that sub-terrain with it;
the other sub-terrains stay ``terrain``."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

import mujoco  # noqa: E402
import torch  # noqa: E402
from mjlab.entity import EntityCfg  # noqa: E402
from mjlab.scene import Scene, SceneCfg  # noqa: E402
from mjlab.sensor.builtin_sensor import ObjRef  # noqa: E402
from mjlab.sim import Simulation, SimulationCfg  # noqa: E402
from mjlab.terrains import TerrainEntityCfg  # noqa: E402
from mjlab.terrains.config import ROUGH_TERRAINS_CFG  # noqa: E402

from robotwright.sensors.config import DEFAULT_SEMANTIC_CLASS_MAPPING  # noqa: E402
from robotwright.sensors.mjlab import SemanticLidarSensorCfg, mjlab_class_mapping  # noqa: E402
from robotwright.sensors.mjlab.terrain_classes import (  # noqa: E402
    NamedSubTerrainCfg,
    name_sub_terrains,
)
from robotwright.sensors.patterns import SpinningLidarPatternCfg  # noqa: E402


def _eye() -> mujoco.MjSpec:
    spec = mujoco.MjSpec()
    spec.worldbody.add_body(name="eye")
    return spec


def _scan(named: bool) -> tuple[object, mujoco.MjModel]:
    """One downward scan from 3 m above the middle of a flat and a stairs sub-terrain."""
    gen = replace(ROUGH_TERRAINS_CFG)
    gen.sub_terrains = {k: gen.sub_terrains[k] for k in ("flat", "pyramid_stairs")}
    gen.num_rows, gen.num_cols, gen.curriculum, gen.seed = 1, 2, True, 0
    if named:
        name_sub_terrains(gen)
        name_sub_terrains(gen)  # twice: no change
    mapping = mjlab_class_mapping({"stairs": ["pyramid_stairs"], **DEFAULT_SEMANTIC_CLASS_MAPPING})
    down = tuple(math.radians(a) for a in (-85, -70, -55, -40, -25))
    lidar = SemanticLidarSensorCfg(
        name="lidar",
        frame=ObjRef(type="body", name="eye", entity="eye"),
        pattern=SpinningLidarPatternCfg(vertical_angles=down, horizontal_resolution=0.1),
        max_distance=30.0,
        semantic_class_mapping=mapping,
    )
    terrain = TerrainEntityCfg(terrain_type="generator", terrain_generator=gen)
    cfg = SceneCfg(num_envs=1, terrain=terrain, entities={"eye": EntityCfg(spec_fn=_eye)})
    cfg.sensors = (lidar,)
    scene = Scene(cfg, device="cpu")
    sim = Simulation(num_envs=1, cfg=SimulationCfg(), spec=scene.spec, device="cpu")
    scene.initialize(sim.mj_model, sim.model, sim.data)
    sim.set_sensor_context(scene.sensor_context)
    scene["eye"].write_mocap_pose_to_sim(torch.tensor([[0.0, 0.0, 3.0, 1.0, 0.0, 0.0, 0.0]]))
    sim.forward()
    scene.update(0.1)
    sim.sense()
    return scene["lidar"], sim.mj_model


def test_each_sub_terrain_s_geoms_carry_its_class() -> None:
    lidar, model = _scan(named=True)
    names = lidar.class_names
    stairs = [g for g in range(model.ngeom) if model.geom(g).name.startswith("pyramid_stairs_")]
    flat = [g for g in range(model.ngeom) if model.geom(g).name.startswith("flat_")]
    assert stairs and flat
    assert {names[lidar.geom_semantic_class[g]] for g in stairs} == {"stairs"}
    assert {names[lidar.geom_semantic_class[g]] for g in flat} == {"terrain"}
    ids, labels = lidar.data.geom_ids[0], lidar.data.semantic_labels[0]
    on_stairs = torch.isin(ids, torch.tensor(stairs))
    on_flat = torch.isin(ids, torch.tensor(flat))
    assert on_stairs.sum() > 20 and on_flat.sum() > 20  # the scan sees both
    assert {names[c] for c in labels[on_stairs].tolist()} == {"stairs"}
    assert {names[c] for c in labels[on_flat].tolist()} == {"terrain"}


def test_without_names_every_terrain_hit_is_terrain() -> None:
    lidar, model = _scan(named=False)
    hit = lidar.data.geom_ids[0] >= 0
    assert hit.sum() > 40
    assert {lidar.class_names[c] for c in lidar.data.semantic_labels[0][hit].tolist()} == {
        "terrain"
    }


def test_the_wrapper_keeps_the_sub_terrain_s_spawn_settings() -> None:
    gen = replace(ROUGH_TERRAINS_CFG)
    before = {k: (v.proportion, v.size) for k, v in gen.sub_terrains.items()}
    name_sub_terrains(gen)
    assert all(isinstance(v, NamedSubTerrainCfg) for v in gen.sub_terrains.values())
    assert {k: (v.proportion, v.size) for k, v in gen.sub_terrains.items()} == before
    assert {k: v.name for k, v in gen.sub_terrains.items()} == {k: k for k in before}
