"""The semantic LiDAR in an Isaac Lab 3 scene (kit-less, Newton, warp's CPU device).

One scene serves the module: terrain, a two-link robot carrying the sensors on its
base, a moving cracker box, a static sofa shared by the environments and a crate that
the seed's ``mesh_prim_paths`` leave out. Labels are checked ray by ray against a
reference the test computes itself with ``newton.intersect_ray`` and the seed's rules,
and against Isaac Lab's ``MultiMeshRayCaster(update_mesh_ids=True)``.
"""

from __future__ import annotations

import math
import os

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip(
        "isaaclab_newton", reason="Isaac Lab 3 not installed (the Isaac Lab stage of .ci/run)"
    )

import isaaclab_scenes as scenes  # noqa: E402  (conftest puts this folder on the path)
import newton  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402
import warp as wp  # noqa: E402
from isaaclab.scene import InteractiveScene  # noqa: E402
from isaaclab.sensors.ray_caster import MultiMeshRayCasterCfg  # noqa: E402
from isaaclab.sensors.ray_caster.patterns import LidarPatternCfg  # noqa: E402
from isaaclab.utils import math as math_utils  # noqa: E402
from isaaclab_newton.sensors import NewtonRaycastSensor  # noqa: E402

from robotwright.errors import SensorError  # noqa: E402
from robotwright.sensors.isaaclab import (  # noqa: E402
    LidarCfg,
    LivoxPatternCfg,
    SemanticLidarCfg,
    SemanticLidarSensor,
)

BASE = "{ENV_REGEX_NS}/Robot/base"
IL_PATTERN = LidarPatternCfg(
    channels=16,
    vertical_fov_range=(-35.0, 15.0),
    horizontal_fov_range=(-180.0, 180.0),
    horizontal_res=2.0,
)


def _seed_cfg(**changes) -> SemanticLidarCfg:
    """The seed's configuration, as written in the specification."""
    cfg = SemanticLidarCfg(
        prim_path="{ENV_REGEX_NS}/Robot/base",
        mesh_prim_paths=[
            "/World/ground",
            "/world/SM_sofa_1",
            "{ENV_REGEX_NS}/cracker_box_0/_03_cracker_box",
        ],
        semantic_class_mapping={
            "terrain": ["ground", "wall", "floor"],
            "dynamic_obstacle": ["cracker_box", "sugar_box", "tomato_soup_can"],
            "valuable": ["sofa", "armchair", "table"],
        },
        return_semantic_labels=True,
        max_distance=40.0,
    )
    for key, value in changes.items():
        setattr(cfg, key, value)
    return cfg


SENSORS = {
    "seed": _seed_cfg(return_mesh_ids=True),
    "everything": SemanticLidarCfg(prim_path=BASE, pattern_cfg=IL_PATTERN, return_mesh_ids=True),
    "no_self": SemanticLidarCfg(prim_path=BASE, pattern_cfg=IL_PATTERN, self_class=None),
    "no_self_recast": SemanticLidarCfg(
        prim_path=BASE, pattern_cfg=IL_PATTERN, self_class=None, pass_through="recast"
    ),
    "il_pattern": _seed_cfg(pattern_cfg=IL_PATTERN),
    "multi_mesh": MultiMeshRayCasterCfg(
        prim_path=BASE,
        mesh_prim_paths=[
            MultiMeshRayCasterCfg.RaycastTargetCfg(
                prim_expr="/World/ground", track_mesh_transforms=False
            ),
            MultiMeshRayCasterCfg.RaycastTargetCfg(prim_expr="{ENV_REGEX_NS}/cracker_box_0"),
            MultiMeshRayCasterCfg.RaycastTargetCfg(
                prim_expr="/World/SM_Sofa_1", track_mesh_transforms=False
            ),
        ],
        pattern_cfg=IL_PATTERN,
        update_mesh_ids=True,
        max_distance=40.0,
    ),
}


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    folder = tmp_path_factory.mktemp("isaaclab_scene")
    with scenes.sim_context() as sim:
        sim._app_control_on_stop_handle = None
        scene = InteractiveScene(scenes.scene_cfg(folder, dict(SENSORS)))
        sim.reset()
        yield sim, scene


