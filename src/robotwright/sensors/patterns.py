"""Scan patterns: which rays a LiDAR casts, in the sensor frame.

Sensor frame convention (as in ROS and Isaac Lab's ray casters): +x forward, +y left,
+z up. Azimuth is measured about +z from +x, elevation from the x-y plane towards +z;
all angles are in radians, all lengths in metres.

Every pattern config answers :meth:`PatternCfg.rays`, which returns ray origins
(``(N, 3)``, metres, sensor frame) and unit directions (``(N, 3)``) for a frame index.
Repetitive patterns return the same rays for every frame; the Livox-style pattern moves
along its scan curve from one frame to the next so successive frames cover new
directions.

Sensors do not call :meth:`PatternCfg.rays` per frame: they compute the pattern's
:class:`RayTable` once (``table_frames`` frames back to back) and cast a window of it
each frame, so a frame costs no pattern arithmetic on the host and the table can live
on the GPU. ``rays(f)`` equals ``ray_table().window(f)`` for every frame.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar, Literal

import numpy as np

from robotwright._limits import limit_for_block
from robotwright.errors import SensorError
from robotwright.sensors._names import PATTERN_NAMES

__all__ = [
    "PatternCfg",
    "RayTable",
    "LivoxPatternCfg",
    "SpinningLidarPatternCfg",
    "GridPatternCfg",
    "PinholeCameraPatternCfg",
    "FilePatternCfg",
    "spherical_to_directions",
    "pattern_from_name",
    "ray_limit",
    "PATTERN_NAMES",
]


def spherical_to_directions(azimuth: np.ndarray, elevation: np.ndarray) -> np.ndarray:
    """Unit vectors ``(N, 3)`` for azimuth/elevation arrays in radians (sensor frame)."""
    az = np.asarray(azimuth, dtype=np.float64)
    el = np.asarray(elevation, dtype=np.float64)
    cos_el = np.cos(el)
    return np.stack([cos_el * np.cos(az), cos_el * np.sin(az), np.sin(el)], axis=-1)


@dataclass(frozen=True)
class RayTable:
    """Every ray a pattern casts over ``num_frames`` frames, frame after frame.

    Frame ``f`` casts rows ``[k * N, (k + 1) * N)`` with ``k = f % num_frames`` and
    ``N = rays_per_frame``: the window advances by one frame each update and wraps
    after ``num_frames`` frames (1 for repetitive patterns).

    Attributes:
        origins: ``(num_frames * N, 3)`` ray origins in the sensor frame [m].
        directions: ``(num_frames * N, 3)`` unit ray directions in the sensor frame.
        rays_per_frame: ``N``.
    """

    origins: np.ndarray
    directions: np.ndarray
    rays_per_frame: int

    @property
    def num_frames(self) -> int:
        return self.directions.shape[0] // self.rays_per_frame

    @property
    def single_origin(self) -> bool:
        """Every ray starts at the sensor origin."""
        return not self.origins.any()

    def window(self, frame: int) -> tuple[np.ndarray, np.ndarray]:
        """Origins and directions ``(N, 3)`` of frame ``frame`` (views into the table)."""
        start = (int(frame) % self.num_frames) * self.rays_per_frame
        stop = start + self.rays_per_frame
        return self.origins[start:stop], self.directions[start:stop]


@dataclass(kw_only=True)
class PatternCfg:
    """Base class of scan patterns."""

    #: True when every frame casts the same rays (lets the sensor cache them).
    repetitive: ClassVar[bool] = True

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:
        """Check every field as it is now: a field changed after construction (by a user,
        mjlab's or Isaac Lab's config system, a command line) is checked again when a
        sensor is built from the pattern (:class:`SensorError` naming the field)."""

    @property
    def num_rays(self) -> int:
        """Number of rays per frame."""
        return int(self._directions(0).shape[0])

    def firing_rate(self) -> float | None:
        """Rays fired per second when the table is a stream in time (a sensor then moves
        its window with simulated time); ``None``: one frame per scan."""
        return None

    def rays(self, frame: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Ray origins ``(N, 3)`` [m] and unit directions ``(N, 3)`` in the sensor frame."""
        self.validate()
        dirs = self._directions(frame)
        return np.zeros_like(dirs), dirs

    def ray_table(self) -> RayTable:
        """The rays of every distinct frame, computed once (see :class:`RayTable`)."""
        self.validate()  # a pattern's own rays() (the grid's) may not
        origins, dirs = self.rays(0)
        return RayTable(
            np.ascontiguousarray(origins, dtype=np.float64),
            np.ascontiguousarray(dirs, dtype=np.float64),
            int(dirs.shape[0]),
        )

    def _directions(self, frame: int) -> np.ndarray:
        raise NotImplementedError


