"""The Dask backend of the executor: a LocalCluster or a running scheduler, and jobs as tasks.

The cluster starts at the first job to run (a calibration whose tests are all cached starts
none) and serves every later map until it is closed. Each job is one task; a task whose
job raised comes back as a :class:`~poro2d.execute.jobs.Failed` value, as a worker that
died too often does (``KilledWorker``). Dask's worker processes ignore Ctrl-C from the
moment they import this module to run a task (:mod:`poro2d.worker_signals`); the command
closes the cluster, quietly (:func:`quiet_shutdown_logs`).
"""

from __future__ import annotations

import logging
import os
import socket
import struct
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit

from poro2d.errors import InputError
from poro2d.execute.cluster_options import CONNECT_TIMEOUT_S, DEFAULT_DASHBOARD, check_scheduler_address
from poro2d.execute.jobs import Failed, Job
from poro2d.typed_result import TypedResult
from poro2d.worker_signals import hold_interrupts, ignore_interrupts_in_dask_worker, release_interrupts

ignore_interrupts_in_dask_worker()  # a worker imports this module to run its first task

#: environment of LocalCluster worker processes: one thread for every numeric library
SINGLE_THREAD_ENV = {
    "NUMBA_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
}


def pin_numba_threads() -> None:
    """One numba thread for the case (its kind may raise it again for its own runs).

    numba re-reads ``NUMBA_NUM_THREADS`` from the environment whenever it compiles, and once
    its threads run, another value there is an error. A worker process may see a value in
    its environment other than the one its numba started with (the cluster's environment is
    applied after start-up), so the first compile in a fresh worker (an empty kernel cache)
    failed every case. The environment is pinned to the running value first.
    """
    try:
        import numba

        os.environ["NUMBA_NUM_THREADS"] = str(numba.config.NUMBA_NUM_THREADS)
        numba.set_num_threads(1)
    except Exception:  # pragma: no cover - numba missing or threading layer unavailable
        pass


def start_client(scheduler: str | None, workers: int | None, threads_needed: int,
                  dashboard: str | None = DEFAULT_DASHBOARD):  # fmt: skip
    """(client, cluster or None): connect to ``scheduler`` or start a LocalCluster.

    The LocalCluster's dashboard listens on ``dashboard`` (None: no dashboard).
    """
    from distributed import Client, LocalCluster

    if scheduler:
        return connect(scheduler), None
    n = workers or os.cpu_count() or 1
    # threads lent to a case wait passively between kernel blocks: on a shared machine a spinning
    # OpenMP thread takes the core of another worker's case
    env = dict(SINGLE_THREAD_ENV, NUMBA_NUM_THREADS=str(max(1, threads_needed)), OMP_WAIT_POLICY="PASSIVE")
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        # the scheduler's web server (health, metrics) runs in any case: on this machine, with
        # the dashboard's pages only when one is asked for
        dashboard_address=dashboard if dashboard is not None else DEFAULT_DASHBOARD,
        scheduler_kwargs={"dashboard": dashboard is not None},
        env=env,
    )
    return Client(cluster), cluster


def connect(scheduler: str):
    """A client of the running scheduler at ``scheduler``; one that does not answer is an InputError."""
    from distributed import Client

    address = check_scheduler_address(scheduler)
    problem = not_a_scheduler(address, CONNECT_TIMEOUT_S)
    if problem is None:
        try:
            return Client(address, timeout=f"{CONNECT_TIMEOUT_S}s")
        except Exception as exc:  # refused, no answer in time, or another server's (a web server on
            # ws:// answers the handshake with a page, tls:// asks for a security config first)
            problem = f"{type(exc).__name__}: {exc}".splitlines()[0]
    allowed = f"a running Dask scheduler that answers within {CONNECT_TIMEOUT_S} s"
    raise InputError("--scheduler", scheduler, allowed, problem)


def not_a_scheduler(address: str, timeout: float) -> str | None:
    """Why the server at a ``tcp://`` ``address`` is not a Dask scheduler; None when it may be.

    A Dask server speaks first: on a new connection it sends its handshake, a message whose
    first two 8-byte words are its length and its count of frames. A server of another kind
    (a web server waiting for a request) sends nothing, and the Dask client would wait on it
    for ever; one that sends something else is not Dask either. Other schemes (tls, ws, ucx)
    start with their own handshake and are left to the client's timeout.
    """
    parts = urlsplit(address)
    if parts.scheme != "tcp":
        return None
    try:
        with socket.create_connection((parts.hostname, parts.port), timeout=timeout) as sock:
            try:  # the first 16 bytes, or what came of them before the end of the stream
                greeting = sock.makefile("rb").read(16)
            except TimeoutError:  # no complete handshake in time: whatever came is not one
                greeting = b""
    except OSError as exc:  # refused or unreachable: the client says so in its own words
        return None if not isinstance(exc, TimeoutError) else f"no connection in {timeout:g} s"
    if len(greeting) < 16:
        return f"the server at {parts.hostname}:{parts.port} sent no Dask handshake in {timeout:g} s"
    length, frames = struct.unpack("<QQ", greeting)
    if not (16 <= length < 1 << 30 and 1 <= frames < 1 << 16):
        return f"the server at {parts.hostname}:{parts.port} does not speak Dask's protocol"
    return None


def quiet_shutdown_logs(client) -> None:
    """Silence Dask's logging here and on the workers before an interrupted run closes them.

    Closing workers in the middle of their cases makes the worker, nanny and scheduler log
    warnings (cancelled tasks, workers killed) that say only that the run was stopped. The
    level stays raised in this process: some of those lines come from the cluster's threads
    after it is closed, and an interrupted command is ending anyway.
    """
    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    try:
        client.run(_silence_distributed_logs)
    except Exception:  # a client already closed or never connected: nothing to silence there
        pass


