"""Spare cores to the cases still running: threads per case when fewer cases than workers remain.

A run of W single-threaded workers leaves cores idle at its end: the last cases run on one
thread each while the workers of finished cases wait. The engine gives the same numbers on
one thread or on up to its ``partitions`` (docs/engine.md), and sets its thread count afresh
at each kernel block (:mod:`poro2d.dem.cores`), so those cores can go to the cases still
running with no number changed. The driver posts the threads per case on a
:class:`ShareBoard` (one small file in a private temporary folder, on this machine) each time
a case ends; a case reads it at most once a second through a :class:`ThreadLender`, and takes
only the threads that have a core free of other processes' work. What the
cores did is kept as a :class:`WorkerUse`: cases per worker, threads per case over time and
the idle core-time.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from poro2d.errors import InputError
from poro2d.io_utils import read_utf8, write_texts
from poro2d.typed_result import TypedResult

#: the board's file, in its folder
BOARD_FILE = "threads-per-case"
#: least seconds between two reads of the board by one case
POLL_S = 1.0


def threads_per_case(workers: int, cases: int, cap: int) -> int:
    """Engine threads for each of ``cases`` cases left on ``workers`` cores: one while the cases
    fill the workers, else ``workers // cases``, at most ``cap`` (the partitions: no change of
    round-off beyond them)."""
    if cases >= workers:
        return 1
    return max(1, min(workers // max(cases, 1), cap))


@dataclass(frozen=True)
class ShareBoard:
    """Where the driver posts the threads per case and the cases read them (a folder's file)."""

    folder: str

    def post(self, threads: int) -> None:
        write_texts(self.folder, [(BOARD_FILE, f"{int(threads)}\n")])

    def read(self) -> int | None:
        """The posted count; None when the board cannot be read (gone at the end of the run)."""
        try:
            return int(read_utf8("threads board", Path(self.folder) / BOARD_FILE, "a count").strip())
        except (InputError, ValueError):
            return None


@contextmanager
def share_board() -> Iterator[ShareBoard]:
    """A board in a new private temporary folder, removed with it at the end."""
    folder = tempfile.mkdtemp(prefix="poro2d-cores-")
    try:
        board = ShareBoard(folder)
        board.post(1)
        yield board
    finally:
        shutil.rmtree(folder, ignore_errors=True)


class OtherLoad:
    """The cores that other processes of this machine kept busy since the last look.

    The machine's busy CPU time less this process's own, over the wall time between two
    looks (psutil's counters; None where they cannot be read: then nothing is held back).
    """

    def __init__(self) -> None:
        self.last = self.sample()

    @staticmethod
    def sample() -> tuple[float, float, float] | None:
        """(wall, the machine's busy CPU seconds, this process's CPU seconds), or None."""
        try:
            import psutil

            cpu, own = psutil.cpu_times(), psutil.Process().cpu_times()
        except Exception:  # noqa: BLE001 - no psutil, or no counters on this system
            return None
        busy = sum(cpu) - cpu.idle - getattr(cpu, "iowait", 0.0)
        return time.monotonic(), busy, own.user + own.system

    def cores(self) -> float | None:
        """Other processes' busy cores since the last call (None: unknown)."""
        now, last = self.sample(), self.last
        self.last = now
        if now is None or last is None or now[0] <= last[0]:
            return None
        return max((now[1] - last[1]) - (now[2] - last[2]), 0.0) / (now[0] - last[0])


def free_cores_allow(posted: int, others: float | None, cores: int) -> int:
    """The threads a case takes of the ``posted`` ones when other processes keep ``others`` of the
    machine's ``cores`` busy: a thread without a free core waits for its partner at every step
    of the engine, and two threads on a shared, loaded core ran at 0.4-0.7 of one thread
    (benchmarks/README.md), so only threads with a core of their own are taken."""
    if others is None:
        return posted
    return max(1, min(posted, int(cores - others + 0.25)))


class ThreadLender:
    """A case's view of the board: the posted threads, read again at most every ``POLL_S``, and
    only as many as the machine has free cores for (:func:`free_cores_allow`)."""

    def __init__(self, board: ShareBoard) -> None:
        self.board = board
        self.threads = 1
        self.read_at = -float("inf")
        self.load = OtherLoad()
        self.cores = os.cpu_count() or 1

    def __call__(self) -> int:
        now = time.monotonic()
        if now - self.read_at >= POLL_S:
            self.read_at = now
            others = self.load.cores()
            posted = self.board.read()
            if posted is not None:
                self.threads = free_cores_allow(posted, others, self.cores)
        return self.threads


@dataclass(eq=False)
class WorkerUse(TypedResult):
    """How a run's workers were used (``worker_use`` of a sweep's summary, of ``sand.json``).

    ``workers``: the cores the cases ran on (the worker processes, at most the machine's cores);
    ``cases``: the cases that ran;
    ``cases_per_worker``: how many each worker ran, by worker; ``threads_over_time``: the
    engine threads offered to each running case, as ``[seconds from the start, cases left,
    threads per case]`` at each change; ``busy_core_s``: the core-time the cases took (their
    time on one thread, and what their threads beyond one took: a case smaller than the
    engine's ``parallel_min_particles``, or on a machine whose other programs hold the cores,
    takes fewer than offered); ``idle_core_s``: the rest of the workers' core-time over the
    run's wall time ``wall_s``.
    """

    workers: int
    cases: int
    cases_per_worker: dict[str, int]
    threads_over_time: list[list[float]]
    wall_s: float
    busy_core_s: float
    idle_core_s: float


def use_text(use: WorkerUse) -> str:
    """One line of a run's worker use: ``6 cases on 2 workers (3 + 3), threads per case 1 -> 2,
    core-time idle 35 s of 420 s``."""
    threads = [int(t) for _, _, t in use.threads_over_time]
    seen = [t for k, t in enumerate(threads) if k == 0 or t != threads[k - 1]]
    counts = " + ".join(str(n) for n in use.cases_per_worker.values())
    return (
        f"{use.cases} case(s) on {use.workers} worker(s) ({counts}), threads per case "
        f"{' -> '.join(map(str, seen)) or '1'}, core-time idle {use.idle_core_s:.0f} s of "
        f"{use.workers * use.wall_s:.0f} s"
    )


class CoreClock:
    """The driver's account of the cores: the cases left and the threads posted, over time."""

    def __init__(self, workers: int, cases: int, cap: int, board: ShareBoard | None = None) -> None:
        self.workers, self.cases, self.cap, self.board = workers, cases, cap, board
        self.t0 = time.perf_counter()
        self.left = cases
        self.steps: list[list[float]] = []
        self.since = self.t0
        self._post()

    def _threads(self) -> int:
        return threads_per_case(self.workers, self.left, self.cap) if self.board is not None else 1

    def _post(self) -> None:
        threads = self._threads()
        if self.board is not None and (not self.steps or self.steps[-1][2] != threads):
            self.board.post(threads)
        if not self.steps or self.steps[-1][1:] != [self.left, threads]:
            self.steps.append([round(self.since - self.t0, 3), self.left, threads])

    def note(self) -> str:
        """The progress line's note: the threads per case, once more than one."""
        threads = self._threads()
        return f"{threads} threads per case" if threads > 1 else ""

    def case_ended(self) -> None:
        """One case fewer: the cores of its worker go to the cases left."""
        self.since = time.perf_counter()
        self.left = max(self.left - 1, 0)
        self._post()

    def use(self, rows: list) -> WorkerUse:
        """The record of the run so far; ``rows``: the row of each case that ran (its ``worker``, or
        ``host`` and ``pid``; its ``time_s`` and the ``lent_core_s`` its threads beyond one took)."""
        self.since = time.perf_counter()
        wall = self.since - self.t0
        per_worker: dict[str, int] = {}
        busy = 0.0
        for r in rows:
            w = r.worker or f"{r.host}:{r.pid}"
            per_worker[w] = per_worker.get(w, 0) + 1
            busy += (r.time_s or 0.0) + float(r.extra.get("lent_core_s") or 0.0)
        return WorkerUse(self.workers, len(rows), per_worker, self.steps, wall, busy,
                         max(self.workers * wall - busy, 0.0))  # fmt: skip


__all__ = [
    "CoreClock",
    "ShareBoard",
    "OtherLoad",
    "ThreadLender",
    "WorkerUse",
    "free_cores_allow",
    "share_board",
    "threads_per_case",
    "use_text",
]
