"""Warp kernels of the Isaac Lab LiDAR: pattern windows, pass-through re-casts, results.

Every kernel runs on the device of the sensor (warp's CPU device or CUDA) and reads
per-environment state (timestamps, masks) from device arrays, so nothing is decided on
the host per ray.
"""

from __future__ import annotations

import warp as wp

#: Distance [m] a re-cast ray starts past a shape it passes through.
PASS_THROUGH_EPS = 1.0e-4


@wp.kernel(enable_backward=False)
def pattern_window(
    env_mask: wp.array(dtype=wp.bool),
    timestamp: wp.array(dtype=wp.float32),
    frame_period: float,
    num_frames: int,
    table_starts: wp.array(dtype=wp.vec3f),
    table_dirs: wp.array(dtype=wp.vec3f),
    table_local_dirs: wp.array(dtype=wp.vec3f),
    ray_starts: wp.array2d(dtype=wp.vec3f),
    ray_dirs: wp.array2d(dtype=wp.vec3f),
    local_dirs: wp.array2d(dtype=wp.vec3f),
    frame: wp.array(dtype=wp.int32),
):
    """Rays of each due environment's current window: frame ``floor(t / period) % F``.

    ``t`` is the environment's simulated time since its last reset, so each environment
    scans at its own phase. Table rows are already in the carrier frame (offset applied);
    ``local_dirs`` keeps the sensor-frame directions (for range images). dim=(E, N).
    """
    env, ray = wp.tid()
    if not env_mask[env]:
        return
    k = int(wp.floor(timestamp[env] / frame_period)) % num_frames
    if k < 0:
        k = k + num_frames
    row = k * ray_starts.shape[1] + ray
    ray_starts[env, ray] = table_starts[row]
    ray_dirs[env, ray] = table_dirs[row]
    local_dirs[env, ray] = table_local_dirs[row]
    if ray == 0:
        frame[env] = k


