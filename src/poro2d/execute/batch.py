"""``complete_jobs``: the one way a laboratory test runs its jobs on local processes (named so
because it hands back a list, not a typed result as the API's ``run_*`` do).

Every test that runs replicates, seeds or stresses in parallel does the same four things: it
reads the finished jobs back, draws a bar per job still to run, runs those on the executor's
local processes (or a running Dask scheduler), and raises once they have all ended if any
failed (an input error as it is, the others together,
:func:`poro2d.execute.jobs.results_or_raise`). Direct shear, biaxial, critical state and the
criterion's replicates call this.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from poro2d.execute.executor import Executor
from poro2d.execute.jobs import Failed, Job, results_or_raise
from poro2d.execute.options import RunOptions
from poro2d.progress import JobsProgress


def complete_jobs(
    jobs: Sequence[Job],
    *,
    title: str,
    what: str,
    options: RunOptions,
    workers: int,
    finished: Sequence[Any | None] | None = None,
    show: Callable[..., None] | None = None,
    done_text: Callable[[Any], str] | None = None,
    start_first: Callable[[Job], Any] | None = None,
) -> list:
    """The results of ``jobs`` in job order.

    ``finished``: each job's result read back (None: to run; default: every job runs);
    ``title``: the bars' heading, one bar per job to run; ``what``: how a failure counts them
    (``"biaxial test(s)"``); ``options``: where they run (``workers`` local processes, or the
    running scheduler of ``options``) and whether bars show; ``show(bars, index, phase, *rest)``:
    draws a job's live report (default: the phase and its fraction); ``done_text(result)``: the
    bar's words when a job ends (default: ``done``); ``start_first``: a sort key of the jobs'
    start order in the pool. Every job runs even when one fails; then the failures are raised.
    """
    results = list(finished) if finished is not None else [None] * len(jobs)
    todo = [k for k, res in enumerate(results) if res is None]
    if not todo:
        return results
    with JobsProgress(title, [jobs[k].label for k in todo], enabled=options.progress) as bars:

        def ended(index: int, outcome) -> None:
            if not isinstance(outcome, Failed):
                bars.done(index, *(() if done_text is None else (done_text(outcome),)))

        report = bars.update if show is None else (lambda index, *msg: show(bars, index, *msg))
        with Executor(options.test_backend(workers)) as executor:
            outcomes = executor.map(
                [jobs[k] for k in todo], on_report=report, on_done=ended, start_first=start_first
            )
        done = results_or_raise(outcomes, what)
    for k, res in zip(todo, done, strict=True):
        results[k] = res
    return results


__all__ = ["complete_jobs"]
