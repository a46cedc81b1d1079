"""One scan per list build: the counting scan keeps each row's partners for the filling.

A row with up to ``CAND_SLOTS`` partners is copied from what the counting scan kept; a
longer one is scanned again. Either way the list must be the one the two-scan build
(:func:`poro2d.dem.neighbors.build_pairs`, no kept partners) makes, slot for slot: the order
of a row is the order of its force sums, so any other order would change the numbers.
"""

from __future__ import annotations

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls
from poro2d.dem.neighbors import CAND_SLOTS, brute_force_pairs, build_pairs


def _packing(n: int, ratio: float, seed: int) -> Simulation:
    """Disks of radii 1 mm to ``ratio`` mm on random spots in a box, the largest numbered first
    (so their rows hold many small partners), and an unsettled start (rebuilds follow)."""
    rng = np.random.default_rng(seed)
    r = 1e-3 * np.sort(rng.uniform(1.0, ratio, n) ** 3 / ratio**2 + 1.0)[::-1]
    side = np.sqrt(np.sum(np.pi * r**2) / 0.6)
    pos = rng.uniform(r.max(), side - r.max(), (n, 2))
    p = Particles(pos=pos, radius=r, density=2650.0, thickness=0.01, kn=1e6, ks=1e6, mu=0.3,
                  vel=rng.normal(0.0, 0.2, (n, 2)))  # fmt: skip
    return Simulation(p, Walls.box(0.0, 0.0, side, side, 1e6, 1e6, 0.3), gravity=(0.0, -9.81))


def _two_scan_list(sim: Simulation) -> tuple[np.ndarray, np.ndarray]:
    """The list of the last build made again from the positions it was built at."""
    n, cap = sim.particles.n, sim.pairs.capacity
    start, other, fs = np.zeros(n + 1, np.int64), np.zeros(cap, np.int64), np.zeros(cap)
    new = (np.zeros(n + 1, np.int64), np.zeros(cap, np.int64), np.zeros(cap))
    build_pairs(sim.work.pos_build, sim.particles.radius, sim.skin, start, other, fs, *new)
    return start, other[: start[n]]


@pytest.mark.parametrize("ratio, seed", [(1.5, 0), (12.0, 1)])
def test_kernel_lists_are_the_two_scan_lists_slot_for_slot(ratio, seed):
    sim = _packing(600, ratio, seed)
    sim.run(1)
    rows = np.diff(sim.pairs.start)
    if ratio > 10:  # long rows are scanned again, short ones copied: both kinds are here
        assert rows.max() > CAND_SLOTS and np.any((rows > 0) & (rows <= CAND_SLOTS))
    for _ in range(3):
        start, other = _two_scan_list(sim)
        np.testing.assert_array_equal(sim.pairs.start, start)
        np.testing.assert_array_equal(sim.pairs.other[: sim.pairs.used], other)
        found = {(int(i), int(j)) for i, j in zip(sim.pairs.rows(), other, strict=True)}
        assert found == brute_force_pairs(sim.work.pos_build, sim.particles.radius, sim.skin)
        res = sim.run(40)
        assert res.rebuilds > 0  # the next comparison is of a list built again


@pytest.mark.parametrize("past", [1e-4, 1e-7])
def test_rows_reaching_just_into_the_next_cell_find_their_partner(past):
    """A row reads only the cells its reach touches. A disk of the largest radius ``past``
    (of a cell's side) beyond its cell's edge reaches the next cell but one side's width
    (its reach is 2 r_max + skin, the side itself) by that little: the partner it finds
    there, a hair inside its reach, is one a range narrowed by rounding would miss."""
    r, skin = 1e-3, 2e-4
    size = 2 * r + skin  # the grid's side; the disk at the origin puts the edges at k size
    pos, pairs = [(0.0, 0.0)], set()
    for c, lane in ((2, 1.5), (5, 3.5)):
        for axis in (0, 1):
            a = np.array([lane, lane]) * size if axis == 0 else np.array([9.5 + lane / 2, 0.0]) * size
            a[axis] = (c + past) * size
            b = a.copy()
            b[axis] += size * (1.0 - 0.5 * past)  # within reach, in cell c + 1
            pairs.add((len(pos), len(pos) + 1))
            pos += [tuple(a), tuple(b)]
    # fillers apart from each other and from the pairs, so that the grid keeps its side
    pos += [(x * size, y * size) for x in np.arange(0.0, 12.0, 1.1) for y in (8.5, 9.6, 10.7, 11.8)]
    pos = np.array(pos)
    radius = np.full(len(pos), r)
    n, cap = len(pos), 256
    assert (np.ptp(pos[:, 0]) / size + 1) * (np.ptp(pos[:, 1]) / size + 1) <= 4 * n + 16
    start, other, fs = np.zeros(n + 1, np.int64), np.zeros(cap, np.int64), np.zeros(cap)
    new = (np.zeros(n + 1, np.int64), np.zeros(cap, np.int64), np.zeros(cap))
    total = build_pairs(pos, radius, skin, start, other, fs, *new)
    rows = np.repeat(np.arange(n), np.diff(start))
    found = {(int(i), int(j)) for i, j in zip(rows, other[:total], strict=True)}
    assert found == brute_force_pairs(pos, radius, skin) == pairs
