"""Warp kernels of the batched engine (imported only when warp is installed)."""

from __future__ import annotations

import warp as wp


@wp.kernel
def world_rays(
    pat_o: wp.array(dtype=wp.vec3),
    pat_d: wp.array(dtype=wp.vec3),
    rot: wp.array(dtype=wp.mat33),
    pos: wp.array(dtype=wp.vec3),
    pnt: wp.array2d(dtype=wp.vec3),
    vec: wp.array2d(dtype=wp.vec3),
):
    """World rays of every environment from one pattern and one pose per environment."""
    e, i = wp.tid()
    r = rot[e]
    pnt[e, i] = pos[e] + r @ pat_o[i]
    vec[e, i] = r @ pat_d[i]
