"""Warp kernels of the device-resident LiDAR pipeline (imported only when warp is installed).

One frame on the device, for ``E`` environments and ``N`` rays per frame:

1. :func:`advance_frame` moves the pattern window (frame counter kept on the device, so
   the whole frame can be captured in a CUDA graph);
2. :func:`sensor_pose` reads the carrier's pose from the simulation's arrays and makes
   the sensor pose and the ray rotation (alignment ``base``/``yaw``/``world``);
3. :func:`world_rays` turns the window of the pattern table into world rays;
4. MuJoCo Warp casts them (``mujoco_warp.rays`` over its BVH);
5. :func:`finish_rays` refines curved hits in float64, applies the range model (min/max,
   Gaussian noise, dropout, seeded per environment), looks up labels and makes points.

Frames: world frame unless stated; distances [m]; quaternions (w, x, y, z).
"""

from __future__ import annotations

from typing import Any

import warp as wp

#: ``ray_alignment`` codes of :func:`sensor_pose`.
ALIGN_BASE, ALIGN_YAW, ALIGN_WORLD = 0, 1, 2
#: MuJoCo geom type ids of the curved primitives refined in float64.
SPHERE, CAPSULE, ELLIPSOID, CYLINDER = 2, 3, 4, 5


@wp.kernel
def advance_frame(
    frame: wp.array(dtype=wp.int32),
    num_frames: wp.int32,
    rays_per_frame: wp.int32,
    window: wp.array(dtype=wp.int32),
):
    """Next frame: ``frame += 1`` and the first table row of its window."""
    f = frame[0] + 1
    frame[0] = f
    window[0] = (f % num_frames) * rays_per_frame