def _silence_distributed_logs() -> None:
    logging.getLogger("distributed").setLevel(logging.CRITICAL)


def check_reachable(scheduler: str | None) -> None:
    """Connect to ``scheduler`` once and let go: an unreachable one is refused before any work.

    A command calls it before it prints its first line, so that a scheduler that does not
    answer is its only line; the sweeps connect again when they start.
    """
    if scheduler:
        connect(scheduler).close()


@dataclass(eq=False)
class ClusterInfo(TypedResult):
    """What a sweep records of the Dask cluster it ran on (the ``cluster`` key of its record)."""

    scheduler: str | None
    workers: int
    threads: int
    local_cluster: bool
    dashboard: str | None


class DaskCluster:
    """A Dask client for the executor: ``client`` as given, or one started at the first job.

    A client it starts (a LocalCluster of ``workers`` single-threaded processes whose numba
    may start ``threads``, or a connection to ``scheduler``) is its own to close.
    """

    def __init__(self, scheduler: str | None, workers: int | None, dashboard: str | None,
                 threads: int, client=None) -> None:  # fmt: skip
        self.scheduler, self.workers, self.dashboard, self.threads = scheduler, workers, dashboard, threads
        self.client = client
        self.local = None  # the LocalCluster started here
        self.own = client is None
        # read when the cluster starts, kept after it is closed (what the results record of it)
        self.scheduler_info: dict | None = None
        self.local_cluster = False

    def start(self):
        """The client, the cluster started first if it is not yet (Ctrl-C held while it starts)."""
        if self.client is not None and self.scheduler_info is not None:
            return self.client
        if self.own:
            held = hold_interrupts() if not self.scheduler else None
            try:
                self.client, self.local = start_client(
                    self.scheduler, self.workers, self.threads, self.dashboard
                )
            except BaseException:
                release_interrupts(held)
                raise
            # a Ctrl-C of the start-up arrives here, with the cluster in hand to close
            release_interrupts(held)
        self.local_cluster = self.local is not None
        self.scheduler_info = self.client.scheduler_info()
        return self.client

    def info(self) -> ClusterInfo | None:
        """Scheduler, workers, threads, whether it is a local cluster, the dashboard; None before the start.

        The dashboard is asked of the client, so before it is closed.
        """
        if self.scheduler_info is None:
            return None
        workers = self.scheduler_info.get("workers", {})
        dashboard = None
        if self.client is not None and (self.dashboard is not None or self.scheduler):
            try:
                dashboard = self.client.dashboard_link
            except Exception:  # no dashboard (bokeh missing, or disabled on the scheduler)
                pass
        return ClusterInfo(
            scheduler=self.scheduler or self.scheduler_info.get("address"),
            workers=len(workers),
            threads=sum(w.get("nthreads", 0) for w in workers.values()),
            local_cluster=self.local_cluster,
            dashboard=dashboard,
        )

    def map(self, jobs: Sequence[Job], on_done: Callable[[int, Any], None] | None) -> list:
        """Every job as a task; ``on_done(index, outcome)`` as each ends; outcomes in job order."""
        from distributed import as_completed

        client = self.start()
        futures = {
            client.submit(_run_task, job, key=job.key or job.label, retries=job.retries, pure=False): i
            for i, job in enumerate(jobs)
        }
        outcomes: list = [None] * len(jobs)
        for future in as_completed(list(futures)):
            i = futures[future]
            if future.status == "finished":
                outcomes[i] = future.result()
            else:  # the job raised, or the task itself failed (KilledWorker after too many worker deaths)
                tb = future.traceback()
                frames = "".join(traceback.format_tb(tb)) if tb else ""
                outcomes[i] = Failed(jobs[i].label, future.exception(), frames)
            if on_done is not None:
                on_done(i, outcomes[i])
            future.release()
        return outcomes

    def quiet(self) -> None:
        """Before an interrupted run closes its own cluster: no log lines from its shutdown."""
        if self.own and self.client is not None:
            quiet_shutdown_logs(self.client)

    def close(self) -> None:
        """Close the client and cluster started here (a given client stays open)."""
        if not self.own:
            return
        if self.client is not None:
            # the workers' work is done: a heartbeat that meets the closing scheduler logs a
            # traceback from the worker's process (seen under a notebook's cell), noise here
            try:
                self.client.run(_silence_distributed_logs)
            except Exception:  # a client already closed or never connected: nothing to silence
                pass
            self.client.close()
        if self.local is not None:
            # a finished run's workers are told to stop; on a loaded machine one may take longer
            # than the nanny waits, and it says so ("Worker process still alive ... killing") for
            # a worker whose work is done: noise under a command's or a notebook's answer
            nanny = logging.getLogger("distributed.nanny")
            level = nanny.level
            nanny.setLevel(logging.ERROR)
            try:
                self.local.close()
            finally:
                nanny.setLevel(level)
        self.client = self.local = None


def _run_task(job: Job):
    """A job on a Dask worker (importing this module there makes the worker ignore Ctrl-C).

    A job that raises comes back as its :class:`Failed` value, as from the other backends:
    raised, it would make the worker log Dask's "Compute Failed" lines on the command's
    terminal for a failure the caller reports in its own words (or, for a calibration test
    without equilibrium, as an expected outcome). A job with retries raises instead, so that
    Dask runs it again.
    """
    if job.retries:
        return job.run()
    try:
        return job.run()
    except Exception as exc:
        return Failed.of(job, exc)


__all__ = [
    "SINGLE_THREAD_ENV",
    "ClusterInfo",
    "DaskCluster",
    "check_reachable",
    "connect",
    "not_a_scheduler",
    "pin_numba_threads",
    "quiet_shutdown_logs",
    "start_client",
]
