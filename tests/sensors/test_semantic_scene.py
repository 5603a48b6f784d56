"""The framework-free class-labelled scene: slots, classes by construction, layouts that
keep their distances, paths that stay in the arena, and configs refused by field."""

from __future__ import annotations

import math
import re

import pytest

torch = pytest.importorskip("torch", reason="torch not installed (the torch extra)")

from robotwright.errors import SensorError  # noqa: E402
from robotwright.sensors.config import DEFAULT_SEMANTIC_CLASS_MAPPING  # noqa: E402
from robotwright.sensors.semantic import classify_path  # noqa: E402
from robotwright.sensors.semantic_scene import (  # noqa: E402
    SceneAssetCfg,
    SemanticSceneCfg,
    advance,
    sample_layout,
)


def test_slots_cycle_through_the_assets_and_carry_their_names() -> None:
    cfg = SemanticSceneCfg(num_obstacles=4, num_valuables=2)
    names = [s.name for s in cfg.slots()]
    assert names == [
        "obstacle_0_cracker_box",
        "obstacle_1_sugar_box",
        "obstacle_2_tomato_soup_can",
        "obstacle_3_cracker_box",
        "valuable_0_sofa",
        "valuable_1_armchair",
    ]
    assert [s.dynamic for s in cfg.slots()] == [True] * 4 + [False] * 2


def test_every_default_object_falls_in_its_group_s_class_under_the_seed_mapping() -> None:
    cfg = SemanticSceneCfg()
    classes = cfg.expected_classes()
    assert set(classes) == {s.name for s in cfg.slots()}
    for slot in cfg.slots():
        want = "dynamic_obstacle" if slot.dynamic else "valuable"
        assert classes[slot.name] == want
        # The name as a sensor sees it (entity / prim path) classifies the same.
        path = f"/World/envs/env_3/{slot.name}/{slot.asset.name}"
        ids = ["unknown", *DEFAULT_SEMANTIC_CLASS_MAPPING]
        assert ids[classify_path(path, DEFAULT_SEMANTIC_CLASS_MAPPING)] == want


def test_a_user_mapping_decides_the_classes() -> None:
    cfg = SemanticSceneCfg(mapping={"furniture": ["sofa", "table"], "clutter": ["box"]})
    classes = cfg.expected_classes()
    assert classes["valuable_0_sofa"] == "furniture"
    assert classes["valuable_1_armchair"] == "unknown"
    assert classes["obstacle_2_tomato_soup_can"] == "unknown"
    assert classes["obstacle_0_cracker_box"] == "clutter"


def test_layouts_keep_the_keep_out_disc_and_the_gaps() -> None:
    torch.manual_seed(0)
    cfg = SemanticSceneCfg(num_obstacles=3, num_valuables=2, arena_half=3.0, keep_out=0.7)
    layout = sample_layout(cfg, 200, "cpu")
    slots = cfg.slots()
    radius = torch.tensor([s.asset.footprint_radius for s in slots])
    assert layout.xy.shape == (200, 5, 2) and layout.yaw.shape == (200, 5)
    assert float(layout.xy.abs().max()) <= 3.0
    assert bool(((layout.xy.norm(dim=-1) - radius) >= 0.7 - 1e-6).all())
    gaps = torch.cdist(layout.xy, layout.xy) - radius[:, None] - radius[None, :]
    gaps += torch.eye(5) * 1e9
    assert float(gaps.min()) >= cfg.min_separation - 1e-6
    speeds = layout.velocity.norm(dim=-1)
    assert bool((speeds[:, 3:] == 0).all())  # valuables stay put
    low, high = cfg.obstacle_speed
    assert bool(((speeds[:, :3] >= low - 1e-6) & (speeds[:, :3] <= high + 1e-6)).all())
    # Draws differ between environments.
    assert float((layout.xy[0] - layout.xy[1]).abs().max()) > 0.1


def test_an_impossible_layout_still_gives_the_best_try() -> None:
    cfg = SemanticSceneCfg(num_obstacles=10, num_valuables=3, arena_half=0.8, keep_out=0.5)
    layout = sample_layout(cfg, 4, "cpu")
    assert bool(torch.isfinite(layout.xy).all()) and float(layout.xy.abs().max()) <= 0.8