@wp.func
def _pose(
    carrier_pos: wp.vec3,
    r: wp.mat33,
    offset_pos: wp.vec3,
    offset_mat: wp.mat33,
    alignment: wp.int32,
    e: wp.int32,
    pos_w: wp.array(dtype=wp.vec3),
    quat_w: wp.array(dtype=wp.vec4),
    sensor_mat: wp.array(dtype=wp.mat33),
    ray_rot: wp.array(dtype=wp.mat33),
):
    """Write environment ``e``'s sensor pose: carrier pose ``(carrier_pos, r)`` and the
    sensor's offset in the carrier frame."""
    m = r @ offset_mat
    pos_w[e] = carrier_pos + r @ offset_pos
    sensor_mat[e] = m
    q = wp.quat_from_matrix(m)  # warp order: x, y, z, w
    quat_w[e] = wp.vec4(q[3], q[0], q[1], q[2])
    if alignment == ALIGN_BASE:
        ray_rot[e] = m
    elif alignment == ALIGN_YAW:
        yaw = wp.atan2(m[1, 0], m[0, 0])
        c = wp.cos(yaw)
        s = wp.sin(yaw)
        ray_rot[e] = wp.mat33(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
    else:
        ray_rot[e] = wp.identity(n=3, dtype=wp.float32)


@wp.kernel
def sensor_pose(
    carrier_pos: wp.array2d(dtype=wp.vec3),
    carrier_mat: wp.array2d(dtype=wp.mat33),
    carrier: wp.int32,
    offset_pos: wp.vec3,
    offset_mat: wp.mat33,
    alignment: wp.int32,
    pos_w: wp.array(dtype=wp.vec3),
    quat_w: wp.array(dtype=wp.vec4),
    sensor_mat: wp.array(dtype=wp.mat33),
    ray_rot: wp.array(dtype=wp.mat33),
):
    """Sensor pose of each environment from its carrier body/site pose ``[e, carrier]``."""
    e = wp.tid()
    _pose(
        carrier_pos[e, carrier],
        carrier_mat[e, carrier],
        offset_pos,
        offset_mat,
        alignment,
        e,
        pos_w,
        quat_w,
        sensor_mat,
        ray_rot,
    )


@wp.kernel
def sensor_pose_per_env(
    carrier_pos: wp.array2d(dtype=wp.vec3),
    carrier_mat: wp.array2d(dtype=wp.mat33),
    carrier: wp.int32,
    offset_pos: wp.array(dtype=wp.vec3),
    offset_mat: wp.array(dtype=wp.mat33),
    alignment: wp.int32,
    pos_w: wp.array(dtype=wp.vec3),
    quat_w: wp.array(dtype=wp.vec4),
    sensor_mat: wp.array(dtype=wp.mat33),
    ray_rot: wp.array(dtype=wp.mat33),
):
    """As :func:`sensor_pose`, each environment with its own mount offset ``[e]``."""
    e = wp.tid()
    _pose(
        carrier_pos[e, carrier],
        carrier_mat[e, carrier],
        offset_pos[e],
        offset_mat[e],
        alignment,
        e,
        pos_w,
        quat_w,
        sensor_mat,
        ray_rot,
    )


@wp.kernel
def world_rays(
    table_o: wp.array(dtype=wp.vec3),
    table_d: wp.array(dtype=wp.vec3),
    window: wp.array(dtype=wp.int32),
    ray_offset: wp.int32,
    pos_w: wp.array(dtype=wp.vec3),
    ray_rot: wp.array(dtype=wp.mat33),
    pnt: wp.array2d(dtype=wp.vec3),
    vec: wp.array2d(dtype=wp.vec3),
    count: wp.int32,
    step: wp.int32,
):
    """World rays of every environment: the frame's window of the table, rotated and moved.

    ``pnt``/``vec`` may be a column slice of the frame's rays starting at ``ray_offset``.

    Thread ``(e, c)``: rays ``[c * step, (c + 1) * step)`` of environment ``e``, as
    :func:`launch_per_ray` launches it."""
    e, c = wp.tid()
    first = c * step
    for i in range(first, wp.min(first + step, count)):
        k = window[0] + ray_offset + i
        r = ray_rot[e]
        pnt[e, i] = pos_w[e] + r @ table_o[k]
        vec[e, i] = r @ table_d[k]


@wp.func
def _nearest(best: wp.float64, t0: wp.float64, t: wp.float64) -> wp.float64:
    """The candidate root nearer to ``t0`` (roots behind the origin are ignored)."""
    if t >= wp.float64(0.0) and wp.abs(t - t0) < wp.abs(best - t0):
        return t
    return best


@wp.func
def _root(a: wp.float64, b: wp.float64, c: wp.float64, which: wp.int32) -> wp.float64:
    """Root ``which`` (0 or 1) of ``a t^2 + 2 b t + c = 0`` in the stable form, or -1
    (a point behind the origin, which :func:`_nearest` ignores) when there is none."""
    disc = b * b - a * c
    if disc < wp.float64(0.0) or a <= wp.float64(0.0):
        return wp.float64(-1.0)
    sq = wp.sqrt(disc)
    q = -b - sq
    if b < wp.float64(0.0):
        q = -b + sq
    if which == 0:
        return q / a
    if q != wp.float64(0.0):
        return c / q
    return wp.float64(-1.0)


@wp.func
def _quadric(
    best: wp.float64, t0: wp.float64, a: wp.float64, b: wp.float64, c: wp.float64
) -> wp.float64:
    """Both roots of ``a t^2 + 2 b t + c = 0`` offered to :func:`_nearest`."""
    return _nearest(_nearest(best, t0, _root(a, b, c, 0)), t0, _root(a, b, c, 1))


@wp.func
def _side(
    best: wp.float64, t0: wp.float64, p: wp.vec3d, v: wp.vec3d, r: wp.float64, h: wp.float64
) -> wp.float64:
    """Infinite cylinder ``x^2 + y^2 = r^2`` restricted to ``|z| <= h``."""
    a = v[0] * v[0] + v[1] * v[1]
    b = p[0] * v[0] + p[1] * v[1]
    c = p[0] * p[0] + p[1] * p[1] - r * r
    out = best
    for which in range(2):
        t = _root(a, b, c, which)
        if wp.abs(p[2] + t * v[2]) <= h:
            out = _nearest(out, t0, t)
    return out


@wp.func
def _cap_sphere(
    best: wp.float64,
    t0: wp.float64,
    p: wp.vec3d,
    v: wp.vec3d,
    r: wp.float64,
    h: wp.float64,
    sign: wp.float64,
) -> wp.float64:
    """Hemispherical cap of a capsule: sphere of radius ``r`` at ``z = sign * h``."""
    pc = wp.vec3d(p[0], p[1], p[2] - sign * h)
    a = wp.dot(v, v)
    b = wp.dot(pc, v)
    c = wp.dot(pc, pc) - r * r
    out = best
    for which in range(2):
        t = _root(a, b, c, which)
        if sign * (p[2] + t * v[2]) >= h:
            out = _nearest(out, t0, t)
    return out


@wp.func
def _disc(
    best: wp.float64,
    t0: wp.float64,
    p: wp.vec3d,
    v: wp.vec3d,
    r: wp.float64,
    h: wp.float64,
    sign: wp.float64,
) -> wp.float64:
    """Flat cap of a cylinder: the disc of radius ``r`` at ``z = sign * h``."""
    if v[2] == wp.float64(0.0):
        return best
    t = (sign * h - p[2]) / v[2]
    x = p[0] + t * v[0]
    y = p[1] + t * v[1]
    if x * x + y * y <= r * r:
        return _nearest(best, t0, t)
    return best


@wp.func
def refine_curved(
    kind: wp.int32, size: wp.vec3d, p: wp.vec3d, v: wp.vec3d, t0: wp.float64
) -> wp.float64:
    """Float64 distance of a hit on a sphere/capsule/ellipsoid/cylinder found in float32.

    A float32 quadratic solve loses about ``sqrt(eps32) * radius`` (up to ~1e-4 m) on
    grazing rays; the engine already knows which geom was hit, so the exact root is the
    surface intersection nearest to the float32 distance ``t0``. ``p`` and ``v`` are the
    ray origin and direction in the geom frame. Other geom types return ``t0``.
    """
    far = wp.float64(1.0e30)
    best = far
    s0 = size[0]
    s1 = size[1]
    s2 = size[2]
    if kind == SPHERE or kind == ELLIPSOID:  # noqa: SIM109 (no tuples in warp kernels)
        rx = s0
        ry = s0
        rz = s0
        if kind == ELLIPSOID:
            ry = s1
            rz = s2
        ps = wp.vec3d(p[0] / rx, p[1] / ry, p[2] / rz)
        vs = wp.vec3d(v[0] / rx, v[1] / ry, v[2] / rz)
        best = _quadric(best, t0, wp.dot(vs, vs), wp.dot(ps, vs), wp.dot(ps, ps) - wp.float64(1.0))
    elif kind == CAPSULE:
        best = _side(best, t0, p, v, s0, s1)
        best = _cap_sphere(best, t0, p, v, s0, s1, wp.float64(-1.0))
        best = _cap_sphere(best, t0, p, v, s0, s1, wp.float64(1.0))
    elif kind == CYLINDER:
        best = _side(best, t0, p, v, s0, s1)
        best = _disc(best, t0, p, v, s0, s1, wp.float64(-1.0))
        best = _disc(best, t0, p, v, s0, s1, wp.float64(1.0))
    if best == far:
        return t0
    return best


@wp.func
def _to64(a: wp.vec3) -> wp.vec3d:
    return wp.vec3d(wp.float64(a[0]), wp.float64(a[1]), wp.float64(a[2]))


@wp.func
def _rt_mul(r: wp.mat33, x: wp.vec3d) -> wp.vec3d:
    """``R^T x`` in float64 for a float32 rotation ``R``."""
    return wp.vec3d(
        wp.float64(r[0, 0]) * x[0] + wp.float64(r[1, 0]) * x[1] + wp.float64(r[2, 0]) * x[2],
        wp.float64(r[0, 1]) * x[0] + wp.float64(r[1, 1]) * x[1] + wp.float64(r[2, 1]) * x[2],
        wp.float64(r[0, 2]) * x[0] + wp.float64(r[1, 2]) * x[1] + wp.float64(r[2, 2]) * x[2],
    )


@wp.func
def _mix_seed(env_seed: wp.int32, frame: wp.int32) -> wp.int32:
    """One generator seed per (environment, frame), from a per-environment seed."""
    h = wp.uint32(env_seed) * wp.uint32(747796405) ^ (wp.uint32(frame) * wp.uint32(1664525))
    return wp.int32(h ^ (h >> wp.uint32(15)))


@wp.func
def ranged_hit(
    raw_dist: wp.array2d(dtype=wp.float32),
    raw_geom: wp.array2d(dtype=wp.int32),
    pnt: wp.array2d(dtype=wp.vec3),
    vec: wp.array2d(dtype=wp.vec3),
    geom_xpos: wp.array2d(dtype=wp.vec3),
    geom_xmat: wp.array2d(dtype=wp.mat33),
    geom_type: wp.array(dtype=wp.int32),
    geom_size: wp.array(dtype=wp.vec3d),
    refine: wp.int32,
    min_distance: wp.float32,
    max_distance: wp.float32,
    noise_std: wp.float32,
    dropout_prob: wp.float32,
    env_seed: wp.array(dtype=wp.int32),
    frame: wp.array(dtype=wp.int32),
    ray_offset: wp.int32,
    e: wp.int32,
    i: wp.int32,
):
    """Whether ray ``(e, i)`` returns a point, and its distance [m]: a curved hit
    refined in float64, the range ``[min_distance, max_distance]``, Gaussian noise and
    dropout (the range model of :func:`finish_rays`, shared by the adapters)."""
    g = raw_geom[e, i]
    d = raw_dist[e, i]
    hit = g >= 0
    if hit and refine != 0:
        kind = geom_type[g]
        if kind >= SPHERE and kind <= CYLINDER:  # the curved primitives, ids 2..5
            # Geom frame in float64: p = R^T (o - x), v = R^T d.
            r = geom_xmat[e, g]
            p = _rt_mul(r, _to64(pnt[e, i]) - _to64(geom_xpos[e, g]))
            v = _rt_mul(r, _to64(vec[e, i]))
            d = wp.float32(refine_curved(kind, geom_size[g], p, v, wp.float64(d)))
    if hit:
        hit = d >= min_distance and d <= max_distance
    if hit and (noise_std > 0.0 or dropout_prob > 0.0):
        state = wp.rand_init(_mix_seed(env_seed[e], frame[0]), ray_offset + i)
        if noise_std > 0.0:
            d = wp.clamp(d + noise_std * wp.randn(state), min_distance, max_distance)
        if dropout_prob > 0.0 and wp.randf(state) < dropout_prob:
            hit = False
    return hit, d


@wp.kernel
def finish_rays(
    raw_dist: wp.array2d(dtype=wp.float32),
    raw_geom: wp.array2d(dtype=wp.int32),
    pnt: wp.array2d(dtype=wp.vec3),
    vec: wp.array2d(dtype=wp.vec3),
    geom_xpos: wp.array2d(dtype=wp.vec3),
    geom_xmat: wp.array2d(dtype=wp.mat33),
    geom_type: wp.array(dtype=wp.int32),
    geom_size: wp.array(dtype=wp.vec3d),
    refine: wp.int32,
    min_distance: wp.float32,
    max_distance: wp.float32,
    noise_std: wp.float32,
    dropout_prob: wp.float32,
    miss_distance: wp.float32,
    env_seed: wp.array(dtype=wp.int32),
    frame: wp.array(dtype=wp.int32),
    label_lut: wp.array(dtype=wp.int32),
    ray_offset: wp.int32,
    distances: wp.array2d(dtype=wp.float32),
    hit_mask: wp.array2d(dtype=wp.bool),
    geom_ids: wp.array2d(dtype=wp.int32),
    labels: wp.array2d(dtype=wp.int32),
    points: wp.array2d(dtype=wp.vec3),
    count: wp.int32,
    step: wp.int32,
):
    """Range model, labels and points of every ray (see the module docstring).

    A ray is a miss when it hits nothing, hits nearer than ``min_distance`` or further
    than ``max_distance``, or is dropped; noise is added to hits only and clipped to
    ``[min_distance, max_distance]``. Misses: distance ``miss_distance``, mask False,
    geom id -1, label 0, point NaN. The arrays may be a column slice of the frame's rays
    starting at ``ray_offset`` (the random stream of a ray depends on its index only).

    Thread ``(e, c)``: rays ``[c * step, (c + 1) * step)`` of environment ``e``, as
    :func:`launch_per_ray` launches it."""
    e, c = wp.tid()
    first = c * step
    for i in range(first, wp.min(first + step, count)):
        g = raw_geom[e, i]
        hit, d = ranged_hit(
            raw_dist,
            raw_geom,
            pnt,
            vec,
            geom_xpos,
            geom_xmat,
            geom_type,
            geom_size,
            refine,
            min_distance,
            max_distance,
            noise_std,
            dropout_prob,
            env_seed,
            frame,
            ray_offset,
            e,
            i,
        )
        hit_mask[e, i] = hit
        if hit:
            distances[e, i] = d
            geom_ids[e, i] = g
            labels[e, i] = label_lut[g]
            points[e, i] = pnt[e, i] + d * vec[e, i]
        else:
            distances[e, i] = miss_distance
            geom_ids[e, i] = -1
            labels[e, i] = 0
            points[e, i] = wp.vec3(wp.nan, wp.nan, wp.nan)


def launch_per_ray(
    kernel: Any, dim: tuple[int, int], inputs: list, outputs: list, device: Any
) -> None:
    """Launch a per-ray kernel (its last parameters ``count, step``) over ``dim`` =
    (environments, rays): on CUDA a thread a ray (``(E, N)`` threads, ``step`` 1), on
    warp's CPU device a thread per environment looping over its rays (``(E, 1)``,
    ``step`` N): there a 2-D launch's index costs more per ray than a light kernel's
    work (measured 2.4x faster on 320,000 rays)."""
    e, n = dim
    grid, step = ((e, n), 1) if device.is_cuda else ((e, 1), n)
    wp.launch(kernel, dim=grid, inputs=[*inputs, *outputs, n, step], device=device)
