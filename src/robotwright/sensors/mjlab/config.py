"""mjlab config of the semantic LiDAR: plain fields, validated and resolved in ``build()``.

mjlab's idiom is to change a config after creating it (``cfg.frame.name = "trunk"``,
``--env.scene.sensors.2.max-distance 10`` on ``train``), so nothing is derived at
construction: :func:`resolve` checks every field and computes the derived values
(default mapping, miss value, offsets) when the sensor is built, and again when mjlab
initialises it, so a change made at any time before the scene compiles takes effect.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

from mjlab.sensor.builtin_sensor import ObjRef
from mjlab.sensor.raycast_sensor import RayCastSensorCfg

from robotwright.errors import SensorError
from robotwright.sensors.config import (
    DEFAULT_SEMANTIC_CLASS_MAPPING,
    UNKNOWN_CLASS,
    SemanticLidarCfg,
    _is_number,
)
from robotwright.sensors.patterns import GridPatternCfg, LivoxPatternCfg, PatternCfg

if TYPE_CHECKING:
    from robotwright.sensors.mjlab.sensor import MjlabSemanticLidarSensor

__all__ = [
    "MJLAB_TERRAIN_KEYWORD",
    "ResolvedLidarCfg",
    "SemanticLidarSensorCfg",
    "mjlab_class_mapping",
    "parse_class_mapping",
    "resolve",
]

#: Path prefix of the geoms of mjlab's terrain entity (plane, boxes, heightfields).
MJLAB_TERRAIN_KEYWORD = "/world/terrain/"


def mjlab_class_mapping(
    mapping: dict[str, list[str]] | None = None, terrain_class: str = "terrain"
) -> dict[str, list[str]]:
    """A class mapping under which mjlab's terrain geoms belong to ``terrain_class``.

    Returns a copy of ``mapping`` (``None``: the default mapping) with
    :data:`MJLAB_TERRAIN_KEYWORD` appended to the keywords of ``terrain_class`` (the class
    is added last when the mapping lacks it). Keyword matching stays the default
    case-insensitive substring rule, so nothing else changes class. This is the mjlab
    sensor's default mapping.
    """
    base = DEFAULT_SEMANTIC_CLASS_MAPPING if mapping is None else mapping
    out = {k: list(v) for k, v in base.items()}
    keywords = out.setdefault(terrain_class, [])
    if MJLAB_TERRAIN_KEYWORD not in keywords:
        keywords.append(MJLAB_TERRAIN_KEYWORD)
    return out


def is_mjlab_pattern(pattern: object) -> bool:
    """mjlab's own patterns (grid, pinhole, ring) and anything with its protocol."""
    return not isinstance(pattern, PatternCfg) and callable(getattr(pattern, "generate_rays", None))


