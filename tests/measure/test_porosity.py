"""Porosity of a region on known configurations, with disks clipped exactly.

* Lattices: the porosity of a square (1 - pi/4) and hexagonal (1 - pi/(2 sqrt 3))
  lattice of equal disks over whole periods of the lattice, at an offset so the window
  cuts disks, to 1e-12 (the clipping is exact).
* ``disk_rect_areas`` and ``porosity_circle`` against an independent 1D quadrature
  of the vertical chord of each disk clipped by the region (2e5 points, ~1e-7).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.measure.porosity import disk_rect_areas, porosity_circle, porosity_rect


# --------------------------------------------------------------- lattices
def _square_lattice(r, n):
    g = (np.arange(-2, n + 2) + 0.5) * 2 * r
    return np.array([(x, y) for y in g for x in g])


def _hex_lattice(r, nx, ny):
    h = math.sqrt(3) * r
    return np.array([(2 * r * i + r * (j % 2), h * j) for j in range(-2, ny + 2) for i in range(-2, nx + 2)])


@pytest.mark.parametrize("offset", [(0.0, 0.0), (0.37, 0.81), (1.3, 0.2)])
def test_square_lattice_porosity(offset):
    r = 0.5
    pos = _square_lattice(r, 14)
    rad = np.full(len(pos), r)
    x0, y0 = offset[0] * r + 2 * r, offset[1] * r + 2 * r
    for k, m in [(3, 4), (10, 7)]:
        n = porosity_rect(pos, rad, x0, y0, x0 + 2 * r * k, y0 + 2 * r * m)
        assert n == pytest.approx(1 - math.pi / 4, abs=1e-12)


@pytest.mark.parametrize("offset", [(0.0, 0.0), (0.37, 0.81), (1.9, 1.1)])
def test_hex_lattice_porosity(offset):
    r = 1.0
    pos = _hex_lattice(r, 16, 16)
    rad = np.full(len(pos), r)
    x0, y0 = offset[0] * r + 2 * r, offset[1] * r + 2 * r
    for k, m in [(2, 1), (7, 3)]:
        n = porosity_rect(pos, rad, x0, y0, x0 + 2 * r * k, y0 + 2 * math.sqrt(3) * r * m)
        assert n == pytest.approx(1 - math.pi / (2 * math.sqrt(3)), abs=1e-12)
    # a large circle: exact clipping, lattice error only at the rim
    nc = porosity_circle(pos, rad, 16.3, 13.1, 11.0)
    assert nc == pytest.approx(1 - math.pi / (2 * math.sqrt(3)), abs=0.01)


# ----------------------------------------------- clipped areas, quadrature
def _chords(cx, cy, r, x):
    s = np.sqrt(np.maximum(r * r - (x - cx) ** 2, 0.0))
    return cy - s, cy + s


def _quad_rect(cx, cy, r, x0, y0, x1, y1, npts=200_001):
    a, b = max(x0, cx - r), min(x1, cx + r)
    if b <= a:
        return 0.0
    h = (b - a) / npts
    x = a + h * (np.arange(npts) + 0.5)
    lo, hi = _chords(cx, cy, r, x)
    return float(np.sum(np.maximum(np.minimum(hi, y1) - np.maximum(lo, y0), 0.0)) * h)


def _quad_circle(cx, cy, r, ccx, ccy, rr, npts=200_001):
    a, b = max(cx - r, ccx - rr), min(cx + r, ccx + rr)
    if b <= a:
        return 0.0
    h = (b - a) / npts
    x = a + h * (np.arange(npts) + 0.5)
    lo1, hi1 = _chords(cx, cy, r, x)
    lo2, hi2 = _chords(ccx, ccy, rr, x)
    return float(np.sum(np.maximum(np.minimum(hi1, hi2) - np.maximum(lo1, lo2), 0.0)) * h)


def test_disk_rect_areas_against_quadrature():
    rng = np.random.default_rng(4)
    n = 40
    pos = rng.uniform(-1.0, 3.0, (n, 2))
    rad = rng.uniform(0.05, 1.2, n)
    rects = [(0.0, 0.0, 2.0, 1.5), (0.3, -0.2, 0.5, 2.5), (-0.5, 0.7, 2.5, 0.9)]
    for x0, y0, x1, y1 in rects:
        got = disk_rect_areas(pos, rad, x0, y0, x1, y1)
        want = np.array([_quad_rect(*pos[i], rad[i], x0, y0, x1, y1) for i in range(n)])
        assert np.all(np.abs(got - want) <= 1e-6 * np.pi * rad**2), np.max(np.abs(got - want) / rad**2)
        assert np.any((got > 0) & (got < np.pi * rad**2 * 0.999))  # some disks are cut
    # edge cases: inside, outside, touching an edge, rectangle inside the disk
    p = np.array([[0.5, 0.5], [5.0, 5.0], [1.0 + 0.25, 0.5], [0.5, 0.5]])
    r = np.array([0.25, 1.0, 0.25, 10.0])
    got = disk_rect_areas(p, r, 0.0, 0.0, 1.0, 1.0)
    assert got[0] == pytest.approx(np.pi * 0.0625, rel=1e-14)
    assert got[1] == 0.0 and got[2] == 0.0
    assert got[3] == pytest.approx(1.0, rel=1e-14)


def test_porosity_circle_against_quadrature():
    rng = np.random.default_rng(8)
    n = 30
    pos = rng.uniform(-1.5, 1.5, (n, 2))
    rad = rng.uniform(0.05, 0.6, n)
    for cx, cy, rr in [(0.0, 0.0, 1.0), (0.4, -0.3, 0.5), (0.0, 0.0, 3.0)]:
        solid = sum(_quad_circle(*pos[i], rad[i], cx, cy, rr) for i in range(n))
        want = 1.0 - solid / (np.pi * rr * rr)
        got = porosity_circle(pos, rad, cx, cy, rr)
        assert got == pytest.approx(want, abs=1e-6)
    # a small disk wholly inside a larger one, and the larger wholly inside the region
    assert porosity_circle(np.array([[0.1, 0.0]]), np.array([0.2]), 0.0, 0.0, 1.0) == pytest.approx(0.96)
    assert porosity_circle(np.array([[0.0, 0.0]]), np.array([2.0]), 0.5, 0.0, 1.0) == pytest.approx(0.0)


def test_porosity_inputs():
    pos = np.zeros((1, 2))
    rad = np.ones(1)
    with pytest.raises(InputError) as e:
        porosity_rect(pos, rad, 1.0, 0.0, 0.0, 1.0)
    assert e.value.parameter == "rectangle"
    with pytest.raises(InputError) as e:
        porosity_circle(pos, rad, 0.0, 0.0, 0.0)
    assert e.value.parameter == "circle radius"
