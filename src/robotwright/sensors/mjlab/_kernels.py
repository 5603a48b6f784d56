"""Warp kernels of the mjlab adapter: the scan in simulated time with a window per
environment, world rays with drift and angular jitter, and the last pass over each
step's rays (range noise growing with distance, dropout per class, mjlab's miss
convention, and holding the published scan between updates).

Per environment ``e``: ``start[e]`` is the first table row of its window (the oldest
of the ``N`` rays it returns), ``carry[e]`` the fraction of a ray fired but not yet
counted, ``timer[e]`` the seconds since its last published scan [s], ``fresh[e]`` set by
a reset (the next scan starts at its phase and is published).
"""

from __future__ import annotations

import warp as wp

from robotwright.sensors._warp_kernels import _mix_seed, ranged_hit

#: Random-stream offset of the angular jitter (apart from the range model's streams).
JITTER_STREAM = 1 << 30
#: Random-stream offset of the distance-dependent noise and the class dropout.
REALISM_STREAM = 1 << 29


@wp.kernel
def advance_scan(
    elapsed: wp.array(dtype=wp.float64),
    rays_per_second: wp.float64,
    rows: wp.int32,
    rays: wp.int32,
    period: wp.float64,
    fresh: wp.array(dtype=wp.int32),
    start: wp.array(dtype=wp.int32),
    carry: wp.array(dtype=wp.float64),
    timer: wp.array(dtype=wp.float64),
    due: wp.array(dtype=wp.int32),
    published: wp.array(dtype=wp.int32),
):
    """Move each environment's window by the simulated time ``elapsed[0]`` [s] since the
    last sense, and decide whether its scan is published this step (``due``).

    A timed pattern (``rays_per_second > 0``) keeps firing: its window moves by the rays
    fired in that time, so the ``N`` rays returned are the latest ``N`` fired. An
    untimed one moves one frame (``rays`` rows) per published scan. With ``period > 0``
    a scan is published once ``period`` seconds have passed since the last (Isaac
    Lab's ``update_period``); a fresh environment (just reset) is published at once.
    ``published`` keeps the window start of the scan each environment's data hold.
    """
    e = wp.tid()
    dt = elapsed[0]
    if fresh[e] != 0:
        fresh[e] = 0
        timer[e] = wp.float64(0.0)
        due[e] = 1
        published[e] = start[e]
        return
    if rays_per_second > wp.float64(0.0):
        c = carry[e] + dt * rays_per_second
        k = wp.floor(c)
        carry[e] = c - k
        start[e] = wp.int32((wp.int64(start[e]) + wp.int64(k)) % wp.int64(rows))
    t = timer[e] + dt
    if period <= wp.float64(0.0) or t + wp.float64(1.0e-9) >= period:
        due[e] = 1
        if rays_per_second <= wp.float64(0.0):
            start[e] = (start[e] + rays) % rows
        if period > wp.float64(0.0):
            t = t - period * wp.floor((t + wp.float64(1.0e-9)) / period)
        timer[e] = wp.max(t, wp.float64(0.0))
        published[e] = start[e]
    else:
        due[e] = 0
        timer[e] = t


#: Height [m] rays of a held scan start from, pointing up: above any world a model holds.
AWAY_Z = wp.constant(wp.float32(1.0e7))


