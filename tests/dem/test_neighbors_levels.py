"""The neighbour search by size level (wide gradings) against brute force and the reference.

A grading with fines among coarse grains (r_max / r_min above ``Simulation.level_ratio``)
has its lists built from grids by size level (:mod:`poro2d.dem.neighbors`). Checked here:
the list is the brute-force candidate set (random and packed disks, a runaway disk, too
little storage), contact history survives rebuilds (also from rows in another order),
the engine picks the search by the size ratio alone (the paper's and the built-in
gradings keep the one cell grid, and with it their numbers), and on a wide packing the
compiled kernel agrees with the NumPy reference step to the last bit, on 1 or 2 threads,
through a checkpoint.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from poro2d.dem import Particles, Simulation, Walls, checkpoint
from poro2d.dem.neighbors import (
    LV_COUNT,
    brute_force_pairs,
    build_pairs,
    level_scratch,
)
from poro2d.oracles.engine_step import ReferenceDEM
from tests.oracles.test_engine_step import STEP_TOL, _lockstep

RF = 1e-5  # radius of the fines (m)


def _lists(n, cap):
    return (
        np.zeros(n + 1, np.int64), np.zeros(cap, np.int64), np.zeros(cap),
        np.zeros(n + 1, np.int64), np.zeros(cap, np.int64), np.zeros(cap),
    )  # fmt: skip


def _pairs_of(start, other, n):
    rows = np.repeat(np.arange(n), np.diff(start))
    return set(zip(rows.tolist(), other[: start[n]].tolist(), strict=True))


def _wide_radii(rng, n, ratio):
    """Radii log-uniform over ``ratio``, with its two ends present."""
    r = RF * np.exp(rng.uniform(0.0, np.log(ratio), n))
    r[0], r[-1] = RF, RF * ratio
    return r


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    n=st.integers(1, 400),
    spread=st.floats(2e-4, 0.05),
    ratio=st.floats(1.0, 3000.0),
    skin=st.floats(0.0, 2e-5),
    seed=st.integers(0, 2**31 - 1),
    runaway=st.booleans(),
)
def test_level_list_equals_brute_force(n, spread, ratio, skin, seed, runaway):
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0.0, spread, (n, 2))
    rad = _wide_radii(rng, n, ratio)
    if runaway:  # one disk far away: no grid may explode or miss pairs
        pos[n // 2] = (30.0, -12.0)
    oracle = brute_force_pairs(pos, rad, skin)
    lv = level_scratch(n)
    if len(oracle) > 1:  # too small: reports the size, changes nothing
        lists = _lists(n, 1)
        assert build_pairs(pos, rad, skin, *lists, lv) == -len(oracle)
        assert np.all(lists[0] == 0)
    lists = _lists(n, max(1, len(oracle)))
    assert build_pairs(pos, rad, skin, *lists, lv) == len(oracle)
    start, other = lists[0], lists[1]
    assert _pairs_of(start, other, n) == oracle
    for i in range(n):  # rows hold partners j > i, ascending
        row = other[start[i] : start[i + 1]]
        assert np.all(row > i) and np.all(np.diff(row) > 0)
    assert lv.info[: lv.count[0], LV_COUNT].sum() == n


def _packed_wide(seed, n_big=3, ratio=150.0):
    """Coarse disks (up to ``ratio`` times the fines) ringed by touching fines, a few fines
    inside them and some scattered: crowded cells of fines around every coarse disk."""
    rng = np.random.default_rng(seed)
    big = RF * ratio * rng.uniform(0.3, 1.0, n_big)
    big[0] = RF * ratio
    side = 5.0 * big.max()
    bpos = rng.uniform(big.max(), side - big.max(), (n_big, 2))
    gx, gy = np.meshgrid(np.arange(0.0, side, 2.05 * RF), np.arange(0.0, side, 2.05 * RF))
    fines = np.column_stack([gx.ravel(), gy.ravel()])
    gap = np.min([np.hypot(*(fines - p).T) - r for p, r in zip(bpos, big, strict=True)], axis=0)
    ring = (gap > -3 * RF) & (gap < 4 * RF)
    scattered = rng.random(len(fines)) < 300 / len(fines)
    fines = fines[ring | scattered]
    pos = np.concatenate([bpos, fines])
    rad = np.concatenate([big, RF * rng.uniform(0.95, 1.05, len(fines))])
    order = rng.permutation(len(pos))
    return pos[order], rad[order]


def test_packed_wide_list_equals_brute_force_and_single_grid():
    pos, rad = _packed_wide(0)
    n = len(rad)
    skin = 0.3 * RF
    oracle = brute_force_pairs(pos, rad, skin)
    lists = _lists(n, len(oracle))
    assert build_pairs(pos, rad, skin, *lists, level_scratch(n)) == len(oracle)
    assert _pairs_of(lists[0], lists[1], n) == oracle
    one = _lists(n, len(oracle))
    build_pairs(pos, rad, skin, *one)
    assert _pairs_of(one[0], one[1], n) == oracle  # the same candidates as the one grid


@pytest.mark.parametrize("shuffled", [False, True])
def test_level_rebuild_carries_history(shuffled):
    """Shear history of every surviving pair is carried, whether the old rows are ascending
    (the search's own) or in another order (e.g. a list from the one grid or renumbered)."""
    rng = np.random.default_rng(4)
    pos, rad = _packed_wide(1)
    n = len(rad)
    skin = 0.5 * RF
    lists = _lists(n, 200_000)
    nb_start, nb_j, nb_fs = lists[:3]
    lv = level_scratch(n)
    build_pairs(pos, rad, skin, *lists, lv)
    old = _pairs_of(nb_start, nb_j, n)
    total = int(nb_start[n])
    if shuffled:
        for i in range(n):
            a, b = nb_start[i], nb_start[i + 1]
            nb_j[a:b] = nb_j[a:b][::-1].copy()
    rows = np.repeat(np.arange(n), np.diff(nb_start))
    nb_fs[:total] = rows * 1e5 + nb_j[:total]  # a recognisable history per pair
    pos2 = pos + rng.uniform(-0.4 * RF, 0.4 * RF, pos.shape)
    build_pairs(pos2, rad, skin, *lists, lv)
    new = _pairs_of(nb_start, nb_j, n)
    assert new == brute_force_pairs(pos2, rad, skin)
    rows = np.repeat(np.arange(n), np.diff(nb_start))
    want = np.array(
        [
            r * 1e5 + j if (r, j) in old else 0.0
            for r, j in zip(rows.tolist(), nb_j[: nb_start[n]].tolist(), strict=True)
        ]
    )
    assert np.array_equal(nb_fs[: nb_start[n]], want)
    assert len(new & old) > 1000 and len(new - old) > 10


# ------------------------------------------------------------------ the engine


def test_search_follows_the_size_ratio():
    """Narrow and the built-in gradings keep the one cell grid; wide ones get the levels."""
    from poro2d.grading import draw_disks, paper_grading, preset_grading

    for curve in (paper_grading(), preset_grading("wide_cu4"), preset_grading("wide_cu6")):
        r = draw_disks(curve, 2e-3, 0)
        r = np.concatenate([[r.min(), r.max()], r[:: max(1, len(r) // 200)]])[:225]  # both ends kept
        gx, gy = np.meshgrid(np.arange(15), np.arange(15))
        pos = np.column_stack([gx.ravel(), gy.ravel()])[: len(r)] * 2.1 * r.max()
        sim = Simulation(Particles(pos, r, 2650.0, 0.008, 4e5, 4e5, 0.5), _box_of(pos, r))
        assert r.max() / r.min() <= 25.5 and sim.neighbor_search == "cells"
    pos, rad = _packed_wide(2)
    sim = Simulation(Particles(pos, rad, 2650.0, 0.008, 4e5, 4e5, 0.5), _box_of(pos, rad))
    assert sim.neighbor_search == "levels"
    sim.particles.radius[:] = RF  # all alike now: the one grid again
    sim.particles_changed()
    assert sim.neighbor_search == "cells"


def _box_of(pos, rad):
    lo = (pos - rad[:, None]).min(axis=0) - RF
    hi = (pos + rad[:, None]).max(axis=0) + RF
    return Walls.box(lo[0], lo[1], hi[0], hi[1], 2e6, 1.5e6, 0.3)


def wide_packing(seed, threads=1, partitions=2, rolling=False) -> Simulation:
    """Two coarse disks (r = 1.5 mm and 0.4 mm) on a bed of ~300 fines (r ~ 10 um, 1 % overlaps),
    r_max / r_min ~ 150, random velocities and spins, a small skin: many rebuilds."""
    rng = np.random.default_rng(seed)
    width = 300 * 2 * RF
    rows = [
        (RF + 2 * RF * c + RF * (k % 2), RF + np.sqrt(3.0) * RF * k)
        for k in range(2)
        for c in range(150 - k % 2)
    ]
    fines = np.array(rows) * 0.99
    top = fines[:, 1].max() + RF
    big = np.array([1.5e-3, 0.4e-3])
    bpos = np.array([[0.4 * width, top + big[0] * 0.995], [0.9 * width, top + big[1] * 0.995]])
    pos = np.concatenate([fines, bpos])
    n = len(pos)
    rad = np.concatenate([RF * rng.uniform(0.98, 1.02, len(fines)), big])
    kn = rng.uniform(0.8e5, 1.2e5, n)
    p = Particles(
        pos=pos, radius=rad, density=2650.0, thickness=0.01, kn=kn, ks=0.7 * kn,
        mu=rng.uniform(0.05, 0.3, n), vel=rng.normal(0.0, 0.05, (n, 2)), omega=rng.normal(0.0, 50.0, n),
    )  # fmt: skip
    if rolling:
        p.mu_r[:] = rng.uniform(0.02, 0.3, n)
    w = Walls.box(0.0, 0.0, width, top + 2.2 * big[0], 2e5, 1.5e5, 0.3, mu_r=0.1 if rolling else 0.0)
    sim = Simulation(
        p, w, gravity=(0.3, -9.81), local_damping=0.7, skin=0.05 * RF, threads=threads, partitions=partitions
    )
    sim.parallel_min_particles = 0
    return sim


def test_wide_kernel_matches_reference():
    """Lock-step with the NumPy reference (every pair tested directly), summing in the
    engine's slot order, each step from the engine's motion: the same numbers to round-off
    (the engine's fused products, tests/oracles/test_engine_step.py), across many rebuilds."""
    sim = wide_packing(1)
    assert sim.neighbor_search == "levels"
    worst, _, _, rebuilds, ref = _lockstep(sim, 150, engine_order=True, length=RF)
    assert max(worst["pos"], worst["vel"], worst["omega"]) <= STEP_TOL, worst
    p = sim.particles
    assert rebuilds >= 5, rebuilds
    c = sim.contacts()
    kinds = zip(c.i.tolist(), c.j.tolist(), c.kind.tolist(), strict=True)
    got = {(a, b) if k == 0 else (a, "wall", b) for a, b, k in kinds}
    assert got == set(ref.contacts)
    big = len(p.radius) - 2  # the coarse disk rests on many fines
    assert sum(1 for key in ref.contacts if big in key[:2] and len(key) == 2) >= 10
    # the list the kernel built last is the brute-force candidate set of its build positions
    nb = sim.pairs
    assert set(zip(nb.rows().tolist(), nb.other[: nb.used].tolist(), strict=True)) == brute_force_pairs(
        sim.work.pos_build, p.radius, sim.skin
    )


def test_wide_one_step_independent_order():
    """From a shared state, the reference in its own (i, j) order: round-off only."""
    sim = wide_packing(2)
    sim.run(30)
    for _ in range(10):
        ref = ReferenceDEM.from_simulation(sim)
        sim.run(1)
        ref.step()
        scale = max(1e-12, float(np.abs(ref.force).max()))
        assert float(np.abs(sim.force - ref.force).max()) / scale < 1e-10


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 numba threads")
def test_wide_threads_give_identical_results():
    a = wide_packing(3, threads=1, partitions=2, rolling=True)
    b = wide_packing(3, threads=2, partitions=2, rolling=True)
    ra = a.run(80)
    b.run(80)
    assert b.threads_used == 2 and ra.rebuilds >= 3
    for x, y in [
        (a.particles.pos, b.particles.pos), (a.particles.omega, b.particles.omega), (a.force, b.force),
        (a.moment, b.moment), (a.wall_force_vec, b.wall_force_vec), (a.pairs.mr, b.pairs.mr),
    ]:  # fmt: skip
        assert np.array_equal(x, y)


def test_wide_checkpoint_continues_bitwise(tmp_path):
    a = wide_packing(4)
    a.run(40)
    checkpoint.save(a, tmp_path / "wide.npz")
    b = checkpoint.load(tmp_path / "wide.npz")
    assert b.neighbor_search == "levels"
    ra = a.run(60)
    b.run(60)
    assert ra.rebuilds >= 2
    assert np.array_equal(a.particles.pos, b.particles.pos)
    assert np.array_equal(a.particles.omega, b.particles.omega)


def test_kernel_records_hold_the_level_grids():
    """A wide grading's records carry its grids by size level, contiguous int64 (geo float64)."""
    sim = wide_packing(5)
    sim.run(2)
    rec = sim.kernel_records()
    assert rec.levels is sim.work.levels
    for name, arr in rec.levels._asdict().items():
        assert isinstance(arr, np.ndarray) and arr.flags.c_contiguous, name
        assert arr.dtype == (np.float64 if name == "geo" else np.int64), name
    assert rec.levels.count[0] >= 3  # r_max / r_min ~ 150: four levels of a factor 4
