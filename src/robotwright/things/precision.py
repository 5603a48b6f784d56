"""Full-precision numbers in the MJCF sections that Things carry verbatim.

The carried sections (tendons, equalities, keyframes, contact pairs, statistics,
actuators and sensors the Things do not model) come from ``MjSpec.to_xml()``, whose writer rounds every number to six
significant digits (a tendon stiffness of 3.14159265 becomes 3.14159, a keyframe qpos
moves by up to 5e-7). Each number is put back to the value MuJoCo compiled, read from
the compiled ``MjModel`` of the same source, so that our MJCF compiles to that model
exactly.

A value is replaced only when the written text agrees with the compiled value to the
writer's precision (relative 1e-5): an attribute whose compiled value means something
else (a weld ``relpose`` that MuJoCo computes, a connect ``anchor`` given by sites) keeps
its text, so a refinement can never change a value's meaning.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable

import mujoco
import numpy as np

from robotwright.things.attrs import fmt_float

#: The writer's relative precision (``%g``: six significant digits), with a margin.
_RTOL = 1e-5

_TENDON = {
    "stiffness": "tendon_stiffness",
    "springlength": "tendon_lengthspring",
    "damping": "tendon_damping",
    "frictionloss": "tendon_frictionloss",
    "range": "tendon_range",
    "margin": "tendon_margin",
    "width": "tendon_width",
    "armature": "tendon_armature",
    "solreflimit": "tendon_solref_lim",
    "solimplimit": "tendon_solimp_lim",
    "solreffriction": "tendon_solref_fri",
    "solimpfriction": "tendon_solimp_fri",
    "actuatorfrcrange": "tendon_actfrcrange",
}
_KEY = {
    "time": "key_time",
    "qpos": "key_qpos",
    "qvel": "key_qvel",
    "act": "key_act",
    "ctrl": "key_ctrl",
    "mpos": "key_mpos",
    "mquat": "key_mquat",
}
_ACTUATOR = {
    "gear": "actuator_gear",
    "ctrlrange": "actuator_ctrlrange",
    "forcerange": "actuator_forcerange",
    "actrange": "actuator_actrange",
    "lengthrange": "actuator_lengthrange",
    "gainprm": "actuator_gainprm",
    "biasprm": "actuator_biasprm",
    "dynprm": "actuator_dynprm",
    "cranklength": "actuator_cranklength",
    "armature": "actuator_armature",
}
_SENSOR = {"noise": "sensor_noise", "cutoff": "sensor_cutoff"}
_EQ_DATA = {  # equality tag -> attribute -> slice of eq_data
    "connect": {"anchor": slice(0, 3)},
    "weld": {"anchor": slice(0, 3), "relpose": slice(3, 10), "torquescale": slice(10, 11)},
    "joint": {"polycoef": slice(0, 5)},
    "tendon": {"polycoef": slice(0, 5)},
}


def _row(model: mujoco.MjModel, field: str, i: int) -> np.ndarray | None:
    array = getattr(model, field, None)  # fields differ between MuJoCo versions
    if array is None or i >= len(array):
        return None
    return np.atleast_1d(np.asarray(array[i], dtype=float)).ravel()


def refine(elem: ET.Element, values: dict[str, np.ndarray | None]) -> None:
    """Replace each attribute's numbers by ``values[attr]`` (same count, from the start)
    when they agree with the written text to the writer's precision."""
    for attr, compiled in values.items():
        text = elem.get(attr)
        if text is None or compiled is None:
            continue
        try:
            written = np.array([float(v) for v in text.split()])
        except ValueError:
            continue  # not a number list (a name, "auto", ...)
        if len(written) == 0 or len(written) > len(compiled):
            continue
        exact = compiled[: len(written)]
        if np.allclose(written, exact, rtol=_RTOL, atol=0.0) and not np.array_equal(written, exact):
            elem.set(attr, " ".join(fmt_float(v) for v in exact.tolist()))


def _fields(model: mujoco.MjModel, table: dict[str, str], i: int) -> dict[str, np.ndarray | None]:
    return {attr: _row(model, field, i) for attr, field in table.items()}


def refine_tendons(node: ET.Element, model: mujoco.MjModel) -> None:
    """``<tendon>`` children in tendon-id order; wrap coefficients and pulley divisors
    from ``wrap_prm``."""
    for i, tendon in enumerate(node):
        if i >= model.ntendon:
            return
        refine(tendon, _fields(model, _TENDON, i))
        adr = int(model.tendon_adr[i])
        for k, wrap in enumerate(tendon):
            if k >= int(model.tendon_num[i]):
                break
            attr = {"joint": "coef", "pulley": "divisor"}.get(wrap.tag)
            if attr:
                refine(wrap, {attr: np.array([model.wrap_prm[adr + k]])})


def refine_equalities(node: ET.Element, model: mujoco.MjModel) -> None:
    for i, eq in enumerate(node):
        if i >= model.neq:
            return
        data = np.asarray(model.eq_data[i], dtype=float)
        values = {attr: data[part] for attr, part in _EQ_DATA.get(eq.tag, {}).items()}
        values["solref"] = _row(model, "eq_solref", i)
        values["solimp"] = _row(model, "eq_solimp", i)
        refine(eq, values)


def refine_keys(node: ET.Element, model: mujoco.MjModel) -> None:
    for i, key in enumerate(node):
        if i >= model.nkey:
            return
        refine(key, _fields(model, _KEY, i))


def refine_listed(
    elems: list[ET.Element], model: mujoco.MjModel, section: str, start: int = 0
) -> None:
    """Carried ``<actuator>`` or ``<sensor>`` elements, model ids ``start``, ``start+1``..."""
    table = _ACTUATOR if section == "actuator" else _SENSOR
    for i, elem in enumerate(elems, start):
        refine(elem, _fields(model, table, i))


_PAIR = {
    "margin": "pair_margin",
    "gap": "pair_gap",
    "friction": "pair_friction",
    "solref": "pair_solref",
    "solreffriction": "pair_solreffriction",
    "solimp": "pair_solimp",
}


def refine_contact(node: ET.Element, model: mujoco.MjModel) -> None:
    """``<pair>`` elements in pair-id order (``<exclude>`` has no numbers)."""
    pairs = [child for child in node if child.tag == "pair"]
    for i, pair in enumerate(pairs[: model.npair]):
        refine(pair, _fields(model, _PAIR, i))


def refine_statistic(node: ET.Element, model: mujoco.MjModel) -> None:
    stat = model.stat
    refine(
        node,
        {
            name: np.atleast_1d(np.asarray(getattr(stat, name), dtype=float))
            for name in ("meaninertia", "meanmass", "meansize", "extent", "center")
        },
    )


SECTION_REFINERS: dict[str, Callable[[ET.Element, mujoco.MjModel], None]] = {
    "tendon": refine_tendons,
    "equality": refine_equalities,
    "keyframe": refine_keys,
    "contact": refine_contact,
    "statistic": refine_statistic,
}
