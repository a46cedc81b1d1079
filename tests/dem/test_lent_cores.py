"""Cores lent between kernel blocks (:mod:`poro2d.dem.cores`): more threads, the same bits.

A case of a sweep may be given the cores of finished cases while it runs: its simulations
ask the process's lender at every kernel block. The engine's numbers do not depend on its
thread count up to its partitions, so a run whose thread count rises half-way must end in
the state of a run on one thread, bit for bit.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from poro2d.dem import cores
from tests.dem.test_blocks import _assert_same, _settling_box, _state


@pytest.fixture
def no_lender():
    before = cores.lend_cores(None)
    yield
    cores.lend_cores(before)


def test_a_lender_raises_the_threads_but_not_past_the_partitions(no_lender):
    sim = _settling_box(nx=24, ny=44)  # 1056 disks: above the engine's parallel_min_particles
    assert sim.effective_threads == 1 and not cores.lending()
    cores.lend_cores(lambda: 8)
    assert sim.effective_threads == min(2, numba.config.NUMBA_NUM_THREADS) == min(8, sim.partitions, 2)
    small = _settling_box()  # 264 disks: one thread whatever is lent
    assert small.effective_threads == 1
    cores.lend_cores(lambda: 1 / 0)  # a lender that fails lends nothing
    assert cores.cores_lent() == 1 and sim.effective_threads == 1


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 numba threads")
def test_threads_lent_half_way_change_no_bit(no_lender):
    # the lender grants a second thread at its 2nd answer only (two threads wait for each other at
    # every step on a loaded host: a few steps on them say enough)
    runs, used = [], []
    for lend in (False, True):
        sim = _settling_box(nx=24, ny=44)
        sim.run(1500)  # then the stop ratio is met within 500 steps (test_blocks.py)
        asked, lent = [], [0]

        def lender(asked=asked) -> int:
            asked.append(1)
            return 2 if len(asked) == 2 else 1

        if lend:
            cores.lend_cores(lender)
            sim.run(16, check_every=16)  # the first answer: one thread
            sim.run(16, check_every=16)  # the second: two
            lent.append(sim.threads_used)
        else:
            sim.run(32, check_every=16)
        res = sim.run(500, until_ratio=0.9, check_every=16)
        used.append(max(sim.threads_used, *lent))
        runs.append(_state(sim, res))
        if lend:
            assert len(asked) > 2  # asked at each block, not once for the run
    assert used == [1, 2]
    assert cores.lent_core_seconds() > 0.0  # the 16 steps on two threads, counted
    assert runs[0]["converged"] and np.isfinite(runs[0]["steps"])
    _assert_same(runs[0], runs[1])