def _check_positive(name: str, value: float, cls: str) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise SensorError(f"{cls}.{name}: expected a positive finite number, got {value!r}")


#: Most rays one frame may cast (a 4096-env batch of these is already 40 GB of rays), and
#: most rows of a precomputed table: larger requests are refused before any allocation.
#: :func:`ray_limit` changes the first (and the second to at least twice it).
MAX_RAYS_PER_FRAME = 10_000_000
MAX_TABLE_RAYS = 20_000_000

_RAY_LIMIT: contextvars.ContextVar[int] = contextvars.ContextVar(
    "ray_limit", default=MAX_RAYS_PER_FRAME
)


@contextlib.contextmanager
def ray_limit(max_rays: int | None) -> Iterator[None]:
    """Within the block, patterns may cast up to ``max_rays`` rays per frame (``None``:
    the default, :data:`MAX_RAYS_PER_FRAME`)."""
    if max_rays is not None and (
        isinstance(max_rays, bool) or not isinstance(max_rays, int) or max_rays < 1
    ):
        raise SensorError(f"max_rays: expected an integer >= 1, got {max_rays!r}")
    with limit_for_block(_RAY_LIMIT, max_rays):
        yield


def _check_ray_count(count: float, cls: str, what: str = "rays per frame") -> None:
    frame_limit = _RAY_LIMIT.get()
    limit = frame_limit if what == "rays per frame" else max(MAX_TABLE_RAYS, 2 * frame_limit)
    if count > limit:
        raise SensorError(
            f"{cls}: {count:.3g} {what} requested; at most {limit:,} are allowed "
            "(check the resolution, size or field of view; "
            "robotwright.sensors.ray_limit raises the limit)"
        )


def _check_count(name: str, value: int, cls: str) -> None:
    if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < 1:
        raise SensorError(f"{cls}.{name}: expected an integer >= 1, got {value!r}")


# Published field of view and point rate of the Livox sensors this pattern imitates.
_LIVOX_PRESETS: dict[str, dict[str, float]] = {
    # Mid-360: 360 deg horizontal, -7..52 deg vertical, 200k points/s.
    "mid360": {
        "horizontal_fov": 2.0 * math.pi,
        "vertical_fov_min": math.radians(-7.0),
        "vertical_fov_max": math.radians(52.0),
        "points_per_second": 200_000.0,
    },
    # Avia: 70.4 deg x 77.2 deg rosette, 240k points/s (first return).
    "avia": {
        "horizontal_fov": math.radians(70.4),
        "vertical_fov_min": math.radians(-77.2 / 2.0),
        "vertical_fov_max": math.radians(77.2 / 2.0),
        "points_per_second": 240_000.0,
    },
}


