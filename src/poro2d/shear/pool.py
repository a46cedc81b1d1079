"""Direct shear tests on the executor's local processes, with their progress.

A job (:class:`ShearJob`) is a value that pickles: its key (what the test is: a test or a
rate check's rerun, at which stress; results come back in job order),
its case (the specimen's content travels with it: the worker reads no specimen file), the
folder its test keeps its files in (a path string: the worker makes the store from it),
whether it draws its figure and a label for progress lines. Each test is a job of the
executor's local processes (:mod:`poro2d.execute.local`: a fresh process, one numba
thread) and reports its phase there; :func:`poro2d.execute.batch.complete_jobs` reads the finished
tests back and shows a bar per test on a terminal, plain periodic lines in a log.
"""

from __future__ import annotations

from dataclasses import dataclass

from poro2d.execute import Job, RunOptions
from poro2d.execute.batch import complete_jobs
from poro2d.shear.case import ShearCase
from poro2d.shear.results import ShearTestResult
from poro2d.shear.single import DirectShearTest
from poro2d.store import Store


@dataclass(frozen=True)
class ShearJob:
    """One test of a pool: ``key`` says which (``("test", sigma)``, a rate check's ``("rate", sigma)``),
    ``folder`` names its store (None: nothing kept); ``keep_peak``: keep the state at the peak
    (:class:`~poro2d.shear.single.DirectShearTest`)."""

    key: tuple
    case: ShearCase
    folder: str | None
    keep_peak: bool = True
    series: str = ""

    @property
    def rate(self) -> bool:
        """True for a rate check's rerun at half the velocity."""
        return "rate" in self.key

    @property
    def label(self) -> str:
        """How the test is named in progress lines and errors: its normal stress, (v/2) for a rate check."""
        prefix = f"{self.series}: " if self.series else ""
        return prefix + f"{self.case.normal_stress_kpa:g} kPa" + (" (v/2)" if self.rate else "")

    def test(self, progress=None) -> DirectShearTest:
        """The job's test, on one thread."""
        store = Store(self.folder) if self.folder is not None else None
        return DirectShearTest(self.case, store, progress=progress, keep_peak=self.keep_peak, threads=1)


def _run_job(job: ShearJob, report) -> ShearTestResult:
    """Run one test (in a worker process); its phase and fraction go to ``report``."""
    return job.test(progress=report).run()


def _finished(jobs: list[ShearJob]) -> list[ShearTestResult | None]:
    """The results of the finished tests, read back (no process started), in job order; None for a
    test still to run."""
    return [job.test().stored() for job in jobs]


def _slowest_first(job: ShearJob) -> tuple:
    """The half velocity tests, then the highest stress first: the pool's workers end together."""
    return (not job.rate, -job.case.normal_stress_kpa)


def execute_jobs(jobs: list[ShearJob], processes: int, options: RunOptions) -> list[ShearTestResult]:
    """Run the tests of ``jobs`` (finished ones are read back) in up to ``processes`` processes
    (or on the running scheduler of ``options``).

    Returns their results in job order. Every test runs even when one fails; then an input
    error of a test is raised as it is, other failures together
    (:class:`poro2d.execute.JobsFailed`, each test named).
    """
    return complete_jobs(
        [Job(_run_job, (job,), job.label, reports=True) for job in jobs], title="direct shear",
        what="direct shear test(s)", options=options, workers=processes, finished=_finished(jobs),
        show=_show, start_first=lambda j: _slowest_first(j.args[0]),
    )  # fmt: skip


def _show(bars, index: int, phase: str, fraction: float) -> None:
    """A test's bar fills while it shears; its other phases show without a fraction."""
    bars.update(index, phase, fraction if phase == "shearing" else None)


__all__ = ["ShearJob", "execute_jobs"]