@dataclass(kw_only=True)
class SemanticLidarSensorCfg(RayCastSensorCfg):
    """mjlab config of a semantic LiDAR: the SemanticLidarCfg fields on mjlab's ray-cast sensor.

    Every field may be changed after construction (by code or by tyro on ``train`` /
    ``play``) until the scene is built: validation and derived values happen in
    :meth:`build` and again when mjlab initialises the sensor.

    Frames: the pattern is given in the sensor frame (+x forward, +z up), which sits at
    ``offset_pos``/``offset_rot`` in the ``frame`` object's frame; outputs are in the
    world frame; distances [m].

    Attributes:
        name: the sensor's key in ``env.scene``.
        frame: the body, site or geom carrying the sensor (one ``ObjRef``, e.g.
            ``ObjRef(type="body", name="trunk", entity="robot")``).
        pattern: any robotwright pattern (:class:`~robotwright.sensors.LivoxPatternCfg`
            Mid-360/Avia rosettes advance one window per step; spinning, grid, pinhole
            and file patterns repeat), or one of mjlab's own patterns (grid, pinhole,
            ring), cast as a repeating pattern. Default: a 20 000-ray Mid-360.
        offset_pos: sensor position in the frame object's frame [m].
        offset_rot: sensor orientation in that frame, quaternion (w, x, y, z).
        semantic_class_mapping: class -> keywords matched case-insensitively in geom
            paths (``/world/<bodies>/<geom>[/<mesh>]``); class ids 1..K in mapping
            order, 0 = miss/unknown. ``None``: :func:`mjlab_class_mapping` (the default
            mapping with mjlab's terrain geoms as terrain).
        semantic_classes: the same mapping as one string, for command lines (tyro
            reads a dict of lists as a single class): ``CLASS=KW,KW;CLASS=KW``, e.g.
            ``valuable=sofa,table;dynamic_obstacle=box``. Given, it takes the place of
            ``semantic_class_mapping``, which must then be ``None``.
        self_class: class of the geoms of the robot carrying the sensor when rays can
            hit them (``include_geom_groups`` holding their group); appended after the
            mapping's classes unless the mapping has it. ``None``: such geoms are
            classified by their paths like any other.
        min_distance, max_distance: hits nearer or further are misses [m].
        range_noise_std: Gaussian range noise on hits [m], clipped to the range.
        dropout_prob: probability that a hit is dropped (becomes a miss).
        seed: base seed of the per-environment noise streams (``None``: fresh entropy).
        miss_distance: the distance ``get_distances()`` and the distance observation
            terms give a miss [m] (``None``: ``max_distance``); ``data.distances`` keeps
            mjlab's miss value -1.
        num_threads: on warp's CPU device, cast the rays in this many column blocks on
            parallel threads (``None``: one per core); CUDA always casts in one launch.
        refine_curved_hits: recompute hits on spheres, capsules, ellipsoids and cylinders
            in float64 from the compiled geom sizes (turn off when ``geom_size`` is
            randomised per environment).
        ray_alignment: ``"base"``, ``"yaw"`` or ``"world"`` (as mjlab's).
        exclude_parent_body: rays ignore the body carrying the sensor (as mjlab's).
        include_geom_groups: geom groups rays can hit (as mjlab's; here ``(0,)`` by
            default: terrain and props, not the robot's visual and collision groups).
        debug_vis: draw hit points coloured by class in mjlab's viewer.
        debug_vis_max_points: most hit points drawn per environment (evenly spaced).

    Scan timing (simulated time, as the real sensor):
        update_period: seconds between published scans (Isaac Lab's idiom; ``0``: every
            step). Between them the data hold the last scan.
        scan_phase: where each environment's scan starts at a reset: ``"zero"`` (the
            pattern's start) or ``"random"`` (anywhere in the pattern, seeded per env).
            A timed pattern (a Livox rosette, ``points_per_second``) fires in simulated
            time: each scan returns the latest ``N`` rays fired, its window moving by
            ``points_per_second x`` the time since the last step; an untimed pattern
            moves one frame per published scan. A reset of some environments touches
            only theirs.

    Realism, each off by default and seeded per environment (``seed``):
        range_noise_per_meter: extra Gaussian range noise whose standard deviation
            grows with the distance (``x d``), on top of ``range_noise_std``.
        angular_jitter_std: Gaussian tilt of every ray's direction, per axis [rad].
        class_dropout: class name -> probability that a hit on that class is dropped
            (on top of ``dropout_prob``), e.g. ``{"valuable": 0.3}``.
        mount_pos_range: half-ranges (x, y, z) [m] of a uniform offset added to
            ``offset_pos`` per environment at each reset.
        mount_rot_range: half-ranges (roll, pitch, yaw) [rad] of a uniform rotation
            applied after ``offset_rot`` per environment at each reset.
        drift_range: (low, high) [m] of a uniform drift of the ray origins along x, y
            and z, drawn per environment at each reset (Isaac Lab's ``drift_range``).
    """

    frame: ObjRef
    pattern: Any = field(default_factory=LivoxPatternCfg)
    offset_pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    offset_rot: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    semantic_class_mapping: dict[str, list[str]] | None = None
    semantic_classes: str | None = None
    self_class: str | None = "robot"
    min_distance: float = 0.0
    max_distance: float = 40.0
    range_noise_std: float = 0.0
    dropout_prob: float = 0.0
    seed: int | None = 0
    miss_distance: float | None = None
    refine_curved_hits: bool = True
    num_threads: int | None = None
    include_geom_groups: tuple[int, ...] | None = (0,)
    debug_vis_max_points: int = 2000
    update_period: float = 0.0
    scan_phase: Literal["zero", "random"] = "zero"
    range_noise_per_meter: float = 0.0
    angular_jitter_std: float = 0.0
    class_dropout: dict[str, float] | None = None
    mount_pos_range: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mount_rot_range: tuple[float, float, float] = (0.0, 0.0, 0.0)
    drift_range: tuple[float, float] = (0.0, 0.0)

    def build(self) -> MjlabSemanticLidarSensor:
        from robotwright.sensors.mjlab.sensor import MjlabSemanticLidarSensor

        resolve(self)  # a bad field fails here, naming it
        return MjlabSemanticLidarSensor(self)


