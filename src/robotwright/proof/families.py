"""The proof's checks beyond one array per object: contact pairs and excludes, tendon
paths, processed mesh data, each body's geom order, actuator plugins with their
configuration, and inertia compared as one tensor."""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from robotwright.proof.objects import (
    Difference,
    _diff,
    _fmt,
    _inverse,
    _labels,
    _object_text,
    _same_values,
    _Side,
)

if TYPE_CHECKING:
    pass


def _plugin_keys(model: mujoco.MjModel, ids: np.ndarray) -> np.ndarray:
    """Per actuator plugin id: a number standing for the plugin it runs and its
    instance's configuration (-1: no plugin), equal between two models compiled in one
    process exactly when both are."""
    out = np.full(len(ids), -1, dtype=np.int64)
    for k, pid in enumerate(ids):
        if pid < 0:
            continue
        key = (int(model.plugin[pid]), _plugin_config(model, pid))  # slot: per process
        out[k] = int.from_bytes(hashlib.sha1(repr(key).encode()).digest()[:7], "big")
    return out


_PAIR_FIELDS = ("pair_dim", "pair_friction", "pair_solref", "pair_solreffriction",
                "pair_solimp", "pair_margin", "pair_gap")  # fmt: skip


def _contacts(src: _Side, res: _Side, maps: dict[str, dict[int, int]]) -> list[Difference]:
    """Contact pairs (by their two geoms, with every parameter) and excludes (by their
    two bodies), the result's objects seen through the matching."""
    s, r = src.m, res.m
    geoms, bodies = _inverse(maps["geom"]), _inverse(maps["body"])
    out: list[Difference] = []

    def pair_text(g1: int, g2: int) -> str:
        return (
            f"contact pair of {_object_text(src, 'geom', g1)} and {_object_text(src, 'geom', g2)}"
        )

    # A file may name the same two geoms in several pairs (OpenAI's Shadow hand does):
    # each is a pair of its own, matched to the result's in the order both are listed.
    theirs: dict[frozenset, list[int]] = {}
    for p in range(r.npair):
        key = (geoms.get(int(r.pair_geom1[p]), -1), geoms.get(int(r.pair_geom2[p]), -1))
        theirs.setdefault(frozenset(key), []).append(p)
    for p in range(s.npair):
        g1, g2 = int(s.pair_geom1[p]), int(s.pair_geom2[p])
        text = pair_text(g1, g2)
        labels = (*_labels(src, "geom", g1), *_labels(src, "geom", g2), "pair")
        listed = theirs.get(frozenset((g1, g2)))
        q = listed.pop(0) if listed else None
        if q is None:
            out.append(Difference("(object)", "pair", text, "present", "absent", labels))
            continue
        for field in _PAIR_FIELDS:
            a, b = getattr(s, field)[p], getattr(r, field)[q]
            if not _same_values(a, b):
                out.append(Difference(field, "pair", text, _fmt(a), _fmt(b), labels))
    for q in sorted(q for listed in theirs.values() for q in listed):
        out.append(
            Difference(
                "(object)", "pair", f"contact pair #{q} of the result", "absent", "present", ()
            )
        )

    def excluded(model: mujoco.MjModel, remap: dict[int, int] | None) -> set[frozenset]:
        found = set()
        for sig in model.exclude_signature:
            b1, b2 = int(sig) >> 16, int(sig) & 0xFFFF
            if remap is not None:
                b1, b2 = remap.get(b1, -1), remap.get(b2, -1)
            found.add(frozenset((b1, b2)))
        return found

    mine, yours = excluded(s, None), excluded(r, bodies)
    for key in mine ^ yours:
        names = sorted(_object_text(src, "body", b) if b >= 0 else "a body" for b in key)
        text = f"contact exclude of {' and '.join(names)}"
        present = ("present", "absent") if key in mine else ("absent", "present")
        out.append(Difference("(object)", "exclude", text, *present, ("exclude", *names)))
    return out


#: wrap object type -> the family its id is of (pulleys have none).
_WRAP_FAMILY = {
    int(mujoco.mjtWrap.mjWRAP_JOINT): "jnt",
    int(mujoco.mjtWrap.mjWRAP_SITE): "site",
    int(mujoco.mjtWrap.mjWRAP_SPHERE): "geom",
    int(mujoco.mjtWrap.mjWRAP_CYLINDER): "geom",
}


