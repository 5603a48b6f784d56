"""Warp kernel of the mjlab adapter: mjlab's ``RayCastData`` miss convention in place."""

from __future__ import annotations

import warp as wp


@wp.kernel
def mjlab_misses(
    hit_mask: wp.array2d(dtype=wp.bool),
    pnt: wp.array2d(dtype=wp.vec3),
    points: wp.array2d(dtype=wp.vec3),
    normals: wp.array2d(dtype=wp.vec3),
):
    """A miss (nothing hit, out of range or dropped) gets mjlab's values: hit point = ray
    origin, normal = 0. The arrays may be a column slice of the frame's rays."""
    e, i = wp.tid()
    if not hit_mask[e, i]:
        points[e, i] = pnt[e, i]
        normals[e, i] = wp.vec3(0.0, 0.0, 0.0)