@dataclass(frozen=True)
class ResolvedLidarCfg:
    """The values a :class:`SemanticLidarSensorCfg` stands for, checked (see :func:`resolve`).

    Attributes:
        mapping: the class mapping (the default filled in), classes 1..K in order.
        class_names: ``("unknown", *mapping, [self_class])``, indexed by class id.
        self_class_id: class id of the carrier robot's own geoms (0: classify by path).
        miss_distance: the miss value of ``get_distances()`` [m].
        offset_pos: sensor position on the frame object [m].
        offset_rot: unit quaternion (w, x, y, z).
        class_dropout: dropout probability per class id (``len(class_names)`` values).
        (the other fields as the config's, checked)
    """

    mapping: dict[str, list[str]]
    class_names: tuple[str, ...]
    self_class_id: int
    miss_distance: float
    offset_pos: tuple[float, float, float]
    offset_rot: tuple[float, float, float, float]
    update_period: float = 0.0
    random_phase: bool = False
    range_noise_per_meter: float = 0.0
    angular_jitter_std: float = 0.0
    class_dropout: tuple[float, ...] = ()
    mount_pos_range: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mount_rot_range: tuple[float, float, float] = (0.0, 0.0, 0.0)
    drift_range: tuple[float, float] = (0.0, 0.0)

    @property
    def randomised_mount(self) -> bool:
        """Some mount offset or drift is drawn per environment."""
        return any(self.mount_pos_range) or any(self.mount_rot_range) or any(self.drift_range)


