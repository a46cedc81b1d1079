"""Disk numbering: strip order, and renumbering a running simulation without changing its physics."""

from __future__ import annotations

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls
from poro2d.dem.ordering import curve_order, hilbert_index, is_permutation, strip_order
from poro2d.errors import InputError
from tests.oracles.test_engine_step import STEP_TOL, _lockstep, jammed_packing

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


def test_reordered_engine_still_matches_the_numpy_reference():
    sim = _sheared()
    sim.reorder(np.random.default_rng(5).permutation(sim.particles.n))
    worst, slid, stuck, rebuilds, _ = _lockstep(sim, 80, engine_order=True)
    assert slid > 0 and stuck > 0
    assert all(v <= STEP_TOL for v in worst.values()), worst


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


# ---------------------------------------------------------------- the curve order and re-sorting


def _lattice(nx: int, ny: int, seed: int = 0) -> np.ndarray:
    """Centres of an nx x ny square lattice of disks of radius R, shuffled."""
    gx, gy = np.meshgrid(np.arange(nx), np.arange(ny))
    pos = np.column_stack([gx.ravel(), gy.ravel()]) * 2 * R + R
    return pos[np.random.default_rng(seed).permutation(len(pos))]


def test_hilbert_index_walks_every_cell_of_a_block_by_unit_steps():
    side = 16
    x, y = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    d = hilbert_index(x.ravel(), y.ravel(), side)
    assert sorted(d.tolist()) == list(range(side * side))
    walk = np.column_stack([x.ravel(), y.ravel()])[np.argsort(d)]
    assert np.all(np.abs(np.diff(walk, axis=0)).sum(axis=1) == 1)
    # in at one corner, out at the next along x: the walk goes on into the next block
    assert walk[0].tolist() == [0, 0] and walk[-1].tolist() == [side - 1, 0]


def test_curve_order_is_a_permutation_in_strips_across_the_short_side():
    # a disk at the origin puts every lattice centre in the middle of its cell (cell = 2 R)
    pos = np.vstack([[0.0, 0.0], _lattice(64, 16)])
    r = np.full(len(pos), R)
    order = curve_order(pos, r, square=4)
    assert is_permutation(order, len(pos))
    # strips of 4 cells across the short side: 16 strips of 64 disks (and the extra one), one
    # after the other, and within a strip each disk is a neighbour of the one before
    o = pos[order]
    strip = np.floor(o[:, 0] / (8 * R))
    assert np.all(np.diff(strip) >= 0)
    assert np.bincount(strip.astype(int)).tolist() == [65] + [64] * 15
    steps = np.abs(np.diff(o, axis=0)).sum(axis=1)
    np.testing.assert_allclose(steps[np.diff(strip) == 0], 2 * R, rtol=1e-9)
    turned = pos[:, ::-1]  # a tall packing: strips of rows
    assert np.all(turned[curve_order(turned, r, square=4)][:65, 1] < 8 * R)


def test_curve_order_brings_partners_nearer_in_memory_than_strips():
    """On a 128 x 128 lattice, most lattice neighbours end up within 64 indices of each other."""
    pos = _lattice(128, 128, seed=1)
    r = np.full(len(pos), R)
    cell = np.round((pos - R) / (2 * R)).astype(int)
    key = {(a, b): k for k, (a, b) in enumerate(cell.tolist())}
    pairs = [(key[a, b], key[a + 1, b]) for a, b in key if (a + 1, b) in key]
    pairs += [(key[a, b], key[a, b + 1]) for a, b in key if (a, b + 1) in key]
    pairs = np.array(pairs)

    def gaps(order):
        new = np.empty(len(order), dtype=np.int64)
        new[order] = np.arange(len(order))
        return np.abs(new[pairs[:, 0]] - new[pairs[:, 1]])

    strips, curve = gaps(strip_order(pos, r)), gaps(curve_order(pos, r))
    assert np.mean(curve <= 64) > 0.85 > np.mean(strips <= 64)


@pytest.mark.parametrize("square", [0, 3, 2.0])
def test_curve_order_bad_square(square):
    with pytest.raises(InputError, match="square"):
        curve_order(np.zeros((3, 2)), np.ones(3), square=square)


def test_set_sorting_bad_input():
    sim = jammed_packing(0)
    for bad in (0, -5, 2.5):
        with pytest.raises(InputError, match="sort_every"):
            sim.set_sorting(bad)


