"""Isaac Lab configs of the LiDAR: ``LidarCfg`` and ``SemanticLidarCfg`` (``@configclass``).

They are Isaac Lab ``RayCasterCfg`` subclasses (through ``NewtonRaycastSensorCfg``), so
they go into an ``InteractiveSceneCfg`` like any sensor, and Isaac Lab builds the sensor
from ``class_type``. Isaac Lab users and tyro change configs after construction, so the
fields are checked by :func:`resolve` when the sensor is built (and by ``validate()``),
not when the config is made.

Frames and units follow Isaac Lab: ``offset.rot`` is a quaternion (x, y, z, w) of the
sensor in the carrier prim's frame, ``offset.pos`` in metres; outputs are in the world
frame, distances in metres.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from isaaclab.sensors.ray_caster.patterns.patterns_cfg import PatternBaseCfg
from isaaclab.utils import configclass
from isaaclab_newton.sensors import NewtonRaycastSensorCfg

from robotwright.errors import SensorError
from robotwright.sensors.config import (
    DEFAULT_SEMANTIC_CLASS_MAPPING,
    UNKNOWN_CLASS,
    check_class_mapping,
)
from robotwright.sensors.patterns import LivoxPatternCfg, PatternCfg

if TYPE_CHECKING:
    from robotwright.sensors.isaaclab.sensor import LidarSensor, SemanticLidarSensor

__all__ = ["LidarCfg", "ResolvedLidarCfg", "SemanticLidarCfg", "resolve"]

#: Most see-through shapes one ray may pass before it reads as a miss.
MAX_PASS_THROUGH = 64


@configclass
class LidarCfg(NewtonRaycastSensorCfg):
    """A LiDAR on Isaac Lab's Newton ray caster: robotwright patterns, per-ray shape ids.

    Rays are cast with ``newton.intersect_ray`` against the collision shapes of the
    sensor's own environment and of the global world (terrain), moving bodies included.

    Attributes:
        prim_path: the prim carrying the sensor (``"{ENV_REGEX_NS}/Robot/base"``): a
            rigid body, or a prim under one.
        pattern_cfg: a robotwright pattern (:class:`LivoxPatternCfg` Mid-360/Avia, whose
            window advances with each environment's simulated time; spinning, grid,
            pinhole and file patterns repeat), or any Isaac Lab pattern config
            (``LidarPatternCfg``, ``GridPatternCfg``, ...). Default: a 20 000-ray
            Mid-360. Directions are in the sensor frame (+x forward, +z up).
        offset: the sensor's pose on the carrier (Isaac Lab's ``OffsetCfg``; rot is
            x, y, z, w).
        mesh_prim_paths: which shapes rays see: Isaac Lab prim-path regular
            expressions (``{ENV_REGEX_NS}`` allowed), matched case-insensitively against
            each collision shape's prim path and its ancestors, so ``"/World/ground"``
            sees every shape under the ground prim. Shapes not matched are see-through:
            a ray passes them and reports what lies behind. Empty (default): every
            collision shape of the scene is seen.
        exclude_parent_body: the shapes of the rigid body carrying the sensor are
            see-through (a sensor inside its carrier's collision box would otherwise
            see only the box).
        min_distance: hits nearer than this are misses [m].
        max_distance: hits further than this are misses [m] (Isaac Lab's field).
        miss_distance: the distance :meth:`LidarSensor.get_distances` and the distance
            observation terms give a miss [m] (``None``: ``max_distance``).
            ``data.ray_distances`` keeps Isaac Lab's ``inf``.
        pass_through: how rays pass see-through shapes. ``"skip"`` (default): one cast
            whose walk of Newton's shape BVH leaves them out, at the stock cast's cost,
            with no host read (CUDA graphs capture it; falls back to ``"recast"`` with a
            warning where Newton lacks the intersection functions it uses).
            ``"recast"``: the rays that hit one are cast again from just past it, up to
            ``max_pass_through`` times, each pass reading its queue length on the host.
        max_pass_through: with ``pass_through="recast"``, most see-through shapes one ray
            passes; a ray still behind
            one after that many reads as a miss.
    """

    class_type: type[LidarSensor] | str = "{DIR}.sensor:LidarSensor"
    pattern_cfg: Any = LivoxPatternCfg()
    mesh_prim_paths: list[str] = []
    exclude_parent_body: bool = True
    min_distance: float = 0.0
    max_distance: float = 40.0
    miss_distance: float | None = None
    pass_through: str = "skip"
    max_pass_through: int = 4
    # The "recast" pass-through reads its queue length on the host, which a CUDA graph
    # cannot capture; "skip" can be captured: set True to use one.
    use_cuda_graph: bool = False

    def validate_config(self) -> None:
        resolve(self)


@configclass
class SemanticLidarCfg(LidarCfg):
    """:class:`LidarCfg` plus a class per ray from keywords in the hit shape's prim path.

    Attributes:
        semantic_class_mapping: class name -> keywords, matched case-insensitively in
            the hit shape's prim path (``/World/envs/env_0/cracker_box_0/...``); class
            ids 1..K in mapping order, 0 = miss/unknown. ``None``: the default mapping
            (terrain, dynamic_obstacle, valuable).
        terrain_class: the class of global shapes that carry no prim path (Newton names
            a generated height-field terrain ``shape_N``); appended after the mapping's
            classes unless the mapping has it. ``None``: such shapes read 0.
        self_class: the class of the shapes of the robot carrying the sensor (its
            articulation, the carrier body excepted when ``exclude_parent_body``);
            appended after the mapping's classes unless the mapping has it. ``None``:
            they are see-through, so the LiDAR never sees its own robot.
        return_semantic_labels: fill ``data.semantic_labels``.
        return_mesh_ids: fill ``data.mesh_ids`` (the hit Newton shape index per ray, -1
            on a miss).
    """

    class_type: type[SemanticLidarSensor] | str = "{DIR}.sensor:SemanticLidarSensor"
    semantic_class_mapping: dict[str, list[str]] | None = None
    terrain_class: str | None = "terrain"
    self_class: str | None = "robot"
    return_semantic_labels: bool = True
    return_mesh_ids: bool = False


@dataclass(frozen=True)
class ResolvedLidarCfg:
    """The checked values a config stands for (see :func:`resolve`).

    Attributes:
        mapping: class -> keywords (the default filled in), classes 1..K in order.
        class_names: ``("unknown", *mapping, [terrain_class], [self_class])`` by id.
        terrain_class_id: class of unlabelled global shapes (0: none).
        self_class_id: class of the carrier robot's shapes (0: they are see-through).
        miss_distance: the miss value of ``get_distances()`` [m].
        mesh_patterns: compiled ``mesh_prim_paths`` (empty: every shape is seen).
        mesh_prim_paths: the entries as written, one per pattern (for messages).
    """

    mapping: dict[str, list[str]]
    class_names: tuple[str, ...]
    terrain_class_id: int
    self_class_id: int
    miss_distance: float
    mesh_patterns: tuple[re.Pattern[str], ...]
    mesh_prim_paths: tuple[str, ...] = ()


#: How rays pass see-through shapes (:attr:`LidarCfg.pass_through`).
PASS_THROUGH_MODES = ("skip", "recast")


def _number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _class_slot(names: tuple[str, ...], wanted: object, field: str) -> tuple[tuple[str, ...], int]:
    """The id of class ``wanted`` (appended when new); 0 for ``None``."""
    if wanted is None:
        return names, 0
    if not isinstance(wanted, str) or not wanted or wanted.casefold() == UNKNOWN_CLASS:
        raise SensorError(
            f"{field}: expected None or a non-empty class name other than "
            f"{UNKNOWN_CLASS!r}, got {wanted!r}"
        )
    if wanted in names:
        return names, names.index(wanted)
    return (*names, wanted), len(names)


def _mesh_patterns(paths: object, name: str) -> tuple[re.Pattern[str], ...]:
    if isinstance(paths, str) or not isinstance(paths, (list, tuple)):
        raise SensorError(
            f"{name}.mesh_prim_paths: expected a list of prim-path expressions, got "
            f"{type(paths).__name__}"
        )
    out = []
    for p in paths:
        if not isinstance(p, str) or not p:
            raise SensorError(f"{name}.mesh_prim_paths: expected non-empty strings, got {p!r}")
        expr = p.replace("{ENV_REGEX_NS}", "/World/envs/env_.*")
        try:
            out.append(re.compile(expr, re.IGNORECASE))
        except re.error as exc:
            raise SensorError(
                f"{name}.mesh_prim_paths: {p!r} is not a regular expression ({exc})"
            ) from None
    return tuple(out)


def resolve(cfg: Any) -> ResolvedLidarCfg:
    """Check every robotwright field of ``cfg`` and compute the derived values.

    Raises:
        SensorError: naming the config and the field.
    """
    name = type(cfg).__name__
    if not isinstance(cfg, LidarCfg):
        raise SensorError(
            f"expected a robotwright.sensors.isaaclab.LidarCfg or SemanticLidarCfg, got {name} "
            "(the core robotwright.sensors configs are for MuJoCo models)"
        )
    pattern = cfg.pattern_cfg
    if not isinstance(pattern, (PatternCfg, PatternBaseCfg)):
        raise SensorError(
            f"{name}.pattern_cfg: expected a robotwright PatternCfg or an Isaac Lab pattern "
            f"config, got {type(pattern).__name__}"
        )
    for key in ("min_distance", "max_distance"):
        value = getattr(cfg, key)
        if not _number(value) or not math.isfinite(value) or value < 0:
            raise SensorError(f"{name}.{key}: expected a finite number >= 0 [m], got {value!r}")
    if cfg.max_distance <= cfg.min_distance:
        raise SensorError(
            f"{name}: expected min_distance < max_distance, got {cfg.min_distance}, "
            f"{cfg.max_distance}"
        )
    miss = cfg.max_distance if cfg.miss_distance is None else cfg.miss_distance
    if not _number(miss) or not math.isfinite(miss):
        raise SensorError(f"{name}.miss_distance: expected None or a finite number [m]")
    if cfg.pass_through not in PASS_THROUGH_MODES:
        raise SensorError(
            f"{name}.pass_through: expected one of {', '.join(PASS_THROUGH_MODES)}, "
            f"got {cfg.pass_through!r}"
        )
    passes = cfg.max_pass_through
    if (
        not isinstance(passes, int)
        or isinstance(passes, bool)
        or not 0 <= passes <= MAX_PASS_THROUGH
    ):
        raise SensorError(
            f"{name}.max_pass_through: expected an integer in [0, {MAX_PASS_THROUGH}], got {passes!r}"
        )
    if not isinstance(cfg.exclude_parent_body, bool):
        raise SensorError(f"{name}.exclude_parent_body: expected True or False")
    patterns = _mesh_patterns(cfg.mesh_prim_paths, name)
    if not isinstance(cfg, SemanticLidarCfg):
        return ResolvedLidarCfg(
            {}, (UNKNOWN_CLASS,), 0, 0, float(miss), patterns, tuple(cfg.mesh_prim_paths)
        )
    for flag in ("return_semantic_labels", "return_mesh_ids"):
        if not isinstance(getattr(cfg, flag), bool):
            raise SensorError(f"{name}.{flag}: expected True or False")
    raw = (
        DEFAULT_SEMANTIC_CLASS_MAPPING
        if cfg.semantic_class_mapping is None
        else cfg.semantic_class_mapping
    )
    check_class_mapping(raw, f"{name}.semantic_class_mapping")
    mapping = {k: list(v) for k, v in raw.items()}
    names: tuple[str, ...] = (UNKNOWN_CLASS, *mapping)
    names, terrain_id = _class_slot(names, cfg.terrain_class, f"{name}.terrain_class")
    names, self_id = _class_slot(names, cfg.self_class, f"{name}.self_class")
    return ResolvedLidarCfg(
        mapping, names, terrain_id, self_id, float(miss), patterns, tuple(cfg.mesh_prim_paths)
    )
