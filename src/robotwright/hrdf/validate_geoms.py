"""The HRDF checks of geoms, meshes (each file inside the folder and within the size
limit), sites and sensors."""

from __future__ import annotations

import math
import os
from pathlib import Path

from robotwright._assets import check_asset_file, mesh_limit_bytes
from robotwright._names import shown
from robotwright.errors import InputFileError, Problem, UnsafePathError
from robotwright.hrdf import validate_common
from robotwright.hrdf.model import (
    FRAME_OBJTYPES,
    HRDF,
    MESH_INERTIA_MODES,
    SENSOR_OBJTYPES,
    SIMPLE_GEOM_TYPES,
    SITE_TYPES,
    WORLD,
    MeshGeom,
)
from robotwright.hrdf.validate_common import (
    _SIZE_USED,
    QUAT_NORM_TOL,
    _duplicates,
    _quat_problem,
)

#: Smallest and largest size of a mesh scale factor; a factor's sign is free (negative
#: mirrors the mesh on that axis, as in MuJoCo, which hulls and weighs it mirrored).
MESH_SCALE = (1e-6, 1e6)


def _mesh_file(hrdf: HRDF, mesh: MeshGeom) -> str:
    # Plain strings: this runs for every mesh row on every load.
    if mesh.file is None and hrdf.root_dir is not None:
        return f"{hrdf.root_dir}{os.sep}meshes{os.sep}{mesh.name}.{hrdf.meta.mesh_file_type}"
    return str(hrdf.mesh_path(mesh))


def _listing(folder: str, listings: dict[str, dict[str, int]], sizes: bool) -> dict[str, int]:
    """The regular files in ``folder`` that are not symbolic links, by name, listed once
    per check (meshes share a folder), with their size [bytes] when ``sizes`` (else 0):
    the size cap is checked from it, with no other call per mesh."""
    found = listings.get(folder)
    if found is None:
        found = {}
        try:
            with os.scandir(folder) as entries:
                for e in entries:
                    if e.is_file(follow_symlinks=False):
                        found[e.name] = e.stat(follow_symlinks=False).st_size if sizes else 0
        except OSError:
            found = {}
        listings[folder] = found
    return found


def _check_geoms(hrdf: HRDF, body_names: set[str], check_files: bool) -> list[Problem]:
    out: list[Problem] = []
    listings: dict[str, dict[str, int]] = {}
    limit = mesh_limit_bytes()
    hypot = math.hypot
    for table, rows in (("mesh.csv", hrdf.meshes), ("simple_geom.csv", hrdf.simple_geoms)):
        for i, g in enumerate(rows):
            # Quick pass: exactly the negation of every check below (see _check_bodies).
            if (
                validate_common.QUICK_PASS
                and g.body in body_names
                and not abs(hypot(*g.quat) - 1.0) > QUAT_NORM_TOL
                and min(g.rgba) >= 0.0
                and max(g.rgba) <= 1.0
                and g.condim in (1, 3, 4, 6)
                and not g.static_friction < 0
            ):
                continue
            if g.body not in body_names:
                out.append(Problem(table, f"unknown body '{g.body}'", row=i, column="body_name"))
            msg = _quat_problem(g.quat)
            if msg:
                out.append(Problem(table, msg, row=i, column="quat"))
            if not (min(g.rgba) >= 0.0 and max(g.rgba) <= 1.0):
                out.append(
                    Problem(
                        table, f"rgba {g.rgba}: expected values in [0, 1]", row=i, column="rgba"
                    )
                )
            if g.condim not in (1, 3, 4, 6):
                out.append(
                    Problem(
                        table, f"condim {g.condim}: expected 1, 3, 4 or 6", row=i, column="condim"
                    )
                )
            if g.static_friction < 0:
                out.append(
                    Problem(
                        table, "static_friction: expected >= 0", row=i, column="static_friction"
                    )
                )
    for i, g in enumerate(hrdf.simple_geoms):
        if g.type not in SIMPLE_GEOM_TYPES:
            out.append(
                Problem(
                    "simple_geom.csv",
                    f"geom type '{g.type}': expected one of {list(SIMPLE_GEOM_TYPES)}",
                    row=i,
                    column="type",
                )
            )
            continue
        out += _size_problems("simple_geom.csv", g.type, g.size, i)
    for name in sorted(_duplicates(g.name for g in hrdf.simple_geoms)):
        out.append(Problem("simple_geom.csv", f"duplicate geom name '{name}'", column="name"))
    unit = (1.0, 1.0, 1.0)
    ext = hrdf.meta.mesh_file_type
    root = hrdf.root_dir
    # The folder of meshes/<name>.<ext> paths, when it is a plain folder of the robot (not
    # a link): its plain files need no containment check, only a listing.
    default_dir = None
    if root is not None and os.sep not in str(ext):
        candidate = f"{root}{os.sep}meshes"
        if not os.path.islink(candidate):
            default_dir = candidate
    for i, m in enumerate(hrdf.meshes):
        if not m.name:
            out.append(Problem("mesh.csv", "empty mesh name", row=i, column="name"))
            continue
        if m.scale != unit and any(not MESH_SCALE[0] <= abs(s) <= MESH_SCALE[1] for s in m.scale):
            out.append(
                Problem(
                    "mesh.csv",
                    f"scale {m.scale}: expected each between {MESH_SCALE[0]:g} and "
                    f"{MESH_SCALE[1]:g} in size (a negative one mirrors the mesh on that axis)",
                    row=i,
                    column="scale0",
                )
            )
        if m.inertia is not None and m.inertia not in MESH_INERTIA_MODES:
            out.append(
                Problem(
                    "mesh.csv",
                    f"inertia {shown(m.inertia)}: expected one of {list(MESH_INERTIA_MODES)} or empty",
                    row=i,
                    column="inertia",
                )
            )
        # A plain file listed in the robot's own meshes/ folder is inside and exists; its
        # size is the listing's.
        if (
            validate_common.QUICK_PASS
            and default_dir is not None
            and m.file is None
            and os.sep not in m.name
            and (size := _listing(default_dir, listings, check_files).get(f"{m.name}.{ext}"))
            is not None
        ):
            if check_files and size > limit:
                out += _too_large(f"{default_dir}{os.sep}{m.name}.{ext}", i, "name")
            continue
        column = "file" if m.file is not None else "name"
        if root is not None:
            try:
                source = hrdf.mesh_source(m)
            except UnsafePathError as exc:
                # a NUL cannot escape anything: it is simply not a path
                written = m.file if m.file is not None else m.name
                refused = "refused" if "\0" in written else "escapes the robot folder"
                out.append(
                    Problem(
                        "mesh.csv",
                        f"mesh file {refused}: {exc.reason}",
                        row=i,
                        column=column,
                    )
                )
                continue
            if check_files and not os.path.isfile(source):
                out.append(_missing(source, i, column))
            elif check_files:
                out += _too_large(source, i, column)
        elif check_files:
            path = _mesh_file(hrdf, m)
            if not os.path.isfile(path):
                out.append(_missing(path, i, column))
            else:
                out += _too_large(path, i, column)
    return out


