"""Where a file path read from a robot may point: one containment check.

Robot folders, MJCF and URDF files are shared on the web, so a path written inside them
(an HRDF ``mesh.csv`` ``file`` cell or mesh ``name``, an MJCF ``<mesh file>``,
``meshdir`` or ``<include>``, a URDF ``<mesh filename>``) is untrusted: it must not make
robotwright read, compile or copy a file from elsewhere on disk (``/etc/passwd``,
``~/.ssh/id_rsa``). Every reader (HRDF loading and validation, the MJCF and URDF
parsers, the Things MJCF reader) and every copier (``HRDF.save``, generator
``export(copy_meshes=True)``) uses :func:`resolve_inside`:

- the path is resolved the way it will be opened: relative to its base folder, ``..``
  collapsed and symbolic links followed, so a link inside ``meshes/`` that points to
  ``/etc``, or a ``meshes/`` that is itself such a link, counts as outside;
- the resolved path must lie inside the robot's folder, or inside a folder the caller
  trusts explicitly: the ``asset_roots`` argument of the Python readers, a
  :func:`trusted_asset_roots` block, or ``robotwright --asset-root DIR`` on the command
  line (which opens such a block around the command).

Robots built in memory by Python code (no folder) are trusted: their absolute mesh paths
are the caller's own.
"""

from __future__ import annotations

import os
import re
import stat
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from types import SimpleNamespace
from typing import Any

from robotwright._assets import check_asset_file, check_declared_sizes
from robotwright._inputs import MAX_XML_BYTES, _kind, read_bytes
from robotwright.errors import InputFileError, UnsafePathError

__all__ = [
    "check_mjcf_includes",
    "check_mjcf_spec",
    "check_regular",
    "checked_mjcf_spec",
    "resolve_inside",
    "trusted_asset_roots",
    "trusted_roots",
]

PathLike = str | os.PathLike[str]

_TRUSTED: ContextVar[tuple[Path, ...]] = ContextVar("robotwright_trusted_roots", default=())


def resolve_folder(folder: PathLike, label: str) -> Path:
    """``folder`` (``~`` expanded) resolved, symbolic links followed.

    Raises:
        UnsafePathError: it cannot be resolved (a link loop) or is not an existing
            folder; the message starts with ``label`` (how the caller names the folder).
    """
    try:
        resolved = Path(folder).expanduser().resolve()
    except (OSError, RuntimeError) as exc:
        raise UnsafePathError(f"{label} cannot be resolved: {exc}") from None
    if not resolved.is_dir():
        raise UnsafePathError(f"{label} is not a folder")
    return resolved


def _root(folder: PathLike) -> Path:
    return resolve_folder(folder, f"{folder}: trusted asset root")


@contextmanager
def trusted_asset_roots(roots: Iterable[PathLike]) -> Iterator[tuple[Path, ...]]:
    """Within the block, paths that resolve inside one of ``roots`` are accepted by every
    reader and copier, in addition to the robot's own folder (opt-in for shared mesh
    libraries outside the robot folder). Yields every root trusted in the block.

    Raises:
        UnsafePathError: a root is not an existing folder.
    """
    token = _TRUSTED.set(_TRUSTED.get() + tuple(_root(r) for r in roots))
    try:
        yield _TRUSTED.get()
    finally:
        _TRUSTED.reset(token)


def trusted_roots(extra: Iterable[PathLike] | None = None) -> tuple[Path, ...]:
    """The folders trusted here: ``extra`` (resolved) and those of the enclosing
    :func:`trusted_asset_roots` blocks."""
    return tuple(_root(r) for r in extra or ()) + _TRUSTED.get()


