"""Which object of the result is which of the source: bodies by their place in the tree,
the other families by name, or by structure and placement where a name was given by a
reader or writer; and the maps of dofs, qpos columns and activations that follow."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from robotwright.proof.objects import _FALLBACK, _bad_rows, _Side

if TYPE_CHECKING:
    pass


def _robot_bodies(model: mujoco.MjModel, root_body: str | None) -> set[int] | None:
    """Body ids of the robot: the subtree of ``root_body`` (a top-level body, named as
    the parsers name it) when given, else None (every body but the world)."""
    if root_body is None:
        return None
    from robotwright.parsers.reference import body_name

    top = [i for i in range(1, model.nbody) if model.body_parentid[i] == 0]
    ids = [i for i in top if body_name(model, i) == root_body]
    if not ids:
        return None
    return {i for i in range(1, model.nbody) if model.body_rootid[i] == ids[0]}


def _structure_key(side: _Side, fam: str, i: int, body_map: dict[int, int] | None) -> tuple:
    """What an unnamed object is matched by: its family's type fields and its body (as
    a result body id: ``body_map`` maps a source body, None for the result's own)."""
    m = side.m

    def matched_body_get(b: int) -> int:
        return b if body_map is None else body_map.get(b, -1)

    if fam == "body":
        return ("body", matched_body_get(int(m.body_parentid[i])))
    if fam in ("jnt", "geom", "site"):
        body = int(getattr(m, f"{fam}_bodyid")[i])
        kind = int(getattr(m, f"{fam}_type")[i])
        return (fam, matched_body_get(body), kind)
    if fam == "actuator":
        return (fam, int(m.actuator_trntype[i]), int(m.actuator_dyntype[i]))
    if fam == "sensor":
        return (fam, int(m.sensor_type[i]))
    if fam == "tendon":
        return (fam, int(m.tendon_num[i]))
    if fam == "eq":
        return (fam, int(m.eq_type[i]))
    return (fam,)


#: a name the parsers or generators give an unnamed object (``geom_3``, ``body_7``).
_GIVEN = re.compile(r"(body|joint|geom|site|sensor|actuator|tendon|equality|key)_\d+")


def _unnamed(name: str) -> bool:
    return not name or _GIVEN.fullmatch(name) is not None


def _match(src: _Side, res: _Side, fam: str, body_map: dict[int, int]) -> dict[int, int]:
    """Source index -> result index for the objects of ``fam``: by name, then by the
    parsers' name of an unnamed object, then by structure and order."""
    out: dict[int, int] = {}
    s_idx = [int(i) for i in src.kept(fam)]
    r_idx = [int(i) for i in res.kept(fam)]
    r_names = {res.names[fam][j]: j for j in r_idx if res.names[fam][j]}
    taken: set[int] = set()
    fallback = _FALLBACK.get(fam)
    rest = []
    for i in s_idx:
        name = src.names[fam][i] or (fallback.format(i) if fallback else "")
        j = r_names.get(name) if name else None
        if j is not None and j not in taken:
            out[i] = j
            taken.add(j)
        else:
            rest.append(i)
    if not rest:
        return out
    pool: dict[tuple, list[int]] = {}
    # By structure: unnamed objects with the other side's unnamed ones, in order (a named
    # one not found by its name is missing).
    rest = [i for i in rest if not src.names[fam][i]]
    # (a name no source object has is the converter's own: MuJoCo's URDF import names
    # no geom, the parsers name one from its <collision name>)
    src_names = {src.names[fam][i] for i in s_idx}
    for j in r_idx:
        name = res.names[fam][j]
        if j not in taken and (_unnamed(name) or name not in src_names):
            pool.setdefault(_structure_key(res, fam, j, None), []).append(j)
    for i in rest:
        cands = pool.get(_structure_key(src, fam, i, body_map))
        if cands:
            # The one in the same place with the same size, else the next in order (an
            # import may list a link's unnamed geoms in another order). The first that
            # fits is taken: in the usual case, the same order, that is the first looked
            # at, so matching n objects costs n steps, not n squared.
            here = _placement(src, fam, i)
            fits = (k for k, j in enumerate(cands) if _same(here, _placement(res, fam, j)))
            out[i] = cands.pop(0 if here is None else next(fits, 0))
    return out


