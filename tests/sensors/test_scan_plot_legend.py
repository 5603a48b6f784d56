"""The scan picture holds its whole legend, however long the classes' keyword lists."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robotwright.sensors.config import DEFAULT_SEMANTIC_CLASS_MAPPING
from robotwright.sensors.plot import plot_scan


def _edges_blank(path: Path, width: int = 3) -> bool:
    """Whether the picture's outer ``width`` pixels are all background (white): nothing
    drawn runs into, or past, its border."""
    import matplotlib.image

    image = matplotlib.image.imread(str(path))[..., :3]
    strips = (image[:width], image[-width:], image[:, :width], image[:, -width:])
    return all(bool(np.all(strip == 1.0)) for strip in strips)


def _scan(classes: int, n: int = 400, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    points = rng.uniform(-3.0, 3.0, size=(n, 3))
    points[:, 2] = rng.uniform(0.0, 1.5, size=n)
    return points, rng.integers(0, classes, size=n)


def test_default_mapping_legend_is_whole(tmp_path: Path) -> None:
    """The default mapping's long keyword lists (the legend was cut at both sides)."""
    names = ["unknown", *DEFAULT_SEMANTIC_CLASS_MAPPING]
    points, labels = _scan(len(names))
    out = plot_scan(
        points,
        labels,
        names,
        tmp_path / "scan.png",
        sensor_pos=np.array([0.0, 0.0, 1.2]),
        class_keywords=DEFAULT_SEMANTIC_CLASS_MAPPING,
    )
    assert _edges_blank(out)


@pytest.mark.parametrize("seed", range(4))
def test_random_long_keyword_lists_stay_inside_the_picture(tmp_path: Path, seed: int) -> None:
    rng = np.random.default_rng(seed)
    classes = int(rng.integers(2, 9))
    names = ["unknown", *(f"class_{i}" for i in range(1, classes))]
    keywords = {
        name: [f"keyword_{name}_{k}" * int(rng.integers(1, 3)) for k in range(rng.integers(1, 25))]
        for name in names[1:]
    }
    points, labels = _scan(classes, seed=seed)
    out = plot_scan(
        points,
        labels,
        names,
        tmp_path / "scan.png",
        sensor_pos=np.zeros(3),
        class_keywords=keywords,
    )
    assert _edges_blank(out)
