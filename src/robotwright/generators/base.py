"""``GeneratorBase``: the lifecycle shared by every generator (hurodes' API).

A generator is constructed without data (``__init__``), loads its input (``load``),
builds an XML tree on ``xml_root`` (``generate``) and writes it (``export``). ``clean``
undoes ``load`` (and calls ``destroy``); ``destroy`` undoes ``generate`` only.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from abc import ABC, abstractmethod
from pathlib import Path
from typing import Any

from robotwright._atomic import atomic_files, check_output_path, write_text_atomic
from robotwright._names import file_stem
from robotwright._progress import steps
from robotwright.errors import GeneratorError
from robotwright.generators.xmlfmt import to_xml_string

#: Folder (next to the exported file) that ``export(copy_meshes=True)`` copies meshes to.
MESH_COPY_DIR = "meshes"


class GeneratorBase(ABC):
    """Abstract generator: ``xml_root``, ``loaded``, ``load``, ``generate``, ``export``,
    ``clean``, ``destroy``; subclasses implement ``_xml_root_init``, ``_load`` and
    ``_generate``.

    Attributes:
        output_dir: folder the XML is meant to be written to. Relative mesh paths are
            relative to it; ``export(file_path)`` sets it to ``file_path``'s folder for
            the duration of the call. When it is ``None`` (plain ``generate()``), mesh
            paths are absolute so the string loads from anywhere.
    """

    def __init__(self) -> None:
        self._xml_root: ET.Element | None = None
        self._loaded = False
        self._generated = False
        self.output_dir: Path | None = None
        # Absolute source mesh path -> absolute path of its copy (export(copy_meshes=True)).
        self._mesh_copy: dict[Path, Path] = {}

    # -- state --------------------------------------------------------------------------
    @property
    def loaded(self) -> bool:
        """True once ``load()`` succeeded (and until ``clean()``)."""
        return self._loaded

    @property
    def generated(self) -> bool:
        """True when ``xml_root`` holds a generated tree."""
        return self._generated and self._xml_root is not None

    @property
    def xml_root(self) -> ET.Element:
        """The root element of the generated tree (created empty on first access)."""
        if self._xml_root is None:
            self._xml_root = self._xml_root_init()
        return self._xml_root

    @abstractmethod
    def _xml_root_init(self) -> ET.Element:
        """A new, empty root element (``<mujoco>`` or ``<robot>``)."""

    def get_elem(self, tag: str) -> ET.Element:
        """The top-level element ``tag`` under ``xml_root``, created when absent."""
        found = self.xml_root.find(tag)
        if found is None:
            found = ET.SubElement(self.xml_root, tag)
        return found

    def _require_loaded(self, action: str) -> None:
        if not self.loaded:
            raise GeneratorError(
                f"{type(self).__name__}.{action}(): nothing is loaded; call load(...) first "
                f"or build the generator with a from_* class method"
            )

    # -- lifecycle ----------------------------------------------------------------------
    def load(self, *args: Any, **kwargs: Any) -> GeneratorBase:
        """Load the input (handled by ``_load``) and mark the generator loaded."""
        self._load(*args, **kwargs)
        self._loaded = True
        return self

    @abstractmethod
    def _load(self, *args: Any, **kwargs: Any) -> None:
        """Take and check the input data."""

    def generate(self, **kwargs: Any) -> ET.Element:
        """Build the tree on ``xml_root`` from the loaded data and return it.

        Idempotent: a previous result is destroyed first, so calling it twice gives the
        same tree. Raises :class:`GeneratorError` when nothing is loaded.
        """
        self._require_loaded("generate")
        self.destroy()
        root = self.xml_root
        self._generate(**kwargs)
        self._generated = True
        return root

    @abstractmethod
    def _generate(self, **kwargs: Any) -> None:
        """Add the loaded data to ``xml_root``."""

    def clean(self) -> None:
        """Drop the loaded data and the generated tree: back to the just-constructed state."""
        self._clean()
        self._loaded = False
        self.destroy()

    def _clean(self) -> None:  # noqa: B027 - optional hook, empty by default
        """Subclass hook: forget what ``_load`` stored."""

    def destroy(self) -> None:
        """Drop the generated tree (``xml_root``); the loaded data stays."""
        self._xml_root = None
        self._generated = False
        self._destroy()

    def _destroy(self) -> None:  # noqa: B027 - optional hook, empty by default
        """Subclass hook: forget what ``_generate`` stored besides ``xml_root``."""

    # -- output -------------------------------------------------------------------------
    @property
    def xml_str(self) -> str:
        """The generated tree as an indented XML document."""
        if not self.generated:
            raise GeneratorError(f"{type(self).__name__}: nothing generated; call generate() first")
        return to_xml_string(self.xml_root)

    def mesh_sources(self) -> list[tuple[str, Path]]:
        """``(group, absolute path)`` of every mesh file the output references; ``group``
        names the robot (used as sub-folder when meshes are copied)."""
        return []

    def export(
        self,
        file_path: str | Path | None = None,
        *,
        copy_meshes: bool = False,
        meshes_in_place: bool = False,
        **kwargs: Any,
    ) -> str:
        """Generate (from scratch) and return the XML string; write it when ``file_path``
        is given.

        The file is written atomically (temporary file, then rename). Mesh references are
        relative to the file's folder when ``relative_mesh_path`` is true (the default),
        so the file loads as is. With ``copy_meshes=True`` the meshes are first copied
        under ``<folder>/meshes/<robot>/`` and the file references the copies, giving a
        self-contained folder. Meshes a parser staged in a temporary folder (a robot read
        from MJCF/URDF, see :mod:`robotwright.parsers.meshes`) are always copied: that
        folder goes away with the robot, unless ``meshes_in_place``.

        Args:
            file_path: where to write, or ``None`` to only return the string.
            copy_meshes: copy mesh files next to the output (needs ``file_path``).
            meshes_in_place: reference every mesh where it is, a parser's staged copy
                included: for a private file read at once while the robot is held (the
                MJCF a USD export converts), which the staging folder outlives.
            **kwargs: passed to ``generate``.
        """
        self._require_loaded("export")
        if copy_meshes and meshes_in_place:
            raise GeneratorError("export: copy_meshes and meshes_in_place exclude each other")
        if file_path is not None and self._uses_temporary_meshes() and not meshes_in_place:
            copy_meshes = True
        if copy_meshes and file_path is None:
            raise GeneratorError("export(copy_meshes=True) needs a file_path to copy next to")
        # The folder is resolved, not the file: a link at the output's name is replaced,
        # never written through.
        path = _output_path(file_path) if file_path is not None else None
        if path is not None:
            check_output_path(path)  # before any work: a folder, or a file as a parent
        saved_dir, saved_copy = self.output_dir, self._mesh_copy
        try:
            if path is not None:
                self.output_dir = path.parent
            if copy_meshes and path is not None:
                self._mesh_copy = _plan_mesh_copies(self.mesh_sources(), path.parent)
            self.generate(**kwargs)
            text = self.xml_str
            if path is not None and self._mesh_copy:
                # All or nothing: the copies and the file are staged, then moved into place
                # (the file last, so it never names a mesh that is not there yet).
                with atomic_files(path.parent) as staged:
                    copies = self._mesh_copy.items()
                    for src, dst in steps(copies, len(copies), "meshes copied"):
                        if src != dst:
                            staged.copy(src, dst.relative_to(path.parent))
                    staged.write_text(path.name, text)
            elif path is not None:
                write_text_atomic(path, text)
        finally:
            self.output_dir, self._mesh_copy = saved_dir, saved_copy
        return text

    def _uses_temporary_meshes(self) -> bool:
        """Whether a robot of this generator (or of its members) has its meshes in a
        parser's temporary staging folder."""
        hrdf = getattr(self, "hrdf", None)
        if hrdf is not None and getattr(hrdf, "temp_assets", None) is not None:
            return True
        members = getattr(self, "generators", None)
        return isinstance(members, dict) and any(
            g._uses_temporary_meshes() for g in members.values()
        )

    # -- mesh paths ---------------------------------------------------------------------
    def _mesh_file(self, src: str) -> str:
        """Absolute path the output should reference for source mesh ``src``."""
        if not self._mesh_copy:
            return src
        return str(self._mesh_copy.get(Path(src), src))

    def _reference(self, path: str | Path, relative: bool) -> str:
        """How the output names ``path``: relative to ``output_dir`` when asked and known,
        absolute otherwise (always with ``/`` separators)."""
        if relative and self.output_dir is not None:
            return os.path.relpath(path, self.output_dir).replace(os.sep, "/")
        return str(path).replace(os.sep, "/")


def _output_path(file_path: str | Path) -> Path:
    """``file_path`` made absolute with its folder's links resolved (its own name kept)."""
    p = Path(file_path)
    return p.absolute().parent.resolve() / p.name


def _plan_mesh_copies(sources: list[tuple[str, Path]], out_dir: Path) -> dict[Path, Path]:
    """Map each source mesh to ``out_dir/meshes/<group>/<file name>`` (suffix on clashes;
    ``<group>`` is the robot name made a safe folder name by
    :func:`~robotwright._names.file_stem`)."""
    plan: dict[Path, Path] = {}
    taken: set[Path] = set()
    for group, src in sources:
        if src in plan:
            continue
        if not src.is_file():
            raise GeneratorError(f"mesh file '{src}' does not exist (robot '{group}')")
        folder = out_dir / MESH_COPY_DIR / file_stem(group, "robot")
        dst = folder / src.name
        n = 1
        while dst in taken:
            dst = folder / f"{src.stem}_{n}{src.suffix}"
            n += 1
        taken.add(dst)
        plan[src] = dst
    return plan
