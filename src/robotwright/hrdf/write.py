"""Writing an HRDF folder: the tables as CSV (a column only where a row needs it), the
meta as YAML, ``extra.xml`` and the joint mapping, all at once."""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

import yaml

from robotwright._atomic import atomic_dir, copy_mesh_file
from robotwright._progress import steps
from robotwright.errors import (
    HRDFError,
    OutputExistsError,
    Problem,
)
from robotwright.hrdf.layout import BASE_JOINT_FIELDS, EXTRA_MJCF_FILE, JOINT_MAPPING_FILE
from robotwright.hrdf.model import (
    FORMAT_VERSION,
    HRDF,
)
from robotwright.hrdf.tables import (
    NO_DEFAULT,
    TABLES,
    Column,
    format_cell,
)


def table_rows(hrdf: HRDF, stem: str) -> list[Any]:
    """The records of table ``stem`` in CSV row order (``joint``: the root's free joint
    is in ``meta.yaml``, not a row; another root's, in a scene, is a row)."""
    if stem == "body":
        return list(hrdf.bodies)
    if stem == "joint":
        base = hrdf.base_joint
        return [j for j in hrdf.joints if j is not base]
    return list(
        {
            "actuator": hrdf.actuators,
            "mesh": hrdf.meshes,
            "simple_geom": hrdf.simple_geoms,
            "site": hrdf.sites,
            "sensor": hrdf.sensors,
        }[stem]
    )


def _column_needed(col: Column, rows: list[Any]) -> bool:
    """hurodes columns always; extension columns only when some row differs from default."""
    if col.required:
        return True
    return any(getattr(r, col.field) != col.default for r in rows)


def table_csv(hrdf: HRDF, stem: str) -> str | None:
    """The CSV text of one table, or ``None`` when the table has no rows."""
    rows = table_rows(hrdf, stem)
    if not rows:
        return None
    schema = TABLES[stem]
    cols = [c for c in schema if _column_needed(c, rows)]
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow([h for c in cols for h in c.headers])
    for i, rec in enumerate(rows):
        line: list[str] = []
        for c in cols:
            value = i if c.field == "id" else getattr(rec, c.field)
            if c.size == 0:
                line.append(format_cell(value))
            elif value is None:
                line.extend([""] * c.size)
            else:
                line.extend(format_cell(float(v) if c.kind == "float" else v) for v in value)
        writer.writerow(line)
    return out.getvalue()


def _yaml_value(value: Any) -> Any:
    """A plain YAML value: tuples and numpy numbers become lists and Python numbers."""
    if isinstance(value, (tuple, list)):
        return [_yaml_value(v) for v in value]
    if isinstance(value, bool):
        return int(value)
    if hasattr(value, "item"):
        return value.item()
    return value


def meta_dict(hrdf: HRDF) -> dict[str, Any]:
    """The ``meta.yaml`` mapping (hurodes keys, then robotwright's)."""
    meta = hrdf.meta
    sim = meta.simulator_config
    out: dict[str, Any] = {
        "body_parent_id": hrdf.body_parent_id,
        "mesh_file_type": meta.mesh_file_type,
        "simulator_config": None,
        "body_name_config": None,
        "imu_config_list": None,
        "motor_config_list": meta.motor_config_list,
    }
    if sim is not None:
        sim_d: dict[str, Any] = {
            "timestep": sim.timestep,
            "gravity": list(sim.gravity) if sim.gravity is not None else None,
            "ground": None,
        }
        if sim.ground is not None:
            sim_d["ground"] = {
                "type": sim.ground.type,
                "contact_type": sim.ground.contact_type,
                "contact_affinity": sim.ground.contact_affinity,
                "friction": sim.ground.friction,
            }
        if sim.integrator is not None:
            sim_d["integrator"] = sim.integrator
        if sim.option:
            sim_d["option"] = {k: _yaml_value(v) for k, v in sim.option.items()}
        if sim.flag:
            sim_d["flag"] = dict(sim.flag)
        out["simulator_config"] = sim_d
    if meta.body_name_config is not None:
        b = meta.body_name_config
        out["body_name_config"] = {
            "torso_name": b.torso_name,
            "hip_names": b.hip_names,
            "knee_names": b.knee_names,
            "foot_names": b.foot_names,
        }
    if meta.imu_config_list is not None:
        out["imu_config_list"] = [
            {
                "body_name": imu.body_name,
                "device_config_name": imu.device_config_name,
                "device_type": imu.device_type,
                "orientation": list(imu.orientation),
                "position": list(imu.position),
                "value": list(imu.value),
            }
            for imu in meta.imu_config_list
        ]
    out["format_version"] = FORMAT_VERSION
    out["floating_base"] = hrdf.floating_base
    free = [hrdf.base_joint] if hrdf.base_joint is not None else []
    if free and free[0].name is not None:
        out["base_joint_name"] = free[0].name
    if free:
        base = {
            c.csv: _yaml_value(getattr(free[0], c.field))
            for c in TABLES["joint"]
            if c.field in BASE_JOINT_FIELDS
            and getattr(free[0], c.field) != (0.0 if c.default is NO_DEFAULT else c.default)
        }
        if base:
            out["base_joint"] = base
    if meta.mjcf_size:
        out["mjcf_size"] = dict(meta.mjcf_size)
    out.update(meta.extra)
    return out


