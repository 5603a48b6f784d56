"""Sensor configs: :class:`LidarCfg` and :class:`SemanticLidarCfg` (Isaac Lab-style names)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from robotwright._names import shown
from robotwright.errors import InputFileError, SensorError
from robotwright.sensors.patterns import LivoxPatternCfg, PatternCfg

__all__ = [
    "DEFAULT_SEMANTIC_CLASS_MAPPING",
    "LidarCfg",
    "SemanticLidarCfg",
    "check_class_mapping",
    "read_class_mapping",
]

#: Most CPU threads a sensor may start.
MAX_THREADS = 256
#: Longest range a sensor config gives (max and min distance, noise) [m]: far
#: beyond any LiDAR's, a bound for what a user or a file can set.
MAX_RANGE_M = 1e5
#: Largest mount offset from the carrier [m].
MAX_OFFSET_M = 1e4
#: Largest seed (numpy's generators take 64-bit seeds).
MAX_SEED = 2**63 - 1


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _floats(value: object, n: int) -> tuple[float, ...] | None:
    """``value`` as ``n`` floats, or None when it is not a sequence of ``n`` numbers."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        return None
    items = list(value)  # type: ignore[call-overload]
    if len(items) != n or not all(_is_number(v) or isinstance(v, np.floating) for v in items):
        return None
    return tuple(float(v) for v in items)


#: The default mapping: class ids are 1..K in this order, 0 = miss/unknown.
DEFAULT_SEMANTIC_CLASS_MAPPING: dict[str, list[str]] = {
    "terrain": ["ground", "wall", "floor", "plane"],
    "dynamic_obstacle": [
        "cracker_box",
        "sugar_box",
        "tomato_soup_can",
        "_03_cracker_box",
        "_04_sugar_box",
        "_05_tomato_soup_can",
    ],
    "valuable": [
        "sofa",
        "armchair",
        "table",
        "chair",
        "desk",
        "SM_Sofa",
        "SM_Armchair",
        "SM_Table",
    ],
}


