"""Static checks: a settled pile carries its weight.

* A pile of ~300 disks settled to a maximum unbalanced-force ratio of 1e-4 puts its
  whole weight on the bottom wall (frictionless side walls) to 0.1 %; with frictional
  side walls, bottom plus vertical side friction equal the weight to 0.1 % (and the
  side walls do carry a share).

The piles use the default time step (``dt_safety = 0.8``; 0.7 with frictional sides).
The measurements on known configurations are in ``tests/measure/``.
"""

from __future__ import annotations

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls
from tests.dem.grids import staggered_rows

R = 1e-3


# ------------------------------------------------------------------ piles
def _pile(mu_side: float, dt_safety: float, seed: int = 0) -> Simulation:
    """300 disks (radii 0.8-1 mm) dropped from a near-dense staggered arrangement."""
    rng = np.random.default_rng(seed)
    nx, ny = 12, 25
    s = 2.05 * R
    pos = staggered_rows(nx, ny, R, rng, spacing=2.05, offset=0.25, jitter=0.02)
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
