"""Reading and writing HRDF folders (hurodes 0.1.9 folders and robotwright's extension).

Reading collects every problem of every file before raising one
:class:`~robotwright.errors.HRDFError`; writing goes to a temporary folder that is
renamed into place, so a failed save leaves nothing behind.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable
from pathlib import Path

from robotwright._inputs import (
    MAX_XML_BYTES,
)
from robotwright._names import shown
from robotwright._paths import trusted_roots
from robotwright.errors import (
    HRDFError,
    Problem,
)
from robotwright.hrdf.layout import (  # noqa: F401
    _KNOWN_FILES,
    _RECORD_TYPES,
    BASE_JOINT_FIELDS,
    EXTRA_MJCF_FILE,
    HURODES_EXPORT_DIR,
    JOINT_MAPPING_FILE,
    HRDFWarning,
)
from robotwright.hrdf.model import (
    FORMAT_VERSION,
    HRDF,
    Body,
    Joint,
)
from robotwright.hrdf.read_meta import _load_yaml, _parse_meta
from robotwright.hrdf.read_tables import _folder_text, _read_table, _records, _Table
from robotwright.hrdf.tables import (
    HURODES_TABLES,
    TABLES,
)
from robotwright.hrdf.write import meta_dict, table_csv, table_rows, write_hrdf_dir  # noqa: F401


def collect_hrdf_dir(
    path: str | Path, *, asset_roots: Iterable[str | os.PathLike[str]] | None = None
) -> tuple[HRDF | None, list[Problem]]:
    """Read an HRDF folder, returning the model (``None`` if unreadable) and all problems.

    The model is returned even when some rows had problems (those rows are left out), so
    that semantic checks can still run; callers raise when any problem is an error.
    ``asset_roots``: folders outside the robot folder that mesh paths may point into.
    """
    from robotwright.hrdf.validate import check_model

    root = Path(path)
    problems: list[Problem] = []
    try:
        # One listing answers every "is this file there" question below.
        present = {e.name for e in os.scandir(root)}
    except (FileNotFoundError, NotADirectoryError):
        return None, [Problem(str(root), "not a folder: expected an HRDF folder")]
    meta_path = root / "meta.yaml"
    if "meta.yaml" not in present:
        return None, [Problem(str(meta_path), "meta.yaml is missing")]
    raw_meta = _load_yaml(meta_path, problems)
    if problems:  # not a readable YAML file (a folder, a FIFO, a link out, ...)
        return None, problems
    meta, parent_ids, ext = _parse_meta(raw_meta, problems)
    hurodes_format = meta.format_version is None
    if meta.format_version is not None and meta.format_version != FORMAT_VERSION:
        problems.append(
            Problem(
                "meta.yaml",
                f"unsupported format_version {shown(meta.format_version)}: expected {shown(FORMAT_VERSION)}",
                column="format_version",
            )
        )

    tables: dict[str, _Table | None] = {}
    for stem, schema in TABLES.items():
        if f"{stem}.csv" not in present:
            if stem == "body":
                problems.append(Problem("body.csv", "required file is missing"))
            tables[stem] = None
            continue
        csv_path = root / f"{stem}.csv"
        if stem not in HURODES_TABLES and hurodes_format:
            problems.append(
                Problem(
                    csv_path.name,
                    "robotwright table in a folder without format_version; read anyway",
                    severity="warning",
                )
            )
        tables[stem] = _read_table(csv_path, schema, problems, hurodes_format=hurodes_format)

    for child_name in sorted(present - _KNOWN_FILES):
        if not child_name.startswith("."):
            problems.append(Problem(child_name, "unknown file, ignored", severity="warning"))

    if tables.get("body") is None:
        return None, problems

    records: dict[str, list] = {}
    for stem, table in tables.items():
        if stem != "body":
            records[stem] = (
                [] if table is None else _records(_RECORD_TYPES[stem], table.fields, table.rows)
            )

    # Body ids must match row order: hurodes silently uses row order, we refuse to guess.
    body_table = tables["body"]
    id_at = body_table.fields.index("id")
    for i, row in enumerate(body_table.rows):
        if row is not None and row[id_at] != i:
            problems.append(
                Problem(
                    "body.csv",
                    f"id {row[id_at]} does not match the row position {i}: rows must be in id order",
                    row=i,
                    column="id",
                )
            )
    n_bodies = len(body_table.rows)
    if parent_ids is not None and len(parent_ids) != n_bodies:
        problems.append(
            Problem(
                "meta.yaml",
                f"body_parent_id has {len(parent_ids)} entries, body.csv has {n_bodies} rows",
                column="body_parent_id",
            )
        )
        parent_ids = None
    # "id" was checked above; the "parent" field comes from meta.yaml (-1 when unusable).
    body_fields = ["parent" if f == "id" else f for f in body_table.fields]
    parents = parent_ids if parent_ids is not None else [-1] * n_bodies
    bodies: list[Body] = _records(
        Body,
        body_fields,
        [
            None if row is None else (*row[:id_at], parent, *row[id_at + 1 :])
            for row, parent in zip(body_table.rows, parents, strict=True)
        ],
    )

    joints: list[Joint] = [j for j in records["joint"] if j is not None]
    floating = ext.get("floating_base", True if hurodes_format else None)
    if floating is None:
        floating = False
    if not isinstance(floating, bool):
        problems.append(Problem("meta.yaml", "expected true or false", column="floating_base"))
        floating = False
    root_name = None
    roots = [b for b in bodies if b is not None and b.parent == -1]
    if roots:  # a scene's first root is the one meta.yaml's floating_base is of
        root_name = roots[0].name
    if floating and root_name is not None:
        joints.insert(
            0,
            Joint(
                name=ext.get("base_joint_name"),
                body=root_name,
                type="free",
                **ext.get("base_joint", {}),
            ),
        )
    elif ext.get("base_joint"):
        problems.append(
            Problem("meta.yaml", "base_joint given but the base is fixed", column="base_joint")
        )

    joint_mapping = None
    if JOINT_MAPPING_FILE in present:
        joint_mapping = _load_yaml(root / JOINT_MAPPING_FILE, problems)
    meta.joint_mapping = joint_mapping
    mjcf_extra = None
    if EXTRA_MJCF_FILE in present:
        mjcf_extra = _folder_text(root / EXTRA_MJCF_FILE, MAX_XML_BYTES, problems)

    resolved = root.resolve()
    hrdf = HRDF(
        name=resolved.name,
        bodies=[b for b in bodies if b is not None]
        if all(b is not None for b in bodies)
        else bodies,  # type: ignore[misc]
        joints=joints,
        actuators=[a for a in records["actuator"] if a is not None],
        meshes=[m for m in records["mesh"] if m is not None],
        simple_geoms=[g for g in records["simple_geom"] if g is not None],
        sites=[s for s in records["site"] if s is not None],
        sensors=[s for s in records["sensor"] if s is not None],
        meta=meta,
        mjcf_extra=mjcf_extra,
        root_dir=resolved,
        asset_roots=trusted_roots(asset_roots),
    )
    if any(b is None for b in hrdf.bodies):
        return None, problems
    # Every cell was checked finite as it was read.
    problems.extend(check_model(hrdf, check_files=True, finite=False))
    return hrdf, problems


def read_hrdf_dir(
    path: str | Path, *, asset_roots: Iterable[str | os.PathLike[str]] | None = None
) -> HRDF:
    """Load an HRDF folder; raise :class:`HRDFError` listing all errors, warn for the rest.

    ``asset_roots``: folders outside the robot folder that mesh paths may point into.
    """
    hrdf, problems = collect_hrdf_dir(path, asset_roots=asset_roots)
    errors = [p for p in problems if p.severity == "error"]
    if errors or hrdf is None:
        raise HRDFError(errors or problems, summary=f"invalid HRDF folder {path}")
    for p in problems:
        warnings.warn(f"{Path(path).name}/{p}", HRDFWarning, stacklevel=3)
    return hrdf
