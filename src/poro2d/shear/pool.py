"""Direct shear tests in a process pool, with their progress.

A job is a dict: ``key`` (how its result is returned), ``specimen``, ``sigma`` (kPa),
``settings`` (a :class:`ShearSettings` as a dict), ``out``, ``figures`` and optionally
``series`` (a label in progress lines). Each test runs in its own process (the spawn
start method) with one numba thread, and reports its phase through a queue; a progress
bar per test on a terminal, plain periodic lines in a log.
"""

from __future__ import annotations

import time

from poro2d.errors import InputError
from poro2d.shear.settings import ShearSettings
from poro2d.shear.single import DirectShearTest

#: seconds between two progress messages of one test (phase changes are sent at once)
REPORT_INTERVAL_S = 0.5


def _run_job(job: dict, queue=None) -> dict:
    """Run one test (in a worker process); progress goes to ``queue`` as (key, phase, fraction)."""
    last = [0.0, ""]

    def report(phase: str, fraction: float) -> None:
        now = time.monotonic()
        if queue is not None and (now - last[0] > REPORT_INTERVAL_S or phase != last[1] or fraction >= 1.0):
            last[0], last[1] = now, phase
            queue.put((job["key"], phase, fraction))

    res = job_test(job, progress=report).run()
    if queue is not None:
        queue.put((job["key"], "done", 1.0))
    return res


def job_label(job: dict) -> str:
    """How a test is named in progress lines and errors: its normal stress, (v/2) for a rate check."""
    prefix = f"{job['series']}: " if job.get("series") else ""
    return prefix + f"{job['sigma']:g} kPa" + (" (v/2)" if "rate" in job["key"] else "")


def job_test(job: dict, specimen_digest: str | None = None, progress=None) -> DirectShearTest:
    """The test of ``job``, on one thread (``specimen_digest``: when the caller has hashed the specimen)."""
    return DirectShearTest(
        job["specimen"], job["sigma"], ShearSettings(**job["settings"]), out=job["out"], progress=progress,
        figures=job.get("figures", True), threads=1, specimen_digest=specimen_digest,
    )  # fmt: skip


def _finished(jobs: list[dict]) -> tuple[dict, list[dict]]:
    """Results of the finished tests (read back, no process started) and the jobs still to run."""
    from poro2d.dem.checkpoint import state_digest

    results: dict = {}
    todo = []
    digests: dict[str, str] = {}  # each specimen hashed once
    for job in jobs:
        if job["specimen"] not in digests:
            digests[job["specimen"]] = state_digest(job["specimen"])
        done = job_test(job, digests[job["specimen"]]).stored()
        if done is not None:
            results[job["key"]] = done
        else:
            todo.append(job)
    return results, todo


def _run_here(todo: list[dict], bar: _Bars | None, results: dict) -> dict:
    """The tests one after the other in this process; returns the errors by job key."""
    errors: dict = {}
    for job in todo:
        try:
            results[job["key"]] = _run_job(job, _DirectQueue(bar))
        except Exception as exc:  # noqa: BLE001 - reported with the test it belongs to
            errors[job["key"]] = exc
    return errors


def _run_in_pool(todo: list[dict], n: int, bar: _Bars | None, results: dict) -> dict:
    """The tests in ``n`` worker processes; returns the errors by job key."""
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    errors: dict = {}
    ctx = mp.get_context("spawn")
    with ctx.Manager() as manager, ProcessPoolExecutor(max_workers=n, mp_context=ctx) as pool:
        queue = manager.Queue()
        # the slow (half velocity) tests first, so the pool ends together
        order = sorted(todo, key=lambda j: ("rate" not in j["key"], -j["sigma"]))
        futs = {pool.submit(_run_job, job, queue): job["key"] for job in order}
        pending = set(futs)
        while pending:
            finished, pending = wait(pending, timeout=0.25, return_when=FIRST_COMPLETED)
            _drain(queue, bar)
            for f in finished:
                try:
                    results[futs[f]] = f.result()
                except Exception as exc:  # noqa: BLE001
                    errors[futs[f]] = exc
        _drain(queue, bar)
    return errors