def resolve_inside(
    file: PathLike,
    *,
    base: PathLike,
    root: PathLike,
    trusted: Sequence[Path] | None = None,
    what: str = "the robot folder",
    hint: str = " (a folder outside can be trusted with asset_roots / --asset-root)",
) -> Path:
    """The resolved path of ``file`` (a relative one is taken from folder ``base``),
    which must lie inside folder ``root`` or a trusted folder.

    Args:
        file: the path as written in the input.
        base: the folder a relative ``file`` is relative to.
        root: the folder the path must stay inside (the robot's folder).
        trusted: resolved folders also allowed; ``None``: :func:`trusted_roots`.
        what: how messages name ``root``.
        hint: appended to the message (how to trust a folder).

    Raises:
        UnsafePathError: the path leaves ``root`` (the message says where it resolves
            to, and whether a symbolic link took it there), cannot be resolved (a
            link loop) or holds a NUL character. The caller adds the file and element
            the path came from.
    """
    if "\0" in os.fspath(file):  # no file name holds one; the OS refuses it outright
        raise UnsafePathError(
            f"{ascii(os.fspath(file))}: contains a NUL character; expected a file path"
        )
    given = Path(file)
    full = given if given.is_absolute() else Path(base) / given
    try:
        resolved = full.resolve()
        root_path = Path(root).resolve()
    except (OSError, RuntimeError) as exc:  # a symbolic link loop
        raise UnsafePathError(f"'{file}': cannot be resolved: {exc}") from None
    if resolved.is_relative_to(root_path):
        return resolved
    allowed = trusted_roots() if trusted is None else trusted
    if any(resolved.is_relative_to(t) for t in allowed):
        return resolved
    lexical = Path(os.path.normpath(os.path.abspath(full)))
    how = (
        " through a symbolic link"
        if lexical.is_relative_to(os.path.abspath(root)) or lexical.is_relative_to(root_path)
        else ""
    )
    raise UnsafePathError(
        f"'{file}' resolves{how} to {resolved}, outside {what} {root_path}; expected a path "
        f"inside it{hint}"
    )


def check_regular(path: Path) -> Path:
    """``path`` if it is a regular file or does not exist (its reader then reports it).

    MuJoCo and mesh readers open the files a model names with a blocking ``open``: a
    FIFO named as a mesh would hang them, and ``/dev/zero`` would be read until memory
    runs out. ``stat`` answers without opening the file.

    Raises:
        UnsafePathError: ``path`` is a FIFO, a device, a socket or a folder.
    """
    try:
        mode = path.stat().st_mode
    except (OSError, ValueError):
        return path
    if not stat.S_ISREG(mode):
        raise UnsafePathError(f"'{path}' is {_kind(mode)}; expected a regular file")
    return path


# ------------------------------------------------------------------------------- MJCF

#: MJCF asset elements whose files MuJoCo reads at compile time, and the compiler folder
#: their relative paths are taken from (``assetdir`` sets both).
_SPEC_ASSETS = (("meshes", "mesh", "meshdir"), ("hfields", "hfield", "meshdir"))
_SPEC_ASSETS += (("skins", "skin", "meshdir"), ("textures", "texture", "texturedir"))
#: How deep ``<include>`` may nest (MuJoCo refuses include cycles itself, later).
MAX_INCLUDE_DEPTH = 20


def mjcf_asset_file(value: str, folder: str | None, *, strip: bool) -> Path:
    """The path MuJoCo opens for an asset's file attribute ``value`` (a mesh, height
    field, skin or texture file), before it is taken from the model's folder: with
    ``<compiler strippath="true">`` the file name alone (MuJoCo cuts at the last ``/``
    or ``\\``), else the value; an absolute one as is, a relative one under ``folder``
    (``meshdir``/``texturedir``). The one rule that both the checks
    (:func:`check_mjcf_spec`) and the mesh stager of the MJCF reader use, so that the
    path checked is the path read."""
    file = re.split(r"[/\\]", value)[-1] if strip else value
    return Path(folder or "") / file


def _element(tag: str, name: str | None, attr: str, value: str) -> str:
    named = f' name="{name}"' if name else ""
    return f'<{tag}{named} {attr}="{value}">'


def _compiler_dirs(tree: Any) -> list[str]:
    out = []
    for el in tree.iter("compiler"):
        out += [el.get(a) for a in ("meshdir", "texturedir", "assetdir") if el.get(a)]
    return out