@dataclass(kw_only=True)
class LivoxPatternCfg(PatternCfg):
    """Livox-style non-repetitive scan (Mid-360-like or Avia-like).

    Each ray ``i`` of frame ``f`` is fired at time ``t = (f * num_rays + i) /
    points_per_second`` along a scan curve whose frequencies are incommensurate, so the
    curve never closes and successive frames fill new directions (coverage grows with
    integration time, as on the real sensors). This reproduces field of view, point
    rate and the non-repetitive property; it is not the vendors' exact firing table.

    * ``"mid360"``: ``num_lines`` beams spread evenly in azimuth spin about +z at
      ``rotation_hz``; the elevation of each beam follows a triangle wave between
      ``vertical_fov_min`` and ``vertical_fov_max`` at ``elevation_sweep_hz``.
    * ``"avia"``: a Risley-prism rosette: the sum of two unit vectors rotating at
      ``prism_rpm`` (opposite signs give petals through the centre), scaled onto the
      horizontal and vertical field of view.

    Attributes:
        sensor_type: ``"mid360"`` or ``"avia"``.
        num_rays: rays per frame (Mid-360 at 10 Hz gives 20 000).
        points_per_second: firing rate; ``None`` takes the sensor's published rate.
        horizontal_fov, vertical_fov_min, vertical_fov_max: radians; ``None`` takes
            the sensor's published field of view.
        num_lines: beams of the Mid-360-like pattern.
        rotation_hz: spin rate of the Mid-360-like pattern [Hz].
        elevation_sweep_hz: elevation triangle-wave rate [Hz]; its ratio to
            ``rotation_hz`` is irrational by default so the pattern never repeats.
        prism_rpm: rotation rates of the two prisms of the Avia-like rosette [rev/min].
        table_frames: frames in the precomputed ray table; the scan repeats after this
            many frames (default 20: 2 s of a 10 Hz Mid-360, 400 000 directions, twice
            the rays the real sensor needs to cover its field of view).
    """

    repetitive: ClassVar[bool] = False

    sensor_type: Literal["mid360", "avia"] = "mid360"
    num_rays: int = 20_000  # type: ignore[assignment]
    points_per_second: float | None = None
    horizontal_fov: float | None = None
    vertical_fov_min: float | None = None
    vertical_fov_max: float | None = None
    num_lines: int = 4
    rotation_hz: float = 10.0
    elevation_sweep_hz: float = 10.0 * (1.0 + math.sqrt(5.0)) / 2.0 * 37.0
    prism_rpm: tuple[float, float] = (7294.0, -4664.0)
    table_frames: int = 20

    def effective(self, key: str) -> float:
        """The value the pattern fires with: field ``key`` (``points_per_second``,
        ``horizontal_fov``, ``vertical_fov_min``, ``vertical_fov_max``), or where it is
        None, the published value of the current ``sensor_type`` (looked up at each use,
        so that a sensor type changed after construction brings its own preset)."""
        value = getattr(self, key)
        return _LIVOX_PRESETS[self.sensor_type][key] if value is None else value

    def validate(self) -> None:
        name = type(self).__name__
        if self.sensor_type not in _LIVOX_PRESETS:
            raise SensorError(
                f"{name}.sensor_type: expected one of {sorted(_LIVOX_PRESETS)}, got {self.sensor_type!r}"
            )
        _check_count("num_rays", self.num_rays, name)
        _check_count("num_lines", self.num_lines, name)
        _check_count("table_frames", self.table_frames, name)
        _check_ray_count(self.num_rays, name)
        _check_ray_count(
            self.num_rays * self.table_frames, name, "table rows (num_rays x table_frames)"
        )
        for key in ("points_per_second", "horizontal_fov"):
            _check_positive(key, self.effective(key), name)
        for key in ("rotation_hz", "elevation_sweep_hz"):
            _check_positive(key, getattr(self, key), name)
        if self.effective("horizontal_fov") > 2.0 * math.pi + 1e-12:
            raise SensorError(
                f"{name}.horizontal_fov: expected <= 2*pi rad, got {self.effective('horizontal_fov')}"
            )
        lo, hi = self.effective("vertical_fov_min"), self.effective("vertical_fov_max")
        if not (-math.pi / 2 <= lo < hi <= math.pi / 2):
            raise SensorError(
                f"{name}: expected -pi/2 <= vertical_fov_min < vertical_fov_max <= pi/2, got {lo}, {hi}"
            )
        if (
            len(self.prism_rpm) != 2
            or self.prism_rpm[0] == self.prism_rpm[1]
            or not all(math.isfinite(r) for r in self.prism_rpm)
        ):
            raise SensorError(
                f"{name}.prism_rpm: expected two different finite rates, got {self.prism_rpm}"
            )

    def firing_rate(self) -> float | None:
        """The published (or given) points per second: the table is the firing stream."""
        return float(self.effective("points_per_second"))

    def _directions(self, frame: int) -> np.ndarray:
        first = (int(frame) % self.table_frames) * int(self.num_rays)
        return self._fire(first, int(self.num_rays))

    def ray_table(self) -> RayTable:
        self.validate()
        dirs = self._fire(0, self.table_frames * int(self.num_rays))
        return RayTable(np.zeros_like(dirs), dirs, int(self.num_rays))

    def _fire(self, first: int, count: int) -> np.ndarray:
        """Directions of the rays fired ``first .. first + count - 1`` (sensor frame)."""
        idx = np.arange(first, first + count, dtype=np.int64)
        t = idx / self.effective("points_per_second")
        lo, hi = self.effective("vertical_fov_min"), self.effective("vertical_fov_max")
        fov = self.effective("horizontal_fov")
        if self.sensor_type == "mid360":
            line_frac = (idx % self.num_lines) / self.num_lines
            turns = self.rotation_hz * t + line_frac
            az = (2.0 * math.pi) * (turns - np.floor(turns))  # in [0, 2 pi)
            if fov < 2.0 * math.pi:
                # Squeeze one turn into the field of view, centred on +x.
                az = az * (fov / (2.0 * math.pi)) - fov / 2.0
            phase = self.elevation_sweep_hz * t + line_frac
            phase -= np.floor(phase)
            tri = 1.0 - np.abs(2.0 * phase - 1.0)  # triangle wave in [0, 1]
            el = lo + (hi - lo) * tri
        else:
            w1, w2 = (2.0 * math.pi * r / 60.0 for r in self.prism_rpm)
            x = 0.5 * (np.cos(w1 * t) + np.cos(w2 * t))
            y = 0.5 * (np.sin(w1 * t) + np.sin(w2 * t))
            az = x * fov / 2.0
            el = (lo + hi) / 2.0 + y * (hi - lo) / 2.0
        return spherical_to_directions(az, el)


