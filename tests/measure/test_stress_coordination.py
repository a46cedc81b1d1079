"""Coordination and stress on a hexagonal patch of equal disks squeezed into a box.

* ``coordination_number`` counted on the patch, with and without a rattler;
* the Love-Weber ``average_stress`` of the patch against the stress from the wall forces.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls
from poro2d.measure.coordination import coordination_number
from poro2d.measure.stress import average_stress

R = 1e-3


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
