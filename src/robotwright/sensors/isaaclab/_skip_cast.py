"""One cast that skips see-through shapes inside its BVH walk: no re-casts, no host read.

``newton.intersect_ray`` reports the nearest shape a ray meets; a LiDAR mounted inside
its robot, or told to see only some shapes (``mesh_prim_paths``), needs the nearest
*seen* shape. This kernel walks Newton's shape BVH exactly as ``intersect_ray`` does
(the ray's own world, then the global world; the same primitive and mesh intersection
functions) and leaves out the shapes whose ``visible`` entry is 0, so every ray is cast
once whatever it passes, the cost of the stock cast, and nothing is read on the host
(CUDA graphs capture it).

It uses Newton's intersection functions from ``newton._src.geometry.raycast`` (Newton
exports none of them); :func:`skip_cast_kernel` returns ``None`` where they are missing,
and the sensor then re-casts past each see-through shape instead.
"""

from __future__ import annotations

import functools
from typing import Any

import warp as wp

__all__ = ["skip_cast_kernel"]


@functools.cache
def skip_cast_kernel(global_world: bool) -> Any:
    """The kernel (``dim = E * N``), or ``None`` when this Newton lacks the functions."""
    try:
        from newton._src.geometry.raycast import (
            map_ray_to_local,
            ray_intersect_mesh,
            ray_intersect_shape,
        )
        from newton._src.geometry.types import GeoType
    except ImportError:
        return None
    mesh, convex, hfield = int(GeoType.MESH), int(GeoType.CONVEX_MESH), int(GeoType.HFIELD)

    @wp.kernel(enable_backward=False, module="unique")
    def cast_seen(
        bvh_id: wp.uint64,
        group_roots: wp.array(dtype=wp.int32),
        bvh_shape: wp.array(dtype=wp.uint32),
        shape_xform: wp.array(dtype=wp.transform),
        shape_type: wp.array(dtype=int),
        shape_scale: wp.array(dtype=wp.vec3),
        shape_source: wp.array(dtype=wp.uint64),
        visible: wp.array(dtype=wp.int32),
        env_mask: wp.array(dtype=wp.bool),
        num_rays: int,
        origins: wp.array(dtype=wp.vec3),
        directions: wp.array(dtype=wp.vec3),
        worlds: wp.array(dtype=wp.int32),
        max_distance: float,
        total: wp.array(dtype=wp.float32),
        shape_out: wp.array(dtype=wp.int32),
        normal_out: wp.array(dtype=wp.vec3f),
    ):
        i = wp.tid()
        if not env_mask[i // num_rays]:
            return
        origin = origins[i]
        direction = directions[i]
        # Hits beyond the range are misses either way: the walk stops there.
        best = max_distance * 1.0001 + 1.0e-6
        best_shape = wp.int32(-1)
        best_normal = wp.vec3(0.0)
        for k in range(wp.static(2 if global_world else 1)):
            group = worlds[i] if k == 0 else group_roots.shape[0] - 1
            root = group_roots[group]
            if root < 0:
                continue
            query = wp.bvh_query_ray(bvh_id, origin, direction, root)
            leaf = wp.int32(0)
            while wp.bvh_query_next(query, leaf, best):
                s = wp.int32(bvh_shape[leaf])
                if visible[s] == 0:
                    continue
                kind = shape_type[s]
                normal = wp.vec3(0.0)
                if (
                    kind == wp.static(mesh)
                    or kind == wp.static(convex)
                    or kind == wp.static(hfield)
                ):
                    xform = shape_xform[s]
                    o_local, d_local = map_ray_to_local(xform, origin, direction, shape_scale[s])
                    t, n_local, _u, _v, _f = ray_intersect_mesh(
                        o_local, d_local, shape_scale[s], shape_source[s], False, best
                    )
                    if t >= 0.0:
                        normal = wp.normalize(wp.transform_vector(xform, n_local))
                else:
                    t, normal = ray_intersect_shape(
                        shape_xform[s], shape_scale[s], kind, origin, direction, False
                    )
                if t >= 0.0 and t < best:
                    best = t
                    best_shape = s
                    best_normal = normal
        total[i] = wp.where(best_shape < 0, -1.0, best)
        shape_out[i] = best_shape
        normal_out[i] = wp.vec3f(best_normal[0], best_normal[1], best_normal[2])

    return cast_seen
