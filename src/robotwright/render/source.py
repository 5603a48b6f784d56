"""What ``robotwright render`` draws: a robot source turned into a compiled model.

A source is a bundled robot name (or one under ``$HURODES_ASSETS_PATH``), an HRDF
folder, an MJCF file (a robot, or a scene written by ``robotwright compose`` or the
demo) or a URDF file. Robots and URDFs go through the project's own readers and MJCF
generator (what MJCF cannot hold is reported as a
:class:`~robotwright.errors.ConversionWarning`); an MJCF file is compiled by MuJoCo itself after the project's safety checks
(no XML entities; every file it names inside its folder or a trusted one).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco

from robotwright.errors import RobotwrightError

if TYPE_CHECKING:
    from robotwright.hrdf.model import HRDF

__all__ = ["LoadedModel", "SourceError", "load_model"]


class SourceError(RobotwrightError, ValueError):
    """A source that is no robot, HRDF folder, MJCF or URDF file, or that MuJoCo refuses."""


@dataclass
class LoadedModel:
    """A compiled model and where it came from.

    Attributes:
        model: the compiled model.
        title: a short name (robot name or file stem).
        kind: ``"robot"`` (name or HRDF folder), ``"mjcf"`` or ``"urdf"``.
    """

    model: mujoco.MjModel
    title: str
    kind: str

    def initial_data(self) -> mujoco.MjData:
        """State to draw: keyframe 0 when the model has one (a model's home pose, and
        the pose ``robotwright lidar`` scans in), else ``qpos0``; kinematics done."""
        data = mujoco.MjData(self.model)
        if self.model.nkey:
            mujoco.mj_resetDataKeyframe(self.model, data, 0)
        mujoco.mj_forward(self.model, data)
        return data


def load_model(
    source: str | os.PathLike[str], *, asset_roots: tuple[str | os.PathLike[str], ...] = ()
) -> LoadedModel:
    """Load ``source`` (see the module docstring).

    Raises:
        SourceError: unknown kind of file, or MuJoCo cannot compile the MJCF.
        RobotwrightError: what the readers raise for bad input (naming file and field).
    """
    text = os.fspath(source)
    path = Path(text)
    suffix = path.suffix.lower()
    if path.is_file() and suffix in (".xml", ".mjcf"):
        return LoadedModel(_compile_mjcf(path, asset_roots), path.stem, "mjcf")
    if path.is_file() and suffix == ".urdf":
        return _urdf(path, asset_roots)
    if path.is_file():
        raise SourceError(
            f"{path}: cannot draw a '{suffix or 'extensionless'}' file; expected an MJCF "
            "(.xml), a URDF (.urdf), an HRDF folder or a robot name"
        )
    if not path.exists() and suffix in (".xml", ".mjcf", ".urdf"):
        raise SourceError(f"{path}: no such file")
    return _robot(text, asset_roots)


def _hrdf_model(hrdf: HRDF) -> mujoco.MjModel:
    """Compile a robot through the MJCF generator (its conversion warnings, naming what
    MJCF cannot hold, reach the caller as warnings)."""
    from robotwright.generators import MJCFHumanoidGenerator

    return MJCFHumanoidGenerator.from_hrdf(hrdf).to_model()


def _robot(name_or_dir: str, asset_roots: tuple[str | os.PathLike[str], ...]) -> LoadedModel:
    from robotwright.hrdf.assets import resolve_robot
    from robotwright.hrdf.model import HRDF

    folder = resolve_robot(name_or_dir)
    hrdf = HRDF.from_dir(folder, asset_roots=list(asset_roots) or None)
    return LoadedModel(_hrdf_model(hrdf), hrdf.name, "robot")


def _urdf(path: Path, asset_roots: tuple[str | os.PathLike[str], ...]) -> LoadedModel:
    from robotwright.parsers.api import urdf_to_hrdf

    options = {"asset_roots": tuple(asset_roots)} if asset_roots else {}
    return LoadedModel(_hrdf_model(urdf_to_hrdf(path, **options)), path.stem, "urdf")


def _compile_mjcf(path: Path, asset_roots: tuple[str | os.PathLike[str], ...]) -> mujoco.MjModel:
    from robotwright._paths import check_mjcf_includes, check_mjcf_spec, trusted_roots
    from robotwright.errors import ConversionError
    from robotwright.parsers.xmlsafe import parse_xml

    try:
        tree = parse_xml(path)
    except ConversionError as exc:
        raise SourceError(str(exc)) from None
    if tree.tag != "mujoco":
        raise SourceError(
            f"{path}: root element <{tree.tag}>: expected <mujoco> (MJCF); "
            "a URDF is read from a file named .urdf"
        )
    folder = path.resolve().parent
    where = {"source": str(path), "model_dir": folder, "root": folder}
    trusted = trusted_roots(asset_roots)
    check_mjcf_includes(tree, **where, trusted=trusted)
    try:
        spec = mujoco.MjSpec.from_file(str(path))
        check_mjcf_spec(spec, **where, trusted=trusted)
        return spec.compile()
    except ValueError as exc:  # MuJoCo reports parse and compile errors as ValueError
        if isinstance(exc, RobotwrightError):
            raise
        raise SourceError(f"{path}: MuJoCo cannot load it: {exc}") from None
