"""``HRDFMixin``: loads an :class:`~robotwright.hrdf.HRDF` robot into a generator.

Generators themselves do not depend on HRDF (other producers can feed them); this mixin
adds the HRDF input: ``load(hrdf)``, ``from_hrdf``, ``from_hrdf_path``, ``from_robot_name``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, TypeVar

from robotwright.errors import GeneratorError, HRDFError
from robotwright.generators.base import GeneratorBase
from robotwright.hrdf.model import HRDF, MeshGeom

T = TypeVar("T", bound="HRDFMixin")


class HRDFMixin:
    """Adds an ``hrdf`` input to a :class:`GeneratorBase` subclass.

    The HRDF is read, never modified: generation options such as a name prefix only
    change the output.
    """

    hrdf: HRDF | None

    def __init__(self, **kwargs: Any) -> None:
        if not isinstance(self, GeneratorBase):
            raise TypeError(f"{type(self).__name__}: HRDFMixin needs a GeneratorBase subclass")
        super().__init__(**kwargs)
        self.hrdf = None
        self._mesh_abs: dict[tuple[str | None, str], str] = {}

    def _load(self, hrdf: HRDF | None = None, *, validate: bool = True, **kwargs: Any) -> None:
        """Take ``hrdf`` after checking it (every problem listed in one :class:`HRDFError`).

        ``validate=False`` skips the check, for a robot that ``HRDF.from_dir`` has just
        read (it runs the same checks)."""
        if kwargs:
            raise GeneratorError(
                f"{type(self).__name__}.load(): unexpected argument(s) {sorted(kwargs)}; "
                "expected load(hrdf)"
            )
        if not isinstance(hrdf, HRDF):
            raise GeneratorError(
                f"{type(self).__name__}.load(): expected an HRDF robot, got {type(hrdf).__name__}"
            )
        if validate:
            from robotwright.hrdf.validate import check_model

            # Table numbers are not checked finite here (it would double the check's
            # cost on every export): MJCF takes inf as MuJoCo does, masses and inertias
            # are checked finite all the same, and a saved folder is checked in full.
            problems = check_model(hrdf, check_files=False, finite=False)
            errors = [p for p in problems if p.severity == "error"]
            if errors:
                raise HRDFError(errors, f"robot '{hrdf.name}' cannot be generated")
        self.hrdf = hrdf
        self._mesh_abs = {}
        self._on_hrdf_loaded(hrdf)

    def _on_hrdf_loaded(self, hrdf: HRDF) -> None:
        """Hook for generator bases that take settings from the robot (e.g. simulator)."""

    def _clean(self) -> None:
        self.hrdf = None
        self._mesh_abs = {}

    def mesh_abspath(self, mesh: MeshGeom) -> str:
        """Absolute, normalised path of a mesh geom's file (as ``HRDF.mesh_path``; cached
        per load, kept as a string because generation uses it for every mesh row).

        That the path stays inside the robot folder was checked when the robot was
        loaded (``check_model``); :meth:`mesh_sources`, which lists the files that
        ``export(copy_meshes=True)`` copies, checks it again.
        """
        key = (mesh.file, mesh.name)
        path = self._mesh_abs.get(key)
        if path is None:
            hrdf = self.loaded_hrdf
            rel = (
                mesh.file
                if mesh.file is not None
                else (f"meshes/{mesh.name}.{hrdf.meta.mesh_file_type}")
            )
            if hrdf.root_dir is not None and not os.path.isabs(rel):
                rel = os.path.join(hrdf.root_dir, rel)
            path = os.path.abspath(rel)
            self._mesh_abs[key] = path
        return path

    def mesh_sources(self) -> list[tuple[str, Path]]:
        """``(robot name, absolute path)`` of each distinct mesh file.

        Raises:
            robotwright.errors.UnsafePathError: a file leads out of the robot folder now
                (see :meth:`HRDF.mesh_source`): the copier checks again.
        """
        hrdf = self.loaded_hrdf
        seen: dict[str, None] = {}
        for m in hrdf.meshes:
            path = self.mesh_abspath(m)
            if path not in seen:
                hrdf.mesh_source(m)
                seen[path] = None
        return [(hrdf.name, Path(p)) for p in seen]

    @property
    def loaded_hrdf(self) -> HRDF:
        """The loaded robot (:class:`GeneratorError` when nothing is loaded)."""
        if self.hrdf is None:
            raise GeneratorError(f"{type(self).__name__}: no HRDF loaded")
        return self.hrdf

    @classmethod
    def from_hrdf(cls: type[T], hrdf: HRDF, **kwargs: Any) -> T:
        """A generator loaded with ``hrdf`` (``kwargs`` go to the constructor)."""
        instance = cls(**kwargs)
        instance.load(hrdf)  # type: ignore[attr-defined]
        return instance

    @classmethod
    def from_hrdf_path(cls: type[T], hrdf_path: str | Path, **kwargs: Any) -> T:
        """A generator loaded with the HRDF folder at ``hrdf_path`` (anywhere on disk)."""
        instance = cls(**kwargs)
        instance.load(HRDF.from_dir(hrdf_path), validate=False)  # type: ignore[attr-defined]
        return instance

    @classmethod
    def from_robot_name(cls: type[T], robot_name: str, **kwargs: Any) -> T:
        """A generator loaded with robot ``robot_name``: ``$HURODES_ASSETS_PATH/robots/<name>``,
        then the bundled robots."""
        instance = cls(**kwargs)
        instance.load(HRDF.from_robot_name(robot_name), validate=False)  # type: ignore[attr-defined]
        return instance
