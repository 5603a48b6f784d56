"""Mesh files of a parsed robot: staging, lossless format conversion and face counts.

A parsed robot's meshes are gathered in one staging folder (``<work_dir>/meshes/``)
under unique names, so that two source files with the same base name never collide and
``HRDF.save`` copies them into the HRDF folder.

- Binary STL up to :data:`HEAVY_FACES` faces, OBJ and MSH (formats MuJoCo decodes) are
  hard-linked, or copied where links are not possible.
- Other formats (DAE, PLY, ...), ASCII STL (MuJoCo reads binary STL only) and STLs over
  :data:`HEAVY_FACES` faces (MuJoCo's STL decoder refuses them) are converted with
  trimesh, triangles unchanged (``process=False``: no merging, no cleaning), to binary
  STL, or to OBJ above :data:`HEAVY_FACES` faces. Scene transforms of the file are
  applied; materials and textures of the file are dropped (callers report it).
- An OBJ split into several objects (``o``/``g`` lines) is read by MuJoCo as its first
  object only (the other triangles are lost, often leaving an open shell whose volume
  MuJoCo refuses). With ``join_obj_objects`` it is converted the same way, every
  object's triangles kept in one file; without it, it is linked and its object face
  counts are recorded so that callers can report the loss.

Without a ``work_dir`` the staging folder is a :class:`TempFolder`: the parsed HRDF holds
it (``HRDF.temp_assets``, carried by ``dataclasses.replace``), and the folder is removed
once no HRDF holds it any more, or when the interpreter exits. Save the robot
(``HRDF.save``) to keep its meshes.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
import weakref
from dataclasses import dataclass, field
from pathlib import Path

from robotwright._atomic import atomic_path
from robotwright._temporaries import prefix

#: Extensions MuJoCo decodes itself.
MUJOCO_MESH_EXTENSIONS = frozenset({".stl", ".obj", ".msh"})
#: MuJoCo's STL decoder refuses files with more faces than this.
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
        converted: why the file was rewritten (``"format"``, ``"ascii-stl"``,
            ``"heavy-stl"``, ``"obj-objects"``), or ``None`` for a
            link/copy of the source.
        faces: face count when known (converted files and binary STL headers), else None.
        obj_objects: faces per object of an OBJ holding several (see
            :func:`obj_object_faces`), else ``()``.
    """

    source: Path
    rel: str
    converted: str | None
    faces: int | None = None
    obj_objects: tuple[int, ...] = ()


class TempFolder:
    """A temporary folder that lives as long as this object (and is removed at exit at
    the latest). Whoever needs the folder's files holds the object."""

    def __init__(self, kind: str = "mesh") -> None:
        self.path = Path(tempfile.mkdtemp(prefix=prefix(kind)))
        # The callback holds the path only, never self, so the object can be collected.
        self._finalizer = weakref.finalize(self, shutil.rmtree, str(self.path), True)
        self._holder: object | None = None

    def __reduce__(self) -> tuple:
        # Only a confined reader's answer carries a temporary folder (by path, adopted
        # by the process that reads the answer); anywhere else two processes would each
        # remove the same folder.
        from robotwright._confine import in_confined_copy

        if not in_confined_copy():
            raise TypeError("a TempFolder cannot be pickled")
        return (_adopt_temp_folder, (str(self.path),))

    def remove(self) -> None:
        """Remove the folder now."""
        self._finalizer()


def _adopt_temp_folder(path: str) -> TempFolder:
    """A :class:`TempFolder` made by a confined reader, now held here (see
    :mod:`robotwright._confine`)."""
    from robotwright._confine import adoption_holder

    folder = TempFolder.__new__(TempFolder)
    folder._holder = adoption_holder(path)
    folder.path = Path(path)
    folder._finalizer = weakref.finalize(folder, shutil.rmtree, path, True)
    return folder


@dataclass
class MeshStore:
    """Stages mesh files into ``root/meshes``; one entry per distinct source.

    ``join_obj_objects``: convert OBJ files holding several objects into one mesh with
    all their triangles (MuJoCo reads the first object only)."""

    root: Path | None = None
    join_obj_objects: bool = False
    staged: dict[str, StagedMesh] = field(default_factory=dict)
    _used: set[str] = field(default_factory=set)
    #: The temporary folder when ``root`` was not given (None otherwise).
    lifetime: TempFolder | None = None

    def __post_init__(self) -> None:
        if self.root is None:
            self.lifetime = TempFolder()
            self.root = self.lifetime.path
        self.root = Path(self.root)
        (self.root / "meshes").mkdir(parents=True, exist_ok=True)

    def _unique(self, stem: str, ext: str) -> str:
        name, k = f"{stem}{ext}", 1
        while name.lower() in self._used:
            name, k = f"{stem}_{k}{ext}", k + 1
        self._used.add(name.lower())
        return name

    def _write(self, mesh, stem: str) -> tuple[str, int]:
        faces = int(len(mesh.faces))
        ext = ".obj" if faces > HEAVY_FACES else ".stl"
        name = self._unique(stem, ext)
        dest = self.root / "meshes" / name
        with atomic_path(dest) as tmp:
            mesh.export(str(tmp), file_type=ext[1:])
        return f"meshes/{name}", faces

    def add(self, source: Path) -> StagedMesh:
        """Stage ``source`` (an existing file) and return its entry."""
        source = source.resolve()
        key = str(source)
        if key in self.staged:
            return self.staged[key]
        ext = source.suffix.lower()
        faces = stl_face_count(source)
        objects = obj_object_faces(source) if ext == ".obj" else ()
        reason = None
        if ext not in MUJOCO_MESH_EXTENSIONS:
            reason = "format"
        elif ext == ".stl" and faces is None:
            reason = "ascii-stl"
        elif ext == ".stl" and faces > HEAVY_FACES:
            reason = "heavy-stl"
        elif objects and self.join_obj_objects:
            reason = "obj-objects"
        if reason is None:
            name = self._unique(_safe_stem(source), ext)
            dest = self.root / "meshes" / name
            # A hard link costs nothing and, unlike a symlink, resolves inside the
            # staging folder (HRDF checks that mesh files stay inside the robot folder).
            # A confined reader copies instead: Landlock refuses a link that would give
            # a read-only file write access in the staging folder.
            try:
                os.link(source, dest)
            except OSError:
                shutil.copyfile(source, dest)
            entry = StagedMesh(source, f"meshes/{name}", None, faces, objects)
        else:
            rel, faces = self._write(load_triangles(source), _safe_stem(source))
            entry = StagedMesh(source, rel, reason, faces, objects)
        self.staged[key] = entry
        return entry


