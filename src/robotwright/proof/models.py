"""The two models the proof compares: the source as MuJoCo compiles it (reusing the
parser's compile of the same file) and the output, compiled with the same mesh files
so that MuJoCo's processing of a mesh cannot differ between the two."""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco

from robotwright.parsers.mjcf.compiled import _cacheable_mesh_files, _take_parsed

if TYPE_CHECKING:
    from robotwright.hrdf.model import HRDF


# -- the proof of one conversion --------------------------------------------------------------
def source_model(path: Path, kind: str, options: dict) -> mujoco.MjModel | None:
    """The source as MuJoCo compiles it on its own (MJCF: its file; URDF: MuJoCo's URDF
    import, as the round trip's reference), or None when MuJoCo refuses it (nothing to
    prove against). The parser has checked the file's paths already; MuJoCo reads the
    file in a confined reader (:mod:`robotwright._confine`)."""
    return start_source_model(path, kind, options)()


def start_source_model(path: Path, kind: str, options: dict) -> Callable[[], mujoco.MjModel | None]:
    """:func:`source_model` in two halves: the confined reader starts now, and the
    returned call waits for the model. For a caller about to run MuJoCo on other
    threads: a reader started while another thread holds one of MuJoCo's locks would
    wait for it for ever (:func:`robotwright._confine.start_confined`)."""
    from robotwright._confine import start_confined
    from robotwright.parsers.packages import source_read_roots

    # MuJoCo caches the meshes it decodes by file name, in the process that decodes
    # them: the output is read through the source's names only where the source was
    # compiled in this process. A confined reader compiled it in a copy; the output then
    # reads the staged copies (the same bytes), which the output's check decoded here.
    here = _compiled_in_this_process()
    if kind == "mjcf":
        parsed = _take_parsed(path)
        if parsed is not None:
            model, folder, meshdir, files = parsed
            if here:
                _SOURCE_MESHES[id(model)] = _mesh_files(folder, meshdir, files)
            return lambda: model
    roots = source_read_roots(path, kind, options)
    from robotwright.parsers.api import prepare_read

    prepare_read()
    try:
        call = start_confined(
            _compile_source, Path(path), kind, options, roots=roots, what=str(path)
        )
    except Exception:  # noqa: BLE001 - any refusal: MuJoCo has no model to compare with
        return lambda: None

    def finish() -> mujoco.MjModel | None:
        try:
            compiled = call()
        except Exception:  # noqa: BLE001 - as above
            return None
        if compiled is None:
            return None
        model, meshes = compiled
        if meshes is not None and here:
            _SOURCE_MESHES[id(model)] = meshes
        return model

    return finish


def _compiled_in_this_process() -> bool:
    """Whether untrusted files are compiled in this process (no confined reader)."""
    from robotwright._confine import confinement, in_confined_copy

    return in_confined_copy() or not confinement().startswith("landlock")


def _compile_source(
    path: Path, kind: str, options: dict
) -> tuple[mujoco.MjModel, tuple[str, str, dict] | None] | None:
    """:func:`source_model`'s compile, run confined: the model and, for MJCF, its mesh
    files (see :func:`_mesh_files`)."""
    from robotwright.parsers.reference import compile_urdf, urdf_for_mujoco

    try:
        if kind == "mjcf":
            spec = mujoco.MjSpec.from_file(str(path))
            model = spec.compile()
            files = _cacheable_mesh_files(spec)
            meshes = _mesh_files(spec.modelfiledir or "", spec.compiler.meshdir or "", files)
            return model, meshes
        compiler = {
            k: options[k]
            for k in ("balance_inertia", "bound_mass", "bound_inertia")
            if k in options
        }
        text = urdf_for_mujoco(
            path,
            options.get("package_map"),
            inertia_from_geoms=options.get("inertia_from_geoms", "auto"),
            **compiler,
        )
        fuse = options.get("fixed_joints", "keep") == "merge"
        floating = bool(options.get("floating_base"))
        return compile_urdf(text, options.get("density"), fuse_static=fuse, floating=floating), None
    except Exception:  # noqa: BLE001 - any refusal: MuJoCo has no model to compare with
        return None


def _file_key(path: str | Path) -> tuple[int, str] | None:
    """Size and SHA-256 of a file (None when unreadable): a copy has the same key."""

    try:
        data = Path(path).read_bytes()
    except OSError:
        return None
    return len(data), hashlib.sha256(data).hexdigest()


#: id of a source model compiled by :func:`source_model` -> its mesh files (see
#: :func:`_mesh_files`); taken by the proof that compiles the output next.
_SOURCE_MESHES: dict[int, tuple[str, str, dict[tuple[int, str], str]]] = {}