@dataclass(kw_only=True)
class LidarCfg:
    """Configuration of a :class:`~robotwright.sensors.LidarSensor` on a MuJoCo model.

    Attributes:
        prim_path: name of the MuJoCo body or site that carries the sensor. Isaac Lab
            style paths are accepted: ``"{ENV_REGEX_NS}/Robot/base"`` finds a body or
            site named ``Robot/base``, else ``base`` (each MuJoCo world is one
            environment, so the namespace is implied), case-insensitively if need be.
        pattern_cfg: the scan pattern (sensor frame: +x forward, +z up).
        offset_pos: sensor position in the carrier's frame [m].
        offset_rot: sensor orientation in the carrier's frame, quaternion (w, x, y, z).
        ray_alignment: as Isaac Lab's RayCaster: ``"base"`` rays follow the full sensor
            orientation; ``"yaw"`` only its heading (rays stay level when the robot
            pitches or rolls); ``"world"`` rays keep their pattern directions in the
            world frame. The origin always follows the sensor.
        mesh_prim_paths: which geoms rays may hit: shell-style patterns (``fnmatch``,
            case-insensitive) matched against geom names, body names and geom paths
            (``/world/.../body/geom``); a body pattern selects all geoms of the bodies it
            matches. ``{ENV_REGEX_NS}`` at the start stands for any prefix, so the
            Isaac Lab-style ``"{ENV_REGEX_NS}/cracker_box_0/_03_cracker_box"`` and
            ``"/World/ground"`` work as written. Empty (default): every geom.
        exclude_robot: drop the geoms of the robot carrying the sensor (every body
            under the same root body as the carrier) from the hittable set.
        min_distance: hits closer than this are misses [m].
        max_distance: hits further than this are misses [m].
        range_noise_std: standard deviation of Gaussian range noise added to hits [m].
        dropout_prob: probability that a ray returns nothing (becomes a miss).
        seed: seed of the noise and dropout generator (``None``: fresh entropy).
        miss_distance: distance reported for misses; ``None`` (default) means
            ``max_distance``, so observations never hold ``inf``. Points of misses are
            NaN and ``data.hit_mask`` is False for them whatever this value.
        engine: ``"mujoco"`` (``mj_multiRay`` on CPU threads, the reference) or
            ``"warp"`` (mujoco-warp batched rays with a BVH; needs ``robotwright[warp]``).
        device: warp device (``"cpu"``, ``"cuda"``, ``"cuda:0"``); ``None`` picks CUDA
            when present, else CPU. Ignored by the ``"mujoco"`` engine.
        output: what ``data`` and the getters hold: ``"numpy"`` (host copies, float64),
            ``"torch"`` (zero-copy tensors on the sensor's device, float32 / int32 /
            bool) or ``"warp"`` (the device arrays themselves). Torch and warp outputs
            need ``engine="warp"`` and are overwritten in place by every update.
        num_threads: CPU threads of the ``"mujoco"`` engine, and of the ``"warp"`` engine
            on warp's CPU device (rays split in blocks); ``None``: one per core.
    """

    prim_path: str
    pattern_cfg: PatternCfg = field(default_factory=LivoxPatternCfg)
    offset_pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    offset_rot: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    ray_alignment: Literal["base", "yaw", "world"] = "base"
    mesh_prim_paths: list[str] = field(default_factory=list)
    exclude_robot: bool = True
    min_distance: float = 0.0
    max_distance: float = 100.0
    range_noise_std: float = 0.0
    dropout_prob: float = 0.0
    seed: int | None = 0
    miss_distance: float | None = None
    engine: Literal["mujoco", "warp"] = "mujoco"
    device: str | None = None
    num_threads: int | None = None
    output: Literal["numpy", "torch", "warp"] = "numpy"

    def __post_init__(self) -> None:
        name = type(self).__name__
        if not isinstance(self.prim_path, str) or not self.prim_path:
            raise SensorError(
                f"{name}.prim_path: expected the name of a body or site, got {self.prim_path!r}"
            )
        if not isinstance(self.pattern_cfg, PatternCfg):
            raise SensorError(
                f"{name}.pattern_cfg: expected a PatternCfg, got {type(self.pattern_cfg).__name__}"
            )
        self.pattern_cfg.validate()  # its fields as they are now (edited after construction)
        offset_pos = _floats(self.offset_pos, 3)
        if offset_pos is None or not all(abs(v) <= MAX_OFFSET_M for v in offset_pos):
            raise SensorError(
                f"{name}.offset_pos: expected 3 finite numbers [m], each within "
                f"+-{MAX_OFFSET_M:g}, got {self.offset_pos!r}"
            )
        self.offset_pos = offset_pos  # type: ignore[assignment]
        rot = _floats(self.offset_rot, 4)
        norm = math.hypot(*rot) if rot is not None else 0.0  # no overflow on squares
        if not norm > 1e-9 or not math.isfinite(norm):
            raise SensorError(
                f"{name}.offset_rot: expected a non-zero quaternion (w, x, y, z), got {self.offset_rot!r}"
            )
        self.offset_rot = tuple(float(v) / norm for v in self.offset_rot)  # type: ignore[assignment]
        if self.ray_alignment not in ("base", "yaw", "world"):
            raise SensorError(
                f"{name}.ray_alignment: expected 'base', 'yaw' or 'world', got {self.ray_alignment!r}"
            )
        if isinstance(self.mesh_prim_paths, str):
            raise SensorError(
                f"{name}.mesh_prim_paths: expected a list of names/patterns, got a string"
            )
        self.mesh_prim_paths = list(self.mesh_prim_paths)
        for key in ("min_distance", "max_distance", "range_noise_std"):
            value = getattr(self, key)
            if not _is_number(value) or math.isnan(value) or value < 0:
                raise SensorError(
                    f"{name}.{key}: expected a non-negative number [m], got {value!r}"
                )
            if key != "max_distance" and value > MAX_RANGE_M:  # max_distance: finite, below
                raise SensorError(
                    f"{name}.{key}: expected at most {MAX_RANGE_M:g} m, got {value!r}"
                )
        if not self.max_distance <= MAX_RANGE_M or self.max_distance <= self.min_distance:
            raise SensorError(
                f"{name}: expected min_distance < max_distance < inf, got {self.min_distance}, {self.max_distance}"
            )
        if not _is_number(self.dropout_prob) or not (0.0 <= self.dropout_prob <= 1.0):
            raise SensorError(
                f"{name}.dropout_prob: expected a probability in [0, 1], got {self.dropout_prob!r}"
            )
        if self.miss_distance is None:
            self.miss_distance = float(self.max_distance)
        elif not _is_number(self.miss_distance) or math.isnan(self.miss_distance):
            raise SensorError(
                f"{name}.miss_distance: expected a number [m] or None, got {self.miss_distance!r}"
            )
        if self.engine not in ("mujoco", "warp"):
            raise SensorError(f"{name}.engine: expected 'mujoco' or 'warp', got {self.engine!r}")
        if self.output not in ("numpy", "torch", "warp"):
            raise SensorError(
                f"{name}.output: expected 'numpy', 'torch' or 'warp', got {self.output!r}"
            )
        if self.output != "numpy" and self.engine != "warp":
            raise SensorError(
                f"{name}.output={self.output!r} needs engine='warp' (device buffers); "
                "the mujoco engine returns numpy"
            )
        if self.num_threads is not None and (
            not isinstance(self.num_threads, int)
            or isinstance(self.num_threads, bool)
            or not 1 <= self.num_threads <= MAX_THREADS
        ):
            raise SensorError(
                f"{name}.num_threads: expected an integer in [1, {MAX_THREADS}] or None, "
                f"got {self.num_threads!r}"
            )
        if self.seed is not None and (
            not isinstance(self.seed, int)
            or isinstance(self.seed, bool)
            or not 0 <= self.seed <= MAX_SEED
        ):
            raise SensorError(
                f"{name}.seed: expected an integer >= 0 and below 2**63, or None (fresh entropy), "
                f"got {shown(self.seed)}"
            )
        if not isinstance(self.exclude_robot, bool):
            raise SensorError(
                f"{name}.exclude_robot: expected True or False, got {self.exclude_robot!r}"
            )