# Published vertical angles (degrees) of common spinning sensors.
_VLP32C_DEG = (
    -25.0,
    -15.639,
    -11.31,
    -8.843,
    -7.254,
    -6.148,
    -5.333,
    -4.667,
    -4.0,
    -3.667,
    -3.333,
    -3.0,
    -2.667,
    -2.333,
    -2.0,
    -1.667,
    -1.333,
    -1.0,
    -0.667,
    -0.333,
    0.0,
    0.333,
    0.667,
    1.0,
    1.333,
    1.667,
    2.333,
    3.333,
    4.667,
    7.0,
    10.333,
    15.0,
)


@dataclass(kw_only=True)
class SpinningLidarPatternCfg(PatternCfg):
    """Spinning multi-beam LiDAR (Velodyne / Ouster style); repeats every frame.

    Rays are ordered column by column: for each azimuth step, every channel from the
    lowest to the highest vertical angle.

    Attributes:
        vertical_angles: elevation of each channel [rad].
        horizontal_resolution: azimuth step [rad].
        horizontal_fov: azimuth span [rad], ``2*pi`` for a full turn.
        horizontal_start: first azimuth [rad].
    """

    vertical_angles: tuple[float, ...]
    horizontal_resolution: float
    horizontal_fov: float = 2.0 * math.pi
    horizontal_start: float = -math.pi

    def validate(self) -> None:
        name = type(self).__name__
        self.vertical_angles = tuple(float(a) for a in self.vertical_angles)
        if not self.vertical_angles:
            raise SensorError(
                f"{name}.vertical_angles: empty pattern (expected at least one channel)"
            )
        if not all(abs(a) <= math.pi / 2 for a in self.vertical_angles):  # NaN fails too
            raise SensorError(f"{name}.vertical_angles: expected angles in [-pi/2, pi/2] rad")
        _check_positive("horizontal_resolution", self.horizontal_resolution, name)
        _check_positive("horizontal_fov", self.horizontal_fov, name)
        if not (
            isinstance(self.horizontal_start, (int, float)) and math.isfinite(self.horizontal_start)
        ):
            raise SensorError(
                f"{name}.horizontal_start: expected a finite angle [rad], got {self.horizontal_start!r}"
            )
        columns = self.horizontal_fov / self.horizontal_resolution + 1
        _check_ray_count(columns * len(self.vertical_angles), name)

    @property
    def channels(self) -> int:
        return len(self.vertical_angles)

    def azimuths(self) -> np.ndarray:
        """Azimuth of each column [rad]."""
        full = self.horizontal_fov >= 2.0 * math.pi - 1e-9
        n = self.horizontal_fov / self.horizontal_resolution
        n = int(round(n)) if full else int(math.floor(n + 1e-9)) + 1
        return self.horizontal_start + self.horizontal_resolution * np.arange(max(n, 1))

    def _directions(self, frame: int) -> np.ndarray:
        az, el = np.meshgrid(self.azimuths(), np.asarray(self.vertical_angles), indexing="ij")
        return spherical_to_directions(az.ravel(), el.ravel())

    @classmethod
    def vlp16(cls, horizontal_resolution: float = math.radians(0.2)) -> SpinningLidarPatternCfg:
        """Velodyne VLP-16-like: 16 channels from -15 to +15 deg every 2 deg."""
        angles = tuple(math.radians(a) for a in np.arange(-15.0, 15.0 + 1e-9, 2.0))
        return cls(vertical_angles=angles, horizontal_resolution=horizontal_resolution)

    @classmethod
    def vlp32(cls, horizontal_resolution: float = math.radians(0.2)) -> SpinningLidarPatternCfg:
        """Velodyne VLP-32C-like: 32 channels, -25 to +15 deg, denser near the horizon."""
        angles = tuple(math.radians(a) for a in _VLP32C_DEG)
        return cls(vertical_angles=angles, horizontal_resolution=horizontal_resolution)

    @classmethod
    def os128(cls, columns: int = 1024) -> SpinningLidarPatternCfg:
        """Ouster OS1-128-like: 128 channels evenly over 45 deg (-22.5..22.5), ``columns`` per turn."""
        angles = tuple(np.radians(np.linspace(-22.5, 22.5, 128)).tolist())
        return cls(vertical_angles=angles, horizontal_resolution=2.0 * math.pi / columns)