def test_paths_bounce_off_the_arena_sides_and_keep_their_speed() -> None:
    xy = torch.tensor([[2.9, 0.0], [0.0, -2.95]])
    vel = torch.tensor([[1.0, 0.5], [0.0, -1.0]])
    new, v = advance(xy, vel, 0.2, 3.0)
    assert torch.allclose(new, torch.tensor([[2.9, 0.1], [0.0, -2.85]]), atol=1e-6)
    assert v.tolist() == [[-1.0, 0.5], [0.0, 1.0]]
    pos, vel = torch.rand(50, 2) * 6 - 3, torch.randn(50, 2)
    speed = vel.norm(dim=-1)
    for _ in range(500):
        pos, vel = advance(pos, vel, 0.05, 3.0)
        assert float(pos.abs().max()) <= 3.0
    assert torch.allclose(vel.norm(dim=-1), speed)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"num_obstacles": -1}, "num_obstacles"),
        ({"num_valuables": 10**6}, "num_valuables"),
        ({"num_obstacles": True}, "num_obstacles"),
        ({"arena_half": 0.0}, "arena_half"),
        ({"arena_half": math.inf}, "arena_half"),
        ({"keep_out": -0.1}, "keep_out"),
        ({"obstacle_speed": (0.5, 0.1)}, "obstacle_speed"),
        ({"obstacle_speed": (0.0, 1e9)}, "obstacle_speed"),
        ({"obstacles": ()}, "obstacles"),
        ({"obstacles": (SceneAssetCfg("can/../x", "box", (0.1, 0.1, 0.1)),)}, "obstacles[0].name"),
        ({"obstacles": (SceneAssetCfg("can", "cone", (0.1, 0.1)),)}, "obstacles[0].shape"),
        ({"valuables": (SceneAssetCfg("sofa", "box", (0.1, 0.1)),)}, "valuables[0].size"),
        ({"valuables": (SceneAssetCfg("sofa", "box", (0.1, -1.0, 0.1)),)}, "valuables[0].size"),
        ({"valuables": (SceneAssetCfg("sofa", "box", 0.5),)}, "valuables[0].size"),
        (
            {"valuables": (SceneAssetCfg("sofa", "box", (1, 1, 1), (1, 2, 0, 1)),)},
            "valuables[0].rgba",
        ),
        ({"valuables": ("sofa",)}, "valuables"),
        ({"mapping": {"valuable": "sofa"}}, "mapping"),
    ],
)
def test_bad_configs_are_refused_naming_the_field(change: dict, field: str) -> None:
    cfg = SemanticSceneCfg()
    for key, value in change.items():
        setattr(cfg, key, value)  # configs change after construction
    with pytest.raises(SensorError, match="SemanticSceneCfg." + re.escape(field)):
        cfg.check()


def test_scene_state_parks_obstacles_beyond_the_clutter_share_and_poses_them() -> None:
    from robotwright.sensors.semantic_scene import PARK_DEPTH, SceneState

    torch.manual_seed(1)
    state = SceneState(SemanticSceneCfg(num_obstacles=4, num_valuables=2), 3, "cpu")
    ids = torch.arange(3)
    state.redraw(ids, torch.tensor([0.0, 0.5, 1.0]))
    assert state.active[:, :4].sum(dim=1).tolist() == [0, 2, 4]
    assert bool(state.active[:, 4:].all())
    origins = torch.tensor([[10.0, 0.0, 1.0], [0.0, 10.0, 2.0], [0.0, 0.0, 0.0]])
    pos, quat = state.poses(ids, 0, origins)
    assert pos[:, 2].tolist() == pytest.approx([1.0 - PARK_DEPTH, 2.105, 0.105])
    assert torch.allclose(pos[:, :2], origins[:, :2] + state.xy[:, 0])
    yaw = 2.0 * torch.atan2(quat[:, 3], quat[:, 0])
    assert torch.allclose(
        torch.remainder(yaw - state.yaw[:, 0] + math.pi, 2 * math.pi), torch.full((3,), math.pi)
    )
    # Distances: to the nearest active footprint; parked obstacles are not there.
    d = state.distance(origins[:, :2] + state.xy[:, 5], origins, dynamic=False)
    assert torch.allclose(d, -state.radius[5].expand(3))
    far = state.distance(origins[:, :2], origins, dynamic=True)
    assert far[0] == math.inf and math.isfinite(float(far[2]))
    before = state.xy.clone()
    state.step(0.1)
    assert torch.equal(state.xy[:, 4:], before[:, 4:])
    assert float((state.xy[2, :4] - before[2, :4]).abs().max()) > 0