def rewrite_staged(store: MeshStore, rel: str) -> str:
    """Rewrite the staged file ``rel`` with trimesh (triangles unchanged; normals and
    texture coordinates dropped) and return the new file's path relative to the store,
    for a file MuJoCo cannot decode (an OBJ with out-of-range normal indices)."""
    source = store.root / rel
    key = f"{source.resolve()}#rewritten"
    if key not in store.staged:
        new_rel, faces = store._write(load_triangles(source), _safe_stem(source) + "_rewritten")
        store.staged[key] = StagedMesh(source, new_rel, "format", faces)
    return store.staged[key].rel


def mesh_store(work_dir: Path | None, join_obj_objects: bool = False) -> MeshStore:
    """A store in ``work_dir`` (a new temporary folder when None)."""
    if work_dir:
        return MeshStore(Path(work_dir), join_obj_objects)
    return MeshStore(join_obj_objects=join_obj_objects)


def conversion_note(staged: StagedMesh) -> str | None:
    """The warning text for a converted mesh, or for a linked OBJ whose objects after the
    first MuJoCo does not read (None for a plain link/copy)."""
    if staged.converted is None:
        return _objects_note(staged)
    target = staged.rel.rsplit(".", 1)[-1].upper()
    return {
        "format": f"converted to {target} ({staged.rel}); triangles kept, the file's "
        "materials/textures dropped",
        "ascii-stl": f"ASCII STL rewritten as binary STL ({staged.rel}; MuJoCo reads binary "
        "STL only); triangles unchanged",
        "heavy-stl": f"{staged.faces} faces, over MuJoCo's STL limit of {HEAVY_FACES}: "
        f"rewritten as OBJ ({staged.rel}); triangles unchanged",
        "obj-objects": f"{len(staged.obj_objects)} objects (faces {list(staged.obj_objects)}), "
        f"of which MuJoCo reads the first only: joined into one {target} ({staged.rel}); "
        "triangles unchanged, the file's normals/texture coordinates dropped",
    }.get(staged.converted or "")


def conversion_is_cosmetic(staged: StagedMesh) -> bool:
    """Whether :func:`conversion_note`'s change leaves what MuJoCo reads as it was: a new
    file format with the same triangles (not a join of objects MuJoCo would not read)."""
    return staged.converted in ("format", "ascii-stl", "heavy-stl")


def _objects_note(staged: StagedMesh) -> str | None:
    if not staged.obj_objects:
        return None
    first, total = staged.obj_objects[0], sum(staged.obj_objects)
    return (
        f"holds {len(staged.obj_objects)} objects; MuJoCo reads the first only ({first} of "
        f"{total} faces), and so does the converted robot (join_obj_objects joins them)"
    )


def obj_object_faces(path: Path) -> tuple[int, ...]:
    """Face counts of the objects of an OBJ file when it holds more than one, else ``()``.

    An object starts at an ``o`` or ``g`` line, as in MuJoCo's OBJ decoder; objects
    without faces are left out."""
    counts: list[int] = []
    current = 0
    try:
        with path.open("rb") as f:
            for line in f:
                head = line[:2]
                if head in (b"f ", b"f\t"):
                    current += 1
                elif head in (b"o ", b"g ", b"o\t", b"g\t", b"o\n", b"g\n"):
                    if current:
                        counts.append(current)
                    current = 0
    except OSError:
        return ()
    if current:
        counts.append(current)
    return tuple(counts) if len(counts) > 1 else ()


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


def load_triangles(source: Path):
    """The triangles of a mesh file as one ``trimesh.Trimesh`` (scene transforms applied,
    nothing merged or cleaned)."""
    import trimesh

    from robotwright._mesh_reader import load_mesh_file

    try:
        loaded = load_mesh_file(source, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types; name the file and re-raise
        raise MeshConversionError(f"cannot read mesh {source}: {exc}") from exc
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise MeshConversionError(f"mesh {source} holds no triangles")
    return loaded