def check_mjcf_includes(
    tree: Any,
    *,
    source: str,
    model_dir: PathLike,
    root: PathLike,
    trusted: Sequence[Path] | None = None,
    _depth: int = 0,
) -> list[Path]:
    """Check what MuJoCo's XML parser itself opens, before it runs: ``<include file>``
    (each included file is read safely, without entities, and checked the same way) and
    the files of other elements read while parsing (``<flexcomp file>``, ``<model
    file>``), the latter taken both from ``model_dir`` and from every compiler folder.

    Args:
        tree: the root element of the (already safely parsed) main file.
        source: the main file, for messages.
        model_dir: the folder of the main file (MuJoCo resolves includes from it).
        root: the folder every path must stay inside (besides trusted ones).

    Returns:
        The folders of the sub-models (``<asset><model file>``), nested ones too: their
        meshes are named from there.

    Raises:
        UnsafePathError: naming the file and element; also for an included file that is
            not well-formed or unsafe XML, and for includes nested too deep.
    """

    sub_models: list[Path] = []
    pending = [(tree, source, _depth)]
    dirs = [""]
    included: set[Path] = set()
    while pending:
        node, where, depth = pending.pop()
        dirs += _compiler_dirs(node)
        for el in node.iter():
            if not isinstance(el.tag, str):
                continue
            if el.tag == "include":
                value = el.get("file") or ""
                elem = _element("include", None, "file", value)
                try:
                    path = resolve_inside(value, base=model_dir, root=root, trusted=trusted)
                except UnsafePathError as exc:
                    raise UnsafePathError(exc.reason, file=where, element=elem) from None
                if depth + 1 > MAX_INCLUDE_DEPTH:
                    raise UnsafePathError(
                        f"includes nest deeper than {MAX_INCLUDE_DEPTH} levels",
                        file=where,
                        element=elem,
                    )
                if path in included:
                    # MuJoCo refuses a file included twice; expanding every occurrence
                    # first would take exponential time on a fan-out of includes.
                    raise UnsafePathError(
                        f"'{path}' is included more than once; MuJoCo includes a file once",
                        file=where,
                        element=elem,
                    )
                included.add(path)
                child = _read_named_xml(path, "the included file", where, elem)
                pending.append((child, str(path), depth + 1))
                continue
            if el.tag in ("size", "replicate", "flexcomp"):
                check_declared_counts(el, where)
            if el.tag == "hfield" and not el.get("file"):
                # MuJoCo's XML reader allocates the declared samples as it reads the
                # element (3.6 GB for 30,000 x 30,000): refuse an oversized one before.
                _check_declared_hfield(el, where)
            if el.tag in ("mesh", "hfield", "skin", "texture"):
                continue  # read at compile time: see check_mjcf_spec
            for attr, value in el.attrib.items():
                if attr.startswith("file") and value:
                    for folder in dirs:
                        elem = _element(el.tag, el.get("name"), attr, value)
                        try:
                            found = check_regular(
                                resolve_inside(
                                    Path(folder) / value, base=model_dir, root=root, trusted=trusted
                                )
                            )
                        except UnsafePathError as exc:
                            raise UnsafePathError(exc.reason, file=where, element=elem) from None
                        _check_size(found, where, elem)
                        if el.tag == "model" and found.is_file():
                            sub_models.append(found.parent)
                            sub_models += _check_sub_model(found, where, elem, root, trusted, depth)
    return sub_models


def _read_named_xml(path: Path, what: str, where: str, elem: str) -> Any:
    """The root element of the XML file ``path`` that ``elem`` of ``where`` names, read
    safely (regular file, size cap: a FIFO or /dev/zero never blocks; no entities).

    Raises:
        UnsafePathError: naming ``where`` and ``elem``.
    """
    import defusedxml
    import defusedxml.ElementTree as SafeET

    try:
        return SafeET.fromstring(read_bytes(path, MAX_XML_BYTES))
    except InputFileError as exc:
        raise UnsafePathError(exc.reason, file=where, element=elem) from None
    except (defusedxml.DefusedXmlException, SafeET.ParseError, OSError) as exc:
        raise UnsafePathError(
            f"{what} cannot be read as safe XML: {exc}", file=where, element=elem
        ) from None


