"""Tendon, equality and contact sections rebuilt from a compiled ``MjModel``.

MuJoCo's own writer (``MjSpec.to_xml``) prints 6 significant digits and keeps default
classes, so its output is neither exact nor self-contained. These sections are written
instead from the compiled values, every attribute explicit and floats in shortest
round-trip form, so that the HRDF's ``mjcf_extra`` compiles back to the same numbers.

Elements that refer to something outside the robot (or to an unnamed object, which MJCF
cannot reference) are dropped and reported; so are fields of newer MuJoCo versions that
have no MJCF attribute known here when they are not at their default.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable

import mujoco
import numpy as np

from robotwright._names import shown

Warn = Callable[[str, str | None], None]

_DEFAULT = mujoco.MjModel.from_xml_string(
    """<mujoco><worldbody><body name="a"><joint name="j"/><geom name="g" size="1"/>
    <site name="s"/></body><body name="b" pos="1 0 0"><joint name="k"/>
    <geom name="h" size="1"/><site name="t"/></body></worldbody>
    <tendon><spatial name="sp"><site site="s"/><site site="t"/></spatial></tendon>
    <equality><connect body1="a" body2="b" anchor="0 0 0"/></equality>
    <contact><pair geom1="g" geom2="h"/></contact></mujoco>"""
)


def _f(values) -> str:
    out = []
    for v in np.atleast_1d(values):
        v = float(v)
        text = "0" if v == 0 else repr(v)
        out.append(text[:-2] if text.endswith(".0") else text)
    return " ".join(out)


def _name(model: mujoco.MjModel, obj: mujoco.mjtObj, i: int) -> str | None:
    if obj == mujoco.mjtObj.mjOBJ_BODY and i == 0:
        return "world"
    return mujoco.mj_id2name(model, obj, i) or None


def _unheld(model: mujoco.MjModel, fields: tuple[str, ...], i: int) -> list[str]:
    """Fields (of this MuJoCo version) that differ from their default for element ``i``."""
    out = []
    for f in fields:
        if hasattr(model, f) and np.any(getattr(model, f)[i] != getattr(_DEFAULT, f)[0]):
            out.append(f)
    return out


def tendons(
    model: mujoco.MjModel, names: dict[str, set[str]], warn: Warn
) -> tuple[ET.Element | None, set[str]]:
    """``<tendon>`` with every tendon of the robot; returns it and the kept tendon names."""
    section = ET.Element("tendon")
    kept: set[str] = set()
    obj = mujoco.mjtObj
    for t in range(model.ntendon):
        tname = model.tendon(t).name
        where = f'<tendon name="{tname}">' if tname else f"tendon #{t}"
        adr, num = int(model.tendon_adr[t]), int(model.tendon_num[t])
        wraps = []
        missing = []
        for w in range(adr, adr + num):
            wt, oid, prm = int(model.wrap_type[w]), int(model.wrap_objid[w]), model.wrap_prm[w]
            if wt == mujoco.mjtWrap.mjWRAP_JOINT:
                n = _name(model, obj.mjOBJ_JOINT, oid)
                wraps.append(("joint", {"joint": n, "coef": _f(prm)}))
                kind = "joint"
            elif wt == mujoco.mjtWrap.mjWRAP_PULLEY:
                wraps.append(("pulley", {"divisor": _f(prm)}))
                continue
            elif wt == mujoco.mjtWrap.mjWRAP_SITE:
                n = _name(model, obj.mjOBJ_SITE, oid)
                wraps.append(("site", {"site": n}))
                kind = "site"
            else:
                n = _name(model, obj.mjOBJ_GEOM, oid)
                attrs = {"geom": n}
                if prm >= 0:
                    side = _name(model, obj.mjOBJ_SITE, int(prm))
                    attrs["sidesite"] = side
                    if side is None or side not in names["site"]:
                        missing.append(f"site {shown(side)}")
                wraps.append(("geom", attrs))
                kind = "geom"
            if n is None or n not in names[kind]:
                missing.append(f"{kind} {shown(n)}")
        if missing or not tname:
            why = f"it refers to {missing} outside the robot" if missing else "it has no name"
            warn(f"tendon dropped: {why}", where)
            continue
        fixed = wraps and wraps[0][0] == "joint"
        attrs = {"name": tname}
        if model.tendon_group[t]:
            attrs["group"] = str(int(model.tendon_group[t]))
        attrs["limited"] = "true" if model.tendon_limited[t] else "false"
        if model.tendon_limited[t]:
            attrs["range"] = _f(model.tendon_range[t])
        elif np.any(model.tendon_range[t]):
            # MuJoCo ignores the range of an unlimited tendon: harmless, but said.
            warn(
                f"range {model.tendon_range[t].tolist()} of an unlimited tendon dropped "
                "(MuJoCo ignores it)",
                where,
            )
        if hasattr(model, "tendon_actfrclimited") and model.tendon_actfrclimited[t]:
            attrs["actuatorfrclimited"] = "true"
            attrs["actuatorfrcrange"] = _f(model.tendon_actfrcrange[t])
        attrs |= {
            "solreflimit": _f(model.tendon_solref_lim[t]),
            "solimplimit": _f(model.tendon_solimp_lim[t]),
            "solreffriction": _f(model.tendon_solref_fri[t]),
            "solimpfriction": _f(model.tendon_solimp_fri[t]),
            "frictionloss": _f(model.tendon_frictionloss[t]),
            "springlength": _f(model.tendon_lengthspring[t]),
            "stiffness": _f(model.tendon_stiffness[t]),
            "damping": _f(model.tendon_damping[t]),
            "armature": _f(model.tendon_armature[t]),
            "margin": _f(model.tendon_margin[t]),
        }
        if np.any(model.tendon_user[t] != 0):  # padded to <size nuser_tendon> (mjcf_size)
            attrs["user"] = _f(model.tendon_user[t])
        if not fixed:
            attrs["width"] = _f(model.tendon_width[t])
            attrs["rgba"] = _f(model.tendon_rgba[t])
        if model.tendon_matid[t] >= 0:
            warn("tendon material dropped (its colour is kept)", where)
        extra = _unheld(
            model, ("tendon_stiffnesspoly", "tendon_dampingpoly", "tendon_springyield"), t
        )
        if extra:
            warn(f"tendon fields {extra} dropped (not written)", where)
        el = ET.SubElement(section, "fixed" if fixed else "spatial", attrs)
        for tag, wattrs in wraps:
            ET.SubElement(el, tag, wattrs)
        kept.add(tname)
    return (section if len(section) else None), kept


def welds_with_relpose(spec: mujoco.MjSpec, model: mujoco.MjModel) -> list[bool] | None:
    """Per equality of ``model``: whether its source gives a weld ``relpose`` (a non-zero
    quaternion part; MuJoCo computes an omitted one from the reference pose). None when
    the spec's equalities do not line up with the model's.

    Read from the spec, not the compiled model, so that the answer is the same on MuJoCo
    3.11 and 4.x: 4.x flags it in ``eq_data[11]``, but 3.11's ``eq_data`` has 11 entries
    and holds the computed relpose with nothing to tell it from a given one."""
    eqs = spec.equalities
    if len(eqs) != model.neq:
        return None
    return [bool(np.any(np.asarray(e.data[6:10], dtype=float) != 0)) for e in eqs]


def equalities(
    model: mujoco.MjModel,
    names: dict[str, set[str]],
    warn: Warn,
    relpose_given: list[bool] | None = None,
) -> ET.Element | None:
    """``<equality>`` with the robot's connect, weld, joint and tendon constraints.

    ``relpose_given`` (see :func:`welds_with_relpose`): a body weld whose source gave no
    ``relpose`` is written without one, so that MuJoCo computes it again from the
    reference pose (the same body poses give the same value); None writes every body
    weld's compiled relpose, which compiles to the same model."""
    section = ET.Element("equality")
    eq = mujoco.mjtEq
    obj = mujoco.mjtObj
    for e in range(model.neq):
        ename = model.eq(e).name if hasattr(model, "eq") else ""
        ename = ename or mujoco.mj_id2name(model, obj.mjOBJ_EQUALITY, e) or ""
        where = f'<equality name="{ename}">' if ename else f"equality #{e}"
        et = int(model.eq_type[e])
        o1, o2 = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
        data = model.eq_data[e]
        site_based = int(model.eq_objtype[e]) == obj.mjOBJ_SITE
        attrs: dict[str, str] = {"name": ename} if ename else {}
        refs: list[tuple[str, str | None]] = []
        if et in (eq.mjEQ_CONNECT, eq.mjEQ_WELD):
            kind, ot = ("site", obj.mjOBJ_SITE) if site_based else ("body", obj.mjOBJ_BODY)
            n1, n2 = _name(model, ot, o1), _name(model, ot, o2)
            attrs |= {f"{kind}1": n1, f"{kind}2": n2}
            refs += [(kind, n1), (kind, n2)]
            tag = "connect" if et == eq.mjEQ_CONNECT else "weld"
            if not site_based:
                attrs["anchor"] = _f(data[0:3])
                if tag == "weld" and (relpose_given is None or relpose_given[e]):
                    attrs["relpose"] = _f(data[3:10])
            if tag == "weld":
                attrs["torquescale"] = _f(data[10])
        elif et in (eq.mjEQ_JOINT, eq.mjEQ_TENDON):
            kind, ot, tag = (
                ("joint", obj.mjOBJ_JOINT, "joint")
                if et == eq.mjEQ_JOINT
                else ("tendon", obj.mjOBJ_TENDON, "tendon")
            )
            n1 = _name(model, ot, o1)
            attrs[f"{kind}1"] = n1
            refs.append((kind, n1))
            if o2 >= 0:
                n2 = _name(model, ot, o2)
                attrs[f"{kind}2"] = n2
                refs.append((kind, n2))
            attrs["polycoef"] = _f(data[0:5])
        else:
            warn(f"equality of type {mujoco.mjtEq(et).name} dropped (not supported)", where)
            continue
        outside = [f"{k} {shown(n)}" for k, n in refs if n is None or n not in names[k]]
        if outside:
            warn(f"equality dropped: it refers to {outside} outside the robot", where)
            continue
        attrs |= {
            "active": "true" if model.eq_active0[e] else "false",
            "solref": _f(model.eq_solref[e]),
            "solimp": _f(model.eq_solimp[e]),
        }
        ET.SubElement(section, tag, attrs)
    return section if len(section) else None


