"""One executor, three backends: jobs in, outcomes out in job order, failures as values.

Every parallel step of poro2d runs here: the replicate criterion runs and the shear tests
of a series (local processes, with live progress), the cases of a sweep, a relation or a
sensitivity study, and the calibration's shear tests (Dask). A :class:`Backend` says
where; an :class:`Executor` maps :class:`~poro2d.execute.jobs.Job` values to their
results and hands each outcome to ``on_done`` as it ends. A job's result depends on the
job alone, so the outcomes are the same, in the same (job) order, on every backend and
worker count.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from poro2d.execute.cluster_options import DEFAULT_DASHBOARD
from poro2d.execute.jobs import Job
from poro2d.execute.local import map_in_processes, map_inline

if TYPE_CHECKING:
    from poro2d.execute.dask_cluster import ClusterInfo

#: the backends: this process, spawned processes on this machine, a Dask cluster
KINDS = ("inline", "processes", "dask")


@dataclass(frozen=True)
class Backend:
    """Where jobs run.

    ``inline``: one after the other in this process (tests, one worker). ``processes``: up
    to ``processes`` spawned worker processes that report live progress. ``dask``: a
    LocalCluster of ``workers`` single-threaded processes (whose numba may start
    ``threads``; dashboard on ``dashboard``, None: none), or the running scheduler at
    ``scheduler``.
    """

    kind: str = "inline"
    processes: int = 1
    scheduler: str | None = None
    workers: int | None = None
    dashboard: str | None = DEFAULT_DASHBOARD
    threads: int = 1

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"backend {self.kind!r}: one of {', '.join(KINDS)}")

    @classmethod
    def local(cls, processes: int) -> Backend:
        """``processes`` worker processes on this machine; inline for one."""
        return cls("processes", processes=processes) if processes > 1 else cls("inline")

    @classmethod
    def dask(cls, scheduler: str | None = None, workers: int | None = None, *,
             dashboard: str | None = DEFAULT_DASHBOARD, threads: int = 1) -> Backend:  # fmt: skip
        """A Dask LocalCluster, or the running scheduler at ``scheduler``."""
        return cls("dask", scheduler=scheduler, workers=workers, dashboard=dashboard, threads=threads)


class Executor:
    """Maps jobs on one :class:`Backend`; a Dask cluster starts at the first job, lasts until :meth:`close`.

    ``client``: an existing ``distributed.Client`` for the Dask backend (tests, notebooks),
    left open at the end. Used as a context manager, the executor closes what it started,
    quietly after a Ctrl-C.
    """

    def __init__(self, backend: Backend, *, client=None) -> None:
        self.backend = backend
        self._dask = None
        if backend.kind == "dask":
            from poro2d.execute.dask_cluster import DaskCluster

            self._dask = DaskCluster(backend.scheduler, backend.workers, backend.dashboard, backend.threads,
                                     client=client)  # fmt: skip

    def map(
        self,
        jobs: Sequence[Job],
        *,
        on_report: Callable[..., None] | None = None,
        on_done: Callable[[int, Any], None] | None = None,
        start_first: Callable[[Job], Any] | None = None,
    ) -> list:
        """The outcome of every job in job order: its result, or a ``Failed`` value.

        ``on_report(index, phase, *rest)`` gets the live messages of jobs that report
        (local backends); ``on_done(index, outcome)`` is called as each job ends.
        ``start_first`` is a sort key of the jobs that orders their start in a process pool
        (the slowest first, so that the workers end together).
        """
        jobs = list(jobs)
        if self._dask is not None:
            return self._dask.map(jobs, on_done)
        if self.backend.kind == "inline" or self.backend.processes <= 1 or len(jobs) <= 1:
            return map_inline(jobs, on_report, on_done)
        order = list(range(len(jobs)))
        if start_first is not None:
            order.sort(key=lambda i: start_first(jobs[i]))
        return map_in_processes(jobs, order, min(self.backend.processes, len(jobs)), on_report, on_done)

    def start(self) -> None:
        """Start the Dask cluster now (before the first job), for its dashboard and workers."""
        if self._dask is not None:
            self._dask.start()

    def cluster_info(self) -> ClusterInfo | None:
        """What is recorded of a started Dask cluster (scheduler, workers, threads, local_cluster,
        dashboard); None for the local backends and before the start.
        """
        return self._dask.info() if self._dask is not None else None

    def quiet(self) -> None:
        """Silence the shutdown of a cluster this executor started (an interrupted run)."""
        if self._dask is not None:
            self._dask.quiet()

    def close(self) -> None:
        if self._dask is not None:
            self._dask.close()

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is not None and issubclass(exc_type, KeyboardInterrupt):
            self.quiet()
        self.close()


__all__ = ["KINDS", "Backend", "Executor"]
