"""Direct shear tests on the executor's local processes, with their progress.

A job is a dict: ``key`` (how its result is returned), ``specimen``, ``sigma`` (kPa),
``settings`` (a :class:`ShearSettings` as a dict), ``out``, ``figures`` and optionally
``series`` (a label in progress lines). Each test is a job of the executor's local
processes (:mod:`poro2d.execute.local`: a fresh process, one numba thread) and reports its
phase there; :class:`poro2d.progress.JobsProgress` shows a bar per test on a terminal,
plain periodic lines in a log.
"""

from __future__ import annotations

from poro2d.execute import Backend, Executor, Failed, Job, results_or_raise
from poro2d.progress import JobsProgress
from poro2d.shear.settings import ShearSettings
from poro2d.shear.single import DirectShearTest


def _run_job(job: dict, report) -> dict:
    """Run one test (in a worker process); its phase and fraction go to ``report``."""
    return job_test(job, progress=report).run()


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


def _slowest_first(job: dict) -> tuple:
    """The half velocity tests, then the highest stress first: the pool's workers end together."""
    return ("rate" not in job["key"], -job["sigma"])


def execute_jobs(jobs: list[dict], processes: int, progress: bool) -> dict:
    """Run the tests of ``jobs`` (finished ones are read back) in up to ``processes`` processes.

    Returns ``{job["key"]: result}`` in job order. Every test runs even when one fails;
    then an input error of a test is raised as it is, other failures together
    (:class:`poro2d.execute.JobsFailed`, each test named).
    """
    results, todo = _finished(jobs)
    if not todo:
        return results
    names = [job_label(j) for j in todo]
    with JobsProgress("direct shear", names, enabled=progress) as bars:

        def show(index: int, phase: str, fraction: float) -> None:
            bars.update(index, phase, fraction if phase == "shearing" else None)

        def ended(index: int, outcome) -> None:
            if not isinstance(outcome, Failed):
                bars.done(index)

        outcomes = Executor(Backend.local(processes)).map(
            [Job(_run_job, (job,), name, reports=True) for job, name in zip(todo, names, strict=True)],
            on_report=show, on_done=ended, start_first=lambda j: _slowest_first(j.args[0]),
        )  # fmt: skip
        done = results_or_raise(outcomes, "direct shear test(s)")
    results.update((job["key"], res) for job, res in zip(todo, done, strict=True))
    return {j["key"]: results[j["key"]] for j in jobs}


__all__ = ["execute_jobs", "job_label", "job_test"]
