"""Jobs on this machine: inline, one after the other, or in spawned worker processes.

Local processes serve steps of commands that run on one machine (``poro2d paper``,
``shear``, ``strength``: a ``--processes`` count, no cluster options): their workers
report each job's phase and fraction a few times a second through one queue to this
process, where the command draws a bar per job (on Dask every message would go through
the scheduler's publish/subscribe). With one process, or one job, they run inline.

Each worker is a fresh interpreter (the spawn start method) so that numba starts there
with the thread count the job sets, not the parent's. The workers ignore Ctrl-C, as
Dask's do (:mod:`poro2d.worker_signals`): the command takes it, cancels the jobs not
started and ends the worker processes this pool started.
"""

from __future__ import annotations

import signal
import time
from collections.abc import Callable, Sequence

from poro2d.execute.jobs import Failed, Job
from poro2d.worker_signals import hold_interrupts, release_interrupts

#: least seconds between two messages of one job with the same phase (a new phase goes at once)
REPORT_INTERVAL_S = 0.5
#: seconds the parent waits for a job to finish before it reads the workers' messages again
POLL_S = 0.25

#: in a worker process: the queue its messages go to (set when the worker starts)
_queue = None


def map_inline(jobs: Sequence[Job], on_report, on_done) -> list:
    """The jobs one after the other in this process; outcomes in job order."""
    outcomes: list = []
    for i, job in enumerate(jobs):
        try:  # without on_report, the job's messages go nowhere (Job.run)
            outcome = job.run(
                _Throttle(lambda *msg, i=i: on_report(i, *msg)) if on_report is not None else None
            )
        except Exception as exc:  # noqa: BLE001 - returned with the job it belongs to
            outcome = Failed.of(job, exc)
        outcomes.append(outcome)
        if on_done is not None:
            on_done(i, outcome)
    return outcomes


def map_in_processes(jobs: Sequence[Job], order: list[int], n: int, on_report, on_done) -> list:
    """The jobs in ``n`` spawned worker processes, started in ``order``; outcomes in job order."""
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    outcomes: list = [None] * len(jobs)
    ctx = mp.get_context("spawn")  # a fresh interpreter: numba takes the thread count the job sets
    queue = ctx.Queue()
    before = {child.pid for child in ctx.active_children()}  # processes started before this pool
    pool = ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=_start_worker, initargs=(queue,))
    # the workers start as the jobs are submitted; a Ctrl-C meanwhile is raised when all are
    # started (the workers ignore it: it is the command's, which ends them)
    held = hold_interrupts()
    try:
        futures = {pool.submit(_run_reporting, jobs[i], i): i for i in order}
        release_interrupts(held)
        pending = set(futures)
        while pending:
            finished, pending = wait(pending, timeout=POLL_S, return_when=FIRST_COMPLETED)
            _drain(queue, on_report)
            for future in sorted(finished, key=futures.get):
                i = futures[future]
                try:
                    outcomes[i] = future.result()
                except Exception as exc:  # noqa: BLE001 - returned with the job it belongs to
                    outcomes[i] = Failed.of(jobs[i], exc)
                if on_done is not None:
                    on_done(i, outcomes[i])
    except BaseException:  # Ctrl-C (or a failing display): no job is started any more
        release_interrupts(held)
        pool.shutdown(wait=False, cancel_futures=True)
        _end_workers(before)
        raise
    finally:
        pool.shutdown(wait=True)
    _drain(queue, on_report)
    return outcomes


def _start_worker(queue) -> None:
    """In a new worker: Ctrl-C is the command's to handle; messages go to ``queue``."""
    global _queue
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _queue = queue


def _run_reporting(job: Job, index: int):
    """``job`` in a worker, its messages tagged with the job's index."""
    return job.run(_Throttle(lambda *msg: _queue.put((index, *msg))))


class _Throttle:
    """A job's ``report``: a new phase passes at once, the same phase at most every REPORT_INTERVAL_S."""

    def __init__(self, send: Callable[..., None]) -> None:
        self._send = send
        self._last_time = -float("inf")
        self._last_phase: object = None

    def __call__(self, phase, *rest) -> None:
        now = time.monotonic()
        if phase == self._last_phase and now - self._last_time < REPORT_INTERVAL_S:
            return
        self._last_time, self._last_phase = now, phase
        self._send(phase, *rest)


def _drain(queue, on_report) -> None:
    """Hand every message waiting in ``queue`` on to ``on_report``."""
    import queue as queue_module

    while True:
        try:
            index, *msg = queue.get_nowait()
        except (queue_module.Empty, EOFError, OSError):
            return
        if on_report is not None:
            on_report(index, *msg)


def _end_workers(before: set[int]) -> None:
    """Stop the worker processes of this pool (they ignore Ctrl-C): the children not in ``before``.

    A job stopped here resumes from its files when the command is rerun.
    """
    import multiprocessing as mp

    for child in mp.active_children():
        if child.pid not in before:
            child.terminate()


__all__ = ["REPORT_INTERVAL_S", "map_in_processes", "map_inline"]
