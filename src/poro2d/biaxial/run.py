"""``run_biaxial``: biaxial tests on replicate specimens and the spread of their angles.

Everything is checked before the first test starts; bad input raises
:class:`poro2d.errors.InputError` naming the parameter. The replicates run as jobs of the
executor (:mod:`poro2d.execute`), one per specimen, on local processes.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass

from poro2d.biaxial.case import BiaxialCase
from poro2d.biaxial.curve import CURVE_COLUMNS, OPTIONAL_COLUMNS
from poro2d.biaxial.lab import LabCurve, read_lab_curve
from poro2d.biaxial.parts import (
    DEFINITIONS,
    AngleSpread,
    BiaxialTestSummary,
    Definitions,
    angle_spreads,
    spread_of,
)
from poro2d.biaxial.record import folder_stage
from poro2d.biaxial.results import BiaxialResult, BiaxialTestResult
from poro2d.biaxial.single import BiaxialTest, check_quasi_static
from poro2d.errors import InputError, check_int
from poro2d.execute import Job, RunOptions
from poro2d.execute.batch import complete_jobs
from poro2d.io_utils import Provenance
from poro2d.measure.spread import Spread
from poro2d.store import Store, claimed

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "biaxial"

#: the most replicates one call runs
MAX_REPLICATES = 50


@dataclass(frozen=True)
class BiaxialJob:
    """One replicate: its case, and the folder its files go to (a path string; None: nothing kept)."""

    case: BiaxialCase
    folder: str | None
    label: str

    def test(self, report=None) -> BiaxialTest:
        store = Store(self.folder) if self.folder is not None else None
        return BiaxialTest(self.case, store, progress=report)

    def run(self, report) -> BiaxialTestResult:
        return self.test(report).run()

    def stored(self) -> BiaxialTestResult | None:
        """The test's result when its folder holds it finished (read here: no process started).

        A folder holding another test is refused here, before any test of the study runs."""
        test = self.test()
        if test.store is not None:
            folder_stage(test.store, self.case).check()
        return test.stored()


def _run_job(job: BiaxialJob, report) -> BiaxialTestResult:
    """Run one replicate (in a worker process); its phase and fraction go to ``report``."""
    return job.run(report)


def replicate_cases(case, replicates: int) -> list[BiaxialCase]:
    """One case per replicate: ``case`` and its quick specimen's next seeds, or the given cases."""
    if isinstance(case, BiaxialCase):
        return [case.replicate(k) for k in range(replicates)]
    if isinstance(case, Sequence) and not isinstance(case, str | bytes) and case:
        cases = list(case)
        if not all(isinstance(c, BiaxialCase) for c in cases):
            raise InputError("case", [type(c).__name__ for c in cases], "BiaxialCase values")
        if replicates != 1:
            raise InputError("replicates", replicates, "1 with a list of cases (each case is a replicate)")
        if len({c.confining_kpa for c in cases}) != 1:
            raise InputError("case", [c.confining_kpa for c in cases], "cases at one confining stress")
        return cases
    raise InputError("case", type(case).__name__, "a BiaxialCase or a list of them (one per replicate)")


def lab_curve(value) -> LabCurve | None:
    """Laboratory curves as given, read from a CSV path, or None."""
    if value is None or isinstance(value, LabCurve):
        return value
    if isinstance(value, str | os.PathLike):
        return read_lab_curve(value)
    raise InputError("lab", type(value).__name__, "a laboratory CSV path, a LabCurve or None")


def check_run(store, options: RunOptions, cases: list[BiaxialCase]) -> int:
    """``store`` and every case's strain rate checked, before any file or progress line; the worker
    processes (default one per test, at most one per core)."""
    if store is not None and not isinstance(store, Store):
        raise InputError("store", type(store).__name__, "a poro2d.store.Store or None")
    for case in cases:
        check_quasi_static(case)
    return options.local_workers(len(cases))