@dataclass(kw_only=True)
class SemanticLidarCfg(LidarCfg):
    """:class:`LidarCfg` plus per-ray semantic classes.

    Attributes:
        semantic_class_mapping: class name -> keywords. A geom's class is the first
            class (in mapping order) one of whose keywords occurs, case-insensitively,
            in the geom's path (``/world/<bodies>/<geom>`` plus ``/<mesh>`` for mesh
            geoms). Class ids are 1..K in mapping order; 0 means miss or unknown.
            ``None``: :data:`DEFAULT_SEMANTIC_CLASS_MAPPING`.
        return_semantic_labels: compute ``data.semantic_labels``.
        return_mesh_ids: fill ``data.mesh_ids`` (the hit geom id per ray, -1 on a miss).
    """

    semantic_class_mapping: dict[str, list[str]] | None = None
    return_semantic_labels: bool = True
    return_mesh_ids: bool = False

    def __post_init__(self) -> None:
        super().__post_init__()
        name = type(self).__name__
        if self.semantic_class_mapping is None:
            self.semantic_class_mapping = {
                k: list(v) for k, v in DEFAULT_SEMANTIC_CLASS_MAPPING.items()
            }
        check_class_mapping(self.semantic_class_mapping, f"{name}.semantic_class_mapping")

    def build(self) -> None:
        """Refuse to be built as an mjlab sensor: mjlab's ``scene.sensors`` calls ``build()``."""
        from robotwright.errors import SensorError

        raise SensorError(
            f"{type(self).__name__} is the core sensor's config, not an mjlab sensor config: "
            "in mjlab's scene.sensors use robotwright.sensors.mjlab.SemanticLidarSensorCfg"
        )


#: The name of class id 0 (a miss, or a geom no class names): no class may take it.
UNKNOWN_CLASS = "unknown"


def check_class_mapping(mapping: object, where: str) -> None:
    """Check a semantic class mapping: a dict of non-empty class names (not
    :data:`UNKNOWN_CLASS`, whatever its case) to non-empty lists of non-empty keyword
    strings (a string is refused: it is not split into letters).

    Raises:
        SensorError: naming ``where`` (a config field or a file) and the class.
    """
    if not isinstance(mapping, dict):
        raise SensorError(
            f"{where}: expected a dict of class name -> keywords, got {type(mapping).__name__}"
        )
    for cls, keywords in mapping.items():
        if not isinstance(cls, str) or not cls:
            raise SensorError(f"{where}: class names must be non-empty strings, got {cls!r}")
        if cls.casefold() == UNKNOWN_CLASS:
            raise SensorError(
                f"{where}: class name {cls!r} is reserved for id 0 (misses and geoms no class "
                "names); choose another name"
            )
        if isinstance(keywords, str) or not isinstance(keywords, (list, tuple)):
            raise SensorError(
                f"{where}[{cls!r}]: expected a list of keywords, got "
                f"{type(keywords).__name__} {keywords!r:.80}"
            )
        if not keywords:
            raise SensorError(f"{where}[{cls!r}]: empty keyword list (class can never match)")
        if any(not isinstance(k, str) or not k for k in keywords):
            raise SensorError(f"{where}[{cls!r}]: keywords must be non-empty strings")


#: Largest ``--mapping`` file (a mapping of a hundred classes is a few kB).
MAX_MAPPING_BYTES = 1 << 20


def read_class_mapping(path: Path) -> dict[str, list[str]]:
    """The ``--mapping`` JSON file ``{class name: [keywords]}``, read as every untrusted
    input is (regular file, size cap, UTF-8, bounded nesting) and checked as the Python
    API checks a mapping (a keyword string, an empty list, a class named ``unknown``
    are refused).

    Raises:
        SensorError: naming the file and what is wrong.
    """
    from robotwright._inputs import load_json, read_text

    expected = "expected a JSON object {class: [keywords]}"
    try:
        mapping = load_json(read_text(path, MAX_MAPPING_BYTES), path)
    except InputFileError as exc:
        raise SensorError(f"--mapping {exc}") from None
    except OSError as exc:
        raise SensorError(f"--mapping {path}: {exc.strerror or exc}") from None
    except json.JSONDecodeError as exc:
        raise SensorError(f"--mapping {path}: not valid JSON ({exc}); {expected}") from None
    if not isinstance(mapping, dict):
        raise SensorError(f"--mapping {path}: {expected}, got a JSON {type(mapping).__name__}")
    check_class_mapping(mapping, f"--mapping {path}")
    return mapping