def _check_sub_model(
    path: Path, where: str, elem: str, root: PathLike, trusted: Sequence[Path] | None, depth: int
) -> list[Path]:
    """An ``<asset><model file>`` sub-model is a model of its own: MuJoCo reads its
    includes from its folder and its meshes and textures with its own ``<compiler
    meshdir/texturedir/assetdir>``. Check them so, inside the same root; returns the
    folders of its own sub-models."""
    import mujoco

    if depth + 1 > MAX_INCLUDE_DEPTH:
        raise UnsafePathError(
            f"sub-models nest deeper than {MAX_INCLUDE_DEPTH} levels", file=where, element=elem
        )
    tree = _read_named_xml(path, "the sub-model", where, elem)
    here = {"source": str(path), "model_dir": path.parent, "root": root, "trusted": trusted}
    try:
        nested = check_mjcf_includes(tree, **here, _depth=depth + 1)
        try:
            spec = mujoco.MjSpec.from_file(str(path))
        except ValueError:
            return nested  # MuJoCo refuses the sub-model: it reads none of its assets
        check_mjcf_spec(spec, **here)
    except UnsafePathError as exc:
        raise UnsafePathError(str(exc), file=where, element=elem) from None
    return nested


#: Bytes MuJoCo allocates per replicated body and per flexcomp point at least (an
#: estimate on the low side): the counts a file may declare follow the reader's memory
#: budget (``--max-reader-mb``).
_BYTES_PER_REPLICA = 40_000
_BYTES_PER_FLEX_POINT = 4_000
_USER_FIELDS = (
    "nuser_body", "nuser_jnt", "nuser_geom", "nuser_site", "nuser_cam",
    "nuser_tendon", "nuser_actuator", "nuser_sensor",
)  # fmt: skip


def _declared_int(el: Any, attr: str) -> int:
    try:
        return int(float(el.get(attr) or 0))
    except (ValueError, OverflowError):
        return 0  # not a number: MuJoCo's reader refuses it


def check_declared_counts(el: Any, source: str) -> None:
    """Refuse a ``<size>``, ``<replicate>`` (with the ``<replicate>`` elements nested in
    it) or ``<flexcomp>`` element declaring more than the confined reader's memory budget
    holds, before MuJoCo's reader allocates it: a 200-byte file with ``<size
    nuserdata="3e8">`` asks for 2.4 GB.

    Raises:
        InputFileError: naming ``source``, the element, the count and the override.
    """
    from robotwright._reader_budget import reader_memory_bytes

    budget = reader_memory_bytes()
    hint = "(--max-reader-mb raises the reader's memory budget)"

    def refuse(what: str, count: int, need: int) -> None:
        raise InputFileError(
            source,
            f"<{el.tag}>: {what} asks for {count:,} ({need / 10**6:,.0f} MB or more), over "
            f"the reader's memory budget of {budget / 10**6:,.0f} MB {hint}",
        )

    if el.tag == "size":
        for attr in ("nuserdata", *_USER_FIELDS):
            count = _declared_int(el, attr)
            if count * 8 > budget:
                refuse(attr, count, count * 8)
    elif el.tag == "replicate":
        copies = _replicas(el)
        if copies * _BYTES_PER_REPLICA > budget:
            refuse("count (nested replicates multiplied)", copies, copies * _BYTES_PER_REPLICA)
    elif el.tag == "flexcomp":
        counts = (el.get("count") or "").split()
        points = 1
        for text in counts[:3]:
            try:
                points *= max(1, int(float(text)))
            except (ValueError, OverflowError):
                return
        if points * _BYTES_PER_FLEX_POINT > budget:
            refuse("count (points)", points, points * _BYTES_PER_FLEX_POINT)


def _replicas(el: Any) -> int:
    """Copies a ``<replicate>`` makes of its deepest content: its count times the largest
    product below it."""
    below = [_replicas(child) for child in el if getattr(child, "tag", None) == "replicate"]
    return max(1, _declared_int(el, "count")) * max([1, *below])


