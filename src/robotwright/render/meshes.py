"""Triangles of the geoms in a :class:`mujoco.MjvScene`, for the software renderer.

MuJoCo's own :func:`mujoco.mjv_updateScene` decides what is visible (geom and site
groups, materials, colours, poses); this module only turns each visible ``mjvGeom``
into world-frame triangles: primitives come from
:func:`robotwright.scene.geometry.primitive_mesh` (the browser viewer's shapes too), meshes
and height fields from the compiled model's arrays.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np

from robotwright.scene.geometry import hfield_surface, primitive_mesh

__all__ = ["SceneTriangles", "scene_triangles"]

_G = mujoco.mjtGeom

#: Cells per side of a finite plane (a plane is tessellated so that the part of it
#: behind the camera is clipped cell by cell, and its shading stays even).
_PLANE_CELLS = 24


@dataclass
class SceneTriangles:
    """World-frame triangles of a scene with one colour per triangle.

    Attributes:
        vertices: ``(T, 3, 3)`` triangle corners in the world frame [m].
        rgba: ``(T, 4)`` colour of each triangle (MuJoCo's geom or material colour).
        plane: ``(T,)`` True where the triangle belongs to a plane geom.
        checker: ``(T,)`` checker cell size [m] of a textured plane (the software
            renderer samples no textures: a textured plane is drawn in the texture's
            mean colour with a checker), 0 elsewhere.
        skipped: descriptions of scene elements that were not drawn (e.g. flex, skin).
    """

    vertices: np.ndarray
    rgba: np.ndarray
    plane: np.ndarray
    checker: np.ndarray
    skipped: list[str] = field(default_factory=list)


def _local_mesh(
    model: mujoco.MjModel, geom: mujoco.MjvGeom, reach: float
) -> tuple[np.ndarray, np.ndarray, bool] | str:
    """Vertices and faces of one scene geom in its own frame, whether it is a plane;
    or a description of why it is not drawn."""
    t, size = int(geom.type), np.asarray(geom.size, dtype=np.float64)
    if t in (_G.mjGEOM_CYLINDER, _G.mjGEOM_CAPSULE):
        # The scene holds (radius, radius, half length) as float32; drawn at MuJoCo's
        # geom size (radius, half length) rounded to 1e-9 m.
        size = np.array([round(float(size[0]), 9), round(float(size[2]), 9)])
    shape = primitive_mesh(t, size, plane_extent=reach, plane_cells=_PLANE_CELLS)
    if shape is not None:
        return (*shape, t == _G.mjGEOM_PLANE)
    is_geom = int(geom.objtype) == mujoco.mjtObj.mjOBJ_GEOM and geom.objid >= 0
    if t == _G.mjGEOM_MESH and is_geom:
        mid = int(model.geom_dataid[geom.objid])
        va, vn = int(model.mesh_vertadr[mid]), int(model.mesh_vertnum[mid])
        fa, fn = int(model.mesh_faceadr[mid]), int(model.mesh_facenum[mid])
        return (
            model.mesh_vert[va : va + vn].astype(np.float64),
            model.mesh_face[fa : fa + fn],
            False,
        )
    if t == _G.mjGEOM_HFIELD and is_geom:
        return (*hfield_surface(model, int(model.geom_dataid[geom.objid])), False)
    return f"{_describe(model, geom)} (type {_type_name(t)})"


def _type_name(t: int) -> str:
    try:
        return _G(t).name.removeprefix("mjGEOM_").lower()
    except ValueError:
        return str(t)


def _describe(model: mujoco.MjModel, geom: mujoco.MjvGeom) -> str:
    try:
        kind = mujoco.mjtObj(int(geom.objtype)).name.removeprefix("mjOBJ_").lower()
    except ValueError:
        kind = "object"
    name = mujoco.mj_id2name(model, int(geom.objtype), int(geom.objid)) if geom.objid >= 0 else None
    return f"{kind} '{name}'" if name else f"{kind} {int(geom.objid)}"


def scene_triangles(
    model: mujoco.MjModel, scene: mujoco.MjvScene, *, plane_reach: float
) -> SceneTriangles:
    """World-frame triangles of every geom MuJoCo put in ``scene``.

    Args:
        model: the compiled model the scene was made from (meshes, height fields).
        scene: a scene filled by :func:`mujoco.mjv_updateScene`.
        plane_reach: half size [m] drawn for an infinite plane (MuJoCo size 0).
    """
    verts, colours, planes, checker, skipped = [], [], [], [], []
    for i in range(scene.ngeom):
        geom = scene.geoms[i]
        rgba = np.asarray(geom.rgba, dtype=np.float64)
        if rgba[3] <= 0.0:
            continue  # MuJoCo draws nothing for a fully transparent geom either
        local = _local_mesh(model, geom, plane_reach)
        if isinstance(local, str):
            skipped.append(local)
            continue
        v, f, is_plane = local
        if len(f) == 0:
            continue
        rot = np.asarray(geom.mat, dtype=np.float64).reshape(3, 3)
        world = v @ rot.T + np.asarray(geom.pos, dtype=np.float64)
        tris = world[np.asarray(f)]
        verts.append(tris)
        colours.append(np.broadcast_to(rgba, (len(tris), 4)))
        planes.append(np.full(len(tris), is_plane))
        cell = 0.0
        tex = _texture(model, geom) if is_plane else None
        if tex is not None:
            mean_rgb, cell = tex
            rgba = np.concatenate([rgba[:3] * mean_rgb, rgba[3:]])
            colours[-1] = np.broadcast_to(rgba, (len(tris), 4))
        checker.append(np.full(len(tris), cell))
    if not verts:
        empty = np.zeros((0, 3, 3))
        return SceneTriangles(
            empty, np.zeros((0, 4)), np.zeros(0, bool), np.zeros(0, bool), skipped
        )
    return SceneTriangles(
        np.concatenate(verts),
        np.concatenate(colours),
        np.concatenate(planes),
        np.concatenate(checker),
        skipped,
    )


def _texture(model: mujoco.MjModel, geom: mujoco.MjvGeom) -> tuple[np.ndarray, float] | None:
    """Mean RGB in [0, 1] of a plane's texture and its checker cell size [m] (a
    builtin checker texture holds 2 x 2 cells per repeat); None without texture."""
    mat = int(geom.matid)
    if mat < 0 or mat >= model.nmat:
        return None
    texids = [int(t) for t in np.atleast_1d(model.mat_texid[mat]) if t >= 0]
    if not texids:
        return None
    tid = texids[0]
    adr, ch = int(model.tex_adr[tid]), int(model.tex_nchannel[tid])
    size = int(model.tex_width[tid]) * int(model.tex_height[tid]) * ch
    texels = model.tex_data[adr : adr + size].reshape(-1, ch)
    mean = texels[:, :3].mean(axis=0) / 255.0 if ch >= 3 else np.full(3, texels.mean() / 255.0)
    repeat = float(model.mat_texrepeat[mat][0]) or 1.0
    if model.mat_texuniform[mat]:
        cell = 1.0 / (2.0 * repeat)
    else:
        cell = 2.0 * float(geom.size[0] or 1.0) / (2.0 * repeat)
    return mean, cell