def _tendon_paths(src: _Side, res: _Side, maps: dict[str, dict[int, int]]) -> list[Difference]:
    """Each matched tendon's path: the kind, object (through the matching) and parameter
    of every element, in order."""
    back = {fam: _inverse(maps[fam]) for fam in set(_WRAP_FAMILY.values())}

    def path(model: mujoco.MjModel, k: int, remap: bool) -> list[tuple]:
        steps = []
        adr, num = int(model.tendon_adr[k]), int(model.tendon_num[k])
        for w in range(adr, adr + num):
            kind = int(model.wrap_type[w])
            fam = _WRAP_FAMILY.get(kind)
            obj = int(model.wrap_objid[w])
            if fam is not None and remap:
                obj = back[fam].get(obj, -2)
            steps.append((kind, obj if fam is not None else -1, float(model.wrap_prm[w])))
        return steps

    out: list[Difference] = []
    for t, u in maps["tendon"].items():
        if u < 0:
            continue
        mine, yours = path(src.m, t, False), path(res.m, u, True)
        same = len(mine) == len(yours) and all(
            a[:2] == b[:2] and _same_values(np.array(a[2]), np.array(b[2]))
            for a, b in zip(mine, yours, strict=False)
        )
        if not same:
            out.append(_diff(src, "tendon", "tendon path", t, str(mine), str(yours)))
    return out


def _mesh_data(src: _Side, res: _Side, geom_map: dict[int, int]) -> list[Difference]:
    """For each matched mesh geom: its mesh's vertex count and bounds (in the mesh's own
    frame, as MuJoCo processed it)."""
    s, r = src.m, res.m
    out: list[Difference] = []
    mesh = int(mujoco.mjtGeom.mjGEOM_MESH)

    def data(model: mujoco.MjModel, g: int) -> tuple[int, np.ndarray]:
        k = int(model.geom_dataid[g])
        adr, num = int(model.mesh_vertadr[k]), int(model.mesh_vertnum[k])
        vert = model.mesh_vert[adr : adr + num]
        return num, np.concatenate([vert.min(axis=0), vert.max(axis=0)])

    for g, h in geom_map.items():
        if h < 0 or int(s.geom_type[g]) != mesh or int(r.geom_type[h]) != mesh:
            continue
        (n1, box1), (n2, box2) = data(s, g), data(r, h)
        if n1 != n2:
            out.append(_diff(src, "geom", "mesh_vertnum", g, str(n1), str(n2)))
        elif not _same_values(box1, box2):
            out.append(_diff(src, "geom", "mesh bounds", g, _fmt(box1), _fmt(box2)))
    return out


def _hull(model: mujoco.MjModel, g: int) -> tuple[int, np.ndarray] | None:
    """The convex hull MuJoCo collides a mesh geom with: its face count and its vertices
    in the geom's body frame (so that two models that place the same hull through
    different mesh frames agree); None when MuJoCo made no hull."""
    k = int(model.geom_dataid[g])
    adr = int(model.mesh_graphadr[k])
    if adr < 0:
        return None
    nvert, nface = int(model.mesh_graph[adr]), int(model.mesh_graph[adr + 1])
    ids = model.mesh_graph[adr + 2 + nvert : adr + 2 + 2 * nvert]
    vert = model.mesh_vert[int(model.mesh_vertadr[k]) + ids].astype(float)
    rot = np.empty(9)
    mujoco.mju_quat2Mat(rot, model.geom_quat[g])
    return nface, vert @ rot.reshape(3, 3).T + model.geom_pos[g]


def _hull_polygons(model: mujoco.MjModel, g: int) -> int:
    """How many polygons MuJoCo merged mesh geom ``g``'s hull faces into (0 where the
    model does not hold them)."""
    polynum = getattr(model, "mesh_polynum", None)
    return 0 if polynum is None else int(polynum[int(model.geom_dataid[g])])


#: Points of one set compared with the whole other set at a time: a hull of thousands of
#: vertices stays a few MB of distances, also in a confined reader's memory budget.
_CHUNK = 256


def _farthest(a: np.ndarray, b: np.ndarray, tol: float) -> float:
    """The largest distance from a point of either set to the other set (m). When the
    sets agree point by point within ``tol`` (a hull compiled from the same vertices
    comes out in the same order) that bound is the answer, without the search."""
    if a.shape == b.shape:
        paired = float(np.linalg.norm(a - b, axis=1).max(initial=0.0))
        if paired <= tol:
            return paired

    def one_way(p: np.ndarray, q: np.ndarray) -> float:
        far = 0.0
        for k in range(0, len(p), _CHUNK):
            d = np.linalg.norm(p[k : k + _CHUNK, None, :] - q[None, :, :], axis=2)
            far = max(far, float(d.min(axis=1).max(initial=0.0)))
        return far

    return max(one_way(a, b), one_way(b, a))


