"""World: the root of a Thing tree, its MJCF options, and the lazily built MuJoCo model."""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from robotwright._atomic import atomic_files, check_output_path
from robotwright.errors import RobotwrightError
from robotwright.things.attrs import Choice, Flag, Integer, Real, ThingAttributeError, Vector
from robotwright.things.base import BaseThing
from robotwright.things.registry import asset_epoch
from robotwright.things.xml_writer import write_mjcf

OPTION_ATTR: dict[str, Any] = {
    "timestep": Real(nonneg=True),
    "impratio": Real(nonneg=True),
    "tolerance": Real(nonneg=True),
    "ls_tolerance": Real(nonneg=True),
    "noslip_tolerance": Real(nonneg=True),
    "ccd_tolerance": Real(nonneg=True),
    "gravity": Vector(3),
    "wind": Vector(3),
    "magnetic": Vector(3),
    "density": Real(nonneg=True),
    "viscosity": Real(nonneg=True),
    "o_margin": Real(),
    "o_solref": Vector(2),
    "o_solimp": Vector(5),
    "o_friction": Vector(5),
    "integrator": Choice("Euler", "RK4", "implicit", "implicitfast"),
    "cone": Choice("pyramidal", "elliptic"),
    "jacobian": Choice("dense", "sparse", "auto"),
    "solver": Choice("PGS", "CG", "Newton"),
    "iterations": Integer(minimum=0),
    "ls_iterations": Integer(minimum=0),
    "noslip_iterations": Integer(minimum=0),
    "ccd_iterations": Integer(minimum=0),
    "sdf_iterations": Integer(minimum=0),
    "sdf_initpoints": Integer(minimum=0),
}
_OPTION_DEFAULTS: dict[str, Any] = {
    "timestep": 0.002,
    "impratio": 1.0,
    "tolerance": 1e-8,
    "ls_tolerance": 0.01,
    "noslip_tolerance": 1e-6,
    "ccd_tolerance": 1e-6,
    "gravity": np.array([0.0, 0, -9.81]),
    "wind": np.zeros(3),
    "magnetic": np.array([0.0, -0.5, 0]),
    "density": 0.0,
    "viscosity": 0.0,
    "o_margin": 0.0,
    "o_solref": np.array([0.02, 1.0]),
    "o_solimp": np.array([0.9, 0.95, 0.001, 0.5, 2.0]),
    "o_friction": np.array([1.0, 1, 0.005, 0.0001, 0.0001]),
    "integrator": "Euler",
    "cone": "pyramidal",
    "jacobian": "auto",
    "solver": "Newton",
    "iterations": 100,
    "ls_iterations": 50,
    "noslip_iterations": 0,
    "ccd_iterations": 35,
    "sdf_iterations": 10,
    "sdf_initpoints": 40,
}


class ThingBuildError(RobotwrightError, ValueError):
    """MuJoCo rejected the model a World's Things describe."""


#: MJCF ``<flag>`` names (``disabled``/``enabled``), from MuJoCo's enums.
_DISABLE_FLAGS = frozenset(
    n[len("mjDSBL_") :].lower() for n in mujoco.mjtDisableBit.__members__ if n != "mjNDISABLE"
)
_ENABLE_FLAGS = frozenset(
    n[len("mjENBL_") :].lower() for n in mujoco.mjtEnableBit.__members__ if n != "mjNENABLE"
)
_COMPILER_ATTR: dict[str, Any] = {
    "autolimits": Flag(),
    "inertiafromgeom": Choice("false", "true", "auto"),
    "inertiagrouprange": Vector(2, integer=True),
    "settotalmass": Real(),
    "boundmass": Real(nonneg=True),
    "boundinertia": Real(nonneg=True),
    "balanceinertia": Flag(),
    "fusestatic": Flag(),
    "alignfree": Flag(),
    "discardvisual": Flag(),
}
_COMPILER_DEFAULTS: dict[str, Any] = {
    "autolimits": True,
    "inertiafromgeom": "auto",
    "inertiagrouprange": np.array([0, 5]),
    "settotalmass": -1.0,
    "boundmass": 0.0,
    "boundinertia": 0.0,
    "balanceinertia": False,
    "fusestatic": False,
    "alignfree": False,
    "discardvisual": False,
}


