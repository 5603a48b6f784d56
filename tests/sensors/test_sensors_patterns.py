"""Scan patterns: ray counts, fields of view, non-repetition, files, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robotwright.errors import SensorError
from robotwright.sensors import (
    FilePatternCfg,
    GridPatternCfg,
    LivoxPatternCfg,
    PinholeCameraPatternCfg,
    SpinningLidarPatternCfg,
    pattern_from_name,
)


def _elevation(d):
    return np.arcsin(np.clip(d[:, 2], -1, 1))


@pytest.mark.parametrize("name", ["mid360", "avia", "vlp16", "vlp32", "os128", "grid", "pinhole"])
def test_presets_give_unit_directions(name):
    origins, dirs = pattern_from_name(name).rays(0)
    assert origins.shape == dirs.shape and dirs.shape[1] == 3 and dirs.shape[0] > 0
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=1), 1.0, atol=1e-12)


def test_spinning_presets_channels_and_angles():
    vlp16 = SpinningLidarPatternCfg.vlp16()
    assert vlp16.channels == 16 and vlp16.num_rays == 16 * 1800
    el = np.degrees(_elevation(vlp16.rays()[1]))
    np.testing.assert_allclose(np.unique(el.round(9)), np.arange(-15, 16, 2), atol=1e-9)
    vlp32 = SpinningLidarPatternCfg.vlp32()
    assert vlp32.channels == 32
    assert math.isclose(min(vlp32.vertical_angles), math.radians(-25)) and math.isclose(
        max(vlp32.vertical_angles), math.radians(15)
    )
    os128 = SpinningLidarPatternCfg.os128(columns=512)
    assert os128.channels == 128 and os128.num_rays == 128 * 512
    # Column-major order: the first `channels` rays share one azimuth.
    d = vlp16.rays()[1]
    az = np.arctan2(d[:, 1], d[:, 0])
    assert np.ptp(az[:16]) < 1e-12 and not np.isclose(az[0], az[16])


def test_mid360_field_of_view_and_size():
    p = LivoxPatternCfg(sensor_type="mid360")
    d = p.rays(0)[1]
    assert d.shape == (20000, 3)
    el = _elevation(d)
    assert el.min() >= math.radians(-7) - 1e-12 and el.max() <= math.radians(52) + 1e-12
    az = np.arctan2(d[:, 1], d[:, 0])
    hist, _ = np.histogram(az, bins=36, range=(-math.pi, math.pi))
    assert hist.min() > 0.5 * hist.mean()  # all around, roughly even


def test_avia_field_of_view():
    p = LivoxPatternCfg(sensor_type="avia")
    d = p.rays(3)[1]
    az = np.arctan2(d[:, 1], d[:, 0])
    el = _elevation(d)
    assert np.abs(az).max() <= math.radians(70.4 / 2) + 1e-9
    assert np.abs(el).max() <= math.radians(77.2 / 2) + 1e-9
    assert (d[:, 0] > 0).all()  # forward-looking


@pytest.mark.parametrize("sensor_type", ["mid360", "avia"])
def test_rosette_successive_frames_cover_new_directions(sensor_type):
    p = LivoxPatternCfg(sensor_type=sensor_type, num_rays=5000)
    frames = [p.rays(f)[1] for f in range(4)]
    assert not np.allclose(frames[0], frames[1])

    def cells(d):  # occupied 0.5 deg x 0.5 deg cells
        az = np.degrees(np.arctan2(d[:, 1], d[:, 0]))
        el = np.degrees(_elevation(d))
        return set(
            zip((az / 0.5).astype(int).tolist(), (el / 0.5).astype(int).tolist(), strict=True)
        )

    covered = cells(frames[0])
    sizes = [len(covered)]
    for f in frames[1:]:
        covered |= cells(f)
        sizes.append(len(covered))
    # Each new frame adds at least 20% new cells: the pattern does not repeat.
    assert all(b > a * 1.2 for a, b in zip(sizes, sizes[1:], strict=False))
    # The same frame index gives the same rays (deterministic).
    np.testing.assert_array_equal(p.rays(2)[1], frames[2])


def test_spinning_pattern_repeats():
    p = SpinningLidarPatternCfg.vlp16()
    np.testing.assert_array_equal(p.rays(0)[1], p.rays(5)[1])


def test_grid_and_pinhole():
    origins, dirs = GridPatternCfg(resolution=0.5, size=(1.0, 1.0)).rays()
    assert origins.shape == (9, 3)
    np.testing.assert_allclose(dirs, np.tile([0, 0, -1.0], (9, 1)))
    cam = PinholeCameraPatternCfg(width=4, height=2, horizontal_fov=math.pi / 2)
    d = cam.rays()[1]
    assert d.shape == (8, 3)
    # Top-left pixel looks left (+y) and up (+z); the image centre row/col straddle +x.
    assert d[0, 1] > 0 and d[0, 2] > 0 and d[-1, 1] < 0 and d[-1, 2] < 0
    # Outer pixel centres sit at 3/4 of the half field of view in tan space.
    np.testing.assert_allclose(d[0, 1] / d[0, 0], 0.75, atol=1e-12)


def test_file_pattern_text_and_npy(tmp_path):
    csv = tmp_path / "pattern.csv"
    csv.write_text("azimuth,elevation\n0,0\n90,0  # left\n0,-90\n", encoding="utf-8")
    d = FilePatternCfg(path=csv, degrees=True).rays()[1]
    np.testing.assert_allclose(d, [[1, 0, 0], [0, 1, 0], [0, 0, -1]], atol=1e-12)
    npy = tmp_path / "pattern.npy"
    np.save(npy, np.array([[math.pi, 0.0]]))
    np.testing.assert_allclose(FilePatternCfg(path=npy).rays()[1], [[-1, 0, 0]], atol=1e-12)


def test_file_pattern_errors(tmp_path):
    empty = tmp_path / "empty.txt"
    empty.write_text("# no rays\n", encoding="utf-8")
    with pytest.raises(SensorError, match="empty.txt: empty pattern"):
        FilePatternCfg(path=empty)
    bad = tmp_path / "bad.txt"
    bad.write_text("0 0\n1 x\n", encoding="utf-8")
    with pytest.raises(SensorError, match="bad.txt: line 2: expected two numbers"):
        FilePatternCfg(path=bad)
    steep = tmp_path / "steep.txt"
    steep.write_text("0 0\n0 100\n", encoding="utf-8")
    with pytest.raises(
        SensorError, match="steep.txt: row 1: expected finite azimuth and elevation"
    ):
        FilePatternCfg(path=steep, degrees=True)
    with pytest.raises(SensorError, match="pattern file not found"):
        FilePatternCfg(path=tmp_path / "missing.csv")


def test_pattern_config_errors():
    with pytest.raises(SensorError, match="empty pattern"):
        SpinningLidarPatternCfg(vertical_angles=(), horizontal_resolution=0.01)
    with pytest.raises(SensorError, match="horizontal_resolution: expected a positive"):
        SpinningLidarPatternCfg(vertical_angles=(0.0,), horizontal_resolution=-0.1)
    with pytest.raises(SensorError, match="num_rays: expected an integer >= 1"):
        LivoxPatternCfg(num_rays=0)
    with pytest.raises(SensorError, match="sensor_type: expected one of"):
        LivoxPatternCfg(sensor_type="mid70")
    with pytest.raises(SensorError, match="unknown pattern 'hdl64'"):
        pattern_from_name("hdl64")


def test_sensor_type_changed_after_construction_brings_its_preset():
    """A pattern edited after construction (as mjlab's and Isaac Lab's config systems
    and command lines do) scans as a pattern built with the new value."""
    edited = LivoxPatternCfg(sensor_type="mid360")
    edited.sensor_type = "avia"
    built = LivoxPatternCfg(sensor_type="avia")
    np.testing.assert_array_equal(edited.ray_table().directions, built.ray_table().directions)
    assert edited.effective("points_per_second") == 240_000.0
    # a field given explicitly stays, whatever the type
    wide = LivoxPatternCfg(sensor_type="mid360", vertical_fov_max=math.radians(30))
    wide.sensor_type = "avia"
    assert wide.effective("vertical_fov_max") == math.radians(30)


@pytest.mark.parametrize(
    ("make", "field", "value", "words"),
    [
        (lambda: LivoxPatternCfg(), "num_rays", 0, "num_rays: expected an integer >= 1"),
        (lambda: LivoxPatternCfg(), "table_frames", 0, "table_frames: expected an integer"),
        (lambda: LivoxPatternCfg(), "sensor_type", "hap", "sensor_type: expected one of"),
        (lambda: GridPatternCfg(), "resolution", -0.1, "resolution: expected a positive"),
        (lambda: PinholeCameraPatternCfg(), "width", 0, "width: expected an integer >= 1"),
        (lambda: SpinningLidarPatternCfg.vlp16(), "vertical_angles", (), "empty pattern"),
    ],
)
def test_field_edited_after_construction_is_checked_when_built(make, field, value, words):
    """``num_rays = 0`` set after construction is a named error when the pattern is used
    (and when a sensor is built from it), not a ZeroDivisionError."""
    from robotwright.sensors.config import LidarCfg

    pattern = make()
    setattr(pattern, field, value)
    with pytest.raises(SensorError, match=words):
        pattern.ray_table()
    with pytest.raises(SensorError, match=words):
        LidarCfg(prim_path="base", pattern_cfg=pattern)
