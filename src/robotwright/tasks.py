"""Ready-made jobs on top of the generator classes: export one robot, compose a scene."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from robotwright._names import file_stem
from robotwright.errors import GeneratorError
from robotwright.generators.composite import MJCFGeneratorComposite
from robotwright.generators.composite_urdf import URDFGeneratorComposite
from robotwright.generators.mjcf import MJCFHumanoidGenerator
from robotwright.generators.placement import Placement
from robotwright.generators.urdf import URDFHumanoidGenerator
from robotwright.hrdf.model import HRDF

RobotRef = str | Path | HRDF


def load_robot(robot: RobotRef) -> HRDF:
    """An HRDF from a robot name, an HRDF folder, a URDF, xacro or MJCF file (see
    :func:`robotwright.sources.load_robot`), or an HRDF object (returned as is)."""
    from robotwright.sources import load_robot as load_source

    return load_source(robot)


def export_robot(
    robot: RobotRef,
    out_dir: str | Path,
    *,
    prefix: str | None = None,
    add_scene: bool = True,
    copy_meshes: bool = True,
) -> dict[str, Path]:
    """Write ``<out_dir>/<name>.xml`` (MJCF) and ``<out_dir>/<name>.urdf`` (URDF with the
    MuJoCo tag) for one robot; meshes are copied to ``<out_dir>/meshes/<name>/`` so the
    folder is self-contained. ``<name>`` is the robot's name made a safe file name
    (:func:`~robotwright._names.file_stem`: a name read from a file never becomes a path).

    Returns:
        ``{"mjcf": path, "urdf": path}``.
    """
    hrdf = load_robot(robot)
    out = Path(out_dir)
    stem = file_stem(hrdf.name, "robot")
    mjcf_path = out / f"{stem}.xml"
    urdf_path = out / f"{stem}.urdf"
    MJCFHumanoidGenerator.from_hrdf(hrdf).export(
        mjcf_path, copy_meshes=copy_meshes, prefix=prefix, add_scene=add_scene
    )
    URDFHumanoidGenerator.from_hrdf(hrdf).export(
        urdf_path, copy_meshes=copy_meshes, add_mujoco_tag=True
    )
    return {"mjcf": mjcf_path, "urdf": urdf_path}


def _keys(
    robots: Sequence[tuple[str, RobotRef]] | Mapping[str, RobotRef],
) -> list[tuple[str, HRDF]]:
    items = list(robots.items()) if isinstance(robots, Mapping) else list(robots)
    out = [(key, load_robot(r)) for key, r in items]
    keys = [k for k, _ in out]
    if len(set(keys)) != len(keys):
        raise GeneratorError(f"robot keys must be unique, got {keys}")
    return out


def compose_scene(
    robots: Mapping[str, RobotRef] | Sequence[tuple[str, RobotRef]],
    out_path: str | Path,
    placements: Mapping[str, Placement | Sequence[float]] | None = None,
    *,
    fmt: str = "mjcf",
    add_scene: bool = True,
    copy_meshes: bool = False,
) -> Path:
    """Write one scene file holding several robots, each prefixed with its key.

    Args:
        robots: ``{key: robot}`` where robot is a name, an HRDF folder or an HRDF.
        out_path: the scene file (``.xml`` for MJCF, ``.urdf`` for URDF).
        placements: ``{key: Placement | (x, y, z[, yaw])}`` (m, rad).
        fmt: ``"mjcf"`` or ``"urdf"`` (URDF gets the MuJoCo tag).
        add_scene: MJCF only: add ground, light and sky.
        copy_meshes: copy meshes next to the file (self-contained folder).
    """
    items = _keys(robots)
    path = Path(out_path)
    if fmt == "mjcf":
        comp = MJCFGeneratorComposite(
            {k: MJCFHumanoidGenerator.from_hrdf(h) for k, h in items}, placements
        )
        comp.load()
        comp.export(path, copy_meshes=copy_meshes, add_scene=add_scene)
    elif fmt == "urdf":
        ucomp = URDFGeneratorComposite(
            {k: URDFHumanoidGenerator.from_hrdf(h) for k, h in items}, placements
        )
        ucomp.load()
        ucomp.export(path, copy_meshes=copy_meshes, add_mujoco_tag=True)
    else:
        raise GeneratorError(f"format '{fmt}': expected 'mjcf' or 'urdf'")
    return path


__all__ = ["compose_scene", "export_robot", "load_robot"]
