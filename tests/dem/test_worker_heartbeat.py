"""A Dask worker stays alive while its task runs a long compiled block.

The scheduler takes a worker whose heartbeats stop for ``worker-ttl`` as dead and restarts it,
losing its task. A heartbeat is sent by Python code in the worker's own thread, so a kernel
that kept Python's lock for a whole block silenced it: a G1-1 sand run on a loaded machine lost
a calibration case every ten minutes that way. The test lowers the limit to 2 s and runs one
block several times as long; with the lock held, the task is restarted until the scheduler
gives up on it (KilledWorker).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls

R = 0.002
STEPS = 1_500_000  # one block of several seconds (7 s at 2e7 particle-steps/s), past the 2 s limit


def _one_long_block(steps: int) -> int:
    rng = np.random.default_rng(5)
    s = 2.02 * R
    h = s * math.sqrt(3) / 2
    pos = np.array([(s * (i + 0.5 + 0.5 * (j % 2)), s / 2 + h * j) for j in range(10) for i in range(10)])
    p = Particles(
        pos=pos, radius=R * rng.uniform(0.8, 1.0, len(pos)), density=2650.0, thickness=0.01,
        kn=1e5, ks=1e5, mu=0.5,
    )  # fmt: skip
    sim = Simulation(p, Walls.box(0.0, 0.0, 11 * s, 12 * s, 1e5, 1e5, 0.3))
    sim.run(1)  # compile (or load) the kernel before the timed part of the task
    return sim.run(steps).steps


@pytest.mark.scenario
def test_a_worker_running_one_long_block_is_not_taken_for_dead():
    dask = pytest.importorskip("dask")
    distributed = pytest.importorskip("distributed")
    limits = {"distributed.scheduler.worker-ttl": "2s", "distributed.scheduler.allowed-failures": 0}
    with dask.config.set(limits):
        with distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster, distributed.Client(cluster) as client:  # fmt: skip
            ran = client.submit(_one_long_block, STEPS, pure=False).result(timeout=600)
    assert ran == STEPS
