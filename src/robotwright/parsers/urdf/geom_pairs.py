"""A URDF link's ``<visual>`` and ``<collision>`` of one shape, read back as one geom.

URDF keeps what is drawn (``<visual>``) apart from what collides (``<collision>``);
MuJoCo has one geom that may do both. Many URDFs, and every URDF that robotwright
writes, describe a geom that is drawn and collides as a visual and a collision of the
same geometry at the same origin. Such a pair becomes one geom of kind ``"both"``
(drawn and colliding), so HRDF -> URDF -> HRDF gives back the geoms it started from
instead of two copies of each.

A visual and a collision are a pair when their geometry (shape, sizes; mesh file and
scale) and origin are equal, bit for bit as parsed, and their names do not disagree
(equal, or at least one of them unnamed): merging then loses nothing (the visual's
colour and the name are kept). Each visual pairs with at most one collision, the first
free one in document order.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

#: Kind of a geom made of a visual and a collision pair: drawn and colliding.
BOTH = "both"


class _PoseLike(Protocol):
    pos: np.ndarray
    rot: np.ndarray


#: One parsed geom: kind ("visual", "collision" or :data:`BOTH`), origin, fields.
Parsed = tuple[str, _PoseLike, dict]


def _shape_key(fields: dict) -> tuple:
    """The fields that define the geometry (not its name or colour)."""
    return tuple(sorted((k, v) for k, v in fields.items() if k not in ("geom_name", "rgba")))


def _same_pose(a: _PoseLike, b: _PoseLike) -> bool:
    return bool(np.array_equal(a.pos, b.pos) and np.array_equal(a.rot, b.rot))


def merge_visual_collision(geoms: list[Parsed]) -> list[Parsed]:
    """``geoms`` of one link with each visual/collision pair (see the module docstring)
    replaced by one geom of kind :data:`BOTH` at the visual's place; the others are kept
    in their order. A merged geom carries the visual's colour and whichever name the two
    give."""
    collisions = [i for i, (kind, _, _) in enumerate(geoms) if kind == "collision"]
    taken: set[int] = set()
    out: list[Parsed] = []
    for kind, pose, fields in geoms:
        if kind != "visual":
            continue
        key = _shape_key(fields)
        for i in collisions:
            if i in taken:
                continue
            _, cpose, cfields = geoms[i]
            vname, cname = fields.get("geom_name"), cfields.get("geom_name")
            if vname and cname and vname != cname:
                continue
            if _shape_key(cfields) == key and _same_pose(pose, cpose):
                taken.add(i)
                merged = {**cfields, **fields, "geom_name": vname or cname}
                out.append((BOTH, pose, merged))
                break
        else:
            out.append((kind, pose, fields))
    out.extend(g for i, g in enumerate(geoms) if g[0] != "visual" and i not in taken)
    return out


__all__ = ["BOTH", "merge_visual_collision"]
