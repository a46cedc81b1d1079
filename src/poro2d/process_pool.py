"""Jobs in worker processes on this machine: the direct shear tests and the replicate criterion runs.

The sweeps, relations and calibrations run on Dask (:mod:`poro2d.sweep.runner`), locally or
on a cluster. The direct shear tests of a series and the replicate criterion runs of
``poro2d paper`` run here instead, for three reasons:

- their workers report each test's phase and fraction a few times a second, and the
  command draws one bar per job from them: one queue to this process, where on Dask every
  message would go through the scheduler's publish/subscribe;
- they are steps of commands that run on one machine (``poro2d paper``, ``shear``,
  ``strength``: a ``--processes`` count, no cluster options); a calibration makes its
  preset specimens with them before its Dask cluster starts;
- with one process (``processes=1``) they run right here, with no worker at all.

Each worker is a fresh interpreter (the spawn start method) so that numba starts there
with the thread count the job sets, not the parent's. The workers ignore Ctrl-C, as
Dask's do (:mod:`poro2d.worker_signals`): the command takes it, cancels the jobs not
started and ends the worker processes this pool started. A job's result depends
on the job alone, so results are the same, and in the same (job) order, whatever the
process count.
"""

from __future__ import annotations

import signal
import time
from collections.abc import Callable, Sequence
from typing import Any

from poro2d.errors import InputError
from poro2d.worker_signals import hold_interrupts, release_interrupts

#: least seconds between two messages of one job with the same phase (a new phase goes at once)
REPORT_INTERVAL_S = 0.5
#: seconds the parent waits for a job to finish before it reads the workers' messages again
POLL_S = 0.25

#: in a worker process: the queue its messages go to (set when the worker starts)
_queue = None


class JobsFailed(RuntimeError):
    """Jobs that raised, each named with its error: ``2 direct shear test(s) failed: 50 kPa: ...``."""

    def __init__(self, what: str, errors: list[tuple[str, BaseException]]) -> None:
        self.errors = errors
        details = "; ".join(f"{name}: {exc}" for name, exc in errors)
        super().__init__(f"{len(errors)} {what} failed: {details}")


def map_jobs(
    task: Callable[..., Any],
    jobs: Sequence[Any],
    processes: int,
    *,
    names: Sequence[str],
    what: str = "job(s)",
    start_first: Callable[[Any], Any] | None = None,
    on_report: Callable[..., None] | None = None,
    on_done: Callable[[int, Any], None] | None = None,
) -> list:
    """``task(job, report)`` for every job, in up to ``processes`` worker processes; results in job order.

    ``task`` is a module-level function (a worker imports it by name). It may call
    ``report(phase, *rest)`` as it goes; ``on_report(index, phase, *rest)`` gets those
    messages here, at most every :data:`REPORT_INTERVAL_S` for one phase. ``on_done(index,
    result)`` is called as each job ends. ``start_first`` is a sort key of the jobs that
    orders their start in the pool (the slowest first, so that the workers end together).
    Every job runs even when one fails; then the first :class:`InputError` (in job order)
    is raised as it is, any other failures together as :class:`JobsFailed` under ``names``.
    """
    if len(names) != len(jobs):
        raise ValueError(f"{len(names)} names for {len(jobs)} jobs")
    results: list = [None] * len(jobs)
    errors: dict[int, BaseException] = {}
    if processes <= 1 or len(jobs) <= 1:
        _run_here(task, jobs, on_report, on_done, results, errors)
    else:
        order = list(range(len(jobs)))
        if start_first is not None:
            order.sort(key=lambda i: start_first(jobs[i]))
        _run_in_pool(task, jobs, order, min(processes, len(jobs)), on_report, on_done, results, errors)
    if errors:
        failed = sorted(errors)
        first_input = next((errors[i] for i in failed if isinstance(errors[i], InputError)), None)
        if first_input is not None:
            raise first_input
        raise JobsFailed(what, [(names[i], errors[i]) for i in failed])
    return results


def _run_here(task, jobs, on_report, on_done, results: list, errors: dict) -> None:
    """The jobs one after the other in this process."""
    for i, job in enumerate(jobs):
        send = (lambda *msg, i=i: on_report(i, *msg)) if on_report is not None else _ignore
        try:
            results[i] = task(job, _Throttle(send))
        except Exception as exc:  # noqa: BLE001 - reported with the job it belongs to
            errors[i] = exc
            continue
        if on_done is not None:
            on_done(i, results[i])


def _run_in_pool(
    task, jobs, order: list[int], n: int, on_report, on_done, results: list, errors: dict
) -> None:
    """The jobs in ``n`` spawned worker processes, started in ``order``."""
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    ctx = mp.get_context("spawn")  # a fresh interpreter: numba takes the thread count the job sets
    queue = ctx.Queue()
    before = {child.pid for child in ctx.active_children()}  # processes started before this pool
    pool = ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=_start_worker, initargs=(queue,))
    # the workers start as the jobs are submitted; with SIGINT blocked meanwhile they start with it
    # blocked (a Ctrl-C then reaches the command alone, which ends them)
    held = hold_interrupts()
    try:
        futures = {pool.submit(_run_reporting, task, jobs[i], i): i for i in order}
        release_interrupts(held)
        pending = set(futures)
        while pending:
            finished, pending = wait(pending, timeout=POLL_S, return_when=FIRST_COMPLETED)
            _drain(queue, on_report)
            for future in sorted(finished, key=futures.get):
                i = futures[future]
                try:
                    results[i] = future.result()
                except Exception as exc:  # noqa: BLE001 - reported with the job it belongs to
                    errors[i] = exc
                    continue
                if on_done is not None:
                    on_done(i, results[i])
    except BaseException:  # Ctrl-C (or a failing display): no job is started any more
        release_interrupts(held)
        pool.shutdown(wait=False, cancel_futures=True)
        _end_workers(before)
        raise
    finally:
        pool.shutdown(wait=True)
    _drain(queue, on_report)


def _start_worker(queue) -> None:
    """In a new worker: Ctrl-C is the command's to handle; messages go to ``queue``."""
    global _queue
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _queue = queue


def _run_reporting(task, job, index: int):
    """``task`` in a worker, its messages tagged with the job's index."""
    return task(job, _Throttle(lambda *msg: _queue.put((index, *msg))))


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


def _ignore(*_msg) -> None:
    pass


__all__ = ["REPORT_INTERVAL_S", "JobsFailed", "map_jobs"]
