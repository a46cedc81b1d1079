"""``RunOptions``: how a run's jobs run and whether it shows progress, the same for every ``run_*``.

What a run computes is its case; where its jobs run is not part of it (a job's result depends on
the job alone, :mod:`poro2d.execute.executor`). Every ``run_*`` of the API therefore takes its
case and one ``RunOptions``, and every command fills it from the same two options,
``--workers`` and ``--scheduler`` (and ``--dashboard`` where a local Dask cluster starts).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from poro2d.errors import InputError
from poro2d.execute.cluster_options import DEFAULT_DASHBOARD, check_cluster_options
from poro2d.execute.executor import Backend


@dataclass(frozen=True)
class RunOptions:
    """Where a run's jobs run and what it shows, checked when made.

    ``workers``: worker processes on this machine (None: the run's default, one per job or per
    core); ``scheduler``: the address of a running Dask scheduler whose own workers run the
    jobs (``workers`` is then refused, not ignored); ``dashboard``: where a local Dask cluster
    serves its dashboard (None: none); ``progress``: live bars on the terminal.
    """

    workers: int | None = None
    scheduler: str | None = None
    dashboard: str | None = DEFAULT_DASHBOARD
    progress: bool = True

    def __post_init__(self) -> None:
        check_cluster_options(self.scheduler, self.workers)
        if not isinstance(self.progress, bool):
            raise InputError("progress", self.progress, "True or False")

    def local_workers(self, jobs: int, per_core: int = 1) -> int:
        """The processes a laboratory test starts for ``jobs`` jobs: ``workers``, else one per job
        and at most ``per_core`` per core (with a scheduler: the jobs, all submitted at once)."""
        if self.workers is not None:
            return self.workers
        if self.scheduler is not None:
            return max(1, jobs)
        return max(1, min(jobs, per_core * (os.cpu_count() or 1)))

    def test_backend(self, workers: int) -> Backend:
        """Where a laboratory test's jobs run: the running scheduler, else ``workers`` local
        processes (inline for one) that report live progress."""
        if self.scheduler is not None:
            return Backend.dask(self.scheduler, dashboard=None)
        return Backend.local(workers)

    def dask_backend(self, threads: int = 1) -> Backend:
        """A Dask backend: the running scheduler, or a LocalCluster of ``workers`` processes."""
        return Backend.dask(self.scheduler, self.workers, dashboard=self.dashboard, threads=threads)


__all__ = ["RunOptions"]
