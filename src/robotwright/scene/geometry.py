"""What a compiled MuJoCo model looks like: one triangle mesh per geom, its colour, and
the frames of bodies and sites.

Everything here reads the compiled ``mujoco.MjModel`` (no viewer library), so it is
what MuJoCo itself draws: geom poses are in their body's frame (``geom_pos``,
``geom_quat``), mesh vertices are MuJoCo's compiled ones (in the mesh frame the geom
pose refers to), colours follow MuJoCo's rule (the material's colour unless the geom's
``rgba`` differs from MuJoCo's default), and lengths are metres. Primitives are
tessellated with trimesh.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import mujoco
import numpy as np
from numpy.typing import ArrayLike, DTypeLike

__all__ = [
    "DEFAULT_GEOM_GROUPS",
    "GeomShape",
    "SiteFrame",
    "body_poses",
    "geom_rgba",
    "geom_shapes",
    "hfield_surface",
    "primitive_mesh",
    "site_frames",
]

#: Geom groups MuJoCo's own viewer shows by default (``mjvOption.geomgroup``).
DEFAULT_GEOM_GROUPS: tuple[int, ...] = (0, 1, 2)

#: MuJoCo's default geom colour: a geom with this ``rgba`` takes its material's colour.
_DEFAULT_RGBA = np.array([0.5, 0.5, 0.5, 1.0], dtype=np.float32)


@dataclass(frozen=True)
class GeomShape:
    """One geom as a triangle mesh in its body's frame.

    Attributes:
        geom_id: MuJoCo geom id.
        body_id: id of the body carrying it (0 = world).
        name: geom name (``geom <id>`` when unnamed).
        group: MuJoCo geom group (0..5).
        rgba: colour drawn, 4 floats in [0, 1].
        pos: geom origin in the body frame [m], shape ``(3,)``.
        quat: geom orientation in the body frame (w, x, y, z), shape ``(4,)``.
        vertices: ``(V, 3)`` vertices in the geom frame [m].
        faces: ``(F, 3)`` vertex indices of the triangles.
    """

    geom_id: int
    body_id: int
    name: str
    group: int
    rgba: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    vertices: np.ndarray
    faces: np.ndarray


@dataclass(frozen=True)
class SiteFrame:
    """A site's frame in its body's frame: ``pos`` [m], ``quat`` (w, x, y, z)."""

    site_id: int
    body_id: int
    name: str
    pos: np.ndarray
    quat: np.ndarray


#: The note of a textured geom drawn in its colour: a look, not a loss (``-v`` only).
TEXTURE_NOT_DRAWN = "texture not drawn, only its colour"


def geom_rgba(model: mujoco.MjModel, geom_id: int) -> np.ndarray:
    """The colour MuJoCo draws geom ``geom_id`` with: the geom's ``rgba`` when it differs
    from MuJoCo's default (0.5, 0.5, 0.5, 1), else its material's colour, else the
    default."""
    rgba = np.array(model.geom_rgba[geom_id], dtype=np.float32)
    matid = int(model.geom_matid[geom_id])
    if matid >= 0 and np.array_equal(rgba, _DEFAULT_RGBA):
        return np.array(model.mat_rgba[matid], dtype=np.float32)
    return rgba


def _name(model: mujoco.MjModel, kind: mujoco.mjtObj, idx: int, label: str) -> str:
    return mujoco.mj_id2name(model, kind, idx) or f"{label} {idx}"


@lru_cache(maxsize=4)
def _unit(kind: str) -> tuple[np.ndarray, np.ndarray]:
    """Unit primitives, tessellated once: sphere of radius 1, cylinder of radius 1 and
    height 2 (along z, centred), box of half size 1."""
    import trimesh

    if kind == "sphere":
        mesh = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    elif kind == "cylinder":
        mesh = trimesh.creation.cylinder(radius=1.0, height=2.0, sections=32)
    else:
        mesh = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    return _frozen(mesh.vertices, mesh.faces)


@lru_cache(maxsize=256)
def _capsule(radius: float, half: float) -> tuple[np.ndarray, np.ndarray]:
    """A capsule along z (its end caps are not a scaled unit shape): one per size."""
    import trimesh

    mesh = trimesh.creation.capsule(height=2.0 * half, radius=radius, count=[24, 24])
    return _frozen(mesh.vertices, mesh.faces)


def _frozen(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Read-only float64 copies of a cached mesh (callers share them)."""
    v, f = np.array(vertices, dtype=np.float64), np.array(faces)
    v.flags.writeable = f.flags.writeable = False
    return v, f


