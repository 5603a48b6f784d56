"""Scan pictures: the plot says when the sensor is upside down, crops to the hits, and
names each class with its keywords; the scene picture draws the points by class."""

from __future__ import annotations

import math

import matplotlib.image as mpimg
import mujoco
import numpy as np
import pytest

from robotwright.render.scan import class_legend, render_scan
from robotwright.sensors.plot import (
    _limits,
    class_color,
    plot_scan,
    tilt_deg,
    upside_down,
    view_stretch,
)


@pytest.mark.parametrize(
    ("quat", "down"),
    [
        ((1, 0, 0, 0), False),
        ((0, 1, 0, 0), True),  # 180 deg about x: the demo's head mount
        ((0, 0, 1, 0), True),  # 180 deg about y
        ((0, 0, 0, 1), False),  # 180 deg about z: yawed, still upright
        ((math.cos(0.4), math.sin(0.4), 0, 0), False),  # tilted 46 deg
        ((math.cos(0.9), math.sin(0.9), 0, 0), True),  # tilted 103 deg
        ((2, 0, 0, 0), False),  # not normalised
        (None, False),
    ],
)
def test_upside_down(quat, down) -> None:
    assert upside_down(quat) is down


def test_limits_crop_to_the_hits() -> None:
    lo, hi = _limits(np.array([1.0, 3.0]), None)
    assert 0.9 < lo < 1.0 and 3.0 < hi < 3.1
    lo, hi = _limits(np.array([1.0, 3.0]), 5.0)  # the sensor is kept in view
    assert hi > 5.0


def test_legend_names_classes_with_keywords() -> None:
    legend = class_legend(
        ("unknown", "terrain", "valuable"),
        (0, 10, 3),
        {"terrain": ["floor", "wall"], "valuable": ["sofa", "table", "chair"]},
    )
    assert [label for label, _ in legend] == [
        "terrain: floor, wall (10 pts)",
        "valuable: sofa, table, chair (3 pts)",
    ]


def test_plot_scan_writes_png(tmp_path) -> None:
    rng = np.random.default_rng(0)
    points = rng.uniform(-2, 2, (500, 3))
    points[:5] = np.nan  # misses are skipped
    labels = rng.integers(0, 3, 500)
    out = plot_scan(
        points,
        labels,
        ("unknown", "terrain", "valuable"),
        tmp_path / "scan.png",
        sensor_pos=np.zeros(3),
        class_keywords={"terrain": ["floor"], "valuable": ["sofa"]},
        sensor_quat=(0, 1, 0, 0),
    )
    assert mpimg.imread(out).shape[2] in (3, 4)


def test_scene_picture_draws_points_in_their_class_colour(tmp_path) -> None:
    model = mujoco.MjModel.from_xml_string(
        """<mujoco><worldbody>
        <geom name="floor" type="plane" size="3 3 0.1" rgba="0.9 0.9 0.9 1"/>
        </worldbody></mujoco>"""
    )
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    xs, ys = np.meshgrid(np.linspace(-1, 1, 60), np.linspace(-1, 1, 60))
    points = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, 0.01)], axis=1)
    labels = np.full(len(points), 2)  # class 2 everywhere
    from robotwright.render import RenderOptions

    opts = RenderOptions(width=120, height=90, camera="top", backend="software")
    picture = render_scan(
        model, data, points, labels, ("unknown", "terrain", "obstacle"), tmp_path / "s.png", opts
    )
    rgb = np.array([int(class_color(2)[i : i + 2], 16) for i in (1, 3, 5)])
    near = (np.abs(picture.image.astype(int) - rgb).max(axis=2) < 40).mean()
    assert near > 0.1
    assert mpimg.imread(tmp_path / "s.png").shape[:2] == (90, 120)


@pytest.mark.parametrize(
    ("quat", "deg"),
    [
        ((1, 0, 0, 0), 0.0),
        ((0, 1, 0, 0), 180.0),
        ((np.cos(np.pi / 4), 0, np.sin(np.pi / 4), 0), 90.0),
        ((np.cos(np.radians(82.5)), 0, np.sin(np.radians(82.5)), 0), 165.0),  # the Go2's radar
    ],
)
def test_the_title_gives_the_sensors_tilt(quat, deg) -> None:
    assert tilt_deg(quat) == pytest.approx(deg, abs=1e-9)


def test_a_flat_view_is_stretched_to_be_read() -> None:
    assert view_stretch((-2.0, 2.0), (0.0, 1.0)) == 1.0  # equal scales
    # A ground from -3 to 32 m seen 0.25 m high: stretched to 4 times wider than high.
    stretch = view_stretch((-3.0, 32.0), (0.0, 0.25))
    assert stretch == pytest.approx(35.0 / 0.25 / 4.0)