class World(BaseThing):
    """The root of a model: the worldbody's Things, physics options and assets.

    ``world.model`` / ``world.data`` compile the tree through ``mujoco.MjSpec`` on first
    use and again after any change in the tree (an attribute set, a Thing attached or
    detached); a rebuild starts from a fresh ``MjData``. ``world.step()`` advances it.

    Option attributes (``timestep`` in s, ``gravity`` in m/s^2, ``integrator``, ...) and
    compiler attributes (``autolimits``, ``inertiafromgeom``, ``settotalmass``, ...) are
    the MJCF ones. ``disabled``/``enabled`` are sets of MJCF ``<flag>`` names.
    ``assets`` lists materials/textures to write even when nothing refers to them;
    ``extra_xml`` holds MJCF sections the Things do not model (kept verbatim, see
    :mod:`robotwright.things.xml_reader`).
    """

    _NAMESPACE = None
    _TAG = "worldbody"
    _CHILD_KINDS = frozenset({"body", "geom", "site", "camera", "light", "raw", "sensor"})
    #: Sensors attached to the World measure MuJoCo's world body.
    _TARGET_AS = "body"
    _NEW_MUJOCO_ATTR = {**OPTION_ATTR, **_COMPILER_ATTR}
    _NEW_BLUEPRINTS_ATTR = {**OPTION_ATTR, **_COMPILER_ATTR}
    _NEW_DEFAULT_VALS = {**_OPTION_DEFAULTS, **_COMPILER_DEFAULTS}
    _NEW_NO_COPY_VALS = {"assets"}

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        object.__setattr__(self, "assets", list(kwargs.pop("assets", [])))
        object.__setattr__(self, "disabled", set(kwargs.pop("disabled", ())))
        object.__setattr__(self, "enabled", set(kwargs.pop("enabled", ())))
        object.__setattr__(self, "extra_xml", dict(kwargs.pop("extra_xml", {})))
        object.__setattr__(self, "_built", None)
        object.__setattr__(self, "_built_version", None)
        object.__setattr__(self, "_built_epoch", None)
        super().__init__(name=name, parent=parent, **kwargs)

    @property
    def bodies(self) -> list[Any]:
        return [c for c in self._children if c._NAMESPACE == "body"]

    def all_joints(self) -> list[Any]:
        return [t for t in self.walk() if t._NAMESPACE == "joint"]

    def all_geoms(self) -> list[Any]:
        return [t for t in self.walk() if t._NAMESPACE == "geom"]

    def set_all(self, kind: str, **values: Any) -> int:
        """Bulk edit over every Thing of namespace ``kind`` (see :meth:`Body.set_all`)."""
        from robotwright.things.body import Body

        return Body.set_all(self, kind, **values)  # type: ignore[arg-type]

    def copy(self, **kwargs: Any) -> World:
        new = super().copy(**kwargs)
        object.__setattr__(new, "assets", list(self.assets))
        object.__setattr__(new, "disabled", set(self.disabled))
        object.__setattr__(new, "enabled", set(self.enabled))
        object.__setattr__(new, "extra_xml", dict(self.extra_xml))
        return new  # type: ignore[return-value]

    # ------------------------------------------------------------------ MJCF
    def _compiler_xml(self) -> str:
        parts = ['angle="radian"']
        for key, spec in _COMPILER_ATTR.items():
            value = getattr(self, key)
            if not spec.equal(value, _COMPILER_DEFAULTS[key]):
                parts.append(f'{key}="{spec.format(value)}"')
        return f"<compiler {' '.join(parts)}/>"

    def _option_xml(self, writer: Any) -> str:
        parts = []
        for key, spec in OPTION_ATTR.items():
            value = getattr(self, key)
            if not spec.equal(value, _OPTION_DEFAULTS[key]):
                parts.append(f'{key}="{spec.format(value)}"')
        for kind, names, known in (
            ("disabled", self.disabled, _DISABLE_FLAGS),
            ("enabled", self.enabled, _ENABLE_FLAGS),
        ):
            unknown = sorted(str(f) for f in set(names) - known)
            if unknown:  # flag names are written as attribute names: vocabulary only
                raise ThingAttributeError(
                    f"{self._label()}: {kind} flags {unknown}: expected MuJoCo <flag> "
                    f"names, from {sorted(known)}"
                )
        flags = [f'{f}="disable"' for f in sorted(self.disabled)]
        flags += [f'{f}="enable"' for f in sorted(self.enabled)]
        if not parts and not flags:
            return ""
        head = f"<option {' '.join(parts)}".rstrip()
        if not flags:
            return head + "/>"
        return f"{head}>\n    <flag {' '.join(flags)}/>\n  </option>"

    def _head_xml(self) -> list[str]:
        return [
            self.extra_xml[k]
            for k in ("size", "visual", "statistic", "default")
            if k in self.extra_xml
        ]

    def _tail_xml(self) -> list[str]:
        return [
            self.extra_xml[k]
            for k in ("contact", "equality", "tendon", "keyframe")
            if k in self.extra_xml
        ]

    def to_xml_string(self) -> str:
        """The MJCF text of this World (files referenced by their paths as stored)."""
        if not self._stale():
            return self._built_text  # the text the current model was compiled from
        return write_mjcf(self)[0]

    def export(self, path: str | os.PathLike[str], copy_assets: bool = True) -> Path:
        """Write the MJCF to ``path`` atomically.

        With ``copy_assets`` every mesh/texture file is copied to ``<dir>/assets/`` and
        referenced relative to the written file, so the folder is self-contained.
        Returns the written path.
        """
        path = Path(path)
        check_output_path(path)  # before any work: a folder, or a file as a parent
        out_dir = path.parent
        copies: dict[str, str] = {}

        def path_for(file: str) -> str:
            src = os.path.abspath(file)
            if not copy_assets:
                return os.path.relpath(src, out_dir.resolve())
            if src not in copies:
                base = os.path.basename(src)
                stem, ext = os.path.splitext(base)
                candidate, k = base, 1
                while candidate in copies.values():
                    candidate = f"{stem}_{k}{ext}"
                    k += 1
                copies[src] = candidate
            return f"assets/{copies[src]}"

        text = write_mjcf(self, path_for)[0]
        for src in copies:
            if not os.path.isfile(src):
                raise FileNotFoundError(f"{self._label()}: asset file {src!r} does not exist")
        # Compiled before anything is written: a model MuJoCo refuses leaves no output.
        self.model  # noqa: B018 - compiles, or raises
        # All or nothing: assets and file are staged, then moved into place (the file last,
        # so an old file keeps loading until then). Regular files only are copied.
        with atomic_files(out_dir) as staged:
            for src, rel in copies.items():
                staged.copy(Path(src), f"assets/{rel}")
            staged.write_text(path.name, text)
        return path

    # ------------------------------------------------------------------ reading
    @classmethod
    def from_xml_string(
        cls,
        xml: str,
        base_dir: str | os.PathLike[str] | None = None,
        strict: bool = False,
        asset_roots: Iterable[str | os.PathLike[str]] | None = None,
    ) -> World:
        """Build Things from MJCF text; relative file paths resolve against ``base_dir``
        (default: the working directory) and must stay inside it or inside one of
        ``asset_roots``. See :mod:`robotwright.things.xml_reader`."""
        from robotwright.things.xml_world import world_from_string

        return world_from_string(xml, base_dir=base_dir, strict=strict, asset_roots=asset_roots)

    @classmethod
    def from_xml_path(
        cls,
        path: str | os.PathLike[str],
        strict: bool = False,
        asset_roots: Iterable[str | os.PathLike[str]] | None = None,
    ) -> World:
        """Build Things from an MJCF file (``<include>`` and relative paths resolve from
        it); every file it names must lie inside its folder or inside one of
        ``asset_roots`` (:class:`~robotwright.errors.UnsafePathError` otherwise)."""
        from robotwright.things.xml_world import world_from_path

        return world_from_path(path, strict=strict, asset_roots=asset_roots)

    # ------------------------------------------------------------------ simulation
    def _stale(self) -> bool:
        return (
            self._built is None
            or self._built_version != self._version
            or self._built_epoch != asset_epoch()
        )

    def _ensure_built(self) -> tuple[mujoco.MjModel, mujoco.MjData, dict[int, int]]:
        if self._stale():
            self.rebuild()
        model, data, index = self._built
        if data is None:  # created on first use, so that compiling alone stays cheap
            data = mujoco.MjData(model)
            mujoco.mj_forward(model, data)
            object.__setattr__(self, "_built", (model, data, index))
        return model, data, index

    def rebuild(self) -> None:
        """Compile the tree now (normally done lazily by ``model``/``data``/``step``)."""
        text, order = write_mjcf(self)
        try:
            spec = mujoco.MjSpec.from_string(text)
            model = spec.compile()
        except ValueError as exc:
            raise ThingBuildError(
                f"{self._label()}: MuJoCo could not compile the Things: {exc} "
                "(see world.to_xml_string() for the MJCF that was compiled)"
            ) from None
        index: dict[int, int] = {}
        for ids in order.values():
            for i, thing_id in enumerate(ids):
                index[thing_id] = i
        object.__setattr__(self, "_built", (model, None, index))
        object.__setattr__(self, "_built_version", self._version)
        object.__setattr__(self, "_built_epoch", asset_epoch())
        object.__setattr__(self, "_built_text", text)
        object.__setattr__(self, "_spec", spec)

    @property
    def model(self) -> mujoco.MjModel:
        """The compiled ``MjModel`` (rebuilt when the tree changed)."""
        if self._stale():
            self.rebuild()
        return self._built[0]

    @property
    def data(self) -> mujoco.MjData:
        """The ``MjData`` of the current build (fresh after each rebuild)."""
        return self._ensure_built()[1]

    @property
    def spec(self) -> mujoco.MjSpec:
        """The ``MjSpec`` the current model was compiled from."""
        self._ensure_built()
        return self._spec

    def step(self, n: int = 1) -> None:
        """Advance the simulation by ``n`` steps of ``timestep`` seconds."""
        model, data, _ = self._ensure_built()
        for _ in range(n):
            mujoco.mj_step(model, data)

    def forward(self) -> None:
        model, data, _ = self._ensure_built()
        mujoco.mj_forward(model, data)
