"""The range image tells a cell no ray scanned from one whose rays missed, and takes the
rays' cells computed once (the framework terms look them up per pattern frame)."""

from __future__ import annotations

import math

import pytest

torch = pytest.importorskip("torch", reason="torch not installed (the torch extra)")

from robotwright.sensors import learning_obs  # noqa: E402


def _dirs(*angles: tuple[float, float]) -> torch.Tensor:
    """Unit directions from (azimuth, elevation) pairs [rad]."""
    out = [(math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)) for a, e in angles]
    return torch.tensor(out, dtype=torch.float64)


def test_scanned_channel_tells_no_ray_from_a_miss() -> None:
    # a 2 x 2 image over azimuth -1..1 and elevation -0.5..0.5: rays in 3 of the 4 cells
    dirs = _dirs((-0.5, 0.25), (0.5, 0.25), (-0.5, -0.25))
    bounds = (-1.0, 1.0, -0.5, 0.5, False)
    hit = torch.tensor([[True, False, False]])
    dist = torch.tensor([[2.0, 0.0, 0.0]])
    labels = torch.tensor([[1, 0, 0]])
    image = learning_obs.range_image(
        dirs[None], hit, dist, 4.0, labels, 2, bounds, 2, 2, scanned=True
    )
    assert image.shape == (1, 4, 2, 2)
    depth, scanned = image[0, 0], image[0, 3]
    assert depth.tolist() == [[0.5, 1.0], [1.0, 1.0]]  # a miss and an unscanned cell alike
    assert scanned.tolist() == [[1.0, 1.0], [1.0, 0.0]]  # ... told apart here
    assert image[0, 2].tolist() == [[1.0, 0.0], [0.0, 0.0]]  # class 1 where it was hit
    plain = learning_obs.range_image(dirs[None], hit, dist, 4.0, labels, 2, bounds, 2, 2)
    assert torch.equal(plain, image[:, :3])


def test_cells_given_once_equal_cells_computed_each_time() -> None:
    gen = torch.Generator().manual_seed(0)
    dirs = torch.nn.functional.normalize(torch.randn(500, 3, generator=gen, dtype=torch.float64))
    bounds = learning_obs.direction_bounds(dirs)
    hit = torch.rand(3, 500, generator=gen) > 0.3
    dist = torch.rand(3, 500, generator=gen) * 10
    labels = torch.randint(0, 4, (3, 500), generator=gen)
    cells = learning_obs.ray_cells(dirs, bounds, 16, 8)
    assert cells.shape == (500,) and int(cells.min()) >= 0 and int(cells.max()) < 128
    each = learning_obs.range_image(
        dirs.expand(3, 500, 3), hit, dist, 10.0, labels, 4, bounds, 16, 8, scanned=True
    )
    once = learning_obs.range_image(
        None, hit, dist, 10.0, labels, 4, bounds, 16, 8, cells=cells, scanned=True
    )
    assert torch.equal(each, once)
