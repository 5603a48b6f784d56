"""Parts of a limb that overlap: a geometric check that MuJoCo's contact filter cannot hide.

MuJoCo never reports contacts between a body and its parent (unless the parent is fixed
to the world, as a limb's base is), so two motor housings on consecutive bodies overlap
unseen by every contact-based check. Here each pair of parts is measured with
``mujoco.mj_geomDistance`` (the signed distance of two geoms, whatever their bodies),
except the pairs that meet by construction: the parts that share a joint point (a
housing and the links that end in it, two links joined at a joint, the housings of one
connector's degrees of freedom). The base is joined to nothing: a connector stands on it
with a clearance, so a housing or link that reaches into it overlaps.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from robotwright.grammar.build import Limb

#: Depth (m) from which two parts count as overlapping: below a tenth of a millimetre is
#: parts that touch, as the build places a housing against its neighbours.
OVERLAP_TOLERANCE = 1e-4


@dataclass(frozen=True)
class Overlap:
    """Two parts that overlap by ``depth`` m at pose number ``pose``."""

    pose: int
    a: str
    b: str
    depth: float


def _joint_points(limb: Limb) -> dict[str, frozenset[int]]:
    """Per geom name, the joint points it is built onto (connector node ids)."""
    body_index = {b.name: i for i, b in enumerate(limb.bodies)}
    starts: dict[int, set[int]] = {i: set() for i in range(len(limb.bodies))}
    for j in limb.joints:
        starts[body_index[j.body]].add(j.node)
    ends: dict[int, set[int]] = {i: set() for i in range(len(limb.bodies))}
    for i, b in enumerate(limb.bodies):
        if b.parent >= 0:
            ends[b.parent] |= starts[i]
    housing_node = {f"{j.name}_housing": j.node for j in limb.joints}
    out: dict[str, frozenset[int]] = {}
    for i, b in enumerate(limb.bodies):
        for g in b.geoms:
            if g.name in housing_node:
                out[g.name] = frozenset({housing_node[g.name]})
            elif b.parent < 0:
                out[g.name] = frozenset()  # the base
            else:
                out[g.name] = frozenset(starts[i] | ends[i])
    return out


def checked_pairs(limb: Limb, model: mujoco.MjModel, prefix: str = "") -> np.ndarray:
    """(n, 2) geom ids of ``model`` (the limb's names prefixed with ``prefix``) whose
    parts are not built to meet: no shared joint point, and on different bodies, or two
    housings of different connectors on one body (connectors in a row without a link
    between them; the other parts of one body are one piece)."""
    points = {prefix + n: p for n, p in _joint_points(limb).items()}
    names = [n for n in points if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) >= 0]
    ids = [model.geom(n).id for n in names]
    body = model.geom_bodyid
    pairs = [
        (ids[i], ids[k])
        for i in range(len(names))
        for k in range(i + 1, len(names))
        if not points[names[i]] & points[names[k]]
        and (
            body[ids[i]] != body[ids[k]]
            or names[i].endswith("_housing")
            and names[k].endswith("_housing")
        )
    ]
    return np.array(pairs, dtype=int).reshape(-1, 2)


def hidden_pairs(model: mujoco.MjModel, pairs: np.ndarray) -> np.ndarray:
    """The ``pairs`` MuJoCo's collision detection never reports: two geoms of one body
    (or of bodies welded together), or of a body and its parent, unless the parent is
    welded to the world (MuJoCo's parent filter spares the world's children). Where
    MuJoCo's contacts are already watched, these are the pairs left to measure."""
    weld, parent = model.body_weldid, model.body_parentid
    w1, w2 = weld[model.geom_bodyid[pairs[:, 0]]], weld[model.geom_bodyid[pairs[:, 1]]]
    p1, p2 = weld[parent[w1]], weld[parent[w2]]
    hidden = (w1 == w2) | ((p1 == w2) & (w2 != 0)) | ((p2 == w1) & (w1 != 0))
    return pairs[hidden]


class OverlapCheck:
    """The overlap check of one compiled model holding the limb (alone, or worn with
    its names prefixed with ``prefix``), made once and used at many poses: the pairs
    measured (:func:`checked_pairs`; with ``hidden_only`` just the ones MuJoCo's contacts
    cannot see, :func:`hidden_pairs`), where each joint's value goes in ``qpos``, and
    the bounding-sphere reach of each pair."""

    def __init__(
        self,
        limb: Limb,
        model: mujoco.MjModel,
        prefix: str = "",
        tolerance: float = OVERLAP_TOLERANCE,
        hidden_only: bool = False,
    ) -> None:
        pairs = checked_pairs(limb, model, prefix)
        self.pairs = hidden_pairs(model, pairs) if hidden_only else pairs
        self.model = model
        self.tolerance = tolerance
        self.qpos_adr = np.array(
            [model.jnt_qposadr[model.joint(prefix + j.name).id] for j in limb.joints], dtype=int
        )
        self._reach = model.geom_rbound[self.pairs[:, 0]] + model.geom_rbound[self.pairs[:, 1]]
        self._fromto = np.zeros(6)

    def pose(self, data: mujoco.MjData, q: np.ndarray) -> None:
        """Put ``data`` at joint vector ``q`` (``limb.joints`` order), kinematics done."""
        data.qpos[self.qpos_adr] = q
        mujoco.mj_kinematics(self.model, data)

    def at(self, data: mujoco.MjData, pose: int = 0, first_only: bool = False) -> list[Overlap]:
        """The pairs overlapping by more than the tolerance in ``data`` (kinematics
        computed), reported as at pose number ``pose``. A pair is measured only where
        their bounding spheres meet, so a pose costs a few microseconds per close pair."""
        out: list[Overlap] = []
        if len(self.pairs) == 0:
            return out
        a_pos, b_pos = data.geom_xpos[self.pairs[:, 0]], data.geom_xpos[self.pairs[:, 1]]
        close = self.pairs[np.linalg.norm(a_pos - b_pos, axis=1) < self._reach]
        for a, b in close:
            d = mujoco.mj_geomDistance(
                self.model, data, int(a), int(b), self.tolerance, self._fromto
            )
            if d < -self.tolerance:
                names = self.model.geom(int(a)).name, self.model.geom(int(b)).name
                out.append(Overlap(pose, *names, -d))
                if first_only:
                    break
        return out

    def over(self, poses: np.ndarray, first_only: bool = False) -> list[Overlap]:
        """:meth:`at` each of ``poses`` (joint vectors); ``first_only`` stops at the
        first overlap found."""
        out: list[Overlap] = []
        if len(self.pairs) == 0:
            return out
        data = mujoco.MjData(self.model)
        for k, q in enumerate(np.atleast_2d(poses)):
            self.pose(data, q)
            out += self.at(data, k, first_only)
            if first_only and out:
                break
        return out


def overlaps(
    limb: Limb,
    model: mujoco.MjModel,
    poses: np.ndarray,
    tolerance: float = OVERLAP_TOLERANCE,
    first_only: bool = False,
    prefix: str = "",
) -> list[Overlap]:
    """Every pair of parts overlapping by more than ``tolerance`` m at each of ``poses``
    (joint vectors in ``limb.joints`` order, rad or m), in ``model``: the limb alone or
    worn by a carrier (its names prefixed with ``prefix``); see :class:`OverlapCheck`.
    ``first_only`` stops at the first overlap found."""
    return OverlapCheck(limb, model, prefix, tolerance).over(poses, first_only)