def resolve(cfg: Any) -> ResolvedLidarCfg:
    """Check every field of ``cfg`` and compute the derived values.

    Raises:
        SensorError: naming the config and the field, when ``cfg`` is not a
            :class:`SemanticLidarSensorCfg` or a field is out of its domain.
    """
    if not isinstance(cfg, SemanticLidarSensorCfg):
        raise SensorError(
            f"expected a robotwright.sensors.mjlab.SemanticLidarSensorCfg, got "
            f"{type(cfg).__name__} (the core SemanticLidarCfg is not an mjlab sensor config)"
        )
    name = type(cfg).__name__
    if not isinstance(cfg.name, str) or not cfg.name:
        raise SensorError(f"{name}.name: expected a non-empty string")
    if not isinstance(cfg.frame, ObjRef) or cfg.frame.type not in ("body", "site", "geom"):
        raise SensorError(
            f"{name}.frame: expected one ObjRef of a body, site or geom, got {cfg.frame!r}"
        )
    if not isinstance(cfg.pattern, PatternCfg) and not is_mjlab_pattern(cfg.pattern):
        raise SensorError(
            f"{name}.pattern: expected a robotwright PatternCfg or an mjlab pattern, "
            f"got {type(cfg.pattern).__name__}"
        )
    for flag in ("refine_curved_hits", "exclude_parent_body", "debug_vis"):
        if not isinstance(getattr(cfg, flag), bool):
            raise SensorError(f"{name}.{flag}: expected True or False")
    groups = cfg.include_geom_groups
    if groups is not None and (
        not isinstance(groups, tuple)
        or not all(isinstance(g, int) and not isinstance(g, bool) and 0 <= g < 6 for g in groups)
    ):
        raise SensorError(
            f"{name}.include_geom_groups: expected None or a tuple of geom groups 0..5, "
            f"got {groups!r}"
        )
    vis = cfg.debug_vis_max_points
    if not isinstance(vis, int) or isinstance(vis, bool) or not 0 <= vis <= 1_000_000:
        raise SensorError(f"{name}.debug_vis_max_points: expected an integer in [0, 1000000]")
    if cfg.self_class is not None and (
        not isinstance(cfg.self_class, str)
        or not cfg.self_class
        or cfg.self_class.lower() == UNKNOWN_CLASS
    ):
        raise SensorError(
            f"{name}.self_class: expected None or a non-empty class name other than "
            f"{UNKNOWN_CLASS!r}, got {cfg.self_class!r}"
        )
    if cfg.semantic_classes is not None:
        if cfg.semantic_class_mapping is not None:
            raise SensorError(
                f"{name}: semantic_classes and semantic_class_mapping both given; expected one"
            )
        mapping = parse_class_mapping(cfg.semantic_classes, f"{name}.semantic_classes")
    elif cfg.semantic_class_mapping is None:
        mapping = mjlab_class_mapping()
    else:
        mapping = cfg.semantic_class_mapping
    # The core config validates and normalises the shared fields (ranges, noise,
    # mapping, offsets, alignment, seed) with the same rules; its messages are put in
    # this config's terms (its class and field names).
    try:
        core = _core_config(cfg, mapping)
    except SensorError as exc:
        raise SensorError(_in_terms_of(str(exc), name)) from None
    miss = float(core.miss_distance)  # type: ignore[arg-type]
    if not math.isfinite(miss):
        raise SensorError(f"{name}.miss_distance: expected a finite number [m]")
    resolved = {k: list(v) for k, v in (core.semantic_class_mapping or {}).items()}
    names = ("unknown", *resolved)
    self_id = 0
    if cfg.self_class is not None:
        if cfg.self_class in resolved:
            self_id = names.index(cfg.self_class)
        else:
            names = (*names, cfg.self_class)
            self_id = len(names) - 1
    return ResolvedLidarCfg(
        mapping=resolved,
        class_names=names,
        self_class_id=self_id,
        miss_distance=miss,
        offset_pos=tuple(float(v) for v in core.offset_pos),  # type: ignore[arg-type]
        offset_rot=tuple(float(v) for v in core.offset_rot),  # type: ignore[arg-type]
        **_timing_and_realism(cfg, name, names),
    )


def _number(cfg: Any, name: str, key: str, low: float, high: float = math.inf) -> float:
    value = getattr(cfg, key)
    if not _is_number(value) or not low <= float(value) <= high:
        bound = f"in [{low}, {high}]" if math.isfinite(high) else f">= {low}"
        raise SensorError(f"{name}.{key}: expected a finite number {bound}, got {value!r}")
    return float(value)


def _numbers(cfg: Any, name: str, key: str, n: int, low: float, what: str) -> tuple[float, ...]:
    value = getattr(cfg, key)
    if (
        isinstance(value, (str, bytes))
        or not hasattr(value, "__len__")
        or len(value) != n
        or not all(_is_number(v) and math.isfinite(v) and v >= low for v in value)
    ):
        raise SensorError(f"{name}.{key}: expected {n} finite numbers ({what}), got {value!r}")
    return tuple(float(v) for v in value)


