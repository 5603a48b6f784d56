"""Mesh files of a parsed robot: staging, format conversion and face counts.

A parsed robot's meshes are gathered in one staging folder (``<work_dir>/meshes/``)
under unique names, so that two source files with the same base name never collide and
``HRDF.save`` copies them into the HRDF folder. Formats MuJoCo reads (STL, OBJ, MSH) are
linked (or copied where links are not possible); other formats (DAE, PLY, ...) are
converted to binary STL with trimesh, which keeps the geometry in the file's own units
and drops the file's materials and textures (reported by the caller).
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: Extensions MuJoCo decodes itself.
MUJOCO_MESH_EXTENSIONS = frozenset({".stl", ".obj", ".msh"})
#: Meshes above this many faces are reported (MuJoCo refuses STLs over 200k faces).
HEAVY_FACES = 200_000


class MeshConversionError(Exception):
    """A mesh file could not be read or converted (message names the file)."""


def _safe_stem(path: Path) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", path.stem) or "mesh"


@dataclass
class StagedMesh:
    """A mesh file in the staging folder.

    Attributes:
        source: the original file.
        rel: path relative to the staging folder (``meshes/<name>.<ext>``).
        converted: True when the file was converted (not a link/copy of the source).
        faces: face count when known (converted files and STL headers), else None.
    """

    source: Path
    rel: str
    converted: bool
    faces: int | None = None


@dataclass
class MeshStore:
    """Stages mesh files into ``root/meshes``; one entry per distinct source file."""

    root: Path = field(default_factory=lambda: Path(tempfile.mkdtemp(prefix="robotwright-mesh-")))
    staged: dict[Path, StagedMesh] = field(default_factory=dict)
    _used: set[str] = field(default_factory=set)

    def __post_init__(self) -> None:
        self.root = Path(self.root)
        (self.root / "meshes").mkdir(parents=True, exist_ok=True)

    def _unique(self, stem: str, ext: str) -> str:
        name, k = f"{stem}{ext}", 1
        while name.lower() in self._used:
            name, k = f"{stem}_{k}{ext}", k + 1
        self._used.add(name.lower())
        return name

    def add_mirrored(self, source: Path, signs: tuple[float, float, float]) -> StagedMesh:
        """Stage ``source`` mirrored by the per-axis ``signs`` (each +1 or -1): vertices
        are multiplied by the signs and, for an odd number of flips, the face winding is
        reversed so that normals still point outwards."""
        import trimesh

        key = Path(f"{source.resolve()}#mirror{signs}")
        if key in self.staged:
            return self.staged[key]
        try:
            # process=False: keep triangles exactly as in the file (no merging/cleaning)
            mesh = trimesh.load(str(source), force="mesh", process=False)
        except Exception as exc:  # trimesh raises many types; name the file
            raise MeshConversionError(f"cannot read mesh {source}: {exc}") from exc
        mesh.apply_transform(np.diag([*signs, 1.0]))
        name = self._unique(_safe_stem(source) + "_mirrored", ".stl")
        dest = self.root / "meshes" / name
        tmp = dest.with_name(dest.name + ".tmp")
        mesh.export(str(tmp), file_type="stl")
        os.replace(tmp, dest)
        entry = StagedMesh(source, f"meshes/{name}", True, int(len(mesh.faces)))
        self.staged[key] = entry
        return entry

    def add(self, source: Path) -> StagedMesh:
        """Stage ``source`` (an existing file) and return its entry."""
        source = source.resolve()
        if source in self.staged:
            return self.staged[source]
        ext = source.suffix.lower()
        # MuJoCo reads binary STL only: an ASCII STL is converted like other formats.
        ascii_stl = ext == ".stl" and stl_face_count(source) is None
        if ext in MUJOCO_MESH_EXTENSIONS and not ascii_stl:
            name = self._unique(_safe_stem(source), ext)
            dest = self.root / "meshes" / name
            # A hard link costs nothing and, unlike a symlink, resolves inside the
            # staging folder (HRDF checks that mesh files stay inside the robot folder).
            try:
                os.link(source, dest)
            except OSError:
                shutil.copyfile(source, dest)
            entry = StagedMesh(source, f"meshes/{name}", False, stl_face_count(source))
        else:
            name = self._unique(_safe_stem(source), ".stl")
            dest = self.root / "meshes" / name
            faces = convert_to_stl(source, dest)
            entry = StagedMesh(source, f"meshes/{name}", True, faces)
        self.staged[source] = entry
        return entry


def stl_face_count(path: Path) -> int | None:
    """Face count of a binary STL from its header (None for ASCII STL or other formats)."""
    if path.suffix.lower() != ".stl":
        return None
    try:
        size = path.stat().st_size
        with path.open("rb") as f:
            head = f.read(84)
    except OSError:
        return None
    if len(head) < 84:
        return None
    count = int.from_bytes(head[80:84], "little")
    # A binary STL is exactly 84 + 50 * count bytes; anything else is ASCII.
    return count if size == 84 + 50 * count else None


def convert_to_stl(source: Path, dest: Path) -> int:
    """Convert ``source`` (any format trimesh reads, scene transforms applied) to binary
    STL at ``dest`` (written to a temporary file, then renamed). Returns the face count."""
    import trimesh

    try:
        loaded = trimesh.load(str(source), force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types; name the file and re-raise
        raise MeshConversionError(f"cannot read mesh {source}: {exc}") from exc
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise MeshConversionError(f"mesh {source} holds no triangles")
    tmp = dest.with_name(dest.name + ".tmp")
    loaded.export(str(tmp), file_type="stl")
    os.replace(tmp, dest)
    return int(len(loaded.faces))