def _step(sim, scene, steps: int = 1, box_phase: float = 0.0) -> None:
    """Sweep the cracker box sideways (kinematic) and step the simulation."""
    box = scene["cracker_box"]
    dt = sim.get_physics_dt()
    for _ in range(steps):
        t = float(scene["seed"]._timestamp.numpy()[0]) + box_phase
        n = scene.num_envs
        pos = torch.tensor(scenes.BOX_START, dtype=torch.float32).repeat(n, 1)
        pos += scene.env_origins.cpu()
        pos[:, 1] += 1.2 * math.sin(3.0 * t)
        zero = torch.zeros(n)
        quat = math_utils.quat_from_euler_xyz(zero, zero, zero + t)
        box.write_root_pose_to_sim_index(root_pose=torch.cat([pos, quat], dim=-1).to(box.device))
        scene.write_data_to_sim()
        sim.step()
        scene.update(dt)


# -- the reference: newton.intersect_ray called here, the seed's rules applied here --------
def _seed_class(path: str) -> int:
    lowered = path.lower()
    for cls, keywords in enumerate(scenes.SEED_MAPPING.values(), start=1):
        if any(k in lowered for k in keywords):
            return cls
    return 0


def _seed_shape_tables(model) -> tuple[np.ndarray, np.ndarray]:
    """Which shapes the seed's mesh_prim_paths let rays see, and their classes: decided
    from Newton's raw shape labels (the height-field terrain is the one global HFIELD)."""
    labels = list(model.shape_label)
    types = model.shape_type.numpy()
    worlds = model.shape_world.numpy()
    seen = np.zeros(len(labels), dtype=bool)
    classes = np.zeros(len(labels), dtype=np.int32)
    for s, label in enumerate(labels):
        low = label.lower()
        if worlds[s] == -1 and types[s] == int(newton.GeoType.HFIELD):
            seen[s], classes[s] = True, 1  # /World/ground's generated terrain
        elif low.startswith("/world/sm_sofa_1/") or (
            low.startswith("/world/envs/env_") and "/cracker_box_0/_03_cracker_box" in low
        ):
            seen[s], classes[s] = True, _seed_class(label)
    return seen, classes


def _reference(sensor, seen: np.ndarray, classes: np.ndarray, max_distance: float):
    """Per ray (distance, class) by repeated direct ``newton.intersect_ray`` calls that
    step past every shape the seed does not list."""
    model = sensor.backend.model
    starts = sensor.ray_starts_w.torch.reshape(-1, 3).double().cpu().numpy()
    dirs = sensor.ray_directions_w.torch.reshape(-1, 3).double().cpu().numpy()
    count = starts.shape[0]
    worlds = np.repeat(np.arange(sensor.num_instances, dtype=np.int32), sensor.num_rays)
    total = np.zeros(count)
    label = np.zeros(count, dtype=np.int32)
    hit = np.zeros(count, dtype=bool)
    active = np.arange(count)
    origin = starts.copy()
    for _ in range(10):
        if active.size == 0:
            break
        out_d = wp.empty(active.size, dtype=wp.float32, device=model.device)
        out_s = wp.empty(active.size, dtype=wp.int32, device=model.device)
        newton.intersect_ray(
            model,
            ray_origins=wp.array(
                origin[active].astype(np.float32), dtype=wp.vec3, device=model.device
            ),
            ray_directions=wp.array(
                dirs[active].astype(np.float32), dtype=wp.vec3, device=model.device
            ),
            ray_worlds=wp.array(worlds[active], dtype=wp.int32, device=model.device),
            out_dist=out_d,
            out_shape_id=out_s,
        )
        d, s = out_d.numpy().astype(np.float64), out_s.numpy()
        missed = s < 0
        total[active[missed]] = np.inf
        go_on = ~missed & ~seen[np.maximum(s, 0)]
        done = ~missed & seen[np.maximum(s, 0)]
        idx = active[done]
        total[idx] += d[done]
        hit[idx] = total[idx] <= max_distance
        label[idx] = np.where(hit[idx], classes[s[done]], 0)
        nxt = active[go_on]
        total[nxt] += d[go_on] + 1e-4
        origin[nxt] = starts[nxt] + dirs[nxt] * total[nxt, None]
        active = nxt
    return np.where(hit, total, np.inf), label, hit


