"""What the proof compares: the object families of a compiled ``MjModel``, the fields of each
that are physics, the tolerances, and a :class:`Difference` named by its object."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from robotwright._mjmodel import actuator_count

if TYPE_CHECKING:
    pass


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


def _inverse(mapping: dict[int, int]) -> dict[int, int]:
    return {r: s for s, r in mapping.items() if r >= 0}


def _same_values(a: np.ndarray, b: np.ndarray) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = max(float(np.abs(a).max(initial=0.0)), float(np.abs(b).max(initial=0.0)))
    return a.shape == b.shape and bool(np.all(np.abs(a - b) <= RTOL * scale + ATOL))


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