def _grid(nx: int, ny: int, hx: float, hy: float) -> tuple[np.ndarray, np.ndarray]:
    """A flat ``nx`` x ``ny`` cell grid over ``[-hx, hx] x [-hy, hy]`` at z = 0."""
    xs, ys = np.linspace(-hx, hx, nx + 1), np.linspace(-hy, hy, ny + 1)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    verts = np.stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)], axis=1)
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    a = (i * (ny + 1) + j).ravel()
    b, c, d = a + (ny + 1), a + (ny + 1) + 1, a + 1
    faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return verts, faces


def primitive_mesh(
    gtype: int,
    size: ArrayLike,
    *,
    plane_extent: float,
    plane_cells: int = 1,
    dtype: DTypeLike = np.float64,
) -> tuple[np.ndarray, np.ndarray] | None:
    """The triangles of a MuJoCo primitive geom in the geom's own frame.

    Args:
        gtype: the geom type (``mujoco.mjtGeom``).
        size: MuJoCo's geom size [m] (``geom_size``): sphere (radius), capsule and
            cylinder (radius, half length along z), ellipsoid radii and box half sizes
            (x, y, z), plane half sizes (x, y).
        plane_extent: half size [m] drawn for a plane side of size 0 (or less), which
            MuJoCo draws as infinite.
        plane_cells: cells per side of a plane (two triangles each).
        dtype: type of the vertices; a sphere, ellipsoid, box or cylinder is a unit
            shape scaled in this type.

    Returns:
        ``(vertices, faces)``: ``(V, 3)`` vertices [m] and ``(F, 3)`` vertex indices of
        the triangles (counter-clockwise seen from outside, a plane's facing +z); None
        for a type that is not a primitive (mesh, height field, SDF).
    """
    G = mujoco.mjtGeom
    size = np.asarray(size, dtype=np.float64)
    if gtype in (G.mjGEOM_SPHERE, G.mjGEOM_ELLIPSOID, G.mjGEOM_BOX, G.mjGEOM_CYLINDER):
        if gtype == G.mjGEOM_SPHERE:
            kind, scale = "sphere", np.full(3, size[0])
        elif gtype == G.mjGEOM_ELLIPSOID:
            kind, scale = "sphere", size[:3]
        elif gtype == G.mjGEOM_BOX:
            kind, scale = "box", size[:3]
        else:
            kind, scale = "cylinder", size[[0, 0, 1]]
        v, f = _unit(kind)
        return v.astype(dtype) * scale.astype(dtype), f
    if gtype == G.mjGEOM_CAPSULE:
        v, f = _capsule(float(size[0]), float(size[1]))
        return v.astype(dtype), f
    if gtype == G.mjGEOM_PLANE:
        hx = float(size[0]) if size[0] > 0 else plane_extent
        hy = float(size[1]) if size[1] > 0 else plane_extent
        v, f = _grid(plane_cells, plane_cells, hx, hy)
        return v.astype(dtype), f
    return None


def _mesh(model: mujoco.MjModel, mesh_id: int) -> tuple[np.ndarray, np.ndarray]:
    v0, nv = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
    f0, nf = int(model.mesh_faceadr[mesh_id]), int(model.mesh_facenum[mesh_id])
    return (
        np.asarray(model.mesh_vert[v0 : v0 + nv], dtype=np.float32),
        np.asarray(model.mesh_face[f0 : f0 + nf], dtype=np.int32),
    )


#: Most height-field samples drawn (512 x 512): a larger field is drawn from an evenly
#: spaced subset of its rows and columns (its first and last included). Drawing every
#: sample of a 3000 x 3000 field took 18 million triangles and 10 GB of memory.
MAX_HFIELD_DRAWN = 512 * 512