@wp.kernel
def world_rays_windowed(
    table_o: wp.array(dtype=wp.vec3),
    table_d: wp.array(dtype=wp.vec3),
    start: wp.array(dtype=wp.int32),
    rows: wp.int32,
    ray_offset: wp.int32,
    pos_w: wp.array(dtype=wp.vec3),
    ray_rot: wp.array(dtype=wp.mat33),
    drift: wp.array(dtype=wp.vec3),
    jitter_std: wp.float32,
    env_seed: wp.array(dtype=wp.int32),
    frame: wp.array(dtype=wp.int32),
    hold: wp.int32,
    due: wp.array(dtype=wp.int32),
    origins: wp.int32,
    pnt: wp.array2d(dtype=wp.vec3),
    vec: wp.array2d(dtype=wp.vec3),
    count: wp.int32,
    step: wp.int32,
):
    """World rays of environment ``e``: table rows ``start[e] + i`` (wrapping), rotated
    and moved to the sensor, origins shifted by the environment's ``drift`` [m] and
    directions tilted by Gaussian angular jitter of ``jitter_std`` [rad] per axis.
    ``pnt``/``vec`` may be a column slice of the rays starting at ``ray_offset``;
    ``origins`` is 0 when every table origin is the sensor's (the rotation of a zero
    offset is skipped).

    With ``hold`` (scans held between updates), an environment whose scan is not
    ``due`` gets rays that start far above the world and point up: the BVH's root
    box turns them away at once, so its held scan costs next to no cast.

    Thread ``(e, c)``: rays ``[c * step, (c + 1) * step)`` of environment ``e``, as
    :func:`~robotwright.sensors._warp_kernels.launch_per_ray` launches it."""
    e, c = wp.tid()
    first = c * step
    for i in range(first, wp.min(first + step, count)):
        if hold != 0 and due[e] == 0:
            pnt[e, i] = wp.vec3(0.0, 0.0, AWAY_Z)
            vec[e, i] = wp.vec3(0.0, 0.0, 1.0)
            continue
        k = start[e] + ray_offset + i
        while k >= rows:  # a subtraction, not a division: start < rows, and mostly N <= rows
            k -= rows
        r = ray_rot[e]
        d = r @ table_d[k]
        if jitter_std > wp.float32(0.0):
            state = wp.rand_init(_mix_seed(env_seed[e], frame[0]), JITTER_STREAM + ray_offset + i)
            g = wp.vec3(wp.randn(state), wp.randn(state), wp.randn(state)) * jitter_std
            d = wp.normalize(d + (g - wp.dot(g, d) * d))
        o = pos_w[e] + drift[e]
        if origins != 0:
            o = o + r @ table_o[k]
        pnt[e, i] = o
        vec[e, i] = d


@wp.kernel
def finish_rays_mjlab(
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
    label_lut: wp.array(dtype=wp.int32),
    ray_offset: wp.int32,
    distances: wp.array2d(dtype=wp.float32),
    hit_mask: wp.array2d(dtype=wp.bool),
    geom_ids: wp.array2d(dtype=wp.int32),
    labels: wp.array2d(dtype=wp.int32),
    points: wp.array2d(dtype=wp.vec3),
    normals: wp.array2d(dtype=wp.vec3),
    count: wp.int32,
    step: wp.int32,
):
    """The range model and labels of every ray with mjlab's miss values (distance -1,
    hit point = ray origin, normal 0), in one pass: the plain case (no realism option
    of this adapter, scans published every step), where :func:`mjlab_finish` has
    nothing else to do.

    Thread ``(e, c)``: rays ``[c * step, (c + 1) * step)`` of environment ``e``, as
    :func:`~robotwright.sensors._warp_kernels.launch_per_ray` launches it."""
    e, c = wp.tid()
    first = c * step
    for i in range(first, wp.min(first + step, count)):
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
            g = raw_geom[e, i]
            distances[e, i] = d
            geom_ids[e, i] = g
            labels[e, i] = label_lut[g]
            points[e, i] = pnt[e, i] + d * vec[e, i]
        else:
            distances[e, i] = wp.float32(-1.0)
            geom_ids[e, i] = -1
            labels[e, i] = 0
            points[e, i] = pnt[e, i]
            normals[e, i] = wp.vec3(0.0, 0.0, 0.0)


