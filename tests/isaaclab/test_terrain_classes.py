"""A class per sub-terrain in Isaac Lab (kit-less, Newton, CPU): ``name_sub_terrains``
imports each sub-terrain of the generator as its own prim named after its key, and a
mapping that lists a key as a class keyword labels every ray on that sub-terrain with
it; the other sub-terrains and the border stay ``terrain``."""

from __future__ import annotations

import math
import os

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip("isaaclab_newton", reason="Isaac Lab 3 not installed")

import isaaclab_scenes as scenes  # noqa: E402


def _scene_cfg():
    import isaaclab.sim as sim_utils
    import isaaclab.terrains as tg
    from isaaclab.assets import RigidObjectCfg
    from isaaclab.scene import InteractiveSceneCfg
    from isaaclab.terrains import TerrainGeneratorCfg, TerrainImporterCfg
    from isaaclab.utils import configclass

    from robotwright.sensors.config import DEFAULT_SEMANTIC_CLASS_MAPPING
    from robotwright.sensors.isaaclab import SemanticLidarCfg
    from robotwright.sensors.isaaclab.terrain_classes import name_sub_terrains
    from robotwright.sensors.patterns import SpinningLidarPatternCfg

    generator = TerrainGeneratorCfg(
        size=(8.0, 8.0),
        border_width=1.0,
        num_rows=1,
        num_cols=2,
        curriculum=True,
        use_cache=False,
        seed=0,
        sub_terrains={
            "boxes": tg.MeshRandomGridTerrainCfg(
                proportion=0.5, grid_width=0.45, grid_height_range=(0.05, 0.1), platform_width=2.0
            ),
            "pyramid_stairs": tg.MeshPyramidStairsTerrainCfg(
                proportion=0.5,
                step_height_range=(0.05, 0.1),
                step_width=0.3,
                platform_width=3.0,
                border_width=0.2,
            ),
        },
    )
    terrain = TerrainImporterCfg(
        prim_path="/World/ground", terrain_type="generator", terrain_generator=generator
    )
    name_sub_terrains(terrain)
    down = tuple(math.radians(a) for a in (-80, -60, -45, -30))
    carrier = RigidObjectCfg(
        prim_path="{ENV_REGEX_NS}/Carrier",
        spawn=sim_utils.CuboidCfg(
            size=(0.2, 0.2, 0.1),
            rigid_props=sim_utils.UsdPhysicsRigidBodyCfg(kinematic_enabled=True),
            mass_props=sim_utils.MassCfg(mass=1.0),
            collision_props=sim_utils.UsdPhysicsCollisionCfg(),
        ),
        init_state=RigidObjectCfg.InitialStateCfg(pos=(0.0, 4.0, 4.0)),  # over the seam
    )
    lidar = SemanticLidarCfg(
        prim_path="{ENV_REGEX_NS}/Carrier",
        pattern_cfg=SpinningLidarPatternCfg(vertical_angles=down, horizontal_resolution=0.02),
        max_distance=40.0,
        semantic_class_mapping={"stairs": ["pyramid_stairs"], **DEFAULT_SEMANTIC_CLASS_MAPPING},
    )

    @configclass
    class SceneCfg(InteractiveSceneCfg):
        ground = terrain

    cfg = SceneCfg(num_envs=1, env_spacing=0.0)
    cfg.carrier, cfg.lidar = carrier, lidar
    return cfg


def test_each_sub_terrain_is_its_own_prim_and_its_rays_carry_its_class() -> None:
    import numpy as np
    from isaaclab.scene import InteractiveScene

    with scenes.sim_context() as sim:
        sim._app_control_on_stop_handle = None
        scene = InteractiveScene(_scene_cfg())
        sim.reset()
        sim.step()
        scene.update(sim.get_physics_dt())
        lidar = scene["lidar"]
        names, shapes = lidar.class_names, lidar.shapes
        kinds = {"stairs": [], "boxes": [], "border": []}
        for i, path in enumerate(shapes.labels):
            for kind, prefix in (
                ("stairs", "/World/ground/pyramid_stairs_0_1/"),
                ("boxes", "/World/ground/boxes_0_0/"),
                ("border", "/World/ground/border/"),
            ):
                if path.startswith(prefix):
                    kinds[kind].append(i)
        assert all(kinds.values()), kinds
        assert {names[shapes.classes[i]] for i in kinds["stairs"]} == {"stairs"}
        assert {names[shapes.classes[i]] for i in kinds["boxes"] + kinds["border"]} == {"terrain"}
        ids = lidar.data.shape_ids.torch.numpy().reshape(-1)
        labels = lidar.data.semantic_labels.torch.numpy().reshape(-1)
        on_stairs, on_boxes = np.isin(ids, kinds["stairs"]), np.isin(ids, kinds["boxes"])
        assert on_stairs.sum() > 20 and on_boxes.sum() > 20, (on_stairs.sum(), on_boxes.sum())
        assert {names[c] for c in np.unique(labels[on_stairs])} == {"stairs"}
        assert {names[c] for c in np.unique(labels[on_boxes])} == {"terrain"}