def _check_against_reference(sensor) -> int:
    _ = sensor.data  # the update (rays, BVH refit) the reference then reads
    seen, classes = _seed_shape_tables(sensor.backend.model)
    ref_dist, ref_label, ref_hit = _reference(sensor, seen, classes, sensor.cfg.max_distance)
    labels = sensor.get_semantic_labels().reshape(-1).cpu().numpy()
    hit = sensor.get_hit_mask().reshape(-1).cpu().numpy()
    dist = sensor.data.ray_distances.torch.reshape(-1).cpu().numpy()
    np.testing.assert_array_equal(hit, ref_hit)
    np.testing.assert_array_equal(labels, ref_label)
    np.testing.assert_allclose(dist[hit], ref_dist[hit], atol=2e-3)
    assert np.isinf(dist[~hit]).all()
    return int(hit.sum())


# -- the tests ----------------------------------------------------------------------------
def test_seed_config_labels_every_ray_exactly_through_motion_and_resets(world):
    sim, scene = world
    sensor = scene["seed"]
    assert isinstance(sensor, SemanticLidarSensor)
    assert sensor.class_names[:4] == ("unknown", "terrain", "dynamic_obstacle", "valuable")
    seen_classes = set()
    checked_hits = 0
    for step in range(12):
        _step(sim, scene, 3)
        if step == 6:
            scene.reset(env_ids=torch.tensor([1]))
        checked_hits += _check_against_reference(sensor)
        seen_classes |= set(np.unique(sensor.get_semantic_labels().cpu().numpy()).tolist())
    assert {1, 2, 3} <= seen_classes, f"the scene should show all three classes, saw {seen_classes}"
    assert checked_hits > 1000


def test_pattern_taken_from_isaac_lab_config_is_exact_too(world):
    sim, scene = world
    _step(sim, scene, 2)
    assert scene["il_pattern"].num_rays == scene["multi_mesh"].num_rays
    assert _check_against_reference(scene["il_pattern"]) > 100


def test_labels_agree_with_isaac_lab_multi_mesh_ray_caster(world):
    sim, scene = world
    ours, theirs = scene["il_pattern"], scene["multi_mesh"]
    target_class = torch.tensor([1, 2, 3])  # ground, cracker box, sofa (target order)
    agreeing = exact = 0
    for _ in range(5):
        _step(sim, scene, 4)
        their_hits = theirs.data.ray_hits_w.torch
        their_ids = theirs.data.ray_mesh_ids.torch.reshape(ours.get_hit_mask().shape).long()
        our_hits = ours.data.ray_hits_w.torch
        both = torch.isfinite(their_hits).all(-1) & ours.get_hit_mask()
        gap = (their_hits - our_hits).norm(dim=-1)
        same = both & (gap < 1e-3)
        # Newton casts on the height field it rasterised from the terrain mesh, Isaac
        # Lab's caster on the mesh itself: their terrain hits differ by centimetres.
        near = both & (gap < 0.05)
        assert near.sum() >= 0.95 * both.sum(), float(gap[both].max())
        theirs_cls = target_class[their_ids.clamp(0, 2).cpu()]
        ours_cls = ours.get_semantic_labels().long().cpu()
        assert torch.equal(ours_cls[near.cpu()], theirs_cls[near.cpu()])
        agreeing += int(near.sum())
        exact += int(same.sum())
    assert agreeing > 500 and exact > 200


def test_livox_window_advances_with_each_environments_simulated_time(world):
    sim, scene = world
    sensor = scene["seed"]
    pattern: LivoxPatternCfg = sensor.cfg.pattern_cfg
    period = pattern.num_rays / pattern.effective("points_per_second")
    assert sensor.frame_period == pytest.approx(period)
    scene.reset()
    _step(sim, scene, 25)
    _ = sensor.data
    t = sensor._timestamp.numpy()
    frames = sensor.data.frame.torch.cpu().numpy()
    np.testing.assert_array_equal(frames, np.floor(t / period).astype(int) % sensor.num_frames)
    scene.reset(env_ids=torch.tensor([1]))
    _step(sim, scene, 1)
    frames = sensor.data.frame.torch.cpu().numpy()
    assert frames[1] == 0 and frames[0] >= 2
    # Each environment casts the rows of its own window of the pattern's table.
    local = sensor.data.ray_directions_local.torch
    table = torch.as_tensor(pattern.ray_table().directions, dtype=torch.float32)
    n = sensor.num_rays
    for env, frame in enumerate(frames):
        torch.testing.assert_close(
            local[env], table[frame * n : (frame + 1) * n], atol=1e-6, rtol=0
        )


