"""Non-overlapping placement of disks in a band."""

from __future__ import annotations

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.specimen import Band, draw_disks, paper_grading, place_disks, solid_fraction

W, H = 0.305, 0.124
LAYER_H = H / 4


def assert_valid(placement, band: Band) -> None:
    """Plain O(N^2) check: no overlaps, every disk fully inside the band."""
    x, y = placement.positions[:, 0], placement.positions[:, 1]
    r = placement.radii
    assert np.all(x - r >= band.x0) and np.all(x + r <= band.x1)
    assert np.all(y - r >= band.y0) and np.all(y + r <= band.y1)
    dist = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
    gap = dist - (r[:, None] + r[None, :])
    np.fill_diagonal(gap, np.inf)
    assert gap.min() >= 0.0


@pytest.fixture(scope="module")
def layer_radii() -> np.ndarray:
    """One of the paper's four layers: solid fraction 0.86 in a 0.305 x 0.031 m band."""
    return draw_disks(paper_grading(), 0.86 * W * LAYER_H, 5)


def test_dense_layer_at_reduced_radius(layer_radii):
    band = Band(0.0, W, 0.0, LAYER_H)
    assert solid_fraction(layer_radii, band) == pytest.approx(0.86)
    p = place_disks(layer_radii, band, 1)
    assert 0.5 < p.scale < 1.0
    np.testing.assert_allclose(p.radii, layer_radii * p.scale, rtol=0, atol=0)
    assert p.positions.shape == (layer_radii.size, 2)
    assert_valid(p, band)


def test_band_with_offset(layer_radii):
    band = Band(0.01, 0.01 + W, 2 * LAYER_H, 3 * LAYER_H)
    assert_valid(place_disks(layer_radii, band, 2), band)
    assert_valid(place_disks(layer_radii, (0.01, 0.01 + W, 2 * LAYER_H, 3 * LAYER_H), 2), band)


def test_deterministic_and_seed_dependent(layer_radii):
    band = (0.0, W, 0.0, LAYER_H)
    a = place_disks(layer_radii, band, 9)
    b = place_disks(layer_radii, band, 9)
    c = place_disks(layer_radii, band, 10)
    assert np.array_equal(a.positions, b.positions) and a.scale == b.scale
    assert not np.array_equal(a.positions, c.positions)


def test_full_box_places_every_disk():
    # its time is part of the preparation wall time benchmarks/bench_preparation.py prints
    radii = draw_disks(paper_grading(), 0.86 * W * H, 3)
    assert 2500 < radii.size < 2700
    band = Band(0.0, W, 0.0, H)
    p = place_disks(radii, band, 3)
    assert p.positions.shape == (radii.size, 2)
    assert_valid(p, band)


def test_loose_band_places_at_full_size():
    radii = draw_disks(paper_grading(), 0.25 * W * LAYER_H, 4)
    band = Band(0.0, W, 0.0, LAYER_H)
    auto = place_disks(radii, band, 4)
    assert auto.scale == 1.0
    full = place_disks(radii, band, 4, full_size=True)
    assert full.scale == 1.0 and full.restarts == 0
    assert_valid(full, band)


def test_full_size_fails_clearly_when_dense(layer_radii):
    with pytest.raises(InputError, match="full_size"):
        place_disks(layer_radii, (0.0, W, 0.0, LAYER_H), 1, full_size=True)


def test_restarts_reduce_the_scale(layer_radii):
    band = Band(0.0, W, 0.0, LAYER_H)
    first = np.sqrt(0.40 / solid_fraction(layer_radii, band))
    p = place_disks(layer_radii, band, 1, max_attempts=2)
    assert p.restarts > 0
    assert p.scale == pytest.approx(first * 0.97**p.restarts)
    assert_valid(p, band)
    with pytest.raises(InputError, match="max_restarts"):
        place_disks(layer_radii, band, 1, max_attempts=1, target_fraction=0.8, max_restarts=0)


@pytest.mark.parametrize(
    ("radii", "band", "kwargs", "parameter"),
    [
        ([0.02], (0.0, 0.3, 0.0, 0.031), {}, "radii"),  # disk taller than the band
        ([0.002, 0.01], (0.0, 0.015, 0.0, 0.1), {}, "radii"),  # disk wider than the band
        ([], (0.0, 0.3, 0.0, 0.031), {}, "radii"),
        ([0.001, -0.001], (0.0, 0.3, 0.0, 0.031), {}, "radii"),
        ([0.001, np.nan], (0.0, 0.3, 0.0, 0.031), {}, "radii"),
        ([0.0099] * 40, (0.0, 0.1, 0.0, 0.1), {}, "radii"),  # more disk area than band area
        ([0.001], (0.0, 0.3, 0.031, 0.0), {}, "band.y1"),
        ([0.001], (0.3, 0.3, 0.0, 0.031), {}, "band.x1"),
        ([0.001], (0.0, 0.3, 0.0), {}, "band"),
        ([0.001], (0.0, 0.3, 0.0, 0.031), {"target_fraction": 0.0}, "target_fraction"),
        ([0.001], (0.0, 0.3, 0.0, 0.031), {"shrink": 1.0}, "shrink"),
        ([0.001], (0.0, 0.3, 0.0, 0.031), {"max_attempts": 0}, "max_attempts"),
        ([0.001], (0.0, 0.3, 0.0, 0.031), {"max_restarts": -1}, "max_restarts"),
    ],
)
def test_input_errors(radii, band, kwargs, parameter):
    with pytest.raises(InputError) as err:
        place_disks(radii, band, 0, **kwargs)
    assert err.value.parameter == parameter
    assert parameter in str(err.value)


def test_seed_must_be_an_integer():
    with pytest.raises(InputError, match="seed"):
        place_disks([0.001], (0.0, 0.3, 0.0, 0.031), 1.5)
