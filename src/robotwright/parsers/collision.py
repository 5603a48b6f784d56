"""Opt-in repairs of collision meshes: decimation to a face budget, convex decomposition.

Dense collision meshes slow MuJoCo's collision detection (it collides the convex hull
of each mesh geom; a concave part is filled in). Two repairs, each applied only when
asked for, and only to *collision* mesh geoms (``contact_type`` or ``contact_affinity``
non-zero); visual meshes are never touched, also when a visual and a collision geom
share one mesh file (the collision geom gets its own new file):

- ``max_faces``: a mesh with more triangles is decimated to at most that many with
  ``fast-simplification`` (quadric edge collapse). hurodes offers 8,000 faces.
- ``convex_decomposition``: the mesh is split into convex parts with ``coacd``
  (CoACD); each part becomes one collision geom with the pose, body and contact
  settings of the original, so the robot collides with the concave shape.

Both packages are in the ``meshfix`` extra (``pip install 'robotwright[meshfix]'``),
imported only when a repair runs. Every repaired geom is reported with its face count
and volume before and after (volumes in m^3 with the mesh ``scale`` applied; "n/a"
where the input is not watertight, as its volume is then undefined). New mesh files are
binary STL files in ``out_dir`` (default: a temporary folder that lives as long as the
returned robot).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from robotwright._names import file_stem, shown
from robotwright.errors import ConversionError, Problem
from robotwright.hrdf.model import HRDF, MeshGeom


@dataclass(frozen=True)
class CollisionMeshConfig:
    """Which repairs run (none by default).

    Attributes:
        max_faces: decimate collision meshes with more triangles to at most this many
            (``None``: no decimation). At least 4.
        convex_decomposition: split each collision mesh into convex parts (CoACD).
        threshold: CoACD's concavity threshold (0.01 .. 1; smaller = more, finer parts).
        max_parts: at most this many convex parts per mesh (``-1``: no limit).
        seed: CoACD's random seed (fixed, so the same input gives the same parts).
        resolution: CoACD's sampling resolution (CoACD's own default: 2000).
        mcts_iterations: CoACD's tree-search iterations (CoACD's own default: 150).
        preprocess_resolution: CoACD's manifold-repair voxel resolution (default 50).

    The CoACD defaults here (1000, 60, 30) are lower than CoACD's own, for speed (a
    robot arm's links in seconds rather than minutes); raise them for finer parts.
    """

    max_faces: int | None = None
    convex_decomposition: bool = False
    threshold: float = 0.05
    max_parts: int = -1
    seed: int = 0
    resolution: int = 1000
    mcts_iterations: int = 60
    preprocess_resolution: int = 30

    def __post_init__(self) -> None:
        if self.max_faces is not None and (
            isinstance(self.max_faces, bool) or not isinstance(self.max_faces, int)
        ):
            raise ValueError(f"max_faces={shown(self.max_faces)}: expected an integer or None")
        if self.max_faces is not None and self.max_faces < 4:
            raise ValueError(f"max_faces={self.max_faces}: expected at least 4 faces")
        if not (isinstance(self.threshold, (int, float)) and 0.01 <= self.threshold <= 1.0):
            raise ValueError(f"threshold={shown(self.threshold)}: expected 0.01 <= threshold <= 1")
        if not isinstance(self.max_parts, int) or (self.max_parts != -1 and self.max_parts < 1):
            raise ValueError(f"max_parts={shown(self.max_parts)}: expected -1 or at least 1")
        for name in ("resolution", "mcts_iterations", "preprocess_resolution"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"{name}={shown(value)}: expected an integer >= 1")

    @property
    def active(self) -> bool:
        return self.max_faces is not None or self.convex_decomposition


@dataclass(frozen=True)
class MeshRepair:
    """What one repair did to one collision geom.

    Attributes:
        body: the body of the geom.
        mesh: the mesh (asset) name before the repair.
        action: ``"decimated"`` or ``"decomposed"``.
        faces_before: triangles before.
        faces_after: triangles after (summed over the parts).
        volume_before: volume before (m^3), ``None`` when the input is not watertight.
        volume_after: volume after (m^3, summed over the parts), ``None`` likewise.
        parts: number of geoms the repair made.
    """

    body: str
    mesh: str
    action: str
    faces_before: int
    faces_after: int
    volume_before: float | None
    volume_after: float | None
    parts: int = 1

    def __str__(self) -> str:
        if self.volume_before and self.volume_after is not None:
            change = f"{100.0 * (self.volume_after / self.volume_before - 1.0):+.2f}%"
            volume = f"volume {self.volume_before:.6g} -> {self.volume_after:.6g} m^3 ({change})"
        else:
            volume = "volume change n/a (a mesh before or after is not watertight)"
        parts = f" into {self.parts} convex parts" if self.action == "decomposed" else ""
        return (
            f"collision mesh '{self.mesh}' of body '{self.body}' {self.action}{parts}: "
            f"{self.faces_before} -> {self.faces_after} faces, {volume}"
        )


def _is_collision(geom: MeshGeom) -> bool:
    return geom.contact_type != 0 or geom.contact_affinity != 0


def _volume(mesh: object, scale: np.ndarray) -> float | None:
    if not getattr(mesh, "is_watertight", False):
        return None
    return abs(float(mesh.volume)) * float(np.prod(np.abs(scale)))  # type: ignore[attr-defined]


def _import(module: str) -> object:
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ConversionError(
            [
                Problem(
                    "collision meshes",
                    f"this repair needs {module.replace('_', '-')}: "
                    "pip install 'robotwright[meshfix]'",
                )
            ]
        ) from None


def repair_collision_meshes(
    hrdf: HRDF, config: CollisionMeshConfig, out_dir: str | os.PathLike[str] | None = None
) -> tuple[HRDF, list[MeshRepair]]:
    """A copy of ``hrdf`` whose collision meshes are repaired as ``config`` asks.

    Returns:
        The repaired robot (visual geoms, primitives and all other tables unchanged) and
        one :class:`MeshRepair` per repaired geom, in mesh-table order.

    Raises:
        ConversionError: a repair's package is missing, or a mesh cannot be read.
    """
    if not config.active:
        return hrdf, []
    import trimesh

    holder: object | None = None
    if out_dir is None:
        from robotwright.parsers.meshes import TempFolder

        holder = TempFolder("collision")
        folder = holder.path  # type: ignore[attr-defined]
    else:
        folder = Path(out_dir)
        folder.mkdir(parents=True, exist_ok=True)
    folder = Path(folder).resolve()
    simplify = _import("fast_simplification") if config.max_faces is not None else None
    coacd = _import("coacd") if config.convex_decomposition else None
    taken = {m.name for m in hrdf.meshes}
    meshes: list[MeshGeom] = []
    repairs: list[MeshRepair] = []
    # A mesh file used by several collision geoms (four identical feet) is repaired once.
    done: dict[tuple[str, tuple[float, ...]], tuple[list[tuple[str, str]], list[tuple]]] = {}
    for geom in hrdf.meshes:
        if not _is_collision(geom):
            meshes.append(geom)
            continue
        source = str(hrdf.mesh_source(geom))
        key = (source, tuple(geom.scale))
        if key not in done:
            done[key] = _repair_file(source, geom, config, simplify, coacd, taken, folder, trimesh)
        outputs, stats = done[key]
        if not stats:
            meshes.append(geom)
            continue
        decomposed = stats[-1][1] == "decomposed"
        for k, (name, file) in enumerate(outputs):
            made = replace(geom, name=name, file=file)
            if decomposed and geom.geom_name is not None:
                made = replace(made, geom_name=f"{geom.geom_name}_part{k}")
            meshes.append(made)
        repairs += [MeshRepair(geom.body, *fields) for fields in stats]
    if not repairs:
        return hrdf, []
    holders = hrdf.temp_assets if holder is None else (hrdf.temp_assets, holder)
    return (
        replace(
            hrdf,
            meshes=meshes,
            asset_roots=(*hrdf.asset_roots, folder),
            temp_assets=holders,
        ),
        repairs,
    )


def _repair_file(
    source: str,
    geom: MeshGeom,
    config: CollisionMeshConfig,
    simplify: Any,
    coacd: Any,
    taken: set[str],
    folder: Path,
    trimesh: Any,
) -> tuple[list[tuple[str, str]], list[tuple]]:
    """Repair one mesh file: the ``(mesh name, file)`` of each output geom, and the
    :class:`MeshRepair` fields (less the body) of each repair made (none: unchanged)."""
    from robotwright._mesh_reader import load_mesh_file

    try:
        # process=True merges duplicate vertices (STL), so watertightness is known.
        loaded = load_mesh_file(source, force="mesh", process=True)
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise ConversionError(
            [Problem("mesh.csv", f"cannot read mesh '{geom.name}': {exc}")]
        ) from None
    scale = np.asarray(geom.scale, dtype=float)
    vertices = np.asarray(loaded.vertices, dtype=float)
    faces = np.asarray(loaded.faces, dtype=np.int64)
    volume = _volume(loaded, scale)
    name = geom.name
    outputs: list[tuple[str, str]] = [(geom.name, geom.file or source)]
    stats: list[tuple] = []
    if simplify is not None and len(faces) > config.max_faces:
        new_v, new_f = simplify.simplify(vertices, faces, target_count=config.max_faces)
        part = trimesh.Trimesh(new_v, new_f, process=False)
        after = _volume(part, scale) if volume is not None else None
        stats.append((name, "decimated", len(faces), len(new_f), volume, after))
        name = _unique(taken, f"{geom.name}_{config.max_faces}f")
        outputs = [(name, _write(part, folder, name))]
        vertices, faces, volume = np.asarray(new_v), np.asarray(new_f), after
    if coacd is None:
        return outputs, stats
    coacd.set_log_level("error")
    parts = coacd.run_coacd(
        coacd.Mesh(vertices, faces),
        threshold=float(config.threshold),
        max_convex_hull=config.max_parts,
        seed=config.seed,
        resolution=config.resolution,
        mcts_iterations=config.mcts_iterations,
        preprocess_resolution=config.preprocess_resolution,
    )
    outputs = []
    total_faces, total_volume = 0, 0.0
    for k, (pv, pf) in enumerate(parts):
        hull = trimesh.Trimesh(np.asarray(pv), np.asarray(pf), process=False)
        total_faces += len(pf)
        total_volume += abs(float(hull.volume)) * float(np.prod(np.abs(scale)))
        part_name = _unique(taken, f"{name}_part{k}")
        outputs.append((part_name, _write(hull, folder, part_name)))
    after = total_volume if volume is not None and math.isfinite(total_volume) else None
    stats.append((name, "decomposed", len(faces), total_faces, volume, after, len(outputs)))
    return outputs, stats


def _unique(taken: set[str], base: str) -> str:
    name, k = base, 1
    while name in taken:
        name = f"{base}_{k}"
        k += 1
    taken.add(name)
    return name


def _write(mesh: Any, folder: Path, name: str) -> str:
    """``mesh`` as ``folder/<stem>.stl`` (binary), ``<stem>`` the mesh name made a safe
    file name (a geom name comes from the robot file) and numbered when taken; returns
    the path."""
    stem = file_stem(name, "mesh")
    path, k = folder / f"{stem}.stl", 1
    while path.exists():
        path, k = folder / f"{stem}_{k}.stl", k + 1
    mesh.export(str(path), file_type="stl")
    return str(path)


#: ``convert`` / CLI options that select the repairs (not parser options).
COLLISION_OPTIONS = ("collision_max_faces", "convex_decomposition")


def pop_config(options: dict) -> CollisionMeshConfig:
    """The repairs ``options`` ask for (``collision_max_faces``, ``convex_decomposition``),
    removed from ``options`` so that the rest go to the parser."""
    try:
        return CollisionMeshConfig(
            max_faces=options.pop("collision_max_faces", None),
            convex_decomposition=bool(options.pop("convex_decomposition", False)),
        )
    except ValueError as exc:
        problem = Problem("collision_max_faces (--collision-max-faces)", str(exc))
        raise ConversionError([problem]) from None
