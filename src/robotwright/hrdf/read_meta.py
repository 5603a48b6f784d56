"""Reading an HRDF folder's ``meta.yaml`` (untrusted): every key checked against its
expected type and range, each problem naming the key."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from robotwright._inputs import (
    MAX_YAML_BYTES,
    load_yaml,
)
from robotwright._names import shown
from robotwright.errors import (
    Problem,
)
from robotwright.hrdf.layout import BASE_JOINT_FIELDS, EXTENSION_META_KEYS, HURODES_META_KEYS
from robotwright.hrdf.model import (
    GROUND_TYPES,
    INTEGRATORS,
    BodyNameConfig,
    GroundConfig,
    ImuConfig,
    Meta,
    SimulatorConfig,
)
from robotwright.hrdf.read_tables import _folder_read
from robotwright.hrdf.tables import (
    TABLES,
)


def _load_yaml(path: Path, problems: list[Problem]) -> Any:
    return _folder_read(path, lambda p: load_yaml(p, MAX_YAML_BYTES), problems)


def _float_list(value: Any, size: int, key: str, problems: list[Problem]) -> tuple | None:
    if value is None:
        return None
    if (
        not isinstance(value, list)
        or len(value) != size
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    ):
        problems.append(Problem("meta.yaml", f"expected a list of {size} numbers", column=key))
        return None
    return tuple(float(v) for v in value)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _checked(value: Any, ok: bool, key: str, expected: str, problems: list[Problem]) -> Any:
    """``value`` when ``ok`` (or ``None``); else ``None`` after reporting it at ``key``."""
    if value is None or ok:
        return value
    problems.append(Problem("meta.yaml", f"{shown(value)}: expected {expected}", column=key))
    return None


def _number(value: Any, key: str, problems: list[Problem], *, minimum: float = -math.inf) -> Any:
    ok = _is_number(value) and value >= minimum
    low = "" if minimum == -math.inf else f" >= {minimum:g}"
    return _checked(value, ok, key, f"a finite number{low}", problems)


def _bitmask(value: Any, key: str, problems: list[Problem]) -> Any:
    ok = isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 2**31
    return _checked(value, ok, key, "an integer bitmask in [0, 2^31)", problems)


def _text(value: Any, key: str, problems: list[Problem]) -> Any:
    return _checked(value, isinstance(value, str) and value != "", key, "a name", problems)


def _option_and_flag(sim: dict, problems: list[Problem]) -> tuple[dict[str, Any], dict[str, str]]:
    """``simulator_config.option`` and ``.flag``: every name and value checked against
    :mod:`robotwright.hrdf.options` (they are written into MJCF as attributes)."""
    from robotwright.hrdf.options import flag_problem, option_problem

    out: list[dict[str, Any]] = []
    for key, check in (("option", option_problem), ("flag", flag_problem)):
        raw = sim.get(key)
        kept: dict[str, Any] = {}
        if raw is not None and not isinstance(raw, dict):
            problems.append(
                Problem("meta.yaml", "expected a mapping", column=f"simulator_config.{key}")
            )
        for name, value in (raw or {}).items() if isinstance(raw, dict) else ():
            why = check(str(name), value)
            if why is not None:
                problems.append(Problem("meta.yaml", why, column=f"simulator_config.{key}.{name}"))
            else:
                kept[str(name)] = list(value) if isinstance(value, list) else value
        out.append(kept)
    return out[0], out[1]


def _base_joint(raw: Any, problems: list[Problem]) -> dict[str, Any]:
    """``base_joint``: the root free joint's properties, each checked like its
    ``joint.csv`` column (see :data:`BASE_JOINT_FIELDS`)."""
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        problems.append(Problem("meta.yaml", "expected a mapping", column="base_joint"))
        return {}
    columns = {c.csv: c for c in TABLES["joint"] if c.field in BASE_JOINT_FIELDS}
    out: dict[str, Any] = {}
    for name, value in raw.items():
        key = f"base_joint.{name}"
        col = columns.get(name)
        if col is None:
            problems.append(Problem("meta.yaml", f"expected one of {sorted(columns)}", column=key))
            continue
        if col.kind == "floats" or col.size:
            size = len(value) if col.kind == "floats" and isinstance(value, list) else col.size
            got = _float_list(value, size, key, problems)
            if got is not None and not all(map(math.isfinite, got)):
                problems.append(Problem("meta.yaml", "expected finite numbers", column=key))
                got = None
            if got is not None:
                out[col.field] = got
        elif col.kind == "int":
            if value in (0, 1) and not isinstance(value, float):
                out[col.field] = bool(value)
            else:
                problems.append(
                    Problem("meta.yaml", f"{shown(value)}: expected 0 or 1", column=key)
                )
        else:
            got = _number(value, key, problems)
            if got is not None:
                out[col.field] = float(got)
    return out


def _mjcf_size(raw: Any, problems: list[Problem]) -> dict[str, int]:
    """``mjcf_size``: MJCF ``<size>`` ``nuser_*`` values (integers >= 0)."""
    from robotwright.hrdf.model import NUSER_KEYS

    if raw is None:
        return {}
    if not isinstance(raw, dict):
        problems.append(Problem("meta.yaml", "expected a mapping", column="mjcf_size"))
        return {}
    out: dict[str, int] = {}
    for name, value in raw.items():
        key = f"mjcf_size.{name}"
        if name not in NUSER_KEYS:
            problems.append(Problem("meta.yaml", f"expected one of {list(NUSER_KEYS)}", column=key))
        elif isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 2**31:
            out[name] = value
        else:
            problems.append(
                Problem("meta.yaml", f"{shown(value)}: expected an integer >= 0", column=key)
            )
    return out


def _parse_meta(raw: Any, problems: list[Problem]) -> tuple[Meta, list[Any] | None, dict]:
    """Returns (meta, body_parent_id, robotwright keys)."""
    meta = Meta(format_version=None, imu_config_list=None)
    if not isinstance(raw, dict):
        problems.append(Problem("meta.yaml", "expected a mapping of keys"))
        return meta, None, {}
    parent_ids = raw.get("body_parent_id")
    if parent_ids is None:
        problems.append(Problem("meta.yaml", "required key is missing", column="body_parent_id"))
    elif not isinstance(parent_ids, list) or not all(
        isinstance(p, int) and not isinstance(p, bool) for p in parent_ids
    ):
        problems.append(
            Problem("meta.yaml", "expected a list of integers", column="body_parent_id")
        )
        parent_ids = None

    mft = raw.get("mesh_file_type")
    if mft is not None:
        if mft not in ("stl", "obj"):
            problems.append(
                Problem(
                    "meta.yaml",
                    f"expected 'stl' or 'obj', got {shown(mft)}",
                    column="mesh_file_type",
                )
            )
        else:
            meta.mesh_file_type = mft

    sim = raw.get("simulator_config")
    if sim is None:
        meta.simulator_config = None
    elif isinstance(sim, dict):
        ground_raw = sim.get("ground")
        ground = None
        if isinstance(ground_raw, dict):
            key = "simulator_config.ground."
            gtype = ground_raw.get("type")
            ground = GroundConfig(
                type=_checked(
                    gtype, gtype in GROUND_TYPES, key + "type", repr(GROUND_TYPES[0]), problems
                ),
                contact_type=_bitmask(
                    ground_raw.get("contact_type"), key + "contact_type", problems
                ),
                contact_affinity=_bitmask(
                    ground_raw.get("contact_affinity"), key + "contact_affinity", problems
                ),
                friction=_number(ground_raw.get("friction"), key + "friction", problems, minimum=0),
            )
        elif ground_raw is not None:
            problems.append(
                Problem("meta.yaml", "expected a mapping", column="simulator_config.ground")
            )
        integrator = sim.get("integrator")
        option, flag = _option_and_flag(sim, problems)
        meta.simulator_config = SimulatorConfig(
            timestep=_number(sim.get("timestep"), "simulator_config.timestep", problems),
            gravity=_float_list(sim.get("gravity"), 3, "simulator_config.gravity", problems),
            ground=ground,
            integrator=_checked(
                integrator,
                integrator in INTEGRATORS,
                "simulator_config.integrator",
                f"one of {list(INTEGRATORS)}",
                problems,
            ),
            option=option,
            flag=flag,
        )
        for key in sim:
            if key not in ("timestep", "gravity", "ground", "integrator", "option", "flag"):
                problems.append(
                    Problem(
                        "meta.yaml",
                        "unknown key, ignored",
                        column=f"simulator_config.{key}",
                        severity="warning",
                    )
                )
    else:
        problems.append(Problem("meta.yaml", "expected a mapping", column="simulator_config"))

    bnc = raw.get("body_name_config")
    if bnc is None:
        meta.body_name_config = None
    elif isinstance(bnc, dict):
        meta.body_name_config = BodyNameConfig(
            torso_name=bnc.get("torso_name"),
            hip_names=bnc.get("hip_names"),
            knee_names=bnc.get("knee_names"),
            foot_names=bnc.get("foot_names"),
        )
    else:
        problems.append(Problem("meta.yaml", "expected a mapping", column="body_name_config"))

    imus = raw.get("imu_config_list")
    if imus is not None:
        if not isinstance(imus, list):
            problems.append(Problem("meta.yaml", "expected a list", column="imu_config_list"))
        else:
            meta.imu_config_list = []
            for i, imu in enumerate(imus):
                key = f"imu_config_list[{i}]"
                if not isinstance(imu, dict) or not isinstance(imu.get("body_name"), str):
                    problems.append(
                        Problem("meta.yaml", "expected a mapping with body_name", column=key)
                    )
                    continue
                pos = _float_list(
                    imu.get("position", [0.0, 0.0, 0.0]), 3, key + ".position", problems
                )
                ori = _float_list(
                    imu.get("orientation", [1.0, 0.0, 0.0, 0.0]), 4, key + ".orientation", problems
                )
                value = imu.get("value") or []
                if not isinstance(value, list):
                    problems.append(
                        Problem(
                            "meta.yaml",
                            f"{shown(value)}: expected a list of linacc, angvel, quat",
                            column=key + ".value",
                        )
                    )
                    value = []
                bad = [v for v in value if v not in ("linacc", "angvel", "quat")]
                if bad:
                    problems.append(
                        Problem(
                            "meta.yaml",
                            f"unknown IMU values {bad}: expected linacc, angvel, quat",
                            column=key + ".value",
                        )
                    )
                meta.imu_config_list.append(
                    ImuConfig(
                        body_name=imu["body_name"],
                        position=pos or (0.0, 0.0, 0.0),
                        orientation=ori or (1.0, 0.0, 0.0, 0.0),
                        value=list(value),
                        device_type=imu.get("device_type"),
                        device_config_name=imu.get("device_config_name"),
                    )
                )
    meta.motor_config_list = raw.get("motor_config_list")
    meta.format_version = raw.get("format_version")
    ext = {k: raw[k] for k in ("floating_base", "base_joint_name") if k in raw}
    if "base_joint_name" in ext:
        ext["base_joint_name"] = _text(ext["base_joint_name"], "base_joint_name", problems)
    ext["base_joint"] = _base_joint(raw.get("base_joint"), problems)
    meta.mjcf_size = _mjcf_size(raw.get("mjcf_size"), problems)
    meta.extra = {k: v for k, v in raw.items() if k not in HURODES_META_KEYS + EXTENSION_META_KEYS}
    for key in meta.extra:
        problems.append(
            Problem("meta.yaml", "unknown key, kept verbatim", column=key, severity="warning")
        )
    return meta, parent_ids, ext