def _mesh_files(
    folder: str, meshdir: str, files: Iterable[str]
) -> tuple[str, str, dict[tuple[int, str], str]]:
    """The folders and mesh file names of an MJCF as MuJoCo read them: its model folder,
    its mesh folder, and per file content (size, SHA-256) the name as written."""
    import os

    base = Path(folder or ".") / meshdir
    names: dict[tuple[int, str], str] = {}
    for file in files:
        if file and not os.path.isabs(file):
            key = _file_key(base / file)
            if key is not None:
                names.setdefault(key, file)
    return folder, meshdir, names


def _mesh_sources(hrdf: HRDF) -> list[Path]:
    """The files the HRDF's meshes are read from, for :func:`_compile_with_same_files`;
    a mesh whose file cannot be found is left out (the compile that needs it fails)."""
    originals = []
    for m in hrdf.meshes:
        try:
            originals.append(hrdf.mesh_source(m))
        except Exception:  # noqa: BLE001 - an unreadable mesh fails the compile
            continue
    return originals


def _compile_with_same_files(
    xml: str,
    originals: Iterable[Path],
    discard_visual: bool = False,
    source: tuple[str, str, dict[tuple[int, str], str]] | None = None,
) -> mujoco.MjModel:
    """Compile ``xml``; a mesh file with the same bytes as one of ``originals`` (a copy or
    a link the writer made) is read through that path, or, given the ``source``'s mesh
    files (:func:`_mesh_files`), by the name the source's compile read it by: MuJoCo
    caches a compiled mesh by that name, so the values compared are the same and the
    second processing of every mesh (most of a compile) is saved. ``discard_visual``:
    compile as MuJoCo's URDF import does (``discardvisual``: geoms that neither collide
    nor carry mass left out)."""
    by_key: dict[tuple[int, str], str] = {}
    for p in originals:
        key = _file_key(p)
        if key is not None:
            by_key.setdefault(key, str(p))
    from robotwright._mjspec_cache import compiled

    folder, meshdir, names = source or ("", "", {})

    def read_as_the_source(spec: mujoco.MjSpec) -> None:
        if discard_visual:
            spec.compiler.discardvisual = True
        # Where MuJoCo reads each file (the writer may give a mesh folder); every file is
        # then given as an absolute path or, read as the source read it, by its name.
        own = Path(spec.modelfiledir or ".") / (spec.compiler.meshdir or "")
        relative = False
        for mesh in spec.meshes:
            if mesh.file:
                path = own / mesh.file
                key = _file_key(path)
                if key is not None and key in names:
                    mesh.file = names[key]
                    relative = True
                else:
                    absolute = str(path.absolute())
                    mesh.file = by_key.get(key, absolute) if key else absolute
        if relative:
            # Other files, read from the writer's folders, by absolute paths.
            home = Path(spec.modelfiledir or ".")
            for tex in spec.textures:
                if tex.file:
                    tex.file = str((home / (spec.compiler.texturedir or "") / tex.file).absolute())
            for other in (*spec.hfields, *spec.skins):
                if other.file:
                    other.file = str((home / other.file).absolute())
            spec.compiler.texturedir = ""
        spec.modelfiledir, spec.compiler.meshdir = (folder, meshdir) if relative else ("", "")

    return compiled(xml, read_as_the_source)


def result_model(
    hrdf: HRDF,
    out_kind: str,
    work_dir: Path | None,
    *,
    discard_visual: bool = False,
    source: mujoco.MjModel | None = None,
) -> tuple[mujoco.MjModel, list[str]]:
    """What the output of ``hrdf`` compiles to, and the notes its writer gives: an HRDF
    folder saved and read back (into ``work_dir``), then generated as MJCF; an MJCF as
    ``export`` writes it; a URDF as MuJoCo imports it. ``discard_visual``: the MJCF
    compiled as MuJoCo compiles a URDF (visual geoms left out), to compare with a URDF
    source. ``source``: the source as :func:`source_model` compiled it (its meshes are
    read by the same names, from MuJoCo's cache)."""
    files = _SOURCE_MESHES.pop(id(source), None) if source is not None else None
    import dataclasses
    import tempfile
    import warnings

    from robotwright.proof.roundtrip.sides import our_mjcf_text, our_urdf_model

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if out_kind == "urdf":
            model = our_urdf_model(hrdf)
        else:
            originals = _mesh_sources(hrdf)
            if out_kind == "mjcf":
                model = _compile_with_same_files(
                    our_mjcf_text(hrdf), originals, discard_visual, files
                )
            else:
                from robotwright.hrdf.model import HRDF as _HRDF

                with tempfile.TemporaryDirectory(prefix="proof-", dir=work_dir) as tmp:
                    folder = Path(tmp) / "robot"
                    hrdf.save(folder)
                    loaded = _HRDF.from_dir(folder, asset_roots=hrdf.asset_roots)
                    # named after the folder it is read from; under the robot's own name
                    # the text is the one the export's check parsed (parsed once)
                    loaded = dataclasses.replace(loaded, name=hrdf.name)
                    model = _compile_with_same_files(
                        our_mjcf_text(loaded), originals, discard_visual, files
                    )
    return model, [str(w.message) for w in caught]