def _sorting(seed=3, every=7, threads=1) -> Simulation:
    sim = jammed_packing(seed, threads=threads)
    sim.sort_min_particles = 0  # the small test packing is renumbered too
    sim.parallel_min_particles = 0
    sim.set_sorting(every)
    return sim


def _old_of_new(sim: Simulation, radius0: np.ndarray) -> np.ndarray:
    """Each disk's first number, found by its radius (all differ and travel with the disk)."""
    by_radius = np.argsort(radius0)
    return by_radius[np.searchsorted(radius0[by_radius], sim.particles.radius)]


def test_sorted_run_renumbers_and_follows_the_unsorted_motion():
    a, b = jammed_packing(3), _sorting(3)
    r0 = a.particles.radius.copy()
    n = a.particles.n
    assert len(np.unique(r0)) == n
    for steps in (7, 20, 33):
        a.run(steps)
        b.run(steps)
        old = _old_of_new(b, r0)
        assert is_permutation(old, n)
        fa, fb = _contact_map(a, np.arange(n)), _contact_map(b, old)
        assert set(fa) == set(fb)
        scale = max(float(np.abs(f).max()) for f in fa.values())
        assert max(float(np.abs(fa[k] - fb[k]).max()) for k in fa) < 1e-9 * scale
        np.testing.assert_allclose(b.particles.pos, a.particles.pos[old], rtol=0, atol=1e-12 * R)
    assert not np.array_equal(old, np.arange(n))  # it did renumber


def test_resort_keeps_shear_history_exactly():
    sim = _sheared()
    n = sim.particles.n
    before = _contact_map(sim, np.arange(n))
    order = curve_order(sim.particles.pos, sim.particles.radius, square=2)
    assert not np.array_equal(order, np.arange(n))
    sim.reorder(order)
    after = _contact_map(sim, order)
    assert set(after) == set(before) and len(before) > 200
    for key, f in before.items():
        np.testing.assert_array_equal(after[key], f)


def test_sorted_run_is_the_same_on_one_and_two_threads_and_however_cut():
    one, two, cut = _sorting(5, threads=1), _sorting(5, threads=2), _sorting(5, threads=1)
    one.run(60)
    two.run(60)
    for k in (4, 10, 1, 45):  # blocks ending between and on the renumbering steps
        cut.run(k)
    assert two.threads_used == 2
    for other in (two, cut):
        np.testing.assert_array_equal(one.particles.pos, other.particles.pos)
        np.testing.assert_array_equal(one.particles.omega, other.particles.omega)
        np.testing.assert_array_equal(one.pairs.fs[: one.pairs.used], other.pairs.fs[: other.pairs.used])


def test_sorted_run_resumes_from_a_checkpoint_bit_for_bit(tmp_path):
    from poro2d.dem import checkpoint

    a, b = _sorting(6), _sorting(6)
    a.run(50)
    b.run(21)  # the renumbering of step 21 is still to come
    checkpoint.save(b, tmp_path / "c.npz")
    c = checkpoint.load(tmp_path / "c.npz")
    assert c.sort_every == 7
    c.sort_min_particles = 0
    c.run(29)
    np.testing.assert_array_equal(a.particles.pos, c.particles.pos)
    np.testing.assert_array_equal(a.particles.vel, c.particles.vel)


def test_curve_ordered_engine_matches_the_numpy_reference():
    sim = _sheared()
    sim.reorder(curve_order(sim.particles.pos, sim.particles.radius, square=2))
    worst, slid, stuck, _, _ = _lockstep(sim, 60, engine_order=True)
    assert slid > 0 and stuck > 0
    assert all(v <= STEP_TOL for v in worst.values()), worst


def test_no_sorting_below_the_disk_count():
    a, b = jammed_packing(2), jammed_packing(2)
    b.set_sorting(5)  # 190 disks: below sort_min_particles, nothing is renumbered
    a.run(30)
    b.run(30)
    np.testing.assert_array_equal(a.particles.pos, b.particles.pos)


def test_summary_names_the_renumbering_only_when_it_happens():
    sim = jammed_packing(1)
    assert "sort_every_steps" not in sim.summary().to_dict()
    sim.set_sorting(9)  # below sort_min_particles: nothing renumbered, nothing said
    assert "sort_every_steps" not in sim.summary().to_dict()
    sim.sort_min_particles = 0
    assert sim.summary().to_dict()["sort_every_steps"] == 9