def _timing_and_realism(cfg: Any, name: str, class_names: tuple[str, ...]) -> dict[str, Any]:
    """The checked scan-timing and realism fields of ``cfg`` (see the config's docs)."""
    if cfg.scan_phase not in ("zero", "random"):
        raise SensorError(f"{name}.scan_phase: expected 'zero' or 'random', got {cfg.scan_phase!r}")
    drops = [0.0] * len(class_names)
    given = cfg.class_dropout
    if given is not None:
        if not isinstance(given, dict):
            raise SensorError(f"{name}.class_dropout: expected None or a dict class -> probability")
        for cls, p in given.items():
            if cls not in class_names or cls == UNKNOWN_CLASS:
                raise SensorError(
                    f"{name}.class_dropout: unknown class {cls!r}; expected one of "
                    f"{list(class_names[1:])}"
                )
            if not isinstance(p, (int, float)) or isinstance(p, bool) or not 0.0 <= p <= 1.0:
                raise SensorError(
                    f"{name}.class_dropout[{cls!r}]: expected a probability in [0, 1], got {p!r}"
                )
            drops[class_names.index(cls)] = float(p)
    drift = _numbers(cfg, name, "drift_range", 2, -math.inf, "low, high [m]")
    if drift[0] > drift[1]:
        raise SensorError(f"{name}.drift_range: expected low <= high, got {cfg.drift_range!r}")
    return {
        "update_period": _number(cfg, name, "update_period", 0.0, 3600.0),
        "random_phase": cfg.scan_phase == "random",
        "range_noise_per_meter": _number(cfg, name, "range_noise_per_meter", 0.0, 10.0),
        "angular_jitter_std": _number(cfg, name, "angular_jitter_std", 0.0, math.pi),
        "class_dropout": tuple(drops),
        "mount_pos_range": _numbers(cfg, name, "mount_pos_range", 3, 0.0, "x, y, z >= 0 [m]"),
        "mount_rot_range": _numbers(
            cfg, name, "mount_rot_range", 3, 0.0, "roll, pitch, yaw >= 0 [rad]"
        ),
        "drift_range": drift,
    }


def _core_config(cfg: Any, mapping: dict[str, list[str]]) -> SemanticLidarCfg:
    return SemanticLidarCfg(
        prim_path=cfg.frame.prefixed_name(),
        pattern_cfg=cfg.pattern if isinstance(cfg.pattern, PatternCfg) else GridPatternCfg(),
        offset_pos=cfg.offset_pos,
        offset_rot=cfg.offset_rot,
        ray_alignment=cfg.ray_alignment,
        min_distance=cfg.min_distance,
        max_distance=cfg.max_distance,
        range_noise_std=cfg.range_noise_std,
        dropout_prob=cfg.dropout_prob,
        seed=cfg.seed,
        miss_distance=cfg.miss_distance,
        num_threads=cfg.num_threads,
        semantic_class_mapping=mapping,
    )


#: Field of the core config -> the field of the mjlab config it comes from.
_FIELDS = {"pattern_cfg": "pattern", "prim_path": "frame"}


def _in_terms_of(message: str, name: str) -> str:
    """A core config's error about ``SemanticLidarCfg.<field>`` (or a pattern's) as an
    error about the mjlab config ``name``: the class and field the user set."""
    core = SemanticLidarCfg.__name__
    if message.startswith(core):
        rest = message[len(core) :]
        for ours, theirs in _FIELDS.items():
            if rest.startswith(f".{ours}"):
                rest = f".{theirs}" + rest[len(ours) + 1 :]
        return name + rest
    return f"{name}.pattern: {message}"


def parse_class_mapping(text: object, where: str) -> dict[str, list[str]]:
    """A class mapping written as ``CLASS=KW,KW;CLASS=KW`` (spaces around the parts
    ignored), in order; its classes and keywords are checked by the config as any
    mapping is.

    Raises:
        SensorError: naming ``where``, the part that is wrong and the expected form.
    """
    form = "expected CLASS=KEYWORD,KEYWORD;CLASS=KEYWORD (e.g. 'valuable=sofa,table;box=box')"
    if not isinstance(text, str) or not text.strip():
        raise SensorError(f"{where}: {form}, got {text!r}")
    mapping: dict[str, list[str]] = {}
    for part in text.split(";"):
        if not part.strip():
            continue
        cls, sep, words = part.partition("=")
        cls = cls.strip()
        keywords = [w.strip() for w in words.split(",")]
        if not sep or not cls or not all(keywords):
            raise SensorError(f"{where}: {part.strip()!r}: {form}")
        if cls in mapping:
            raise SensorError(f"{where}: class {cls!r} given twice")
        mapping[cls] = keywords
    if not mapping:
        raise SensorError(f"{where}: {form}, got {text!r}")
    return mapping