def test_own_robot_has_its_class_or_is_see_through(world):
    sim, scene = world
    _step(sim, scene, 1)
    with_self, without = scene["everything"], scene["no_self"]
    robot_id = with_self.class_names.index("robot")
    robot_rays = with_self.get_semantic_labels() == robot_id
    assert robot_rays.any(), "the leg under the base should be in the pattern's view"
    assert not (without.get_semantic_labels() == robot_id).any()
    # Where the leg was hit, the see-through sensor reports what lies behind it, further away.
    d_with = with_self.data.ray_distances.torch[robot_rays]
    d_without = without.data.ray_distances.torch[robot_rays]
    assert (d_without > d_with).all()
    # The carrier body (the sensor sits inside its box) is never hit.
    carrier = np.flatnonzero(with_self.shapes.carrier)
    hit_ids = with_self.get_mesh_ids().cpu().numpy()
    assert not np.isin(hit_ids, carrier).any()


def test_mesh_prim_paths_empty_sees_every_collision_shape(world):
    sim, scene = world
    sensor = scene["everything"]
    shapes = sensor.shapes
    expected = shapes.collides & ~shapes.carrier
    np.testing.assert_array_equal(shapes.visible, expected)
    seed = scene["seed"]
    crate = [i for i, lb in enumerate(seed.shapes.labels) if "/crate/" in lb]
    assert crate and not seed.shapes.visible[crate].any()
    assert "/World/ground" in seed.shapes.labels[0]  # the height field got its path back


def test_getters_follow_isaac_lab_conventions_and_the_seed(world):
    sim, scene = world
    _step(sim, scene, 1)
    sensor = scene["seed"]
    hit = sensor.get_hit_mask()
    dist = sensor.get_distances()
    assert torch.all(dist[~hit] == sensor.cfg.max_distance)
    assert torch.isinf(sensor.data.ray_distances.torch[~hit]).all()
    cloud = sensor.get_pointcloud()
    assert torch.isinf(cloud[~hit]).all() and torch.isfinite(cloud[hit]).all()
    # Every hit point lies at its distance along its ray.
    starts, dirs = sensor.ray_starts_w.torch, sensor.ray_directions_w.torch
    torch.testing.assert_close(
        cloud[hit],
        (starts + dirs * sensor.data.ray_distances.torch[..., None])[hit],
        atol=1e-4,
        rtol=0,
    )
    ids = sensor.get_mesh_ids()
    for shape_id in torch.unique(ids[hit]).tolist():
        cls = sensor.mesh_id_to_semantic_class[shape_id]
        assert torch.all(sensor.get_semantic_labels()[hit & (ids == shape_id)] == cls)
    assert sensor._classify_mesh_path("/World/SM_Sofa_1/geometry/mesh") == 3
    assert sensor.get_semantic_labels(env_ids=[1]).shape == (1, sensor.num_rays)
    with pytest.raises(SensorError, match="return_mesh_ids"):
        scene["il_pattern"].get_mesh_ids()


def test_parent_internals_the_sensor_relies_on_are_still_there(world):
    """Isaac Lab's private parts that robotwright's sensor uses (see sensor.py)."""
    _, scene = world
    for name in (
        "_launch_raycast",
        "_update_ray_infos",
        "_initialize_rays_impl",
        "_initialize_impl",
    ):
        assert callable(getattr(NewtonRaycastSensor, name))
    sensor = scene["seed"]
    e, n = sensor.num_instances, sensor.num_rays
    assert sensor._ray_starts_w.shape == (e, n)
    assert sensor._ray_directions_w.shape == (e, n)
    assert sensor._ray_worlds.shape == (e * n,)
    assert sensor._sensor_site_indices.shape == (e,)
    assert sensor._timestamp.shape == (e,) and sensor._is_outdated.shape == (e,)
    assert sensor._data._ray_hits_w.shape == (e, n)
    assert sensor._data._ray_distances.shape == (e, n)
    assert sensor.ray_starts.warp.shape == (e, n)


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("max_distance", -1.0, "max_distance"),
        ("min_distance", 50.0, "min_distance < max_distance"),
        ("max_pass_through", 999, "max_pass_through"),
        ("mesh_prim_paths", "/World/ground", "mesh_prim_paths"),
        ("self_class", "unknown", "self_class"),
        ("semantic_class_mapping", {"terrain": "ground"}, "terrain"),
        ("pattern_cfg", "mid360", "pattern_cfg"),
    ],
)
def test_bad_fields_fail_when_validated_naming_the_field(field, value, message):
    cfg = _seed_cfg()
    setattr(cfg, field, value)  # a change after construction, as tyro makes
    with pytest.raises(SensorError, match=message):
        cfg.validate()