def _with_folder_mesh_paths(hrdf: HRDF, sources: list[Path]) -> HRDF:
    """A view of ``hrdf`` whose mesh paths all lie inside the folder being written.

    A relative path without ``..`` is kept (the default ``meshes/<name>.<type>`` stays
    implicit). Any other (the absolute path of a robot built in memory, a path into a
    trusted folder outside the robot) becomes ``meshes/<file name>``, numbered when two
    different files would share a name.
    """
    from dataclasses import replace

    ext = hrdf.meta.mesh_file_type
    rels = [m.file if m.file is not None else f"meshes/{m.name}.{ext}" for m in hrdf.meshes]
    inside = [not Path(r).is_absolute() and ".." not in Path(r).parts for r in rels]
    taken = {r: src for r, src, ok in zip(rels, sources, inside, strict=True) if ok}
    meshes = []
    for mesh, rel, src, ok in zip(hrdf.meshes, rels, sources, inside, strict=True):
        if not ok:
            name = Path(rel)
            rel, k = f"meshes/{name.name}", 1
            while taken.setdefault(rel, src) != src:
                rel, k = f"meshes/{name.stem}_{k}{name.suffix}", k + 1
        file = None if rel == f"meshes/{mesh.name}.{ext}" else rel
        meshes.append(replace(mesh, file=file))
    return replace(hrdf, meshes=meshes)


def write_hrdf_dir(hrdf: HRDF, path: str | Path, *, overwrite: bool = False) -> Path:
    """Write ``hrdf`` as a folder at ``path``; validate first, write atomically.

    Mesh files are copied into ``meshes/`` (or to their ``file`` path inside the folder).

    Raises:
        HRDFError: the model is invalid (nothing is written).
        FileExistsError: ``path`` exists and ``overwrite`` is false.
    """
    from robotwright.hrdf.validate import check_model

    problems = [p for p in check_model(hrdf, check_files=True) if p.severity == "error"]
    if problems:
        raise HRDFError(problems, summary=f"cannot save robot '{hrdf.name}'")
    target = Path(path)
    # The copier checks again: every source inside the robot folder or a trusted one.
    sources = [hrdf.mesh_source(m) for m in hrdf.meshes]
    hrdf = _with_folder_mesh_paths(hrdf, sources)

    def fill(tmp: Path) -> None:
        meta_text = yaml.safe_dump(meta_dict(hrdf), default_flow_style=False, allow_unicode=True)
        (tmp / "meta.yaml").write_text(meta_text, encoding="utf-8")
        for stem in TABLES:
            text = table_csv(hrdf, stem)
            if text is not None:
                (tmp / f"{stem}.csv").write_text(text, encoding="utf-8")
        copied: set[str] = set()
        pairs = zip(hrdf.meshes, sources, strict=True)
        for mesh, source in steps(pairs, len(sources), "meshes copied"):
            rel = (
                mesh.file
                if mesh.file is not None
                else f"meshes/{mesh.name}.{hrdf.meta.mesh_file_type}"
            )
            if rel in copied:
                continue
            copied.add(rel)
            dest = tmp / rel
            if not dest.resolve().is_relative_to(tmp.resolve()):
                raise HRDFError(
                    [Problem("mesh.csv", f"mesh path '{rel}' would be written outside {path}")],
                    summary=f"cannot save robot '{hrdf.name}'",
                )
            dest.parent.mkdir(parents=True, exist_ok=True)
            copy_mesh_file(source, dest)  # regular files only, size-capped
        if hrdf.meta.joint_mapping is not None:
            (tmp / JOINT_MAPPING_FILE).write_text(
                yaml.safe_dump(
                    hrdf.meta.joint_mapping, default_flow_style=False, allow_unicode=True
                ),
                encoding="utf-8",
            )
        if hrdf.mjcf_extra:
            (tmp / EXTRA_MJCF_FILE).write_text(hrdf.mjcf_extra, encoding="utf-8")

    if target.exists() and not overwrite:
        raise OutputExistsError(
            f"{target} exists (replace it with overwrite=True, on the command line --overwrite)"
        )
    with atomic_dir(target, kind="hrdf") as tmp:  # replaces only an HRDF output
        fill(tmp)
    return target
