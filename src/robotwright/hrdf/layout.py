"""An HRDF folder's layout: the files it may hold, the keys of ``meta.yaml`` (hurodes'
and this project's extensions) and the warning its reader gives."""

from __future__ import annotations

from robotwright.hrdf.model import (
    Actuator,
    Body,
    Joint,
    MeshGeom,
    Sensor,
    SimpleGeom,
    Site,
)
from robotwright.hrdf.tables import (
    TABLES,
)

_RECORD_TYPES: dict[str, type] = {
    "body": Body,
    "joint": Joint,
    "actuator": Actuator,
    "mesh": MeshGeom,
    "simple_geom": SimpleGeom,
    "site": Site,
    "sensor": Sensor,
}

#: meta.yaml keys hurodes defines.
HURODES_META_KEYS: tuple[str, ...] = (
    "body_parent_id",
    "mesh_file_type",
    "simulator_config",
    "body_name_config",
    "imu_config_list",
    "motor_config_list",
)

#: meta.yaml keys robotwright adds.
EXTENSION_META_KEYS: tuple[str, ...] = (
    "format_version",
    "floating_base",
    "base_joint_name",
    "base_joint",
    "mjcf_size",
)

#: ``joint.csv`` columns that the root's free joint keeps in ``meta.yaml``'s
#: ``base_joint`` mapping (its dof and constraint properties; a free joint has no
#: anchor, axis, range or spring reference of its own).
BASE_JOINT_FIELDS: tuple[str, ...] = (
    "armature",
    "static_friction",
    "dynamic_friction",
    "viscous_friction",
    "stiffness",
    "margin",
    "actuatorgravcomp",
    "solreflimit",
    "solimplimit",
    "solreffriction",
    "solimpfriction",
    "user",
)

EXTRA_MJCF_FILE = "extra.xml"

JOINT_MAPPING_FILE = "joint_mapping.yaml"

#: Where hurodes' generators export a robot by default (``<folder>/exported/robot.xml``):
#: its own output, not robot data, so it is ignored without a warning.
HURODES_EXPORT_DIR = "exported"

_KNOWN_FILES = frozenset(
    {f"{stem}.csv" for stem in TABLES}
    | {"meta.yaml", "meshes", EXTRA_MJCF_FILE, JOINT_MAPPING_FILE, HURODES_EXPORT_DIR}
)


class HRDFWarning(UserWarning):
    """Something in an HRDF folder was not understood and is ignored (named in the message)."""