@dataclass(kw_only=True)
class GridPatternCfg(PatternCfg):
    """Parallel rays from a regular grid of origins (a height scanner), as Isaac Lab's grid.

    Attributes:
        resolution: grid spacing [m].
        size: grid extent along sensor x and y [m].
        direction: ray direction in the sensor frame (normalised), default straight down.
    """

    resolution: float = 0.1
    size: tuple[float, float] = (1.6, 1.0)
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)

    def validate(self) -> None:
        name = type(self).__name__
        _check_positive("resolution", self.resolution, name)
        if len(self.size) != 2 or any(not math.isfinite(s) or s < 0 for s in self.size):
            raise SensorError(
                f"{name}.size: expected two non-negative lengths [m], got {self.size}"
            )
        _check_ray_count(
            (self.size[0] / self.resolution + 1) * (self.size[1] / self.resolution + 1), name
        )
        norm = float(np.linalg.norm(self.direction))
        if len(self.direction) != 3 or not norm > 0 or not math.isfinite(norm):
            raise SensorError(
                f"{name}.direction: expected a non-zero 3-vector, got {self.direction}"
            )

    def _grid(self) -> np.ndarray:
        xs = np.arange(-self.size[0] / 2, self.size[0] / 2 + 1e-9, self.resolution)
        ys = np.arange(-self.size[1] / 2, self.size[1] / 2 + 1e-9, self.resolution)
        gx, gy = np.meshgrid(xs, ys, indexing="xy")
        return np.stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)], axis=-1)

    def _directions(self, frame: int) -> np.ndarray:
        d = np.asarray(self.direction, dtype=np.float64)
        return np.tile(d / np.linalg.norm(d), (self._grid().shape[0], 1))

    def rays(self, frame: int = 0) -> tuple[np.ndarray, np.ndarray]:
        return self._grid(), self._directions(frame)