def hfield_surface(model: mujoco.MjModel, hid: int) -> tuple[np.ndarray, np.ndarray]:
    """The top surface of a height field: ``size`` = (x half, y half, top, bottom) [m];
    MuJoCo's rows run along y from -y to +y, columns along x. At most
    :data:`MAX_HFIELD_DRAWN` samples are drawn."""
    full_rows, full_cols = int(model.hfield_nrow[hid]), int(model.hfield_ncol[hid])
    rx, ry, top = (float(s) for s in model.hfield_size[hid][:3])
    adr = int(model.hfield_adr[hid])
    data = np.asarray(model.hfield_data[adr : adr + full_rows * full_cols])
    stride = max(1.0, math.sqrt(full_rows * full_cols / MAX_HFIELD_DRAWN))
    rows = np.unique(np.linspace(0, full_rows - 1, max(2, round(full_rows / stride))).round())
    cols = np.unique(np.linspace(0, full_cols - 1, max(2, round(full_cols / stride))).round())
    rows, cols = rows.astype(np.int64), cols.astype(np.int64)
    z = data.reshape(full_rows, full_cols)[np.ix_(rows, cols)].astype(np.float32)
    nrow, ncol = len(rows), len(cols)
    xs = (cols / max(full_cols - 1, 1) * 2 - 1).astype(np.float32) * rx
    ys = (rows / max(full_rows - 1, 1) * 2 - 1).astype(np.float32) * ry
    gx, gy = np.meshgrid(xs, ys)
    vertices = np.stack([gx, gy, z * top], axis=-1).reshape(-1, 3)
    r, c = np.meshgrid(np.arange(nrow - 1), np.arange(ncol - 1), indexing="ij")
    a = (r * ncol + c).reshape(-1)
    b, d, e = a + 1, a + ncol, a + ncol + 1
    faces = np.concatenate([np.stack([a, b, e], 1), np.stack([a, e, d], 1)]).astype(np.int32)
    return vertices, faces


def geom_shapes(model: mujoco.MjModel, *, skipped: list[str] | None = None) -> list[GeomShape]:
    """Every geom MuJoCo could draw, as a triangle mesh in its body's frame.

    Geoms of every group are returned (the viewer shows groups 0-2 first, as MuJoCo
    does). Fully transparent geoms (alpha 0) and geom types without a surface to draw
    here (SDF plugins) are left out, and textures are not drawn (a textured geom shows
    its material's colour); when ``skipped`` is a list, a line naming each such geom is
    appended to it.
    """
    G = mujoco.mjtGeom
    # A plane of size 0 is infinite in MuJoCo; drawn as a square 10 times the model's
    # extent (MuJoCo's own renderer also draws a finite patch).
    far = 10.0 * max(float(model.stat.extent), 1.0)
    out: list[GeomShape] = []
    for g in range(model.ngeom):
        name = _name(model, mujoco.mjtObj.mjOBJ_GEOM, g, "geom")
        rgba = geom_rgba(model, g)
        gtype = int(model.geom_type[g])
        if rgba[3] <= 0.0:
            if skipped is not None:
                skipped.append(f"geom '{name}': fully transparent (alpha 0), not drawn")
            continue
        if gtype == G.mjGEOM_MESH:
            shape = _mesh(model, int(model.geom_dataid[g]))
        elif gtype == G.mjGEOM_HFIELD:
            shape = hfield_surface(model, int(model.geom_dataid[g]))
        else:
            shape = primitive_mesh(gtype, model.geom_size[g], plane_extent=far, dtype=np.float32)
            if shape is not None:
                shape = (shape[0], shape[1].astype(np.int32))
        if shape is None:
            if skipped is not None:
                skipped.append(f"geom '{name}': type {G(gtype).name} is not drawn")
            continue
        matid = int(model.geom_matid[g])
        if skipped is not None and matid >= 0 and np.max(model.mat_texid[matid]) >= 0:
            skipped.append(f"geom '{name}': {TEXTURE_NOT_DRAWN}")
        out.append(
            GeomShape(
                geom_id=g,
                body_id=int(model.geom_bodyid[g]),
                name=name,
                group=int(model.geom_group[g]),
                rgba=rgba,
                pos=np.array(model.geom_pos[g], dtype=np.float64),
                quat=np.array(model.geom_quat[g], dtype=np.float64),
                vertices=shape[0],
                faces=shape[1],
            )
        )
    return out


def site_frames(model: mujoco.MjModel) -> list[SiteFrame]:
    """Every site's frame in its body's frame."""
    return [
        SiteFrame(
            site_id=s,
            body_id=int(model.site_bodyid[s]),
            name=_name(model, mujoco.mjtObj.mjOBJ_SITE, s, "site"),
            pos=np.array(model.site_pos[s], dtype=np.float64),
            quat=np.array(model.site_quat[s], dtype=np.float64),
        )
        for s in range(model.nsite)
    ]


def body_poses(
    model: mujoco.MjModel, data: mujoco.MjData, qpos: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """World poses of all bodies after MuJoCo forward kinematics (``mj_kinematics``).

    Args:
        qpos: joint positions to set first (``model.nq`` values); ``None`` keeps
            ``data.qpos``.

    Returns:
        ``(xpos, xquat)``: ``(nbody, 3)`` positions [m] and ``(nbody, 4)`` orientations
        (w, x, y, z), copies.
    """
    if qpos is not None:
        data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    return data.xpos.copy(), data.xquat.copy()