@wp.kernel
def mjlab_finish(
    distances: wp.array2d(dtype=wp.float32),
    hit_mask: wp.array2d(dtype=wp.bool),
    geom_ids: wp.array2d(dtype=wp.int32),
    labels: wp.array2d(dtype=wp.int32),
    points: wp.array2d(dtype=wp.vec3),
    normals: wp.array2d(dtype=wp.vec3),
    pnt: wp.array2d(dtype=wp.vec3),
    vec: wp.array2d(dtype=wp.vec3),
    noise_per_meter: wp.float32,
    class_dropout: wp.array(dtype=wp.float32),
    min_distance: wp.float32,
    max_distance: wp.float32,
    env_seed: wp.array(dtype=wp.int32),
    frame: wp.array(dtype=wp.int32),
    ray_offset: wp.int32,
    hold: wp.int32,
    due: wp.array(dtype=wp.int32),
    out_distances: wp.array2d(dtype=wp.float32),
    out_hit_mask: wp.array2d(dtype=wp.bool),
    out_geom_ids: wp.array2d(dtype=wp.int32),
    out_labels: wp.array2d(dtype=wp.int32),
    out_points: wp.array2d(dtype=wp.vec3),
    out_normals: wp.array2d(dtype=wp.vec3),
    out_pnt: wp.array2d(dtype=wp.vec3),
    out_vec: wp.array2d(dtype=wp.vec3),
    count: wp.int32,
    step: wp.int32,
):
    """The last pass over a ray: extra range noise (standard deviation
    ``noise_per_meter`` x distance, clipped to the range), dropout with the probability
    of the hit's class, mjlab's miss values (hit point = ray origin, normal 0, distance
    -1), then the result written to the published arrays ``out_*``: always when
    ``hold`` is 0 (they may be the arrays read), else only where the environment's scan
    is ``due`` (the others keep their last published scan).

    Thread ``(e, c)``: rays ``[c * step, (c + 1) * step)`` of environment ``e``, as
    :func:`~robotwright.sensors._warp_kernels.launch_per_ray` launches it."""
    e, c = wp.tid()
    first = c * step
    for i in range(first, wp.min(first + step, count)):
        if hold != 0 and due[e] == 0:
            continue
        hit = hit_mask[e, i]
        d = distances[e, i]
        lab = labels[e, i]
        changed = False
        if hit and (noise_per_meter > wp.float32(0.0) or class_dropout[lab] > wp.float32(0.0)):
            state = wp.rand_init(_mix_seed(env_seed[e], frame[0]), REALISM_STREAM + ray_offset + i)
            if noise_per_meter > wp.float32(0.0):
                d = wp.clamp(d + noise_per_meter * d * wp.randn(state), min_distance, max_distance)
                changed = True
            if wp.randf(state) < class_dropout[lab]:
                hit = False
        if hold == 0:
            # The published arrays are the ones read: write only what differs.
            if not hit:
                out_hit_mask[e, i] = False
                out_distances[e, i] = wp.float32(-1.0)
                out_geom_ids[e, i] = -1
                out_labels[e, i] = 0
                out_points[e, i] = pnt[e, i]
                out_normals[e, i] = wp.vec3(0.0, 0.0, 0.0)
            elif changed:
                out_distances[e, i] = d
                out_points[e, i] = pnt[e, i] + d * vec[e, i]
            continue
        out_pnt[e, i] = pnt[e, i]
        out_vec[e, i] = vec[e, i]
        out_hit_mask[e, i] = hit
        if hit:
            out_distances[e, i] = d
            out_geom_ids[e, i] = geom_ids[e, i]
            out_labels[e, i] = lab
            out_points[e, i] = pnt[e, i] + d * vec[e, i]
            out_normals[e, i] = normals[e, i]
        else:
            out_distances[e, i] = wp.float32(-1.0)
            out_geom_ids[e, i] = -1
            out_labels[e, i] = 0
            out_points[e, i] = pnt[e, i]
            out_normals[e, i] = wp.vec3(0.0, 0.0, 0.0)
