"""The atomics, the spin barrier and the start handshake of the worker threads."""

from __future__ import annotations

import time

import numba
import numpy as np
import pytest
from numba import njit, prange

from poro2d.dem.sync import (
    ABORTED,
    GO,
    START,
    atomic_add,
    atomic_cas,
    atomic_load,
    atomic_store,
    barrier,
    fresh_sync,
    start_handshake,
    wall_seconds,
)


@njit(cache=True)
def _atomics(a):
    old = atomic_add(a, 0, 5)
    atomic_store(a, 1, 7)
    miss = atomic_cas(a, 2, 1, 9)  # a[2] is 0: no swap
    hit = atomic_cas(a, 3, 0, 4)
    return old, atomic_load(a, 0), miss, hit


def test_atomics_single_thread():
    a = np.zeros(4, dtype=np.int64)
    a[0] = 2
    old, now, miss, hit = _atomics(a)
    assert (old, now, miss, hit) == (2, 7, 0, 0)
    assert a.tolist() == [7, 7, 0, 4]


@njit(parallel=True, cache=True)
def _lockstep(sync, seen, rounds, nthr):
    """Each worker writes its round number, meets the others, then checks theirs."""
    bad = np.zeros(nthr, dtype=np.int64)
    for t in prange(nthr):
        if start_handshake(sync, nthr):
            for r in range(rounds):
                seen[t] = r
                barrier(sync, nthr)
                for u in range(nthr):
                    if seen[u] != r:
                        bad[t] += 1
                barrier(sync, nthr)
        else:
            bad[t] = -1
    return bad


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 numba threads")
def test_barrier_keeps_workers_in_lockstep():
    numba.set_num_threads(2)
    sync = fresh_sync()
    seen = np.zeros(2, dtype=np.int64)
    bad = _lockstep(sync, seen, 20_000, 2)
    assert bad.tolist() == [0, 0]
    assert sync[START] == GO


def test_handshake_gives_up_when_the_other_worker_never_comes():
    # one worker alone: the partner would only start after it returns (a serialising
    # threading layer); it must give up instead of waiting for ever, and so must the late one
    sync = fresh_sync()
    assert not start_handshake(sync, 2)
    assert sync[START] == ABORTED
    assert not start_handshake(sync, 2)


def test_one_thread_needs_no_partner():
    sync = fresh_sync()
    assert start_handshake(sync, 1)
    barrier(sync, 1)  # returns at once
    assert sync.tolist() == [0] * len(sync)


def test_the_handshake_clock_reads_the_calendar_seconds():
    # the handshake's deadline is read from C's time(NULL): it must be this clock in seconds
    read = njit(lambda: wall_seconds())
    before = int(time.time())
    now = read()
    assert before <= now <= int(time.time()) + 1