def test_plain_lidar_config_has_no_classes():
    cfg = LidarCfg(prim_path=BASE)
    assert cfg.validate() == []
    assert cfg.class_type.__name__ == "LidarSensor" or str(cfg.class_type).endswith("LidarSensor")


def test_observation_terms_in_isaac_lab_style(world):
    from types import SimpleNamespace

    from isaaclab.managers import SceneEntityCfg

    from robotwright.sensors.isaaclab.observations import (
        lidar_distances_normalized,
        lidar_point_cloud,
        lidar_range_image,
        lidar_semantic_obs,
    )

    sim, scene = world
    _step(sim, scene, 2)
    env = SimpleNamespace(scene=scene)
    cfg = SceneEntityCfg("seed")
    sensor = scene["seed"]
    e, n, c = scene.num_envs, sensor.num_rays, len(sensor.class_names)
    obs = lidar_semantic_obs(env, cfg).view(e, n, 2)
    torch.testing.assert_close(obs[..., 0], sensor.get_distances())
    torch.testing.assert_close(obs[..., 1], sensor.get_semantic_labels().float())
    assert torch.isfinite(obs).all()
    norm = lidar_distances_normalized(env, cfg)
    assert float(norm.max()) <= 1.0 + 1e-6
    image = lidar_range_image(env, cfg, width=64, height=16)
    assert image.shape == (e, 1 + c, 16, 64)
    assert float(image[:, 0].min()) >= 0.0 and float(image[:, 0].max()) <= 1.0
    assert float(image[:, 1:].sum(dim=1).max()) <= 1.0 + 1e-5
    # The nearest hit of the whole scan is the darkest cell of the image.
    hit = sensor.get_hit_mask()
    nearest = torch.where(hit, sensor.data.ray_distances.torch, torch.inf).min(dim=1).values
    torch.testing.assert_close(image[:, 0].flatten(1).min(dim=1).values, nearest / 40.0)
    assert lidar_range_image(env, cfg, width=8, height=4, flatten=True).shape == (e, (1 + c) * 32)
    cloud = lidar_point_cloud(env, cfg, max_points=256, frame="sensor")
    assert cloud.shape == (e, 256, 3 + c)
    used = cloud[..., 3:].sum(-1) > 0
    counts = hit.sum(dim=1).clamp(max=256)
    assert torch.equal(used.sum(dim=1), counts)
    # Rays start at the sensor: a point's norm in the sensor frame is its ray's distance.
    dist = sensor.data.ray_distances.torch[hit]
    radii = cloud[..., :3][used].norm(dim=-1)
    assert float(radii.min()) >= float(dist.min()) - 1e-3
    assert float(radii.max()) <= float(dist.max()) + 1e-3
    world_cloud = lidar_point_cloud(env, cfg, max_points=256, frame="world")
    assert torch.isfinite(world_cloud).all()
    with pytest.raises(SensorError, match="max_points"):
        lidar_point_cloud(env, cfg, max_points=0)
    with pytest.raises(SensorError, match="not a robotwright"):
        lidar_semantic_obs(env, SceneEntityCfg("multi_mesh"))
    # The cells looked up from the table equal those of this step's local directions.
    from robotwright.sensors import learning_obs
    from robotwright.sensors.isaaclab.observations import _window_cells

    for _ in range(2):
        want = learning_obs.ray_cells(
            sensor.data.ray_directions_local.torch, sensor.direction_bounds(), 64, 16
        )
        assert torch.equal(_window_cells(sensor, 64, 16), want)
        _step(sim, scene, 1)