def contacts(model: mujoco.MjModel, names: dict[str, set[str]], warn: Warn) -> ET.Element | None:
    """``<contact>`` with the robot's explicit geom pairs and body excludes."""
    section = ET.Element("contact")
    obj = mujoco.mjtObj
    for p in range(model.npair):
        pname = mujoco.mj_id2name(model, obj.mjOBJ_PAIR, p) or ""
        where = f'<pair name="{pname}">' if pname else f"pair #{p}"
        g1 = _name(model, obj.mjOBJ_GEOM, int(model.pair_geom1[p]))
        g2 = _name(model, obj.mjOBJ_GEOM, int(model.pair_geom2[p]))
        outside = [g for g in (g1, g2) if g is None or g not in names["geom"]]
        if outside:
            warn(f"contact pair dropped: geoms {outside} are not (named) robot geoms", where)
            continue
        attrs = {"name": pname} if pname else {}
        attrs |= {
            "geom1": g1,
            "geom2": g2,
            "condim": str(int(model.pair_dim[p])),
            "friction": _f(model.pair_friction[p]),
            "solref": _f(model.pair_solref[p]),
            "solreffriction": _f(model.pair_solreffriction[p]),
            "solimp": _f(model.pair_solimp[p]),
            "margin": _f(model.pair_margin[p]),
            "gap": _f(model.pair_gap[p]),
        }
        extra = _unheld(model, ("pair_adhesion",), p)
        if extra:
            warn(f"contact pair fields {extra} dropped (not written)", where)
        ET.SubElement(section, "pair", attrs)
    for e in range(model.nexclude):
        sig = int(model.exclude_signature[e])
        b1, b2 = _name(model, obj.mjOBJ_BODY, sig >> 16), _name(model, obj.mjOBJ_BODY, sig & 0xFFFF)
        ename = mujoco.mj_id2name(model, obj.mjOBJ_EXCLUDE, e)
        outside = [b for b in (b1, b2) if b is None or b not in names["body"]]
        if outside:
            warn(f"contact exclude dropped: bodies {outside} are not robot bodies", f"exclude #{e}")
            continue
        attrs = {"name": ename} if ename else {}
        attrs |= {"body1": b1, "body2": b2}
        ET.SubElement(section, "exclude", attrs)
    return section if len(section) else None