def run_biaxial(
    case: BiaxialCase | Sequence[BiaxialCase],
    store: Store | None = None,
    *,
    replicates: int = 1,
    lab: str | os.PathLike | LabCurve | None = None,
    options: RunOptions = RunOptions(),
    config: dict | None = None,
) -> BiaxialResult:
    """Biaxial tests of ``case`` on ``replicates`` specimens (quick specimens of seed, seed + 1, ...).

    ``case``: a :class:`BiaxialCase`, or a list of them, one per replicate specimen (then
    ``replicates`` stays 1). ``store``: where the files go (``result.json``, ``curves.csv``,
    and per replicate ``replicate<k>/result.json`` and ``curve.csv``; the figure, ``biaxial.png``,
    is drawn from the result by ``draw_biaxial`` (``report/biaxial_figures.py``)); None:
    nothing is kept. ``lab``: a laboratory CSV of the user's (:mod:`poro2d.biaxial.lab`),
    recorded in the result. ``options``: where the tests run (``workers`` processes, default one
    per replicate and at most one per core, or a running ``scheduler``) and whether bars show.
    ``config``: recorded as it is.

    Returns the :class:`BiaxialResult`: the spread of each angle over the replicates, and each
    replicate's result with its curve (``tests``). A test whose consolidation does not reach
    equilibrium raises RuntimeError once the others have ended. Replicates on several
    processes spawn them, which import the calling script: call this under
    ``if __name__ == "__main__":`` in a script.
    """
    n = check_int("replicates", replicates, 1, MAX_REPLICATES)
    cases = replicate_cases(case, n)
    lab_data = lab_curve(lab)
    workers = check_run(store, options, cases)
    with claimed(store, KIND):
        return _run(cases, store, lab_data, workers, options, config)


def execute_tests(jobs: list[BiaxialJob], workers: int, options: RunOptions) -> list[BiaxialTestResult]:
    """The tests of ``jobs`` in job order: finished ones read back, the others run on up to
    ``workers`` processes (a test that fails raises once the others have ended)."""
    finished = [job.stored() for job in jobs]
    return complete_jobs(
        [Job(_run_job, (job,), job.label, reports=True) for job in jobs], title="biaxial",
        what="biaxial test(s)", options=options, workers=min(workers, max(1, finished.count(None))),
        finished=finished,
    )  # fmt: skip


def replicate_jobs(cases: list[BiaxialCase], store: Store | None, label: str = "") -> list[BiaxialJob]:
    """One job per replicate case, kept in ``store``'s ``replicate<k>`` (None: nothing kept)."""
    return [
        BiaxialJob(c, None if store is None else str(store.child(f"replicate{k + 1}").root),
                   f"{label}replicate {k + 1}")
        for k, c in enumerate(cases)
    ]  # fmt: skip


def _run(cases, store, lab, workers, options, config) -> BiaxialResult:
    t0 = time.perf_counter()
    tests = execute_tests(replicate_jobs(cases, store), workers, options)
    result = summarize(cases, tests, lab, workers, time.perf_counter() - t0, config)
    if store is not None:
        write_study(store, result)
    return result


def summarize(cases, tests, lab, workers, wall, config) -> BiaxialResult:
    """The study's result from its replicates' results."""
    missed = [k + 1 for k, t in enumerate(tests) if not t.critical_state_reached]
    note = (
        "every replicate reached the critical state"
        if not missed
        else f"not yet at critical state in replicate(s) {', '.join(map(str, missed))}: their end angles are "
        "not critical-state angles (a longer --strain, or a larger specimen)"
    )
    summaries = [
        BiaxialTestSummary.of(t, replicate=k + 1, sigma_3_max_error=t.checks.sigma_3_max_error)
        for k, t in enumerate(tests)
    ]
    return BiaxialResult(
        confining_stress_kpa=cases[0].confining_kpa, replicates=len(tests), **angle_spreads(tests),
        axial_strain_at_peak=AngleSpread.of([t.axial_strain_at_peak for t in tests]),
        critical_state_reached=not missed, critical_state_note=note, summaries=summaries,
        definitions=Definitions(**DEFINITIONS), settings=cases[0].settings,
        specimens=[c.specimen.source for c in cases], processes=workers, wall_time_s=wall,
        config=config or {}, provenance=Provenance.now(), lab=lab,
        plastic_max_dilatancy_angle=spread_of(AngleSpread, [t.plastic_max_dilatancy_angle_deg
                                                            for t in tests]),
        stiffness_number=spread_of(Spread, [t.stiffness_number for t in tests]),
        mean_overlap_ratio_at_peak=spread_of(Spread, [t.mean_overlap_ratio_at_peak for t in tests]),
        tests=list(tests),
    )  # fmt: skip


def write_study(store: Store, result: BiaxialResult) -> None:
    """``curves.csv`` (every replicate's rows), then ``result.json``."""
    rows = []
    for k, t in enumerate(result.tests):
        rows += [{"replicate": k + 1, **r} for r in t.curve.rows()]
    columns = [
        k for k in (*CURVE_COLUMNS, *OPTIONAL_COLUMNS) if any(k in t.curve.columns for t in result.tests)
    ]
    store.write_csv("curves.csv", rows, header=["replicate", *columns])  # a column a test lacks stays empty
    store.write_result("result.json", result)


__all__ = [
    "BiaxialJob",
    "MAX_REPLICATES",
    "check_run",
    "execute_tests",
    "lab_curve",
    "replicate_cases",
    "replicate_jobs",
    "run_biaxial",
    "summarize",
    "write_study",
]
