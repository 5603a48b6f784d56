"""The proof of a conversion: the source and the result compiled by MuJoCo, every
per-object array of ``MjModel`` compared.

The fields are not a hand-picked list: every array attribute of ``mujoco.MjModel``
whose name starts with a family prefix (``body_``, ``jnt_``, ``dof_``, ``geom_``,
``site_``, ``actuator_``, ``sensor_``, ``tendon_``, ``eq_``, ``key_``) and whose first
dimension is that family's count (``nbody``, ``njnt``, ...) is compared, as the installed
MuJoCo defines them (MuJoCo 3.11 and 4.x have different sets), and every field of
``model.opt``. ``user`` arrays are among them (``body_user``, ``jnt_user``, ...).

Objects are matched by name, not index (a conversion may reorder them): first by the
name, or the name the parsers give an unnamed object (``body_3``, ``joint_5``, ...),
then the rest by structure: an unnamed geom, site or joint by its body, type and order
in that body; a degree of freedom by its joint and order in it; an unnamed actuator,
sensor, tendon, equality or keyframe by its type and order. Fields holding ids of other
objects (``jnt_bodyid``, ``geom_bodyid``, ``actuator_trnid``, ``sensor_objid``,
``eq_obj1id``, ...) are compared through that matching (the names they point at);
keyframe columns (``key_qpos``, ``key_qvel``, ``key_ctrl``, ``key_act``) through the
joints and actuators they belong to. Addresses and counts into other arrays (``*adr``,
``*num``), tree and bounding-volume bookkeeping, and ids of assets (meshes, materials,
plugins) are not compared: they follow from the rest. Values the compiler derives
from several objects (``body_subtreemass``, ``*_invweight0``, ``dof_M0``,
``actuator_acc0``, ``*length0``) are reported only when nothing else differs: a changed
mass changes the subtree mass of every ancestor, and the mass is the difference to name.

Tolerance: two values of one object's field agree when
``|a - b| <= RTOL * max(|a|, |b| over that object's field) + ATOL`` with ``RTOL = 1e-9``
and ``ATOL = 1e-12`` (the absolute floor: a zero inertia that compiles to 6e-36 is
zero). Integers and flags must be equal.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from robotwright._mjmodel import actuator_count
from robotwright.errors import Problem

if TYPE_CHECKING:
    from robotwright.hrdf.model import HRDF

RTOL = 1e-9
ATOL = 1e-12


def _family_count(model: mujoco.MjModel, fam: str) -> int:
    """Objects of family ``fam`` in ``model`` (actuators, not controls: see
    :func:`robotwright._mjmodel.actuator_count`)."""
    if fam == "actuator":
        return actuator_count(model)
    return int(getattr(model, FAMILIES[fam][0]))


#: family prefix -> (count attribute, MJCF element word used in notes).
FAMILIES: dict[str, tuple[str, str]] = {
    "body": ("nbody", "body"),
    "jnt": ("njnt", "joint"),
    "dof": ("nv", "dof"),
    "geom": ("ngeom", "geom"),
    "site": ("nsite", "site"),
    "actuator": ("nu", "actuator"),
    "sensor": ("nsensor", "sensor"),
    "tendon": ("ntendon", "tendon"),
    "eq": ("neq", "equality"),
    "key": ("nkey", "key"),
}
_OBJ = {
    "body": mujoco.mjtObj.mjOBJ_BODY,
    "jnt": mujoco.mjtObj.mjOBJ_JOINT,
    "geom": mujoco.mjtObj.mjOBJ_GEOM,
    "site": mujoco.mjtObj.mjOBJ_SITE,
    "actuator": mujoco.mjtObj.mjOBJ_ACTUATOR,
    "sensor": mujoco.mjtObj.mjOBJ_SENSOR,
    "tendon": mujoco.mjtObj.mjOBJ_TENDON,
    "eq": mujoco.mjtObj.mjOBJ_EQUALITY,
    "key": mujoco.mjtObj.mjOBJ_KEY,
}
#: the name the parsers give an unnamed object of a family (see parsers/mjcf.py).
_FALLBACK = {"body": "body_{}", "jnt": "joint_{}", "site": "site_{}", "sensor": "sensor_{}"}
#: MuJoCo object type -> family, for the polymorphic id fields.
_OBJ_FAMILY = {
    int(mujoco.mjtObj.mjOBJ_BODY): "body",
    int(mujoco.mjtObj.mjOBJ_XBODY): "body",
    int(mujoco.mjtObj.mjOBJ_JOINT): "jnt",
    int(mujoco.mjtObj.mjOBJ_GEOM): "geom",
    int(mujoco.mjtObj.mjOBJ_SITE): "site",
    int(mujoco.mjtObj.mjOBJ_ACTUATOR): "actuator",
    int(mujoco.mjtObj.mjOBJ_TENDON): "tendon",
    int(mujoco.mjtObj.mjOBJ_CAMERA): "cam",
}
#: fields holding the id of an object of one family.
_ID_FIELDS = {
    "body_parentid": "body",
    "body_rootid": "body",
    "body_weldid": "body",
    "jnt_bodyid": "body",
    "dof_bodyid": "body",
    "dof_jntid": "jnt",
    "dof_parentid": "dof",
    "geom_bodyid": "body",
    "site_bodyid": "body",
}
#: fields holding an object id whose family another field gives.
_POLY_ID_FIELDS = {
    "actuator_trnid": "actuator_trntype",
    "sensor_objid": "sensor_objtype",
    "sensor_refid": "sensor_reftype",
    "eq_obj1id": "eq_objtype",
    "eq_obj2id": "eq_objtype",
}
#: actuator transmission type -> family of its target (slider-crank: first id a site).
_TRN_FAMILY = {0: "jnt", 1: "jnt", 2: "site", 3: "tendon", 4: "site", 5: "body"}
#: equality type -> family when MuJoCo leaves ``eq_objtype`` unset (joint, tendon).
_EQ_FAMILY = {0: "body", 1: "body", 2: "jnt", 3: "tendon"}
#: bookkeeping that follows from the compared fields (see the module docstring).
_SKIP_SUFFIX = ("adr", "num", "treeid", "plugin", "dataid", "matid", "mocapid")
#: physics despite the suffix: an actuator's plugin (compared as the plugin it runs and
#: that instance's configuration, not as an id) and its activation count.
_PHYSICS_DESPITE_SUFFIX = {"actuator_plugin", "actuator_actnum"}
_SKIP_FIELDS = {"body_bvhadr", "body_bvhnum", "actuator_actadr", "key_mpos", "key_mquat",
                # the compiler's shortcuts for an object whose frames coincide: they follow
                # from the compared frames (and the axis order of its principal moments)
                "body_sameframe", "body_simple", "geom_sameframe", "site_sameframe"}  # fmt: skip
#: drawing only (MuJoCo's physics never reads them): colours, visibility groups, shadows
#: and the drawn width of a tendon; a material's colour becomes ``geom_rgba`` as written.
_APPEARANCE = ("_rgba", "_group", "_castshadow", "_width")
#: keyframe field -> the family of its columns (per-column remap).
_KEY_COLUMNS = {"key_qpos": "qpos", "key_qvel": "dof", "key_ctrl": "actuator", "key_act": "act"}
#: MjModel field stem -> the MJCF attribute words a note about it may use.
_ALIASES = {
    "actfrcrange": ("actuatorfrcrange", "actfrcrange"),
    "actfrclimited": ("actuatorfrcrange", "actuatorfrclimited", "actfrclimited"),
    "actgravcomp": ("actuatorgravcomp",),
    "invweight0": ("inertia", "mass"),
    "subtreemass": ("mass",),
    "solref_lim": ("solreflimit", "solref"),
    "solimp_lim": ("solimplimit", "solimp"),
    "solref_fri": ("solreffriction", "solref"),
    "solimp_fri": ("solimpfriction", "solimp"),
    "lengthspring": ("springlength",),
}


@dataclass(frozen=True)
class Difference:
    """One value the result does not hold as the source does.

    Attributes:
        field: the ``MjModel`` attribute (``geom_solref``, ``opt.o_solref``) or
            ``"(object)"`` for an object missing from one side.
        family: the object family (``geom``, ``jnt``, ``opt``, ...).
        obj: the object as notes name it (``geom 'foot'``, ``geom #3 of body 'leg'``).
        source: the source's value (text).
        result: the result's value (text).
        labels: words that name the object in a conversion note.
    """

    field: str
    family: str
    obj: str
    source: str
    result: str
    labels: tuple[str, ...] = ()

    def __str__(self) -> str:
        return f"{self.field} of {self.obj}: source {self.source}, result {self.result}"


def _name(model: mujoco.MjModel, fam: str, i: int) -> str:
    if fam == "dof":
        return ""
    return mujoco.mj_id2name(model, _OBJ[fam], i) or ""


def fields(model: mujoco.MjModel) -> dict[str, list[str]]:
    """Family prefix -> the array attributes of ``model`` compared for it (derived from
    the installed MuJoCo's ``MjModel``, see the module docstring)."""
    out: dict[str, list[str]] = {fam: [] for fam in FAMILIES}
    for attr in dir(model):
        fam = attr.split("_", 1)[0]
        if fam not in FAMILIES or attr in _SKIP_FIELDS:
            continue
        skipped = attr.endswith(_SKIP_SUFFIX) and attr not in _ID_FIELDS
        if attr.endswith(_APPEARANCE) or (skipped and attr not in _PHYSICS_DESPITE_SUFFIX):
            continue
        if attr.endswith("id") and attr not in _ID_FIELDS and attr not in _POLY_ID_FIELDS:
            continue  # ids of assets and other bookkeeping (remapped ones are listed)
        value = getattr(model, attr, None)
        if not isinstance(value, np.ndarray) or value.ndim == 0:
            continue
        count = _family_count(model, fam)
        if value.shape[0] != count:
            continue
        out[fam].append(attr)
    return out


def option_fields(model: mujoco.MjModel) -> list[str]:
    """Every numeric field of ``model.opt`` (MjOption), as the installed MuJoCo has them."""
    out = []
    for attr in dir(model.opt):
        if attr.startswith("_"):
            continue
        value = getattr(model.opt, attr, None)
        if isinstance(value, int | float | np.ndarray):  # bool is an int
            out.append(attr)
    return out


class _Side:
    """One compiled model, with the keys its objects are matched by."""

    def __init__(self, model: mujoco.MjModel, keep_bodies: set[int] | None) -> None:
        self.m = model
        self.keep = keep_bodies
        self.names: dict[str, list[str]] = {
            fam: [_name(model, fam, i) for i in range(_family_count(model, fam))]
            for fam in FAMILIES
            if fam != "dof"
        }

    def kept(self, fam: str) -> np.ndarray:
        """Indices of the objects of ``fam`` that belong to the robot."""
        m = self.m
        n = _family_count(m, fam)
        owner = {"body": None, "jnt": m.jnt_bodyid, "dof": m.dof_bodyid, "geom": m.geom_bodyid,
                 "site": m.site_bodyid}.get(fam, "all")  # fmt: skip
        if isinstance(owner, str):
            return np.arange(n)
        if owner is None:
            return (
                np.array(sorted(self.keep), dtype=int) if self.keep is not None else np.arange(1, n)
            )
        # Objects fixed to the world (a floor, a scene's lights) are scene, not robot;
        # but sites of the world (an IMU frame, a muscle origin) travel with the robot.
        keep = np.ones(m.nbody, dtype=bool)
        if self.keep is not None:
            keep[:] = False
            keep[list(self.keep)] = True
        keep[0] = fam == "site"
        return np.nonzero(keep[owner])[0]


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
            # import may list a link's unnamed geoms in another order).
            here = _placement(src, fam, i)
            same = [k for k, j in enumerate(cands) if _same(here, _placement(res, fam, j))]
            out[i] = cands.pop(same[0] if same else 0)
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


def _fmt(v: np.ndarray) -> str:
    v = np.asarray(v)
    if v.dtype.kind in "iub":
        return str(v.tolist()) if v.ndim else str(int(v))
    flat = [float(f"{x:.10g}") for x in np.atleast_1d(v).ravel()]
    return str(flat[0]) if v.ndim == 0 else str(flat)


def _bad_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row indices where ``a`` and ``b`` differ beyond the tolerance (one row per object)."""
    a2 = a.reshape(a.shape[0], -1)
    b2 = b.reshape(b.shape[0], -1)
    if a.dtype.kind in "iub" and b.dtype.kind in "iub":
        return np.nonzero((a2 != b2).any(axis=1))[0]
    a2, b2 = a2.astype(float), b2.astype(float)
    both_nan = np.isnan(a2) & np.isnan(b2)
    with np.errstate(invalid="ignore"):
        same_inf = np.isinf(a2) & (a2 == b2)
        fin = np.where(np.isfinite(a2) & np.isfinite(b2), 1.0, 0.0)
        mag = np.maximum(np.abs(a2 * fin), np.abs(b2 * fin)).max(axis=1, initial=0.0)
        diff = np.abs(np.nan_to_num(a2 - b2, nan=np.inf))
    ok = (diff <= RTOL * mag[:, None] + ATOL) | both_nan | same_inf
    return np.nonzero(~ok.all(axis=1))[0]


def compare_models(
    source: mujoco.MjModel,
    result: mujoco.MjModel,
    *,
    root_body: str | None = None,
    families: Iterable[str] | None = None,
    options: bool = True,
    geom_order: bool = True,
) -> list[Difference]:
    """Every difference between two compiled models (see the module docstring).

    ``root_body``: the top-level body of ``source`` that is the robot (the others are
    scene and not compared); ``None``: all of it. ``families``: the prefixes compared
    (default all of :data:`FAMILIES`); ``options``: compare ``model.opt`` too;
    ``geom_order``: compare the order of each body's geoms (contacts come in that order).
    """
    src = _Side(source, _robot_bodies(source, root_body))
    res = _Side(result, None)
    wanted = list(FAMILIES) if families is None else list(families)
    maps: dict[str, dict[int, int]] = {"body": _match_bodies(src, res)}
    for fam in ("jnt", "geom", "site", "actuator", "sensor", "tendon", "eq", "key"):
        maps[fam] = _match(src, res, fam, maps["body"])
    maps["dof"] = _dof_map(src, res, maps["jnt"])
    maps["cam"] = {}
    cols = {
        "qpos": _qpos_map(src, res, maps["jnt"]),
        "dof": maps["dof"],
        "actuator": maps["actuator"],
        "act": _act_map(src, res, maps["actuator"]),
    }
    diffs: list[Difference] = []
    if options:
        diffs += _compare_options(source, result)
    src_fields, res_fields = fields(source), fields(result)
    for fam in wanted:
        # The world body is scene (its mass sums what the scene holds): not compared.
        m = {i: j for i, j in maps[fam].items() if fam != "body" or i != 0}
        diffs += _missing(src, res, fam, m)
        if not m:
            continue
        si = np.fromiter(m.keys(), dtype=int, count=len(m))
        ri = np.fromiter(m.values(), dtype=int, count=len(m))
        for attr in src_fields[fam]:
            if attr not in res_fields[fam]:
                continue
            a, b = getattr(source, attr), getattr(result, attr)
            if attr in _KEY_COLUMNS:
                a, b = _key_columns(a, b, cols[_KEY_COLUMNS[attr]])
            a, b = a[si], b[ri]
            if attr in _INERTIA_PAIRS.values():
                continue  # compared with its moments, as one tensor
            if attr in _INERTIA_PAIRS:
                quat = _INERTIA_PAIRS[attr]
                a = _tensors(a, getattr(source, quat)[si])
                b = _tensors(b, getattr(result, quat)[ri])
            elif attr in ("body_ipos", "body_invweight0"):
                # A body without mass or inertia has no centre of mass to place (MuJoCo
                # keeps the position it was given, or its geoms' centre, and computes
                # the inverse weight there).
                empty = _massless(source, si) & _massless(result, ri)
                b = np.where(empty.reshape((-1,) + (1,) * (b.ndim - 1)), a, b)
            elif attr.endswith("quat"):
                # q and -q are the same rotation.
                flip = (a.reshape(len(a), -1) * b.reshape(len(b), -1)).sum(axis=1) < 0
                b = np.where(flip.reshape((-1,) + (1,) * (b.ndim - 1)), -b, b)
            if attr == "actuator_plugin":
                a, b = _plugin_keys(source, a), _plugin_keys(result, b)
            if attr in ("geom_size", "site_size"):
                a, b = (
                    _used_sizes(a, getattr(source, attr[:-4] + "type")[si]),
                    _used_sizes(b, getattr(result, attr[:-4] + "type")[ri]),
                )
            if attr in _ID_FIELDS:
                a = _ids(a, maps[_ID_FIELDS[attr]])
            elif attr in _POLY_ID_FIELDS:
                a, b = _poly_ids(source, result, attr, si, ri, a, b, maps)
            if attr in _ID_FIELDS or attr in _POLY_ID_FIELDS:
                # An id of an object the result lacks: that absence is the difference
                # (reported as the missing object), not every id that points at it.
                gone = (np.asarray(a).reshape(len(a), -1) == -2).any(axis=1)
                b = np.where(gone.reshape((-1,) + (1,) * (np.ndim(b) - 1)), a, b)
            if a.shape[1:] != b.shape[1:]:
                diffs += [
                    _diff(
                        src,
                        fam,
                        attr,
                        int(s),
                        _fmt(getattr(source, attr)[s]),
                        _fmt(getattr(result, attr)[r]),
                    )  # fmt: skip
                    for s, r in zip(si, ri, strict=True)
                ]
                continue
            for row in _bad_rows(a, b):
                shown = (_fmt(a[row]), _fmt(b[row]))
                if attr == "actuator_plugin":  # the plugin and its configuration, not a key
                    shown = (
                        _plugin_text(source, int(source.actuator_plugin[si[row]])),
                        _plugin_text(result, int(result.actuator_plugin[ri[row]])),
                    )
                diffs.append(_diff(src, fam, attr, int(si[row]), *shown))
    if geom_order and "geom" in wanted:
        diffs += _geom_order(src, res, maps["geom"])
    if families is None:  # what simulates beyond the per-object arrays
        diffs += _contacts(src, res, maps)
        diffs += _tendon_paths(src, res, maps)
    if "geom" in wanted:
        diffs += _mesh_data(src, res, maps["geom"])
    primary = [d for d in diffs if not _stem(d.field).endswith(_DERIVED)]
    # A derived value (a subtree mass, an inverse weight) differs because an input did:
    # that input is the difference to report; derived ones alone are reported as such.
    return primary if primary else diffs


#: principal moments -> the rotation of their axes: compared as the one tensor they make
#: in the object's frame (MuJoCo orders and signs principal axes as its eigen-solver
#: returns them; an import and our writer may differ there and hold the same inertia).
_INERTIA_PAIRS = {"body_inertia": "body_iquat"}


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


def _inverse(mapping: dict[int, int]) -> dict[int, int]:
    return {r: s for s, r in mapping.items() if r >= 0}


def _same_values(a: np.ndarray, b: np.ndarray) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = max(float(np.abs(a).max(initial=0.0)), float(np.abs(b).max(initial=0.0)))
    return a.shape == b.shape and bool(np.all(np.abs(a - b) <= RTOL * scale + ATOL))


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

    theirs = {}
    for p in range(r.npair):
        key = (geoms.get(int(r.pair_geom1[p]), -1), geoms.get(int(r.pair_geom2[p]), -1))
        theirs.setdefault(frozenset(key), p)
    for p in range(s.npair):
        g1, g2 = int(s.pair_geom1[p]), int(s.pair_geom2[p])
        text = pair_text(g1, g2)
        labels = (*_labels(src, "geom", g1), *_labels(src, "geom", g2), "pair")
        q = theirs.pop(frozenset((g1, g2)), None)
        if q is None:
            out.append(Difference("(object)", "pair", text, "present", "absent", labels))
            continue
        for field in _PAIR_FIELDS:
            a, b = getattr(s, field)[p], getattr(r, field)[q]
            if not _same_values(a, b):
                out.append(Difference(field, "pair", text, _fmt(a), _fmt(b), labels))
    for q in theirs.values():
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


#: values the compiler derives from the others (and from every body of a subtree).
_DERIVED = ("invweight0", "subtreemass", "M0", "acc0", "length0", "lengthrange")

#: geom type -> how many ``size`` values it uses (sphere 1; capsule, cylinder 2).
_SIZES_USED = {2: 1, 3: 2, 5: 2}


def _used_sizes(size: np.ndarray, types: np.ndarray) -> np.ndarray:
    """``size`` with the values its type does not use set to 0: MuJoCo keeps unused ones
    as written (a sphere site of size 0.01 holds 0.01 0.005 0.005 or 0.01 0.01 0.01)."""
    out = np.array(size, dtype=float, copy=True)
    for t, n in _SIZES_USED.items():
        out[np.asarray(types) == t, n:] = 0.0
    return out


def _key_columns(a: np.ndarray, b: np.ndarray, cmap: dict[int, int]) -> tuple:
    """A keyframe array's columns of the source and, in the same order, the result's."""
    if not cmap or a.ndim != 2:
        return a[:, :0], b[:, :0]
    s = np.fromiter(cmap.keys(), dtype=int)
    r = np.fromiter(cmap.values(), dtype=int)
    return a[:, s], b[:, r]


def _ids(a: np.ndarray, m: dict[int, int]) -> np.ndarray:
    """Source ids mapped to result ids (-2: no counterpart; negative ids kept)."""
    flat = a.reshape(-1)
    mapped = np.fromiter(
        (m.get(int(x), -2) if x >= 0 else int(x) for x in flat), dtype=int, count=flat.size
    )
    return mapped.reshape(a.shape)


def _poly_ids(source, result, attr, si, ri, a, b, maps) -> tuple[np.ndarray, np.ndarray]:
    type_attr = _POLY_ID_FIELDS[attr]
    ts = np.asarray(getattr(source, type_attr))[si]
    out = np.array(a, dtype=int, copy=True)
    for k in range(out.shape[0]):
        t = int(ts[k]) if ts.ndim == 1 else int(ts[k, 0])
        if attr == "actuator_trnid":
            fam = _TRN_FAMILY.get(t)
        elif attr.startswith("eq_"):
            fam = _OBJ_FAMILY.get(t) or _EQ_FAMILY.get(int(source.eq_type[si[k]]))
        else:
            fam = _OBJ_FAMILY.get(t)
        mp = maps.get(fam or "", {})
        row = out[k].reshape(-1)
        for c in range(row.size):
            if row[c] >= 0:
                row[c] = mp.get(int(row[c]), -2) if fam else row[c]
        out[k] = row.reshape(out[k].shape)
    return out, np.asarray(b, dtype=int)


def _missing(src: _Side, res: _Side, fam: str, m: dict[int, int]) -> list[Difference]:
    out = []
    for i in src.kept(fam):
        if int(i) not in m:
            out.append(_diff(src, fam, "(object)", int(i), "present", "absent"))
    matched = set(m.values())
    word = FAMILIES[fam][1]
    for j in res.kept(fam):
        if int(j) not in matched:
            name = res.names[fam][int(j)] if fam in res.names else ""
            what = f"{word} '{name}'" if name else f"{word} #{int(j)} of the result"
            out.append(
                Difference("(object)", fam, what, "absent", "present", (name,) if name else ())
            )
    return out


def _labels(side: _Side, fam: str, i: int) -> tuple[str, ...]:
    """Words naming source object ``i`` of ``fam`` in a conversion note."""
    from robotwright.parsers.reference import body_name, joint_name

    m = side.m
    word = FAMILIES[fam][1]
    out = [f"{word} #{i}"]
    if fam == "dof":
        j = int(m.dof_jntid[i])
        return (*_labels(side, "jnt", j), f"dof #{i}")
    name = side.names[fam][i]
    fallback = _FALLBACK.get(fam)
    for n in (name, fallback.format(i) if fallback else ""):
        if n:
            out += [f'"{n}"', f"'{n}'"]
    if fam == "geom":
        out.append(f'geom #{i} of body "{body_name(m, int(m.geom_bodyid[i]))}"')
    if fam == "jnt" and not name:
        out.append(f"'{joint_name(m, i)}'")
    return tuple(out)


def _object_text(side: _Side, fam: str, i: int) -> str:
    from robotwright.parsers.reference import body_name, joint_name

    m = side.m
    word = FAMILIES[fam][1]
    if fam == "dof":
        j = int(m.dof_jntid[i])
        return f"dof {i - int(m.jnt_dofadr[j])} of joint '{joint_name(m, j)}'"
    name = side.names[fam][i]
    if name:
        return f"{word} '{name}'"
    if fam in ("geom", "site", "jnt"):
        body = body_name(m, int(getattr(m, f"{fam}_bodyid")[i]))
        return f"{word} #{i} of body '{body}'"
    if fam == "body":
        return f"body '{body_name(m, i)}'"
    return f"{word} #{i}"


def _diff(side: _Side, fam: str, attr: str, i: int, a: str, b: str) -> Difference:
    return Difference(attr, fam, _object_text(side, fam, i), a, b, _labels(side, fam, i))


def _compare_options(source: mujoco.MjModel, result: mujoco.MjModel) -> list[Difference]:
    out = []
    for attr in option_fields(source):
        if not hasattr(result.opt, attr):
            continue
        a = np.atleast_1d(np.asarray(getattr(source.opt, attr)))[None, :]
        b = np.atleast_1d(np.asarray(getattr(result.opt, attr)))[None, :]
        if a.shape != b.shape or _bad_rows(a, b).size:
            out.append(Difference(f"opt.{attr}", "opt", "<option>", _fmt(a[0]), _fmt(b[0])))
    return out


# -- notes ----------------------------------------------------------------------------------
def _stem(field: str) -> str:
    return field.split(".", 1)[1] if field.startswith("opt.") else field.split("_", 1)[-1]


def _words(field: str) -> tuple[str, ...]:
    stem = _stem(field)
    return (stem, *_ALIASES.get(stem, ()))


def _mentions(text: str, word: str) -> bool:
    return re.search(rf"(?<![A-Za-z0-9_]){re.escape(word)}(?![A-Za-z0-9_])", text) is not None


def covered(diff: Difference, notes: Sequence[str], absent: set[str] | None = None) -> bool:
    """Whether a conversion note reports ``diff``: for a missing object, a note naming
    it (or naming a body it belongs to that is itself missing); for a value, a note naming
    the object and the field (its MJCF attribute word: ``solref``, ``gravcomp``, ...);
    for an option, a note naming ``<option>`` and the field."""
    named = [n for n in notes if any(lab in n for lab in diff.labels)]
    if diff.field == "(object)":
        return bool(named)
    if diff.family == "opt":
        return any(
            "option" in n and any(_mentions(n, w) for w in _words(diff.field)) for n in notes
        )
    words = _words(diff.field)
    return any(any(_mentions(n, w) for w in words) for n in named)


def uncovered(diffs: Sequence[Difference], notes: Sequence[str]) -> list[Difference]:
    """The differences no note reports (see :func:`covered`); an object whose body is
    missing and reported is reported with it."""
    notes = list(notes)
    missing_bodies = {d.obj for d in diffs if d.field == "(object)" and d.family == "body"}
    reported_bodies = {
        d.obj for d in diffs
        if d.field == "(object)" and d.family == "body" and covered(d, notes)
    }  # fmt: skip
    out = []
    for d in diffs:
        if covered(d, notes):
            continue
        if d.field == "(object)" and d.obj.endswith("'") and " of body '" in d.obj:
            body = "body '" + d.obj.split(" of body '", 1)[1]
            if body in reported_bodies or body in missing_bodies and body in reported_bodies:
                continue
        out.append(d)
    return out


#: how many differences of one field are listed one by one before a count.
LISTED_PER_FIELD = 20


def as_problems(
    file: str, diffs: Sequence[Difference], sides: tuple[str, str] = ("source", "result")
) -> list[Problem]:
    """Conversion notes for differences no note reported: one per object and field (the
    first :data:`LISTED_PER_FIELD` of each field, then one line with the count);
    ``sides`` names the two models compared."""
    out: list[Problem] = []
    per_field: dict[str, int] = {}
    for d in diffs:
        n = per_field.get(d.field, 0)
        per_field[d.field] = n + 1
        if n < LISTED_PER_FIELD:
            what = "the object" if d.field == "(object)" else d.field
            out.append(
                Problem(
                    file,
                    f"proof: {what} differs after conversion: {sides[0]} {d.source}, "
                    f"{sides[1]} {d.result}",
                    element=d.obj,
                    severity="warning",
                )
            )
    for fld, n in per_field.items():
        if n > LISTED_PER_FIELD:
            out.append(
                Problem(
                    file,
                    f"proof: {fld} differs on {n - LISTED_PER_FIELD} more object(s)",
                    severity="warning",
                )
            )
    return out


# -- the proof of one conversion --------------------------------------------------------------
def source_model(path: Path, kind: str, options: dict) -> mujoco.MjModel | None:
    """The source as MuJoCo compiles it on its own (MJCF: its file; URDF: MuJoCo's URDF
    import, as the round trip's reference), or None when MuJoCo refuses it (nothing to
    prove against). The parser has checked the file's paths already; MuJoCo reads the
    file in a confined reader (:mod:`robotwright._confine`)."""
    from robotwright._confine import run_confined
    from robotwright.parsers.packages import source_read_roots

    # MuJoCo caches the meshes it decodes by file name, in the process that decodes
    # them: the output is read through the source's names only where the source was
    # compiled in this process. A confined reader compiled it in a copy; the output then
    # reads the staged copies (the same bytes), which the output's check decoded here.
    here = _compiled_in_this_process()
    if kind == "mjcf":
        parsed = _take_parsed(path)
        if parsed is not None:
            model, folder, meshdir, files = parsed
            if here:
                _SOURCE_MESHES[id(model)] = _mesh_files(folder, meshdir, files)
            return model
    roots = source_read_roots(path, kind, options)
    try:
        compiled = run_confined(
            _compile_source, Path(path), kind, options, roots=roots, what=str(path)
        )
    except Exception:  # noqa: BLE001 - any refusal: MuJoCo has no model to compare with
        return None
    if compiled is None:
        return None
    model, meshes = compiled
    if meshes is not None and here:
        _SOURCE_MESHES[id(model)] = meshes
    return model


def _compiled_in_this_process() -> bool:
    """Whether untrusted files are compiled in this process (no confined reader)."""
    from robotwright._confine import confinement, in_confined_copy

    return in_confined_copy() or not confinement().startswith("landlock")


def _compile_source(
    path: Path, kind: str, options: dict
) -> tuple[mujoco.MjModel, tuple[str, str, dict] | None] | None:
    """:func:`source_model`'s compile, run confined: the model and, for MJCF, its mesh
    files (see :func:`_mesh_files`)."""
    from robotwright.parsers.reference import compile_urdf, urdf_for_mujoco

    try:
        if kind == "mjcf":
            spec = mujoco.MjSpec.from_file(str(path))
            model = spec.compile()
            files = _cacheable_mesh_files(spec)
            meshes = _mesh_files(spec.modelfiledir or "", spec.compiler.meshdir or "", files)
            return model, meshes
        compiler = {
            k: options[k]
            for k in ("balance_inertia", "bound_mass", "bound_inertia")
            if k in options
        }
        text = urdf_for_mujoco(
            path,
            options.get("package_map"),
            inertia_from_geoms=options.get("inertia_from_geoms", "auto"),
            **compiler,
        )
        fuse = options.get("fixed_joints", "keep") == "merge"
        return compile_urdf(text, options.get("density"), fuse_static=fuse), None
    except Exception:  # noqa: BLE001 - any refusal: MuJoCo has no model to compare with
        return None


def _file_key(path: str | Path) -> tuple[int, str] | None:
    """Size and SHA-256 of a file (None when unreadable): a copy has the same key."""
    import hashlib

    try:
        data = Path(path).read_bytes()
    except OSError:
        return None
    return len(data), hashlib.sha256(data).hexdigest()


#: id of a source model compiled by :func:`source_model` -> its mesh files (see
#: :func:`_mesh_files`); taken by the proof that compiles the output next.
_SOURCE_MESHES: dict[int, tuple[str, str, dict[tuple[int, str], str]]] = {}


def _cacheable_mesh_files(spec: mujoco.MjSpec) -> list[str]:
    """The mesh files of ``spec`` the result may read by the same name (MuJoCo's cache):
    not one read with a ``refpos``/``refquat``, which MuJoCo 3.11 keeps in the cached
    mesh (the result holds that frame in its geoms' poses instead)."""
    return [
        m.file
        for m in spec.meshes
        if not (np.any(m.refpos != 0) or np.any(np.asarray(m.refquat) != [1, 0, 0, 0]))
    ]


def _mesh_files(
    folder: str, meshdir: str, files: Iterable[str]
) -> tuple[str, str, dict[tuple[int, str], str]]:
    """The folders and mesh file names of an MJCF as MuJoCo read them: its model folder,
    its mesh folder, and per file content (size, SHA-256) the name as written."""
    import os

    base = Path(folder or ".") / meshdir
    names: dict[tuple[int, str], str] = {}
    for file in files:
        if file and not os.path.isabs(file):
            key = _file_key(base / file)
            if key is not None:
                names.setdefault(key, file)
    return folder, meshdir, names


#: the last MJCF the parser compiled: (resolved path, size and mtime) -> its model, model
#: folder, mesh folder and mesh file names; taken by :func:`source_model` (one compile
#: of the source saved). At most one is kept.
_PARSED: dict[tuple[str, int, int], tuple[mujoco.MjModel, str, str, list[str]]] = {}


def _stat_key(path: str | Path) -> tuple[str, int, int] | None:
    try:
        st = Path(path).stat()
        return str(Path(path).resolve()), st.st_size, st.st_mtime_ns
    except OSError:
        return None


def remember_parsed(path: str | Path, spec: mujoco.MjSpec, model: mujoco.MjModel) -> None:
    """Keep ``model``, the parser's compile of the MJCF file ``path`` from ``spec``
    (compiled, not changed since), for the proof of the conversion that follows."""
    _PARSED.clear()
    key = _stat_key(path)
    if key is not None:
        files = _cacheable_mesh_files(spec)
        _PARSED[key] = (model, spec.modelfiledir or "", spec.compiler.meshdir or "", files)


def _take_parsed(path: str | Path) -> tuple[mujoco.MjModel, str, str, list[str]] | None:
    key = _stat_key(path)
    return _PARSED.pop(key, None) if key is not None else None


def _mesh_sources(hrdf: HRDF) -> list[Path]:
    """The files the HRDF's meshes are read from, for :func:`_compile_with_same_files`;
    a mesh whose file cannot be found is left out (the compile that needs it fails)."""
    originals = []
    for m in hrdf.meshes:
        try:
            originals.append(hrdf.mesh_source(m))
        except Exception:  # noqa: BLE001 - an unreadable mesh fails the compile
            continue
    return originals


def _compile_with_same_files(
    xml: str,
    originals: Iterable[Path],
    discard_visual: bool = False,
    source: tuple[str, str, dict[tuple[int, str], str]] | None = None,
) -> mujoco.MjModel:
    """Compile ``xml``; a mesh file with the same bytes as one of ``originals`` (a copy or
    a link the writer made) is read through that path, or, given the ``source``'s mesh
    files (:func:`_mesh_files`), by the name the source's compile read it by: MuJoCo
    caches a compiled mesh by that name, so the values compared are the same and the
    second processing of every mesh (most of a compile) is saved. ``discard_visual``:
    compile as MuJoCo's URDF import does (``discardvisual``: geoms that neither collide
    nor carry mass left out)."""
    by_key: dict[tuple[int, str], str] = {}
    for p in originals:
        key = _file_key(p)
        if key is not None:
            by_key.setdefault(key, str(p))
    spec = mujoco.MjSpec.from_string(xml)
    if discard_visual:
        spec.compiler.discardvisual = True
    folder, meshdir, names = source or ("", "", {})
    # Where MuJoCo reads each file (the writer may give a mesh folder); every file is
    # then given as an absolute path or, read as the source read it, by the source's name.
    own = Path(spec.modelfiledir or ".") / (spec.compiler.meshdir or "")
    relative = False
    for mesh in spec.meshes:
        if mesh.file:
            path = own / mesh.file
            key = _file_key(path)
            if key is not None and key in names:
                mesh.file = names[key]
                relative = True
            else:
                mesh.file = by_key.get(key, str(path.absolute())) if key else str(path.absolute())
    if relative:
        # Other files, read from the writer's folders, by absolute paths.
        home = Path(spec.modelfiledir or ".")
        for tex in spec.textures:
            if tex.file:
                tex.file = str((home / (spec.compiler.texturedir or "") / tex.file).absolute())
        for other in (*spec.hfields, *spec.skins):
            if other.file:
                other.file = str((home / other.file).absolute())
        spec.compiler.texturedir = ""
    spec.modelfiledir, spec.compiler.meshdir = (folder, meshdir) if relative else ("", "")
    return spec.compile()


def result_model(
    hrdf: HRDF,
    out_kind: str,
    work_dir: Path | None,
    *,
    discard_visual: bool = False,
    source: mujoco.MjModel | None = None,
) -> tuple[mujoco.MjModel, list[str]]:
    """What the output of ``hrdf`` compiles to, and the notes its writer gives: an HRDF
    folder saved and read back (into ``work_dir``), then generated as MJCF; an MJCF as
    ``export`` writes it; a URDF as MuJoCo imports it. ``discard_visual``: the MJCF
    compiled as MuJoCo compiles a URDF (visual geoms left out), to compare with a URDF
    source. ``source``: the source as :func:`source_model` compiled it (its meshes are
    read by the same names, from MuJoCo's cache)."""
    files = _SOURCE_MESHES.pop(id(source), None) if source is not None else None
    import tempfile
    import warnings

    from robotwright.parsers.roundtrip import our_mjcf_text, our_urdf_model

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if out_kind == "urdf":
            model = our_urdf_model(hrdf)
        else:
            originals = _mesh_sources(hrdf)
            if out_kind == "mjcf":
                model = _compile_with_same_files(
                    our_mjcf_text(hrdf), originals, discard_visual, files
                )
            else:
                from robotwright.hrdf.model import HRDF as _HRDF

                with tempfile.TemporaryDirectory(prefix="proof-", dir=work_dir) as tmp:
                    folder = Path(tmp) / "robot"
                    hrdf.save(folder)
                    loaded = _HRDF.from_dir(folder, asset_roots=hrdf.asset_roots)
                    model = _compile_with_same_files(
                        our_mjcf_text(loaded), originals, discard_visual, files
                    )
    return model, [str(w.message) for w in caught]


def prove(
    source: Path,
    kind: str,
    hrdf: HRDF,
    out_kind: str,
    notes: Sequence[str],
    *,
    options: dict | None = None,
    work_dir: Path | None = None,
) -> list[Problem]:
    """The proof of converting ``source`` (``kind``: ``"mjcf"`` or ``"urdf"``) into
    ``hrdf`` and writing it as ``out_kind`` (``"hrdf"``, ``"mjcf"``, ``"urdf"``): one
    conversion note per difference that no note in ``notes`` reports (see
    :func:`as_problems`). Empty when MuJoCo does not compile the source.

    A URDF source is compared with MuJoCo's own import of it (every link a body, visual
    geoms discarded as that import does; the output compiled the same way). A URDF
    output is proved in two steps: the source against our MJCF of ``hrdf`` (what the
    robot holds), and MuJoCo's import of our URDF against that MJCF
    (:func:`robotwright.parsers.proof_urdf.prove_urdf_output`: what a URDF holds)."""
    options = dict(options or {})
    from robotwright.generators.compiles import too_deep_for_mjcf

    deep = too_deep_for_mjcf(hrdf)
    if deep is not None:
        # The robot is written (HRDF and URDF files are flat), but MuJoCo cannot compile
        # an MJCF of it to compare with: say so instead of refusing the conversion.
        return [Problem(str(source), f"proof: not made: {deep}", severity="warning")]
    found: list[Problem] = []
    if out_kind == "urdf":
        # The URDF form against our MJCF of the same robot (what a URDF can hold), and
        # that MJCF against the source (what the robot holds) below.
        from robotwright.parsers.proof_urdf import prove_urdf_output

        found = prove_urdf_output(hrdf, str(source), notes)
        out_kind = "mjcf"
    if kind == "urdf" and options.get("fixed_joints", "keep") == "site":
        # Massless leaf links become sites, others stay bodies: MuJoCo's import has no
        # such choice to compare with (it keeps every link, or fuses every fixed one).
        return found
    src = source_model(source, kind, options)
    if src is None:
        return found
    res, written = result_model(hrdf, out_kind, work_dir, discard_visual=kind == "urdf", source=src)
    root = options.get("root_body")
    families = None
    if out_kind == "urdf" or kind == "urdf":
        # URDF has no sites, sensors, actuators, tendons, equalities or keyframes, and no
        # <option>: what the parser or generator drops of them is in its notes.
        families = ("body", "jnt", "dof", "geom")
    # A URDF has no geom order of its own (MuJoCo's import of it puts a link's geoms in
    # one order, a reader may pair visual and collision elements in another).
    diffs = compare_models(
        src,
        res,
        root_body=root,
        families=families,
        options=families is None,
        geom_order=kind != "urdf",
    )
    return found + as_problems(str(source), uncovered(diffs, [*notes, *written]))
