"""The MJCF reader's geoms: primitives to ``simple_geom.csv``, meshes to ``mesh.csv``
(their files, frames and scale), what the tables cannot hold noted or carried, and the
order of a body's geoms where meshes and primitives interleave."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np

from robotwright._paths import mjcf_asset_file, resolve_inside
from robotwright.errors import ConversionError, Problem, UnsafePathError
from robotwright.hrdf.model import (
    MeshGeom,
    SimpleGeom,
)
from robotwright.parsers import inertia as inr
from robotwright.parsers.meshes import (
    MeshConversionError,
    MeshStore,
    conversion_is_cosmetic,
    conversion_note,
)
from robotwright.parsers.mjcf.common import _differs, _five, _pair, _reparent, _t3, _t4, _user
from robotwright.parsers.reference import body_name
from robotwright.parsers.report import Reporter

_GEOM = {2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box", 7: "mesh"}

#: Material fields beyond the colour (a material with defaults there is just a colour).
_MATERIAL_UNHELD = (
    "mat_texid", "mat_texuniform", "mat_texrepeat", "mat_emission", "mat_specular",
    "mat_shininess", "mat_reflectance", "mat_metallic", "mat_roughness",
)  # fmt: skip

#: Geom fields HRDF has no column for.
_GEOM_UNHELD = ("geom_fluid",)


def _keep_interleaved_order(
    in_order: dict[str, list[tuple[str, int]]], meshes: list, simple: list
) -> None:
    """Give each geom of a body whose mesh and primitive geoms interleave its position
    (``order``): written meshes-first, such a body's contacts would come in another order."""
    for geoms in in_order.values():
        natural = sorted(geoms, key=lambda kind_row: kind_row[0] != "mesh")  # stable
        if natural == geoms:
            continue
        for position, (kind, row) in enumerate(geoms):
            table = meshes if kind == "mesh" else simple
            table[row] = replace(table[row], order=position)


def _mesh_source(
    m_spec: mujoco.MjsMesh,
    spec: mujoco.MjSpec,
    base_dir: Path,
    sub_dirs: list[Path],
    trusted: tuple[Path, ...] | None = None,
) -> Path:
    """The file of mesh ``m_spec`` as MuJoCo finds it (:func:`mjcf_asset_file`: under its
    own model's mesh folder, a sub-model's meshes keeping their ``<compiler meshdir>``;
    ``strippath``), from the main file's folder or the sub-model's, resolved inside the
    main file's folder or a trusted one: the path the checks passed is the path staged,
    whether or not the reader is confined.

    Raises:
        UnsafePathError: the file leaves those folders (naming the mesh element).
    """
    own = getattr(getattr(m_spec, "compiler", None), "meshdir", None)
    folder = (spec.compiler.meshdir or "") if own is None else own
    file = mjcf_asset_file(m_spec.file, folder, strip=bool(spec.strippath))
    element = f'<mesh name="{m_spec.name}" file="{m_spec.file}">'
    found = None
    for base in (base_dir, *sub_dirs):
        try:
            candidate = resolve_inside(file, base=base, root=base_dir, trusted=trusted)
        except UnsafePathError as exc:
            raise UnsafePathError(exc.reason, element=element) from None
        if candidate.is_file():
            return candidate
        found = found or candidate
    assert found is not None
    return found


