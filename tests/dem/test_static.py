"""Static checks: a settled pile carries its weight; measurements on known configurations.

* A pile of ~300 disks settled to a maximum unbalanced-force ratio of 1e-4 puts its
  whole weight on the bottom wall (frictionless side walls) to 0.1 %; with frictional
  side walls, bottom plus vertical side friction equal the weight to 0.1 % (and the
  side walls do carry a share).
* Lattices: the porosity of a square (1 - pi/4) and hexagonal (1 - pi/(2 sqrt 3))
  lattice of equal disks over whole periods of the lattice, at an offset so the window
  cuts disks, to 1e-12 (the clipping is exact).
* ``disk_rect_areas`` and ``porosity_circle`` against an independent 1D quadrature
  of the vertical chord of each disk clipped by the region (2e5 points, ~1e-7).
* ``coordination_number`` counted on a hexagonal patch squeezed into a box, and the
  Love-Weber ``average_stress`` of that patch against the stress from the wall forces.

The piles use the default time step (``dt_safety = 0.8``; 0.7 with frictional sides).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls
from poro2d.dem.measure import (
    average_stress,
    coordination_number,
    disk_rect_areas,
    porosity_circle,
    porosity_rect,
)
from poro2d.errors import InputError

R = 1e-3


# ------------------------------------------------------------------ piles
def _pile(mu_side: float, dt_safety: float, seed: int = 0) -> Simulation:
    """300 disks (radii 0.8-1 mm) dropped from a near-dense staggered arrangement."""
    rng = np.random.default_rng(seed)
    nx, ny = 12, 25
    s = 2.05 * R
    h = s * math.sqrt(3) / 2
    pos = np.array(
        [
            (s * (i + 0.25 + 0.5 * (j % 2)) + rng.uniform(-0.02, 0.02) * R, s / 2 + h * j)
            for j in range(ny)
            for i in range(nx)
        ]
    )
    n = len(pos)
    p = Particles(
        pos=pos, radius=R * rng.uniform(0.8, 1.0, n), density=2650.0, thickness=0.01,
        kn=1e5, ks=1e5, mu=0.5,
    )  # fmt: skip
    width = nx * s + 0.5 * s
    top = 3 * ny * s
    w = Walls()
    w.add((-width, 0.0), (2 * width, 0.0), 1e5, 1e5, 0.5, "bottom")
    w.add((width, -width), (width, top), 1e5, 1e5, mu_side, "right")
    w.add((0.0, top), (0.0, -width), 1e5, 1e5, mu_side, "left")
    return Simulation(p, w, dt_safety=dt_safety)


def test_pile_weight_on_bottom_wall_frictionless_sides():
    sim = _pile(0.0, 0.8)
    res = sim.solve(ratio=1e-4, max_steps=200_000)
    assert res.converged
    weight = float(np.sum(sim.particles.mass)) * 9.81
    fb = sim.wall_force("bottom")
    assert -fb[1] == pytest.approx(weight, rel=1e-3)
    # frictionless side walls take no vertical load at all
    assert abs(sim.wall_force("left")[1]) < 1e-12 * weight
    assert abs(sim.wall_force("right")[1]) < 1e-12 * weight
    # and the horizontal thrusts balance
    assert sim.wall_force("left")[0] + sim.wall_force("right")[0] + fb[0] == pytest.approx(
        0.0, abs=1e-3 * weight
    )


def test_pile_weight_shared_with_frictional_sides():
    sim = _pile(0.5, 0.7)
    res = sim.solve(ratio=1e-4, max_steps=200_000)
    assert res.converged
    weight = float(np.sum(sim.particles.mass)) * 9.81
    fb, fl, fr = (sim.wall_force(w) for w in ("bottom", "left", "right"))
    side = -(fl[1] + fr[1])
    assert abs(side) > 1e-4 * weight  # frictional side walls do take vertical load (either sign)
    assert -fb[1] + side == pytest.approx(weight, rel=1e-3)


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


# ------------------------------------------------- hex patch in a box
def _hex_patch(nx=8, ny=7, grow=1.005, wall_mu=0.5):
    """Rows of nx and nx - 1 equal disks; even rows touch both side walls."""
    h = math.sqrt(3) * R
    pos = np.array([(R + 2 * R * c + R * (j % 2), R + h * j) for j in range(ny) for c in range(nx - j % 2)])
    n = len(pos)
    p = Particles(pos=pos, radius=R * grow, density=2650.0, thickness=0.01, kn=1e6, ks=1e6, mu=0.5)
    width, height = 2 * nx * R, pos[:, 1].max() + R
    w = Walls.box(0.0, 0.0, width, height, 1e6, 1e6, wall_mu)
    sim = Simulation(p, w, gravity=(0.0, 0.0), dt_safety=0.8)
    # expected contacts: horizontal neighbours, diagonal neighbours, walls
    even = (ny + 1) // 2
    odd = ny // 2
    pp = even * (nx - 1) + odd * (nx - 2) + (ny - 1) * 2 * (nx - 1)
    top_row = nx if (ny - 1) % 2 == 0 else nx - 1
    pw = 2 * even + nx + top_row
    return sim, n, pp, pw, width, height


def test_coordination_number_hex_patch():
    sim, n, pp, pw, _w, _h = _hex_patch()
    sim.run(1)  # contacts of the initial (exact lattice) positions
    c = sim.contacts()
    assert int(np.sum(c.kind == 0)) == pp
    assert int(np.sum(c.kind == 1)) == pw
    assert coordination_number(sim) == pytest.approx((2 * pp + pw) / n, rel=1e-15)
    assert coordination_number(sim, exclude_rattlers=True) == pytest.approx((2 * pp + pw) / n, rel=1e-15)


def test_coordination_number_excludes_rattlers():
    sim, n, pp, pw, width, height = _hex_patch(nx=4, ny=3)
    p = sim.particles
    # add a lone disk in a corner pocket above the patch: no contacts
    p2 = Particles(
        pos=np.vstack([p.pos, [[width / 2, height + 5 * R]]]), radius=np.append(p.radius, 0.5 * R),
        density=2650.0, thickness=0.01, kn=1e6, ks=1e6, mu=0.5,
    )  # fmt: skip
    walls = Walls.box(0.0, 0.0, width, height + 10 * R, 1e6, 1e6, 0.5)
    walls.p0[2, 1] = walls.p1[2, 1] = height + 10 * R
    sim2 = Simulation(p2, walls, gravity=(0.0, 0.0), dt_safety=0.8)
    sim2.run(1)
    c = sim2.contacts()
    pp2, pw2 = int(np.sum(c.kind == 0)), int(np.sum(c.kind == 1))
    assert pp2 == pp
    assert coordination_number(sim2) == pytest.approx((2 * pp2 + pw2) / (n + 1))
    assert coordination_number(sim2, exclude_rattlers=True) == pytest.approx((2 * pp2 + pw2) / n)


def test_average_stress_equals_wall_stress():
    """Frictionless walls: their tractions are normal, so the mean stress is F / (L t).

    (With wall friction the shear tractions on the top and bottom walls add
    ``sum f_x x_c / V`` to sigma_xx: 23 % here; the Love-Weber sum then equals the
    full boundary sum ``sum f (x) x_c / V``, checked below as well.)
    """
    sim, _n, _pp, _pw, width, height = _hex_patch(wall_mu=0.0)
    res = sim.solve(ratio=1e-6, max_steps=100_000)
    assert res.converged
    t = sim.particles.thickness
    s_wall_xx = -sim.wall_force("right")[0] / (height * t)
    s_wall_yy = -sim.wall_force("top")[1] / (width * t)
    s = average_stress(sim, 0.0, 0.0, width, height)
    assert s_wall_xx < 0 and s_wall_yy < 0  # compression
    assert s[0, 0] == pytest.approx(s_wall_xx, rel=0.02)
    assert s[1, 1] == pytest.approx(s_wall_yy, rel=0.02)
    assert abs(s[0, 1]) < 0.02 * abs(s[0, 0]) and s[0, 1] == pytest.approx(s[1, 0], abs=1e-3 * abs(s[0, 0]))
    # the other side of the box sees the same stress
    assert -sim.wall_force("left")[0] / (height * t) == pytest.approx(-s_wall_xx, rel=1e-3)


def test_average_stress_equals_boundary_sum_with_wall_friction():
    sim, _n, _pp, _pw, width, height = _hex_patch(wall_mu=0.5)
    sim.particles.vel[:, 0] += 0.01 * np.sign(sim.particles.pos[:, 0] - width / 2)  # mobilise friction
    assert sim.solve(ratio=1e-6, max_steps=100_000).converged
    c = sim.contacts()
    w = c.kind == 1
    boundary = (c.force[w].T @ c.point[w]) / (width * height * sim.particles.thickness)
    s = average_stress(sim, 0.0, 0.0, width, height)
    assert np.allclose(s, boundary, rtol=0, atol=1e-5 * abs(s[0, 0]))