def _placement(side: _Side, fam: str, i: int) -> np.ndarray | None:
    """Where an unnamed geom or site is in its body and its size (None for others)."""
    if fam not in ("geom", "site"):
        return None
    m = side.m
    size = _used_sizes(getattr(m, f"{fam}_size")[i : i + 1], getattr(m, f"{fam}_type")[i : i + 1])
    return np.concatenate([getattr(m, f"{fam}_pos")[i], size[0]])


def _same(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    return a is not None and b is not None and _bad_rows(a[None, :], b[None, :]).size == 0


def _match_bodies(src: _Side, res: _Side) -> dict[int, int]:
    """Bodies in tree order: a body matched by name, or by its matched parent and its
    order among that parent's unmatched children."""
    out: dict[int, int] = {0: 0}
    r_names = {res.names["body"][j]: j for j in range(1, res.m.nbody) if res.names["body"][j]}
    taken = {0}
    children: dict[int, list[int]] = {}
    for j in range(1, res.m.nbody):
        children.setdefault(int(res.m.body_parentid[j]), []).append(j)
    for i in (int(x) for x in src.kept("body")):
        name = src.names["body"][i] or f"body_{i}"
        j = r_names.get(name)
        if j is None or j in taken:
            parent = out.get(int(src.m.body_parentid[i]))
            # By structure: an unnamed body with its parent's unnamed children, in order.
            free = (
                []
                if src.names["body"][i]
                else [
                    k
                    for k in children.get(parent, [])
                    if k not in taken and _unnamed(res.names["body"][k])
                ]
            )
            j = free[0] if free else None
        if j is not None:
            out[i] = j
            taken.add(j)
    return out


def _dof_map(src: _Side, res: _Side, jnt_map: dict[int, int]) -> dict[int, int]:
    out = {}
    for i, j in jnt_map.items():
        a, b = int(src.m.jnt_dofadr[i]), int(res.m.jnt_dofadr[j])
        n = {0: 6, 1: 3}.get(int(src.m.jnt_type[i]), 1)
        if int(res.m.jnt_type[j]) != int(src.m.jnt_type[i]):
            continue
        for k in range(n):
            out[a + k] = b + k
    return out


def _qpos_map(src: _Side, res: _Side, jnt_map: dict[int, int]) -> dict[int, int]:
    out = {}
    for i, j in jnt_map.items():
        if int(res.m.jnt_type[j]) != int(src.m.jnt_type[i]):
            continue
        a, b = int(src.m.jnt_qposadr[i]), int(res.m.jnt_qposadr[j])
        for k in range({0: 7, 1: 4}.get(int(src.m.jnt_type[i]), 1)):
            out[a + k] = b + k
    return out


def _act_map(src: _Side, res: _Side, act_map: dict[int, int]) -> dict[int, int]:
    out = {}
    for i, j in act_map.items():
        a, b = int(src.m.actuator_actadr[i]), int(res.m.actuator_actadr[j])
        if a >= 0 and b >= 0:
            for k in range(int(src.m.actuator_actnum[i])):
                out[a + k] = b + k
    return out


#: geom type -> how many ``size`` values it uses (sphere 1; capsule, cylinder 2).
_SIZES_USED = {2: 1, 3: 2, 5: 2}


def _used_sizes(size: np.ndarray, types: np.ndarray) -> np.ndarray:
    """``size`` with the values its type does not use set to 0: MuJoCo keeps unused ones
    as written (a sphere site of size 0.01 holds 0.01 0.005 0.005 or 0.01 0.01 0.01)."""
    out = np.array(size, dtype=float, copy=True)
    for t, n in _SIZES_USED.items():
        out[np.asarray(types) == t, n:] = 0.0
    return out