def _geoms(
    model: mujoco.MjModel,
    spec: mujoco.MjSpec,
    kept: set[int],
    path: Path,
    store: MeshStore,
    frames: set[int],
    rep: Reporter,
    sub_dirs: list[Path],
    trusted: tuple[Path, ...] | None = None,
) -> tuple[list[MeshGeom], list[SimpleGeom]]:
    """Mesh geoms (files staged, authored poses restored) and primitive geoms;
    ``sub_dirs``: the folders of the sub-models, whose meshes are named from there;
    ``trusted``: the folders outside the robot's that its files may lie in."""
    base_dir = path.resolve().parent
    mesh_files: dict[int, tuple[str, str]] = {}
    meshes: list[MeshGeom] = []
    simple: list[SimpleGeom] = []
    world_geoms: list[str] = []
    materials: set[str] = set()
    unheld_geom: dict[str, list[str]] = {}
    in_order: dict[str, list[tuple[str, int]]] = {}  # body -> its geoms, in model order
    for g in range(model.ngeom):
        b = int(model.geom_bodyid[g])
        if b == 0:
            world_geoms.append(model.geom(g).name or f"geom #{g}")
            continue
        if b not in kept:
            continue
        gt = int(model.geom_type[g])
        gname = model.geom(g).name or None
        where = f'<geom name="{gname}">' if gname else f'geom #{g} of body "{body_name(model, b)}"'
        if gt not in _GEOM:
            rep.warn(f"geom type {mujoco.mjtGeom(gt).name} dropped (not a robot part shape)", where)
            continue
        rgba = model.geom_rgba[g]
        mat = int(model.geom_matid[g])
        # MuJoCo draws the material colour unless the geom's own rgba is not the default.
        if mat >= 0:
            if any(_differs(model, attr, mat) for attr in _MATERIAL_UNHELD):
                materials.add(model.material(mat).name or f"material #{mat}")
            if not _differs(model, "geom_rgba", g):
                rgba = model.mat_rgba[mat]
        for attr in _GEOM_UNHELD:
            if _differs(model, attr, g):
                unheld_geom.setdefault(attr[len("geom_") :], []).append(gname or f"geom #{g}")
        common = {
            "body": body_name(model, b),
            "rgba": _t4(np.clip(rgba, 0.0, 1.0)),
            "contact_type": int(model.geom_contype[g]),
            "contact_affinity": int(model.geom_conaffinity[g]),
            "static_friction": float(model.geom_friction[g, 0]),
            "dynamic_friction": float(model.geom_friction[g, 0]),
            "torsional_friction": float(model.geom_friction[g, 1]),
            "rolling_friction": float(model.geom_friction[g, 2]),
            "group": int(model.geom_group[g]),
            "condim": int(model.geom_condim[g]),
            "geom_name": gname,
            "solref": _pair(model.geom_solref[g]),
            "solimp": _five(model.geom_solimp[g]),
            "margin": float(model.geom_margin[g]),
            "gap": float(model.geom_gap[g]),
            "priority": int(model.geom_priority[g]),
            "solmix": float(model.geom_solmix[g]),
            "user": _user(model.geom_user[g]),
        }
        if gt == 7:
            mid = int(model.geom_dataid[g])
            m_spec = spec.meshes[mid]
            if mid not in mesh_files:
                if not m_spec.file:
                    rep.warn("mesh without a file (inline vertices) dropped", where)
                    continue
                unheld = [
                    attr
                    for attr, default in (
                        ("maxhullvert", -1),
                        ("smoothnormal", False),
                    )
                    if getattr(m_spec, attr) != default
                ]
                if unheld:
                    rep.warn(
                        f"mesh asset '{model.mesh(mid).name}': {unheld} dropped (no HRDF "
                        "column); MuJoCo may centre the mesh differently",
                        where,
                    )
                src = _mesh_source(m_spec, spec, base_dir, sub_dirs, trusted)
                try:
                    # A negative scale stays in the row: MuJoCo mirrors the hull it made
                    # of the file's own vertices, which a mirrored copy would not give.
                    staged = store.add(src)
                except (MeshConversionError, OSError) as exc:
                    raise ConversionError([Problem(str(path), str(exc), element=where)]) from exc
                note = conversion_note(staged)
                if note:
                    cosmetic = conversion_is_cosmetic(staged)
                    rep.warn(f"mesh '{m_spec.file}': {note}", where, cosmetic=cosmetic)
                mesh_files[mid] = (model.mesh(mid).name or Path(m_spec.file).stem, staged.rel)
            mname, rel = mesh_files[mid]
            # Undo MuJoCo's mesh re-centring: compiled = authored * mesh frame.
            mq = model.mesh_quat[mid]
            conj = np.array([mq[0], -mq[1], -mq[2], -mq[3]])
            quat = inr.mul_quat(model.geom_quat[g], conj)
            pos = model.geom_pos[g] - inr.quat_to_mat(quat) @ model.mesh_pos[mid]
            # The mesh's refpos/refquat (the frame its file's vertices are given in)
            # folded into the geom's pose: HRDF meshes are their files as they are.
            ref_q = np.asarray(m_spec.refquat, dtype=float)
            ref_q = ref_q / np.linalg.norm(ref_q)
            ref_inv = np.array([ref_q[0], -ref_q[1], -ref_q[2], -ref_q[3]])
            pos = pos - inr.quat_to_mat(quat) @ (
                inr.quat_to_mat(ref_inv) @ np.asarray(m_spec.refpos)
            )
            quat = inr.mul_quat(quat, ref_inv)
            owner, pos, quat = _reparent(model, b, pos, quat, frames)
            common["body"] = body_name(model, owner)
            mode = m_spec.inertia.name.removeprefix("mjMESH_INERTIA_").lower()
            in_order.setdefault(common["body"], []).append(("mesh", len(meshes)))
            meshes.append(
                MeshGeom(
                    name=mname,
                    file=rel,
                    scale=_t3(m_spec.scale),
                    inertia=None if mode == "legacy" else mode,
                    pos=pos,
                    quat=quat,
                    **common,
                )
            )
        else:
            owner, pos, quat = _reparent(model, b, model.geom_pos[g], model.geom_quat[g], frames)
            common["body"] = body_name(model, owner)
            in_order.setdefault(common["body"], []).append(("simple", len(simple)))
            simple.append(
                SimpleGeom(
                    name="",
                    type=_GEOM[gt],
                    size=_t3(model.geom_size[g]),
                    pos=pos,
                    quat=quat,
                    **common,
                )
            )
    _keep_interleaved_order(in_order, meshes, simple)
    # SimpleGeom.name is the table key; keep the geom's own name when it has one.
    used: set[str] = set()
    for k, sg in enumerate(simple):
        nm = sg.geom_name or f"geom_{k}"
        while nm in used:
            nm = f"{nm}_"
        used.add(nm)
        simple[k] = replace(sg, name=nm)
    if materials:
        rep.warn(
            f"materials {sorted(materials)} replaced by their colour (their textures, "
            "specular, shininess, reflectance, emission dropped)",
            cosmetic=True,
        )
    for attr, gnames in unheld_geom.items():
        shown = gnames[:8] + ([f"... {len(gnames) - 8} more"] if len(gnames) > 8 else [])
        rep.warn(f"geom attribute '{attr}' dropped (no HRDF column) on geoms {shown}")
    if world_geoms:
        shown = ", ".join(world_geoms[:6]) + (", ..." if len(world_geoms) > 6 else "")
        rep.warn(f"{len(world_geoms)} geom(s) of the worldbody dropped (scene, not robot): {shown}")

    return meshes, simple
