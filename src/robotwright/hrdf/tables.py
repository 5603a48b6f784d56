"""Column schemas of the HRDF CSV tables and the cell <-> value conversions.

A schema maps a record field to one or more CSV columns (vectors are flattened:
``pos0..2``). hurodes' columns are ``required`` in the header; robotwright's extension
columns are optional and have a documented default used when the column is absent.

Floats are written with ``repr`` (shortest round-trip form), so a value read is written
back identically and nothing accumulates float noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from robotwright.hrdf.model import (
    MUJOCO_ROLLING_FRICTION,
    MUJOCO_SOLIMP,
    MUJOCO_SOLREF,
    MUJOCO_TORSIONAL_FRICTION,
)

#: Marks a field with no default: an empty cell is an error.
NO_DEFAULT = object()


@dataclass(frozen=True)
class Column:
    """One record field stored in ``size`` CSV columns.

    Attributes:
        field: the dataclass field name.
        kind: ``float``, ``int``, ``str`` (type of each cell) or ``floats`` (one cell
            holding any number of space-separated numbers, e.g. MuJoCo ``user`` data).
        size: 0 for a scalar column named ``csv``; n for ``csv0..csv{n-1}``.
        csv: the CSV column name (or prefix for vectors).
        required: the column must be present in the header (hurodes' columns).
        default: value when the column is absent or (if ``empty_ok``) the cell is empty.
        empty_ok: an empty cell means ``default`` (else it is an error).
    """

    field: str
    kind: str
    csv: str
    size: int = 0
    required: bool = True
    default: Any = NO_DEFAULT
    empty_ok: bool = False

    headers: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        # Computed once: the reader consults it for every cell.
        names = (self.csv,) if self.size == 0 else tuple(f"{self.csv}{i}" for i in range(self.size))
        object.__setattr__(self, "headers", names)


def _geom_common() -> list[Column]:
    return [
        Column("contact_type", "int", "contact_type"),
        Column("contact_affinity", "int", "contact_affinity"),
        Column("static_friction", "float", "static_friction"),
        Column("dynamic_friction", "float", "dynamic_friction"),
        Column("restitution", "float", "restitution", default=None, empty_ok=True),
    ]


def _geom_ext() -> list[Column]:
    return [
        Column(
            "torsional_friction",
            "float",
            "torsional_friction",
            required=False,
            default=MUJOCO_TORSIONAL_FRICTION,
        ),
        Column(
            "rolling_friction",
            "float",
            "rolling_friction",
            required=False,
            default=MUJOCO_ROLLING_FRICTION,
        ),
        Column("group", "int", "group", required=False, default=0),
        Column("condim", "int", "condim", required=False, default=3),
        Column("geom_name", "str", "geom_name", required=False, default=None, empty_ok=True),
        Column("solref", "float", "solref", 2, required=False, default=MUJOCO_SOLREF),
        Column("solimp", "float", "solimp", 5, required=False, default=MUJOCO_SOLIMP),
        Column("margin", "float", "margin", required=False, default=0.0),
        Column("gap", "float", "gap", required=False, default=0.0),
        Column("priority", "int", "priority", required=False, default=0),
        Column("solmix", "float", "solmix", required=False, default=1.0),
        _user(),
        # Position among its body's geoms (both tables), written only where a body
        # interleaves mesh and primitive geoms (contact order follows geom order).
        Column("order", "int", "order", required=False, default=None, empty_ok=True),
    ]


def _user() -> Column:
    """MuJoCo ``user`` data: one cell of space-separated numbers, empty = none."""
    return Column("user", "floats", "user", required=False, default=(), empty_ok=True)


BODY_COLUMNS: list[Column] = [
    Column("diag_inertia", "float", "diag_inertia", 3),
    Column("mass", "float", "mass"),
    Column("inertial_pos", "float", "inertial_pos", 3),
    Column("inertial_quat", "float", "inertial_quat", 4),
    Column("pos", "float", "pos", 3),
    Column("quat", "float", "quat", 4),
    Column("name", "str", "name"),
    Column("id", "int", "id"),
    Column("gravcomp", "float", "gravcomp", required=False, default=0.0),
    _user(),
]

JOINT_COLUMNS: list[Column] = [
    Column("armature", "float", "armature"),
    Column("static_friction", "float", "static_friction"),
    Column("dynamic_friction", "float", "dynamic_friction"),
    Column("viscous_friction", "float", "viscous_friction"),
    Column("pos", "float", "pos", 3),
    Column("axis", "float", "axis", 3),
    Column("name", "str", "name"),
    Column("body", "str", "body_name"),
    # Empty range cells mean "unlimited" in robotwright folders; in hurodes folders they
    # are an error (hurodes would invent +-3.14). io.py enforces the difference.
    Column("range", "float", "range", 2, default=None, empty_ok=True),
    Column("type", "str", "type", required=False, default="hinge"),
    Column("stiffness", "float", "stiffness", required=False, default=0.0),
    Column("springref", "float", "springref", required=False, default=0.0),
    Column("ref", "float", "ref", required=False, default=0.0),
    Column("margin", "float", "margin", required=False, default=0.0),
    Column(
        "actuatorfrcrange",
        "float",
        "actuatorfrcrange",
        2,
        required=False,
        default=None,
        empty_ok=True,
    ),
    Column("actuatorgravcomp", "int", "actuatorgravcomp", required=False, default=False),
    Column("solreflimit", "float", "solreflimit", 2, required=False, default=MUJOCO_SOLREF),
    Column("solimplimit", "float", "solimplimit", 5, required=False, default=MUJOCO_SOLIMP),
    Column("solreffriction", "float", "solreffriction", 2, required=False, default=MUJOCO_SOLREF),
    Column("solimpfriction", "float", "solimpfriction", 5, required=False, default=MUJOCO_SOLIMP),
    _user(),
]

ACTUATOR_COLUMNS: list[Column] = [
    Column("peak_torque", "float", "peak_torque", default=None, empty_ok=True),
    Column("peak_velocity", "float", "peak_velocity", default=None, empty_ok=True),
    Column("d_gain", "float", "d_gain", default=None, empty_ok=True),
    Column("p_gain", "float", "p_gain", default=None, empty_ok=True),
    Column("joint", "str", "joint_name"),
    Column("name", "str", "name", required=False, default=None, empty_ok=True),
    Column("type", "str", "type", required=False, default="motor"),
    Column("gear", "float", "gear", required=False, default=1.0),
    Column("ctrl_range", "float", "ctrl_range", 2, required=False, default=None, empty_ok=True),
    Column("force_range", "float", "force_range", 2, required=False, default=None, empty_ok=True),
    _user(),
]

MESH_COLUMNS: list[Column] = [
    *_geom_common(),
    Column("pos", "float", "pos", 3),
    Column("quat", "float", "quat", 4),
    Column("rgba", "float", "rgba", 4),
    Column("body", "str", "body_name"),
    Column("name", "str", "name"),
    *_geom_ext(),
    Column("file", "str", "file", required=False, default=None, empty_ok=True),
    Column("scale", "float", "scale", 3, required=False, default=(1.0, 1.0, 1.0)),
    Column("inertia", "str", "inertia", required=False, default=None, empty_ok=True),
]

SIMPLE_GEOM_COLUMNS: list[Column] = [
    *_geom_common(),
    Column("type", "str", "type"),
    Column("size", "float", "size", 3),
    Column("pos", "float", "pos", 3),
    Column("quat", "float", "quat", 4),
    Column("rgba", "float", "rgba", 4),
    Column("body", "str", "body_name"),
    Column("name", "str", "name"),
    *_geom_ext(),
]

SITE_COLUMNS: list[Column] = [
    Column("name", "str", "name"),
    Column("body", "str", "body_name"),
    Column("pos", "float", "pos", 3),
    Column("quat", "float", "quat", 4),
    Column("type", "str", "type", required=False, default="sphere"),
    Column("size", "float", "size", 3, required=False, default=(0.005, 0.0, 0.0)),
    Column("rgba", "float", "rgba", 4, required=False, default=(0.5, 0.5, 0.5, 1.0)),
    Column("group", "int", "group", required=False, default=0),
    _user(),
]

SENSOR_COLUMNS: list[Column] = [
    Column("name", "str", "name"),
    Column("type", "str", "type"),
    Column("objtype", "str", "objtype"),
    Column("objname", "str", "objname"),
    Column("reftype", "str", "reftype", required=False, default=None, empty_ok=True),
    Column("refname", "str", "refname", required=False, default=None, empty_ok=True),
    Column("noise", "float", "noise", required=False, default=0.0),
    Column("cutoff", "float", "cutoff", required=False, default=0.0),
    _user(),
]

#: table file stem -> schema, in the order tables are read and written.
TABLES: dict[str, list[Column]] = {
    "body": BODY_COLUMNS,
    "joint": JOINT_COLUMNS,
    "actuator": ACTUATOR_COLUMNS,
    "mesh": MESH_COLUMNS,
    "simple_geom": SIMPLE_GEOM_COLUMNS,
    "site": SITE_COLUMNS,
    "sensor": SENSOR_COLUMNS,
}

#: Tables hurodes reads; the others are robotwright extensions.
HURODES_TABLES: tuple[str, ...] = ("body", "joint", "actuator", "mesh", "simple_geom")


class CellError(ValueError):
    """A cell could not be converted; the message says what was expected."""


def parse_cell(text: str, kind: str) -> Any:
    """Convert one CSV cell (already known non-empty) to ``kind``."""
    if kind == "str":
        return text
    if kind == "floats":
        return tuple(parse_cell(part, "float") for part in text.split())
    if kind == "int":
        try:
            value = float(text)
        except ValueError:
            raise CellError(f"expected an integer, got '{text}'") from None
        if not value.is_integer():
            raise CellError(f"expected an integer, got '{text}'")
        return int(value)
    try:
        value = float(text)
    except ValueError:
        raise CellError(f"expected a number, got '{text}'") from None
    if not math.isfinite(value):
        raise CellError(f"expected a finite number, got '{text}'")
    return value


def format_cell(value: Any) -> str:
    """Format one value for a CSV cell (``None`` -> empty, floats by ``repr``)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (tuple, list)):  # a ``floats`` cell
        return " ".join(repr(float(v)) for v in value)
    return str(value)
