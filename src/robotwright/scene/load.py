"""Any robot source the viewer accepts, turned into a compiled MuJoCo model.

A *source* is one of:

- a bundled robot name (``mini_humanoid``) or a robot under ``$HURODES_ASSETS_PATH``;
- an HRDF folder (``meta.yaml`` inside);
- an MJCF file (``.xml``), including a scene composed by ``robotwright compose`` or the
  demo: compiled by MuJoCo itself, so everything MuJoCo accepts is shown as MuJoCo
  compiles it;
- a URDF file (``.urdf``), or a xacro file (``.xacro``, ``.urdf.xacro``; the ``xacro``
  extra) expanded with its default arguments: read by robotwright's URDF parser
  (``package://`` paths, visual meshes, DAE/OBJ meshes), then generated as MJCF;
- a grammar design folder (``design.txt`` inside, as ``robotwright grammar sample`` or
  ``export`` write it): its MJCF file, else the design rebuilt with the bundled grammar;
- a scan ``.npz`` written by ``robotwright lidar`` or the demo, with the MJCF scene it
  was taken in (``scene=``); without a scene only the points are shown;
- from Python also an :class:`~robotwright.hrdf.model.HRDF` or a ``mujoco.MjModel``.

Each is loaded by the project's own readers with their safety rules (entities refused,
files named by a model must stay inside its folder unless trusted, see
:mod:`robotwright._paths`).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from robotwright._usd_format import USD_SUFFIXES
from robotwright.errors import InputFileError, RobotwrightError

if TYPE_CHECKING:
    from robotwright.hrdf.model import HRDF

__all__ = ["ScanCloud", "ViewError", "ViewScene", "compile_mjcf", "load_source"]

SourceLike = str | os.PathLike[str]

#: Largest scan file read (bytes): a scan of 1e6 rays is about 60 MB uncompressed.
MAX_SCAN_BYTES = 512 * 1024 * 1024


class ViewError(RobotwrightError, ValueError):
    """A source cannot be shown: unknown kind, unreadable file, scan without its fields."""


@dataclass(frozen=True)
class ScanCloud:
    """The hit points of one saved LiDAR scan.

    Attributes:
        points: ``(H, 3)`` hit points in the world frame [m] (misses dropped).
        labels: ``(H,)`` semantic class ids indexing ``class_names`` (0 = unknown).
        class_names: class names by id.
        sensor_pos: sensor position in the world frame [m], shape ``(3,)``.
        sensor_quat: sensor orientation in the world frame (w, x, y, z), shape ``(4,)``.
        num_rays: rays in the scan, hits and misses.
    """

    points: np.ndarray
    labels: np.ndarray
    class_names: tuple[str, ...]
    sensor_pos: np.ndarray
    sensor_quat: np.ndarray
    num_rays: int

    def class_counts(self) -> dict[str, int]:
        """Number of hit points of each class, in class id order."""
        return {n: int((self.labels == i).sum()) for i, n in enumerate(self.class_names)}


@dataclass
class ViewScene:
    """What the viewer draws: a compiled model, and a scan when the source was one.

    Attributes:
        model: the compiled model (an empty world for a scan shown without its scene).
        title: a short name for the page title.
        kind: ``"robot"`` (bundled name or HRDF folder or object), ``"mjcf"``,
            ``"urdf"``, ``"design"``, ``"scan"`` or ``"model"`` (an ``MjModel`` given).
        source: the source as given, for messages.
        scan: the scan's points, for a scan source.
        notes: what the loaders reported (conversion warnings), one line each.
        warnings: how the model shown differs from the robot (physics MuJoCo or the
            generators refuse, replaced to show its geometry), one line each.
    """

    model: mujoco.MjModel
    title: str
    kind: str
    source: str
    scan: ScanCloud | None = None
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def initial_qpos(self) -> np.ndarray:
        """The pose shown first: keyframe 0 when the model has one (the pose
        ``robotwright lidar`` scans in), else ``qpos0``."""
        if self.model.nkey:
            return self.model.key_qpos[0].copy()
        return self.model.qpos0.copy()


def load_source(
    source: SourceLike | HRDF | mujoco.MjModel,
    *,
    scene: SourceLike | None = None,
    asset_roots: tuple[SourceLike, ...] = (),
) -> ViewScene:
    """Load ``source`` (see the module docstring) into a :class:`ViewScene`.

    Args:
        source: robot name, path, :class:`~robotwright.hrdf.model.HRDF` or ``MjModel``.
        scene: the MJCF scene a scan ``.npz`` was taken in (only with a scan).
        asset_roots: folders outside the source's folder its files may come from.

    Raises:
        ViewError: the source is of no known kind, or a scan file lacks its arrays.
        RobotwrightError: what the readers raise for bad input (naming file and field).
    """
    from robotwright.hrdf.model import HRDF

    if isinstance(source, mujoco.MjModel):
        _no_scene(scene, "an MjModel")
        return ViewScene(source, "model", "model", "<MjModel>")
    if isinstance(source, HRDF):
        _no_scene(scene, "a robot")
        model, notes, shown = _hrdf_model(source)
        return ViewScene(model, source.name, "robot", source.name, notes=notes, warnings=shown)
    text = os.fspath(source)
    path = Path(text)
    suffix = path.suffix.lower()
    if suffix == ".npz":
        return _scan_scene(path, scene, asset_roots)
    _no_scene(scene, f"'{text}'")
    if path.is_dir() and (path / "design.txt").is_file():
        return _design_scene(path, asset_roots)
    robot_files = (".xml", ".mjcf", ".urdf", ".xacro", *USD_SUFFIXES)
    if path.is_file() and suffix not in robot_files:
        raise ViewError(
            f"{path}: cannot show a '{suffix or 'extensionless'}' file; expected an MJCF "
            "(.xml), a URDF (.urdf), xacro (.xacro) or USD (.usd, .usda, .usdc) file, a scan "
            "(.npz), an HRDF or design folder, or a robot name"
        )
    if not path.exists() and suffix in robot_files:
        raise ViewError(f"{path}: no such file")
    return _robot_scene(text, asset_roots)


def _no_scene(scene: SourceLike | None, what: str) -> None:
    if scene is not None:
        raise ViewError(f"scene={os.fspath(scene)!r} applies to a scan (.npz), not to {what}")


def _hrdf_model(hrdf: HRDF) -> tuple[mujoco.MjModel, list[str], list[str]]:
    """Compile a robot through the MJCF generator; returns the model, its conversion
    notes, and how the model differs from the robot: a robot whose masses or inertias
    the generators refuse is shown with those replaced (see
    :func:`robotwright.scene.display.for_display`), since a picture needs its geometry
    only."""
    from robotwright.errors import ConversionWarning, HRDFError, RobotwrightError
    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.scene.display import for_display

    shown: list[str] = []
    try:
        generator = MJCFHumanoidGenerator.from_hrdf(hrdf)
    except HRDFError as exc:
        hrdf, shown = for_display(hrdf, exc)  # raises exc unless physics alone is refused
        generator = MJCFHumanoidGenerator.from_hrdf(hrdf)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ConversionWarning)
        try:
            model = generator.to_model()
        except ValueError as exc:  # MuJoCo refuses the model (a mesh it cannot read, ...)
            if isinstance(exc, RobotwrightError):
                raise
            from robotwright.generators.compiles import require_compiles

            require_compiles(hrdf, f"cannot show robot '{hrdf.name}'")  # says where
            reason = " ".join(str(exc).split())  # MuJoCo's message spans lines
            raise ViewError(f"robot '{hrdf.name}': MuJoCo refuses the model: {reason}") from None
    notes = []
    for w in caught:
        if issubclass(w.category, ConversionWarning):
            notes.append(str(w.message))
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return model, notes, shown


def _robot_scene(text: str, asset_roots: tuple[SourceLike, ...]) -> ViewScene:
    """A robot by name, HRDF folder, URDF, xacro or MJCF file (see
    :mod:`robotwright.sources`; the command line's source options apply). An MJCF file
    is compiled by MuJoCo as it stands unless a source option (``--root-body``) asks
    for the robot read from it."""
    from robotwright.sources import load_robot_with_notes, resolve_source, wants_parse

    resolved = resolve_source(text)
    if resolved.kind == "mjcf" and not wants_parse():
        model = compile_mjcf(resolved.path, asset_roots)
        return ViewScene(model, resolved.title, "mjcf", text)
    hrdf, notes = load_robot_with_notes(text, asset_roots=tuple(asset_roots))
    model, more, shown = _hrdf_model(hrdf)
    from robotwright._mjmodel import stand_on_floor

    shift = stand_on_floor(model)
    if shift:  # a floating base: on the floor, not at its root's height
        more.append(
            f"robot '{hrdf.name}' floats: placed {'up' if shift > 0 else 'down'} by "
            f"{abs(shift):.3g} m so that its lowest collision geom touches the floor (z = 0)"
        )
    _warn_fixed_walker(hrdf)
    kind = "robot" if resolved.kind == "hrdf" else resolved.kind.replace("xacro", "urdf")
    title = hrdf.name  # the robot's own name, as info and the outputs call it
    return ViewScene(model, title, kind, text, notes=notes + more, warnings=shown)


def _warn_fixed_walker(hrdf: HRDF) -> None:
    """A walking robot read with its base fixed is drawn and scanned with its legs
    through the floor: said, as a :class:`~robotwright.errors.RobotSetupWarning`."""
    from robotwright.errors import RobotSetupWarning
    from robotwright.generators.standing import fixed_walker, walking_bodies

    feet = walking_bodies(hrdf)
    if feet and not hrdf.floating_base:
        warnings.warn(fixed_walker(hrdf.name, feet), RobotSetupWarning, stacklevel=3)


def compile_mjcf(
    path: Path,
    asset_roots: tuple[SourceLike, ...] = (),
    *,
    error: type[RobotwrightError] = ViewError,
) -> mujoco.MjModel:
    """Compile the MJCF file ``path`` (a robot or a whole scene) with MuJoCo, after the
    checks every MJCF reader makes (:func:`robotwright._paths.checked_mjcf_spec`: no XML
    entities, every file it names inside its folder, ``asset_roots`` or a folder trusted
    with ``--asset-root``, no flood of keyframes); MuJoCo reads it in a confined reader
    (:mod:`robotwright._confine`).

    Raises:
        error: (``ViewError`` unless given) the file is unreadable, not MJCF, or
            refused by MuJoCo, naming the file.
        UnsafePathError: a file it names leaves its folder or is not a regular file.
    """
    from robotwright._confine import run_confined
    from robotwright.parsers.packages import source_read_roots

    roots = source_read_roots(path, "mjcf", {"asset_roots": asset_roots})
    return run_confined(_compile_mjcf_here, path, asset_roots, error, roots=roots, what=str(path))


def _compile_mjcf_here(
    path: Path, asset_roots: tuple[SourceLike, ...], error: type[RobotwrightError]
) -> mujoco.MjModel:
    """:func:`compile_mjcf`'s reading step (run confined)."""
    from robotwright._paths import checked_mjcf_spec, trusted_roots
    from robotwright._xmlsafe import parse_xml
    from robotwright.errors import ConversionError, UnsafePathError

    try:
        tree = parse_xml(path)
    except ConversionError as exc:
        raise error(f"{path}: {exc.problems[0].message}") from None
    if tree.tag != "mujoco":
        raise error(
            f"{path}: root element <{tree.tag}>: expected <mujoco> (MJCF); "
            "a URDF is read from a file named .urdf"
        )
    try:
        return checked_mjcf_spec(path, trusted=trusted_roots(asset_roots)).compile()
    except ConversionError as exc:
        raise error(f"{path}: {exc.problems[0].message}") from None
    except (UnsafePathError, InputFileError):
        raise  # refused before MuJoCo read a file: not MuJoCo's words
    except ValueError as exc:  # MuJoCo reports parse and compile errors as ValueError
        raise error(f"{path}: MuJoCo cannot load it: {exc}") from None


def _design_scene(folder: Path, asset_roots: tuple[SourceLike, ...]) -> ViewScene:
    """A design folder: the MJCF written next to ``design.txt`` (it was built with the
    grammar the design came from); without one, the design rebuilt with the bundled
    grammar."""
    xmls = sorted(folder.glob("*.xml"))
    if len(xmls) == 1:
        model = compile_mjcf(xmls[0], asset_roots)
        return ViewScene(model, f"{folder.name} ({xmls[0].name})", "design", str(folder))
    if len(xmls) > 1:
        raise ViewError(
            f"{folder}: design folder holds several MJCF files "
            f"({', '.join(x.name for x in xmls)}): give the one to show"
        )
    from robotwright.grammar.build import build_hrdf
    from robotwright.grammar.design import Design
    from robotwright.grammar.loader import default_grammar

    design_file = folder / "design.txt"
    from robotwright._inputs import MAX_YAML_BYTES, read_text

    design = Design.from_text(read_text(design_file, MAX_YAML_BYTES), str(design_file))
    model, notes, shown = _hrdf_model(build_hrdf(default_grammar(), design))
    return ViewScene(
        model, f"{folder.name} (design)", "design", str(folder), notes=notes, warnings=shown
    )


_SCAN_FIELDS = ("points", "labels", "class_names")


def _scan_scene(
    path: Path, scene: SourceLike | None, asset_roots: tuple[SourceLike, ...]
) -> ViewScene:
    cloud = read_scan(path)
    if scene is None:
        model = mujoco.MjModel.from_xml_string("<mujoco/>")
        title = path.stem
    else:
        scene_path = Path(scene)
        if not scene_path.is_file():
            raise ViewError(f"{scene_path}: scene file not found")
        model = compile_mjcf(scene_path, asset_roots)
        title = f"{path.stem} in {scene_path.stem}"
        other = _other_scene(path, scene_path, model)
        if other:
            return ViewScene(model, title, "scan", str(path), scan=cloud, warnings=[other])
    return ViewScene(model, title, "scan", str(path), scan=cloud)


def _other_scene(scan: Path, scene: Path, model: mujoco.MjModel) -> str | None:
    """A line when ``scene`` is not the scene ``scan`` was taken in: the scan names every
    geom of its scene (``geom_paths``), which must be this model's; None when they match
    (or the scan is older and does not say)."""
    from robotwright._npz import load_npz
    from robotwright.sensors.lidar import geom_paths

    taken = load_npz(scan, ("geom_paths",)).get("geom_paths")
    if taken is None:
        return None
    here = geom_paths(model)
    taken = [str(p) for p in taken]
    if taken == here:
        return None
    first = next(
        (f"geom {g}: {a} in the scan's, {b} here" for g, (a, b) in enumerate(zip(taken, here))
         if a != b),
        "",
    )  # fmt: skip
    return (
        f"{scan.name} was not taken in {scene.name}: its scene had {len(taken)} geoms, this "
        f"one has {len(here)}" + (f" ({first})" if first else "") + "; the points are drawn "
        "where they were hit, in another scene"
    )


def read_scan(path: Path) -> ScanCloud:
    """Read a scan ``.npz`` (as :func:`robotwright.sensors.scan_to_files` writes it).

    Raises:
        ViewError: naming the file and the missing or malformed array.
    """
    if not path.is_file():
        raise ViewError(f"{path}: no such scan file")
    if path.stat().st_size > MAX_SCAN_BYTES:
        raise ViewError(f"{path}: larger than {MAX_SCAN_BYTES >> 20} MiB; not a scan file")
    from robotwright._npz import load_npz

    try:
        # Declared array sizes are checked against a limit before anything is loaded,
        # and pickled objects are refused (see robotwright._npz).
        arrays = load_npz(path, (*_SCAN_FIELDS, "hit_mask", "sensor_pos", "sensor_quat"))
    except InputFileError as exc:
        raise ViewError(f"{path}: not a readable .npz scan file: it {exc.reason}") from None
    except OSError as exc:
        raise ViewError(f"{path}: not a readable .npz scan file: {exc}") from None
    missing = [k for k in _SCAN_FIELDS if k not in arrays]
    if missing:
        raise ViewError(
            f"{path}: scan file lacks array(s) {', '.join(missing)}; "
            f"expected a scan written by 'robotwright lidar' (has {list(arrays)})"
        )
    points = np.asarray(arrays["points"], dtype=np.float64)
    labels = np.asarray(arrays["labels"])
    names = tuple(str(n) for n in np.asarray(arrays["class_names"]).reshape(-1))
    if points.ndim != 2 or points.shape[1] != 3:
        raise ViewError(f"{path}: 'points': expected shape (N, 3), got {points.shape}")
    if labels.shape != (points.shape[0],) or not np.issubdtype(labels.dtype, np.integer):
        raise ViewError(
            f"{path}: 'labels': expected {points.shape[0]} integer class ids, got "
            f"shape {labels.shape} of {labels.dtype}"
        )
    if not names:
        raise ViewError(f"{path}: 'class_names' is empty")
    hit = np.isfinite(points).all(axis=1)
    if "hit_mask" in arrays:
        hit &= np.asarray(arrays["hit_mask"], dtype=bool).reshape(-1)[: points.shape[0]]
    bad = labels[hit][(labels[hit] < 0) | (labels[hit] >= len(names))]
    if bad.size:
        raise ViewError(
            f"{path}: 'labels': class id {int(bad[0])} outside 0..{len(names) - 1} "
            f"(class_names has {len(names)} entries)"
        )
    pos = np.asarray(arrays.get("sensor_pos", np.full(3, np.nan)), dtype=np.float64).reshape(-1)
    quat = np.asarray(arrays.get("sensor_quat", (1.0, 0.0, 0.0, 0.0)), dtype=np.float64)
    return ScanCloud(
        points=points[hit],
        labels=labels[hit].astype(np.int64),
        class_names=names,
        sensor_pos=pos[:3] if pos.size >= 3 else np.full(3, np.nan),
        sensor_quat=quat.reshape(-1)[:4] if quat.size >= 4 else np.array([1.0, 0, 0, 0]),
        num_rays=int(points.shape[0]),
    )
