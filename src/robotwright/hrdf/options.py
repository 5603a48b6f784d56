"""MuJoCo ``<option>`` attributes and ``<flag>`` switches HRDF keeps, and ``<size>``.

``meta.yaml`` holds them under ``simulator_config.option`` and ``simulator_config.flag``
with MJCF's names and units (see ``docs/hrdf.md``); only what the robot sets (what
differs from MuJoCo's default) is stored, and written back. Each name and value is
checked against the vocabulary below before it reaches any XML.
"""

from __future__ import annotations

import math
from typing import Any

import mujoco
import numpy as np

from robotwright._names import shown

#: ``<option>`` attributes beside ``timestep``, ``gravity`` and ``integrator`` (which
#: ``simulator_config`` has its own keys for): name -> ``(kind, size)``. ``kind`` is
#: ``"float"``, ``"int"`` (>= 0) or a tuple of the MJCF keywords; ``size`` 0 for a
#: scalar. Units: tolerances dimensionless, ``density`` kg/m^3, ``viscosity`` Pa s,
#: ``wind`` m/s, ``magnetic`` T, ``o_margin`` m, ``o_solref``/``o_solimp``/
#: ``o_friction`` as the geom fields they override.
OPTION_FIELDS: dict[str, tuple[Any, int]] = {
    "impratio": ("float", 0),
    "tolerance": ("float", 0),
    "ls_tolerance": ("float", 0),
    "noslip_tolerance": ("float", 0),
    "ccd_tolerance": ("float", 0),
    "sleep_tolerance": ("float", 0),
    "density": ("float", 0),
    "viscosity": ("float", 0),
    "o_margin": ("float", 0),
    "wind": ("float", 3),
    "magnetic": ("float", 3),
    "o_solref": ("float", 2),
    "o_solimp": ("float", 5),
    "o_friction": ("float", 5),
    "iterations": ("int", 0),
    "ls_iterations": ("int", 0),
    "noslip_iterations": ("int", 0),
    "ccd_iterations": ("int", 0),
    "sdf_iterations": ("int", 0),
    "sdf_initpoints": ("int", 0),
    "cone": (("pyramidal", "elliptic"), 0),
    "jacobian": (("dense", "sparse", "auto"), 0),
    "solver": (("PGS", "CG", "Newton"), 0),
}

_DEFAULT_OPT = mujoco.MjModel.from_xml_string("<mujoco/>").opt


def _flag_names() -> dict[str, tuple[str, int]]:
    """MJCF ``<flag>`` attribute -> (``"disable"`` or ``"enable"`` bit kind, bit), from
    the installed MuJoCo (MuJoCo 3.11 and 4 have different sets)."""
    out: dict[str, tuple[str, int]] = {}
    for enum, kind, prefix in (
        (mujoco.mjtDisableBit, "disable", "mjDSBL_"),
        (mujoco.mjtEnableBit, "enable", "mjENBL_"),
    ):
        for attr in dir(enum):
            if attr.startswith(prefix):
                out[attr[len(prefix) :].lower()] = (kind, int(getattr(enum, attr)))
    return out


#: MJCF ``<flag>`` names of the installed MuJoCo -> (bit kind, bit value). A disable bit
#: set is written ``name: disable``; an enable bit set ``name: enable``.
FLAGS: dict[str, tuple[str, int]] = _flag_names()


def options_from_model(model: mujoco.MjModel) -> tuple[dict[str, Any], dict[str, str], list[str]]:
    """The ``<option>`` attributes and ``<flag>`` switches of a compiled model that differ
    from MuJoCo's defaults, as ``(option, flag, unheld)``; ``unheld`` names option
    fields that differ but HRDF cannot hold."""
    opt = model.opt
    option: dict[str, Any] = {}
    for name, (kind, size) in OPTION_FIELDS.items():
        if not hasattr(opt, name):  # a field of another MuJoCo version
            continue
        value = getattr(opt, name)
        if np.array_equal(np.asarray(value), np.asarray(getattr(_DEFAULT_OPT, name))):
            continue
        if isinstance(kind, tuple):
            option[name] = kind[int(value)]
        elif kind == "int":
            option[name] = int(value)
        elif size:
            option[name] = [float(v) for v in value]
        else:
            option[name] = float(value)
    flag: dict[str, str] = {}
    for name, (kind, bit) in FLAGS.items():
        bits = opt.disableflags if kind == "disable" else opt.enableflags
        if int(bits) & bit:
            flag[name] = kind
    unheld = []
    if getattr(opt, "disableactuator", 0):
        unheld.append("actuatorgroupdisable")
    return option, flag, unheld


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def option_problem(name: str, value: Any) -> str | None:
    """Why ``value`` cannot be ``<option name>`` (``None`` when it can)."""
    if name not in OPTION_FIELDS:
        return f"unknown <option> attribute: expected one of {sorted(OPTION_FIELDS)}"
    kind, size = OPTION_FIELDS[name]
    if isinstance(kind, tuple):
        return None if value in kind else f"{shown(value)}: expected one of {list(kind)}"
    if kind == "int":
        ok = isinstance(value, int) and not isinstance(value, bool) and value >= 0
        return None if ok else f"{shown(value)}: expected an integer >= 0"
    if size:
        ok = isinstance(value, list) and len(value) == size and all(map(_number, value))
        return None if ok else f"{shown(value)}: expected a list of {size} finite numbers"
    return None if _number(value) else f"{shown(value)}: expected a finite number"


def flag_problem(name: str, value: Any) -> str | None:
    """Why ``<flag name=value>`` cannot be written (``None`` when it can)."""
    if name not in FLAGS:
        return f"unknown <flag> of MuJoCo {mujoco.__version__}: expected one of {sorted(FLAGS)}"
    if value not in ("enable", "disable"):
        return f"{shown(value)}: expected 'enable' or 'disable'"
    return None


def nuser_from_model(model: mujoco.MjModel) -> dict[str, int]:
    """The ``<size>`` ``nuser_*`` values of a compiled model that are not zero."""
    from robotwright.hrdf.model import NUSER_KEYS

    return {k: int(getattr(model, k)) for k in NUSER_KEYS if int(getattr(model, k, 0)) > 0}


__all__ = [
    "FLAGS",
    "OPTION_FIELDS",
    "flag_problem",
    "nuser_from_model",
    "option_problem",
    "options_from_model",
]