def test_every_mesh_prim_paths_entry_that_matches_nothing_is_named(world):
    """An entry naming no collision shape (a typo, a prim the scene lacks) is listed
    by name, the others are not; the sensor warns each one when it starts."""
    from robotwright.sensors.isaaclab.config import resolve
    from robotwright.sensors.isaaclab.scene_shapes import scene_shapes

    _, scene = world
    sensor = scene["seed"]
    model = sensor.backend.model
    carriers = model.shape_body.numpy()[sensor._sensor_site_indices.numpy()]
    cfg = _seed_cfg()
    cfg.mesh_prim_paths = [*cfg.mesh_prim_paths, "/World/no_such_prim", "{ENV_REGEX_NS}/Sofa"]
    shapes = scene_shapes(model, carriers, resolve(cfg), True, lambda path: 0)
    assert shapes.unmatched_patterns == ("/World/no_such_prim", "{ENV_REGEX_NS}/Sofa")
    seed = scene_shapes(model, carriers, resolve(_seed_cfg()), True, lambda path: 0)
    assert seed.unmatched_patterns == ()
    with pytest.warns(UserWarning, match="'/World/no_such_prim' matches no"):
        sensor.shapes, saved = shapes, sensor.shapes
        try:
            sensor._warn_scene()
        finally:
            sensor.shapes = saved


def test_one_skipping_cast_equals_the_re_casts_past_see_through_shapes(world):
    """pass_through="skip" (one BVH walk leaving the see-through robot out) gives what
    the re-casts past it give, ray for ray, over moving scenes; it loses no hit."""
    sim, scene = world
    skip, recast = scene["no_self"], scene["no_self_recast"]
    assert skip._skip_cast is not None and recast._skip_cast is None
    compared = 0
    for step in range(3):
        _step(sim, scene, 1, box_phase=0.4 * step)
        a, b = skip.data, recast.data
        hit = a.hit_mask.torch
        assert torch.equal(hit, b.hit_mask.torch)
        torch.testing.assert_close(
            a.ray_distances.torch[hit], b.ray_distances.torch[hit], atol=2e-4, rtol=0
        )
        same = a.shape_ids.torch == b.shape_ids.torch
        assert float(same[hit].float().mean()) > 0.999  # ties at shape seams aside
        assert torch.equal(a.semantic_labels.torch[hit & same], b.semantic_labels.torch[hit & same])
        compared += int(hit.sum())
    assert compared > 1000
    assert skip.lost_pass_through_hits == 0


def test_pass_through_defaults_to_the_skipping_cast_and_is_checked() -> None:
    from robotwright.sensors.isaaclab.config import resolve

    assert SemanticLidarCfg(prim_path=BASE).pass_through == "skip"
    with pytest.raises(SensorError, match="pass_through"):
        resolve(SemanticLidarCfg(prim_path=BASE, pass_through="twice"))


def test_hits_lost_to_max_pass_through_are_counted_and_warned(world):
    """With the robot see-through and no pass allowed, every ray that first meets the
    robot reads as a miss: counted on the device, at least the rays a multi-pass
    reference sees a hit for, and warned once."""
    sim, scene = world
    sensor = scene["no_self_recast"]
    _step(sim, scene, 1)
    before = sensor.lost_pass_through_hits
    saved = sensor.cfg.max_pass_through
    sensor.cfg.max_pass_through = 0
    sensor._casts, sensor._lost_warned = 0, False  # the next cast looks at the count
    try:
        with pytest.warns(UserWarning, match="max_pass_through=0"):
            _step(sim, scene, 1)
            _ = sensor.data
        lost = sensor.lost_pass_through_hits - before
        hit = sensor.get_hit_mask().reshape(-1).cpu().numpy()
        seen = sensor.shapes.visible.copy()
        _, _, ref_hit = _reference(sensor, seen, sensor.shapes.classes, sensor.cfg.max_distance)
        missed = int((ref_hit & ~hit).sum())
        assert 0 < missed <= lost <= hit.size
    finally:
        sensor.cfg.max_pass_through = saved
    _step(sim, scene, 1)
    _ = sensor.data
    after = sensor.lost_pass_through_hits
    assert after == before + lost  # four passes: the robot is passed, nothing lost
