"""Disk numbering: strip order, and renumbering a running simulation without changing its physics."""

from __future__ import annotations

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls
from poro2d.dem.ordering import is_permutation, strip_order
from poro2d.errors import InputError
from tests.oracles.test_engine_step import _lockstep, jammed_packing

R = 1e-3


def _contact_map(sim: Simulation, old_of_new: np.ndarray) -> dict:
    """Touching contacts keyed by the disks' old numbers, force on the lower old number."""
    c = sim.contacts()
    out = {}
    for k in range(len(c.i)):
        a = int(old_of_new[c.i[k]])
        if c.kind[k] == 0:
            b = int(old_of_new[c.j[k]])
            f = c.force[k] if a < b else -c.force[k]
            out[(min(a, b), max(a, b))] = f
        else:
            out[(a, "wall", int(c.j[k]))] = c.force[k]
    return out


def _sheared(seed=3) -> Simulation:
    """The jammed packing after 60 steps under the moving lid: many sticking and sliding contacts."""
    sim = jammed_packing(seed)
    sim.run(60)
    return sim


def _strips_then_along(o: np.ndarray, across: int, width: float) -> bool:
    """Strip index never decreases; within a strip the other coordinate never decreases."""
    s = np.floor((o[:, across] - o[:, across].min()) / width)
    along = o[:, 1 - across]
    same = np.diff(s) == 0
    return bool(np.all(np.diff(s) >= 0) and np.all(np.diff(along)[same] >= 0))


def test_strip_order_runs_across_the_short_side():
    gx, gy = np.meshgrid(np.arange(40), np.arange(8))  # wide: 40 columns of 8
    pos = np.column_stack([gx.ravel(), gy.ravel()]) * 2 * R + R
    pos = pos[np.random.default_rng(0).permutation(len(pos))]
    r = np.full(len(pos), R)
    w = 2.7183 * R  # no lattice line falls on a strip edge
    order = strip_order(pos, r, width=w)
    assert is_permutation(order, len(pos))
    assert _strips_then_along(pos[order], 0, w)  # columns
    assert not _strips_then_along(pos[order], 1, w)
    turned = pos[:, ::-1]  # the same grid on end: rows
    assert _strips_then_along(turned[strip_order(turned, r, width=w)], 1, w)
    # the default strip is two largest diameters wide
    assert _strips_then_along(pos[strip_order(pos, r)], 0, 4.0 * R)


@pytest.mark.parametrize(
    "pos, radius, width, name",
    [
        (np.zeros((3, 3)), np.ones(3), None, "positions"),
        (np.zeros((3, 2)), np.ones(4), None, "radius"),
        (np.zeros((3, 2)), np.ones(3), 0.0, "strip width"),
    ],
)
def test_strip_order_bad_input(pos, radius, width, name):
    with pytest.raises(InputError, match=name):
        strip_order(pos, radius, width)


def test_reorder_rejects_what_is_not_a_permutation():
    sim = jammed_packing(0)
    n = sim.particles.n
    for bad in (np.arange(n - 1), np.zeros(n, dtype=int), np.arange(n) + 1, np.linspace(0, n - 1, n)):
        with pytest.raises(InputError, match="order"):
            sim.reorder(bad)


def test_reorder_keeps_every_contact_and_its_force_exactly():
    sim = _sheared()
    n = sim.particles.n
    before = _contact_map(sim, np.arange(n))
    sliding_before = sim.contacts()
    order = np.random.default_rng(7).permutation(n)
    pos = sim.particles.pos.copy()
    sim.reorder(order)
    after = _contact_map(sim, order)
    assert set(after) == set(before)
    assert len(before) > 200 and np.any(np.abs(sliding_before.fs) > 0)
    for key, f in before.items():
        np.testing.assert_array_equal(after[key], f)
    np.testing.assert_array_equal(sim.particles.pos, pos[order])


def test_reordered_run_follows_the_same_motion():
    """The shear history is carried with the right sign: one step later the forces agree to round-off."""
    a, b = _sheared(), _sheared()
    n = a.particles.n
    order = np.random.default_rng(11).permutation(n)
    b.reorder(order)
    for steps in (1, 10):
        a.run(steps)
        b.run(steps)
        fa = _contact_map(a, np.arange(n))
        fb = _contact_map(b, order)
        assert set(fa) == set(fb)
        scale = max(float(np.abs(f).max()) for f in fa.values())
        worst = max(float(np.abs(fa[k] - fb[k]).max()) for k in fa)
        assert worst < 1e-9 * scale
        np.testing.assert_allclose(b.particles.pos, a.particles.pos[order], rtol=0, atol=1e-12 * R)
        np.testing.assert_allclose(b.wall_force_vec, a.wall_force_vec, rtol=1e-9, atol=1e-9 * scale)


def test_identity_reorder_changes_nothing():
    a, b = _sheared(), _sheared()
    b.reorder(np.arange(b.particles.n))
    a.run(50)
    b.run(50)
    np.testing.assert_array_equal(a.particles.pos, b.particles.pos)
    np.testing.assert_array_equal(a.particles.omega, b.particles.omega)


def test_reordered_engine_still_matches_the_numpy_reference_bitwise():
    sim = _sheared()
    sim.reorder(np.random.default_rng(5).permutation(sim.particles.n))
    worst, slid, stuck, rebuilds, _ = _lockstep(sim, 80, engine_order=True)
    assert slid > 0 and stuck > 0
    assert all(v == 0.0 for v in worst.values()), worst


def test_strip_order_shortens_the_cross_band():
    """A wide packing numbered in rows is cut along its length; in columns, across its height."""
    gx, gy = np.meshgrid(np.arange(60), np.arange(12))
    rng = np.random.default_rng(2)
    pos = np.column_stack([gx.ravel(), gy.ravel()]) * 2 * R + R
    rows = np.lexsort((pos[:, 0], pos[:, 1]))
    pos = pos[rows] + rng.uniform(-0.05 * R, 0.05 * R, pos.shape)
    p = Particles(pos=pos, radius=R * 1.001, density=2650.0, thickness=0.01, kn=1e6, ks=1e6, mu=0.3)
    sim = Simulation(p, Walls.box(0.0, 0.0, 120 * R, 24 * R, 1e6, 1e6, 0.3), gravity=(0.0, -9.81))
    sim.run(1)
    deferred_rows = int(sim.work.dstart[-1])
    sim.reorder(strip_order(sim.particles.pos, sim.particles.radius))
    sim.run(1)
    deferred_cols = int(sim.work.dstart[-1])
    assert deferred_rows >= 55  # about one row of 60
    assert deferred_cols <= 20  # about one column of 12 (plus the cut's step)