@dataclass(kw_only=True)
class PinholeCameraPatternCfg(PatternCfg):
    """One ray per pixel of a pinhole camera looking along +x (image right = -y, up = +z).

    Rays are ordered row by row from the top-left pixel; a depth image is
    ``distances.reshape(height, width)``.

    Attributes:
        width, height: image size [pixels].
        horizontal_fov: horizontal field of view [rad]; the vertical one follows from the
            aspect ratio (square pixels).
    """

    width: int = 64
    height: int = 48
    horizontal_fov: float = math.pi / 2.0

    def validate(self) -> None:
        name = type(self).__name__
        _check_count("width", self.width, name)
        _check_count("height", self.height, name)
        _check_ray_count(self.width * self.height, name)
        _check_positive("horizontal_fov", self.horizontal_fov, name)
        if self.horizontal_fov >= math.pi:
            raise SensorError(
                f"{name}.horizontal_fov: expected < pi rad, got {self.horizontal_fov}"
            )

    def _directions(self, frame: int) -> np.ndarray:
        f = (self.width / 2.0) / math.tan(self.horizontal_fov / 2.0)  # focal length [px]
        u = np.arange(self.width) + 0.5 - self.width / 2.0
        v = np.arange(self.height) + 0.5 - self.height / 2.0
        uu, vv = np.meshgrid(u, v, indexing="xy")
        d = np.stack([np.full(uu.size, f), -uu.ravel(), -vv.ravel()], axis=-1)
        return d / np.linalg.norm(d, axis=1, keepdims=True)


@dataclass(kw_only=True)
class FilePatternCfg(PatternCfg):
    """Ray angles read from a file: one ray per row, columns azimuth and elevation.

    Accepted files: ``.npy`` holding an ``(N, 2)`` array, or text (``.csv``, ``.txt``):
    comma or whitespace separated, ``#`` comments, an optional header line.

    Attributes:
        path: the file.
        degrees: the angles in the file are in degrees (default radians).
    """

    path: str | Path
    degrees: bool = False
    _angles: np.ndarray = field(init=False, repr=False, compare=False)
    _read_as: tuple[str, bool] | None = field(default=None, init=False, repr=False, compare=False)

    def validate(self) -> None:
        if self._read_as == (str(self.path), bool(self.degrees)):
            return  # read and checked as it is now
        path = Path(self.path)
        data = _read_pattern_file(path)
        angles = _load_npy(data, path) if path.suffix == ".npy" else _read_angle_table(data, path)
        angles = np.asarray(angles, dtype=np.float64)
        if angles.ndim != 2 or angles.shape[1] != 2:
            raise SensorError(
                f"{path}: expected N rows of (azimuth, elevation), got shape {angles.shape}"
            )
        if angles.shape[0] == 0:
            raise SensorError(f"{path}: empty pattern (no rays)")
        _check_ray_count(angles.shape[0], str(path))
        if self.degrees:
            angles = np.radians(angles)
        bad = np.flatnonzero(
            ~np.isfinite(angles).all(axis=1) | (np.abs(angles[:, 1]) > math.pi / 2 + 1e-12)
        )
        if bad.size:
            raise SensorError(
                f"{path}: row {int(bad[0])}: expected finite azimuth and elevation in [-pi/2, pi/2] rad"
                f"{' (file read as degrees)' if self.degrees else ''}, got {angles[bad[0]].tolist()}"
            )
        self._angles = angles
        self._read_as = (str(self.path), bool(self.degrees))

    def _directions(self, frame: int) -> np.ndarray:
        self.validate()
        return spherical_to_directions(self._angles[:, 0], self._angles[:, 1])