def _check_declared_hfield(el: Any, source: str) -> None:
    """:func:`robotwright._assets.check_declared_sizes` on an ``<hfield nrow ncol>``
    element of the XML (the same limit and message as on the parsed model)."""
    try:
        nrow, ncol = int(el.get("nrow") or 0), int(el.get("ncol") or 0)
    except ValueError:
        return  # not a number: MuJoCo's reader refuses it
    hfield = SimpleNamespace(file="", nrow=nrow, ncol=ncol, name=el.get("name") or "")
    check_declared_sizes(SimpleNamespace(hfields=[hfield], textures=[]), source=source)


def check_mjcf_spec(
    spec: Any,
    *,
    source: str,
    model_dir: PathLike,
    root: PathLike,
    trusted: Sequence[Path] | None = None,
) -> None:
    """Check every file a ``mujoco.MjSpec`` reads when compiled (mesh, height field, skin
    and texture files, cube faces included) as MuJoCo resolves them: an absolute file as
    is, else under ``meshdir``/``texturedir`` (itself absolute, or under ``model_dir``);
    with ``strippath`` the file name only.

    Raises:
        UnsafePathError: naming ``source`` and the element.
    """
    compiler = getattr(spec, "compiler", None)
    strip = bool(getattr(spec, "strippath", False))
    for group, tag, dir_attr in _SPEC_ASSETS:
        folder = getattr(compiler, dir_attr, None)
        if folder is None:
            folder = getattr(spec, dir_attr, "")
        for item in getattr(spec, group, []):
            files = [("file", item.file)]
            if tag == "texture":
                files += [(f"cubefiles[{k}]", f) for k, f in enumerate(item.cubefiles)]
            for attr, value in files:
                if not value:
                    continue
                elem = _element(tag, item.name, attr, value)
                try:
                    found = check_regular(
                        resolve_inside(
                            mjcf_asset_file(value, folder, strip=strip),
                            base=model_dir,
                            root=root,
                            trusted=trusted,
                        )
                    )
                except UnsafePathError as exc:
                    raise UnsafePathError(exc.reason, file=source, element=elem) from None
                _check_size(found, source, elem)
    # Sizes the model declares (height field samples, built-in textures) are allocated
    # when it compiles: refuse them over the same limit first.
    check_declared_sizes(spec, source=source)


def _check_size(path: Path, source: str, element: str) -> None:
    """The asset size cap (:func:`robotwright._assets.check_asset_file`) on a file
    named by ``element`` of ``source``: the message names all three."""
    try:
        check_asset_file(path)
    except InputFileError as exc:
        raise InputFileError(f"{source}: {element}: {exc.path}", exc.reason) from None


def checked_mjcf_spec(path: PathLike, *, trusted: Sequence[Path] | None = None) -> Any:
    """The ``mujoco.MjSpec`` of the MJCF file ``path``, after the checks every MJCF
    reader makes before MuJoCo opens a file: the XML is read safely (regular file, size
    cap, no entities), and every file it names (includes, meshes, textures, height
    fields) resolves inside the file's folder or a trusted one and is a regular file.

    Raises:
        UnsafePathError: a named file leaves the folder or is not a regular file (file
            and element named).
        robotwright.errors.ConversionError: the file itself is missing, not a regular
            file, too large, unsafe or not well-formed XML.
        ValueError: MuJoCo's parser refuses the file.
    """
    import mujoco

    from robotwright._xmlsafe import parse_xml

    path = Path(path)
    tree = parse_xml(path)
    folder = path.resolve().parent
    where = {"source": str(path), "model_dir": folder, "root": folder}
    check_mjcf_includes(tree, **where, trusted=trusted)
    spec = mujoco.MjSpec.from_file(str(path))
    check_mjcf_spec(spec, **where, trusted=trusted)
    # Keyframes are allocated when the model compiles: refuse a flood of them first.
    from robotwright._limits import keyframes_problem

    problem = keyframes_problem(max(len(spec.keys), spec.nkey))
    if problem is not None:
        raise InputFileError(path, problem)
    return spec