@wp.kernel(enable_backward=False)
def first_pass(
    env_mask: wp.array(dtype=wp.bool),
    hit_dist: wp.array(dtype=wp.float32),
    hit_shape: wp.array(dtype=wp.int32),
    hit_normal: wp.array(dtype=wp.vec3f),
    shape_visible: wp.array(dtype=wp.int32),
    max_distance: float,
    num_rays: int,
    total: wp.array(dtype=wp.float32),
    shape: wp.array(dtype=wp.int32),
    normal: wp.array(dtype=wp.vec3f),
    pending: wp.array(dtype=wp.int32),
    pending_count: wp.array(dtype=wp.int32),
):
    """Take the first cast: a hit on a seen shape is final; a hit on a see-through shape
    within range is queued for a re-cast past it. dim=(E * N,)."""
    i = wp.tid()
    if not env_mask[i // num_rays]:
        return
    s = hit_shape[i]
    t = hit_dist[i]
    total[i] = t
    shape[i] = s
    normal[i] = hit_normal[i]
    if s >= 0 and t <= max_distance and shape_visible[s] == 0:
        slot = wp.atomic_add(pending_count, 0, 1)
        pending[slot] = i
        shape[i] = -2  # not final yet


@wp.kernel(enable_backward=False)
def gather_pending(
    pending: wp.array(dtype=wp.int32),
    total: wp.array(dtype=wp.float32),
    starts: wp.array(dtype=wp.vec3f),
    dirs: wp.array(dtype=wp.vec3f),
    worlds: wp.array(dtype=wp.int32),
    sub_starts: wp.array(dtype=wp.vec3f),
    sub_dirs: wp.array(dtype=wp.vec3f),
    sub_worlds: wp.array(dtype=wp.int32),
):
    """Re-cast rays start just past the see-through shape they hit. dim=(pending,)."""
    j = wp.tid()
    i = pending[j]
    d = dirs[i]
    sub_starts[j] = starts[i] + d * (total[i] + PASS_THROUGH_EPS)
    sub_dirs[j] = d
    sub_worlds[j] = worlds[i]


@wp.kernel(enable_backward=False)
def scatter_pass(
    pending: wp.array(dtype=wp.int32),
    sub_dist: wp.array(dtype=wp.float32),
    sub_shape: wp.array(dtype=wp.int32),
    sub_normal: wp.array(dtype=wp.vec3f),
    shape_visible: wp.array(dtype=wp.int32),
    max_distance: float,
    last_pass: int,
    total: wp.array(dtype=wp.float32),
    shape: wp.array(dtype=wp.int32),
    normal: wp.array(dtype=wp.vec3f),
    next_pending: wp.array(dtype=wp.int32),
    next_count: wp.array(dtype=wp.int32),
    lost: wp.array(dtype=wp.int32),
):
    """Merge a re-cast into the rays' results; rays still behind see-through shapes are
    queued again, or on the last pass become misses, counted in ``lost[0]``.
    dim=(pending,)."""
    j = wp.tid()
    i = pending[j]
    s = sub_shape[j]
    if s < 0:
        total[i] = -1.0
        shape[i] = -1
        return
    t = total[i] + PASS_THROUGH_EPS + sub_dist[j]
    total[i] = t
    normal[i] = sub_normal[j]
    if t > max_distance or shape_visible[s] != 0:
        shape[i] = s
        return
    if last_pass != 0:
        total[i] = -1.0
        shape[i] = -1
        wp.atomic_add(lost, 0, 1)
        return
    slot = wp.atomic_add(next_count, 0, 1)
    next_pending[slot] = i


@wp.kernel(enable_backward=False)
def add_count(src: wp.array(dtype=wp.int32), dst: wp.array(dtype=wp.int32)):
    """``dst[0] += src[0]`` on the device (no host read). dim=1."""
    dst[0] = dst[0] + src[0]


@wp.kernel(enable_backward=False)
def finish_rays(
    env_mask: wp.array(dtype=wp.bool),
    starts_w: wp.array2d(dtype=wp.vec3f),
    dirs_w: wp.array2d(dtype=wp.vec3f),
    total: wp.array(dtype=wp.float32),
    shape: wp.array(dtype=wp.int32),
    normal: wp.array(dtype=wp.vec3f),
    shape_class: wp.array(dtype=wp.int32),
    min_distance: float,
    max_distance: float,
    drift: wp.array(dtype=wp.vec3f),
    hits_w: wp.array2d(dtype=wp.vec3f),
    distances: wp.array2d(dtype=wp.float32),
    normals_w: wp.array2d(dtype=wp.vec3f),
    hit_mask: wp.array2d(dtype=wp.bool),
    shape_ids: wp.array2d(dtype=wp.int32),
    labels: wp.array2d(dtype=wp.int32),
):
    """Isaac Lab's outputs (``inf`` on a miss; the ray-cast z drift on hits) plus the hit
    mask, the hit shape id (-1 on a miss) and its class (0 on a miss). dim=(E, N)."""
    env, ray = wp.tid()
    if not env_mask[env]:
        return
    i = env * starts_w.shape[1] + ray
    t = total[i]
    s = shape[i]
    if s >= 0 and t >= min_distance and t <= max_distance:
        p = starts_w[env, ray] + t * dirs_w[env, ray]
        hits_w[env, ray] = wp.vec3f(p[0], p[1], p[2] + drift[env][2])
        distances[env, ray] = t
        normals_w[env, ray] = normal[i]
        hit_mask[env, ray] = True
        shape_ids[env, ray] = s
        labels[env, ray] = shape_class[s]
    else:
        inf3 = wp.vec3f(wp.inf, wp.inf, wp.inf)
        hits_w[env, ray] = inf3
        distances[env, ray] = wp.inf
        normals_w[env, ray] = inf3
        hit_mask[env, ray] = False
        shape_ids[env, ray] = -1
        labels[env, ray] = 0