def _read_pattern_file(path: Path) -> bytes:
    """The bytes of pattern file ``path``: a regular file within the table size limit
    (a pattern file may come with a downloaded robot or scene), else :class:`SensorError`
    naming it."""
    from robotwright._inputs import MAX_TABLE_BYTES, read_bytes
    from robotwright.errors import InputFileError

    try:
        return read_bytes(path, MAX_TABLE_BYTES)
    except FileNotFoundError:
        raise SensorError(f"{path}: pattern file not found") from None
    except InputFileError as exc:
        raise SensorError(f"{path}: pattern file {exc.reason}") from None
    except OSError as exc:
        raise SensorError(f"{path}: cannot read pattern file: {exc.strerror or exc}") from None


def _load_npy(data: bytes, path: Path) -> np.ndarray:
    """The array of a ``.npy`` file's bytes: real numbers only (no pickled objects, no
    strings, booleans, complex numbers or records), else :class:`SensorError`."""
    import io
    import pickle

    fmt = np.lib.format
    try:
        # The header's shape is checked against the bytes present first: np.load
        # allocates the whole declared array before reading it (a 200-byte file can
        # declare terabytes).
        head = io.BytesIO(data)
        version = fmt.read_magic(head)
        if version not in ((1, 0), (2, 0)):
            raise ValueError(f"format version {version}; expected 1.0 or 2.0")
        read_header = fmt.read_array_header_1_0 if version == (1, 0) else fmt.read_array_header_2_0
        shape, _, dtype = read_header(head)
        need = math.prod(shape) * dtype.itemsize
        if need > len(data) - head.tell():
            raise ValueError(
                f"the header declares shape {shape} ({need} bytes), more than the file holds"
            )
        array = np.load(io.BytesIO(data), allow_pickle=False)
    except (ValueError, EOFError, OSError, pickle.UnpicklingError) as exc:
        why = " ".join(str(exc).split())[:200]
        raise SensorError(f"{path}: not a readable .npy array ({why})") from None
    if not isinstance(array, np.ndarray) or array.dtype.kind not in "iuf":
        got = array.dtype if isinstance(array, np.ndarray) else "an .npz archive"
        raise SensorError(f"{path}: expected an array of real numbers, got {got}")
    return array


def _read_angle_table(data: bytes, path: Path) -> np.ndarray:
    from robotwright._inputs import decode
    from robotwright.errors import InputFileError

    rows: list[list[float]] = []
    header_seen = False
    try:
        text = decode(data, path)
    except InputFileError as exc:
        raise SensorError(f"{path}: pattern file {exc.reason}") from None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = [p for p in line.replace(",", " ").split() if p]
        try:
            values = [float(p) for p in parts]
        except ValueError:
            if not rows and not header_seen:
                header_seen = True  # one header line is allowed before the data
                continue
            raise SensorError(f"{path}: line {lineno}: expected two numbers, got {raw!r}") from None
        if len(values) != 2:
            raise SensorError(
                f"{path}: line {lineno}: expected 2 columns (azimuth, elevation), got {len(values)}"
            )
        rows.append(values)
    return np.asarray(rows, dtype=np.float64).reshape(-1, 2)


def pattern_from_name(name: str) -> PatternCfg:
    """A preset pattern config by name (see :data:`PATTERN_NAMES`)."""
    key = name.lower()
    if key in ("mid360", "avia"):
        return LivoxPatternCfg(sensor_type=key)  # type: ignore[arg-type]
    if key == "vlp16":
        return SpinningLidarPatternCfg.vlp16()
    if key == "vlp32":
        return SpinningLidarPatternCfg.vlp32()
    if key == "os128":
        return SpinningLidarPatternCfg.os128()
    if key == "grid":
        return GridPatternCfg()
    if key == "pinhole":
        return PinholeCameraPatternCfg()
    raise SensorError(f"unknown pattern {name!r}: expected one of {', '.join(PATTERN_NAMES)}")