def _collision_hulls(src: _Side, res: _Side, geom_map: dict[int, int]) -> list[Difference]:
    """For each matched mesh geom that collides: the convex hull MuJoCo computed for it
    (what its contacts are made with), compared by vertex and face count and by the
    farthest any hull vertex lies from the other hull's vertices, in the body frame. A
    mirrored copy of a mesh or a dropped ``maxhullvert`` changes the hull while every
    other array may agree."""
    s, r = src.m, res.m
    out: list[Difference] = []
    mesh = int(mujoco.mjtGeom.mjGEOM_MESH)
    for g, h in geom_map.items():
        if h < 0 or int(s.geom_type[g]) != mesh or int(r.geom_type[h]) != mesh:
            continue
        if not (s.geom_contype[g] or s.geom_conaffinity[g]):
            continue  # drawn only: no contact is made with its hull
        a, b = _hull(s, g), _hull(r, h)
        if a is None or b is None:
            if (a is None) != (b is None):
                shown = ("no hull" if a is None else "a hull", "no hull" if b is None else "a hull")
                out.append(_diff(src, "geom", "collision hull", g, *shown))
            continue
        (fa, va), (fb, vb) = a, b
        # The polygons MuJoCo merges the hull's coplanar triangles into (what its convex
        # collision walks): the same points in another order can merge otherwise.
        pa, pb = _hull_polygons(s, g), _hull_polygons(r, h)
        if (len(va), fa, pa) != (len(vb), fb, pb):
            out.append(
                _diff(
                    src,
                    "geom",
                    "collision hull",
                    g,
                    f"{len(va)} vertices, {fa} faces, {pa} polygons",
                    f"{len(vb)} vertices, {fb} faces, {pb} polygons",
                )  # fmt: skip
            )
            continue
        tol = 1e-9 * max(float(np.ptp(va, axis=0).max(initial=0.0)), 1.0)
        far = _farthest(va, vb, tol)
        if far > tol:
            out.append(
                _diff(
                    src,
                    "geom",
                    "collision hull",
                    g,
                    "the source's hull",
                    f"a hull with a vertex {far:.3g} m from it",
                )  # fmt: skip
            )
    return out


def _geom_order(src: _Side, res: _Side, geom_map: dict[int, int]) -> list[Difference]:
    """One difference per body whose geoms the result holds in another order (MuJoCo
    finds and solves contacts in geom order: a reordered body's contacts differ)."""
    by_body: dict[int, list[tuple[int, int]]] = {}
    for s, r in geom_map.items():
        if r >= 0:
            by_body.setdefault(int(src.m.geom_bodyid[s]), []).append((s, r))
    out = []
    for body, pairs in by_body.items():
        pairs.sort()
        results = [r for _, r in pairs]
        if results == sorted(results):
            continue
        names = [_object_text(src, "geom", s) for s, _ in pairs]
        shown = [names[k] for k in sorted(range(len(pairs)), key=lambda k: results[k])]
        out.append(_diff(src, "body", "geom order", body, ", ".join(names), ", ".join(shown)))
    return out


def _plugin_config(model: mujoco.MjModel, pid: int) -> bytes:
    start = int(model.plugin_attradr[pid])
    ends = [int(a) for a in model.plugin_attradr if a > start]
    return bytes(model.plugin_attr[start : min(ends, default=len(model.plugin_attr))])


def _plugin_text(model: mujoco.MjModel, pid: int) -> str:
    """An actuator's plugin as a note shows it: none, or the plugin and its values."""
    if pid < 0:
        return "no plugin"
    values = [v.decode(errors="replace") for v in _plugin_config(model, pid).split(b"\0") if v]
    return f"plugin #{int(model.plugin[pid])} with configuration values {values}"


def _massless(model: mujoco.MjModel, idx: np.ndarray) -> np.ndarray:
    """Per body of ``idx``: whether its mass and principal moments are all zero."""
    return (model.body_mass[idx] == 0) & (model.body_inertia[idx] == 0).all(axis=1)


def _tensors(moments: np.ndarray, quats: np.ndarray) -> np.ndarray:
    """Per object, the inertia tensor ``R diag(moments) R^T`` in the object's frame as
    its six values ``xx yy zz xy xz yz`` (kg m^2)."""
    out = np.zeros((len(moments), 6))
    mat = np.zeros(9)
    for k, (d, q) in enumerate(zip(moments, quats, strict=True)):
        mujoco.mju_quat2Mat(mat, np.asarray(q, dtype=float))
        r = mat.reshape(3, 3)
        t = r @ np.diag(np.asarray(d, dtype=float)) @ r.T
        out[k] = (t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2])
    return out