def execute_jobs(jobs: list[dict], processes: int, progress: bool) -> dict:
    """Run the tests of ``jobs`` (finished ones are read back) in up to ``processes`` processes.

    Returns ``{job["key"]: result}``; the slow (half velocity) tests start first so the pool
    ends together. An input error of a test is raised as it is; other failures together.
    """
    results, todo = _finished(jobs)
    if not todo:
        return results
    n = min(processes, len(todo))
    labels = {j["key"]: job_label(j) for j in todo}
    bar = _Bars(labels) if progress else None
    try:
        errors = _run_here(todo, bar, results) if n <= 1 else _run_in_pool(todo, n, bar, results)
    finally:
        if bar is not None:
            bar.stop()
    if errors:
        key, exc = next(iter(errors.items()))
        if isinstance(exc, InputError):
            raise exc
        msgs = "; ".join(f"{labels[k]}: {e}" for k, e in errors.items())
        raise RuntimeError(f"{len(errors)} direct shear test(s) failed: {msgs}")
    return results


class _Bars:
    """One rich progress bar per test, with elapsed time and ETA, on a terminal.

    In a log (stderr not a terminal) one plain line for all tests instead, at most every
    ``LINE_INTERVAL_S`` seconds and once at the end, e.g.
    ``direct shear: 50 kPa done; 100 kPa shearing 42 %; 200 kPa consolidating; elapsed 0:03:10``.
    """

    def __init__(self, labels: dict) -> None:
        from rich.progress import (
            BarColumn,
            Progress,
            TaskProgressColumn,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        from poro2d.progress import ProgressLines, live_console

        self._state = {k: [v, "waiting", 0.0] for k, v in labels.items()}  # label, phase, fraction
        self._t0 = time.perf_counter()
        console = live_console()
        self._lines = ProgressLines() if console is None else None
        if self._lines is not None:
            return
        self._p = Progress(
            TextColumn("[bold]{task.description}"), BarColumn(), TaskProgressColumn(),
            TextColumn("{task.fields[phase]}"), TimeElapsedColumn(), TextColumn("eta"), TimeRemainingColumn(),
            console=console,
        )  # fmt: skip
        self._tasks = {k: self._p.add_task(v, total=1.0, phase="waiting") for k, v in labels.items()}
        self._p.start()

    def update(self, key, phase: str, fraction: float) -> None:
        state = self._state.get(key)
        if state is None:
            return
        state[1] = phase
        if phase in ("shearing", "done"):
            state[2] = 1.0 if phase == "done" else fraction
        if self._lines is not None:
            self._lines.write(self.line(), state=self._news())
        elif phase == "shearing":
            self._p.update(self._tasks[key], completed=fraction, phase=phase)
        elif phase == "done":
            self._p.update(self._tasks[key], completed=1.0, phase="done")
        else:
            self._p.update(self._tasks[key], phase=phase)

    def line(self) -> str:
        """Every test's phase (and how far it has sheared) on one line."""
        from poro2d.progress import clock_text

        tests = "; ".join(
            f"{label} {phase}" + (f" {100.0 * frac:.0f} %" if phase == "shearing" else "")
            for label, phase, frac in self._state.values()
        )
        return f"direct shear: {tests}; elapsed {clock_text(time.perf_counter() - self._t0)}"

    def _news(self) -> tuple:
        """What a line reports, as printed (not the clock)."""
        return tuple((phase, round(100.0 * frac)) for _label, phase, frac in self._state.values())

    def stop(self) -> None:
        if self._lines is not None:
            self._lines.write(self.line(), force=True, state=self._news())
        else:
            self._p.stop()


class _DirectQueue:
    """A stand-in for the process queue when the tests run in this process."""

    def __init__(self, bar: _Bars | None) -> None:
        self.bar = bar

    def put(self, item) -> None:
        if self.bar is not None:
            self.bar.update(*item)


def _drain(queue, bar: _Bars | None) -> None:
    import queue as _q

    while True:
        try:
            item = queue.get_nowait()
        except (_q.Empty, EOFError, OSError):
            return
        if bar is not None:
            bar.update(*item)


__all__ = ["execute_jobs", "job_label", "job_test"]