def _size_problems(table: str, kind: str, size: tuple[float, ...], row: int) -> list[Problem]:
    """A geom's or site's ``size``: the values its type uses must be > 0."""
    used = _SIZE_USED.get(kind, 3)
    if all(v > 0 for v in size[:used]):
        return []
    message = f"{kind} size {size}: expected the first {used} value(s) > 0"
    return [Problem(table, message, row=row, column="size0")]


def _missing(path: str | Path, row: int, column: str) -> Problem:
    why = "is not a regular file" if os.path.exists(path) else "does not exist"
    return Problem("mesh.csv", f"mesh file '{path}' {why}", row=row, column=column)


def _too_large(path: str | Path, row: int, column: str) -> list[Problem]:
    """The mesh size cap (``--max-mesh-mb``), checked with ``stat`` before MuJoCo or a
    mesh reader opens the file (see :mod:`robotwright._assets`)."""
    try:
        check_asset_file(path, image=False)
    except InputFileError as exc:
        return [Problem("mesh.csv", f"mesh file {exc}", row=row, column=column)]
    return []


def _check_sites_sensors(hrdf: HRDF, body_names: set[str]) -> list[Problem]:
    out: list[Problem] = []
    for name in sorted(_duplicates(s.name for s in hrdf.sites)):
        out.append(Problem("site.csv", f"duplicate site name '{name}'", column="name"))
    for i, s in enumerate(hrdf.sites):
        if s.body not in body_names and s.body != WORLD:
            out.append(
                Problem(
                    "site.csv",
                    f"unknown body '{s.body}': expected a body of body.csv, or '{WORLD}' for "
                    "a site fixed in the world",
                    row=i,
                    column="body_name",
                )
            )
        if s.type not in SITE_TYPES:
            out.append(
                Problem(
                    "site.csv",
                    f"site type '{s.type}': expected one of {list(SITE_TYPES)}",
                    row=i,
                    column="type",
                )
            )
        msg = _quat_problem(s.quat)
        if msg:
            out.append(Problem("site.csv", msg, row=i, column="quat"))
        if s.type in SITE_TYPES:
            out += _size_problems("site.csv", s.type, s.size, i)
    for name in sorted(_duplicates(s.name for s in hrdf.sensors)):
        out.append(Problem("sensor.csv", f"duplicate sensor name '{name}'", column="name"))
    targets = {
        "site": {s.name for s in hrdf.sites},
        "body": body_names,
        "xbody": body_names,
        "joint": {j.name for j in hrdf.joints if j.name},
        "actuator": {a.name for a in hrdf.actuators if a.name},
    }
    for i, s in enumerate(hrdf.sensors):
        # Type and object types become XML element and attribute names: vocabulary only.
        allowed = SENSOR_OBJTYPES.get(s.type)
        if allowed is None:
            out.append(
                Problem(
                    "sensor.csv",
                    f"sensor type {shown(s.type)}: expected an MJCF sensor element that reads one "
                    f"object, one of {sorted(SENSOR_OBJTYPES)}",
                    row=i,
                    column="type",
                )
            )
            continue
        if s.objtype not in allowed:
            out.append(
                Problem(
                    "sensor.csv",
                    f"objtype {shown(s.objtype)}: expected one of {list(allowed)} for a {s.type} sensor",
                    row=i,
                    column="objtype",
                )
            )
            continue
        if s.reftype is not None and s.reftype not in FRAME_OBJTYPES:
            out.append(
                Problem(
                    "sensor.csv",
                    f"reftype {shown(s.reftype)}: expected one of {list(FRAME_OBJTYPES)}",
                    row=i,
                    column="reftype",
                )
            )
        known = targets.get(s.objtype)
        if known is not None and s.objname not in known:
            out.append(
                Problem(
                    "sensor.csv",
                    f"sensor '{s.name}' reads unknown {s.objtype} '{s.objname}'",
                    row=i,
                    column="objname",
                )
            )
    return out
