"""The calibration's shear tests on the executor's Dask backend: one job per unit, the cluster started once.

The cluster is a LocalCluster of ``workers`` single-threaded processes, or a running
scheduler at ``scheduler`` (:class:`~poro2d.execute.options.RunOptions`); it starts at the first
unit that is not cached and serves both rounds.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from poro2d.calibration.units import CalibrationUnit, UnitRow, compute_unit
from poro2d.execute import Executor, Failed, Job
from poro2d.execute.options import RunOptions
from poro2d.labtest.records import ByName
from poro2d.store import Store
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class UnitFailure(ByName, TypedResult):
    """A unit whose test failed (no equilibrium): left out of the fit, and said in ``failures``; the
    unit's own values read off it by name (:meth:`~poro2d.labtest.records.ByName.of`)."""

    key: str
    sigma: float
    fp: float
    mu_r: float
    specimen: str
    error: str
    traceback: str | None


@dataclass(eq=False)
class ClusterRecord(TypedResult):
    """What is recorded of the cluster and the work (``cluster`` in ``result.json``)."""

    scheduler: str | None
    workers: int | None
    local_cluster: bool
    tests_run: int
    tests_reused: int
    tests_failed: int
    test_time_sum_s: float
    wall_time_tests_s: float


class UnitRunner:
    """Runs units on a Dask cluster started at the first unit that is not cached; ``options``: where
    the jobs run and whether bars show (:class:`~poro2d.execute.options.RunOptions`)."""

    def __init__(self, options: RunOptions) -> None:
        self.options = options
        self.executor = Executor(options.dask_backend())
        self.failures: list[UnitFailure] = []
        self.what = "shear tests"  # the kind of the units run last (their WHAT)
        self.broken: set[str] = set()  # keys of units that failed for another reason than their test
        self.ran = self.reused = 0
        self.busy_s = 0.0
        self.wall_s = 0.0

    def run(self, units: list[CalibrationUnit], cache: Store | None, label: str) -> list[UnitRow | None]:
        """The rows of ``units`` in their order (None: the test failed, said in ``failures``): read
        back when ``cache`` holds them, else run as Dask tasks."""
        from poro2d.progress import CountProgress

        rows = [unit.stored_row(cache) for unit in units]
        todo = [k for k, row in enumerate(rows) if row is None]
        for k in todo:
            units[k].check_entry(cache)  # a damaged entry is refused here, before any test runs
        cached = len(units) - len(todo)
        self.reused += cached
        if not todo:
            return rows
        t0 = time.perf_counter()
        done_before = f" ({cached} of {len(units)} cached)" if cached else ""
        try:
            self.what = units[0].WHAT  # shear or biaxial tests: one kind per calibration
            bars = self.options.progress
            with CountProgress(label + done_before, len(todo), self.what, enabled=bars) as bar:

                def ended(index: int, outcome) -> None:
                    rows[todo[index]] = self._take(units[todo[index]], outcome)
                    bar.advance(f"{len(self.failures)} failed" if self.failures else "")

                jobs = [
                    Job(compute_unit, (units[k], cache), units[k].key, key=f"calibrate-{units[k].key}")
                    for k in todo
                ]
                self.executor.map(jobs, on_done=ended)
        except KeyboardInterrupt:
            self.executor.quiet()
            raise
        finally:
            self.wall_s += time.perf_counter() - t0
        self._refuse_broken()
        return rows

    def _refuse_broken(self) -> None:
        """Refuse to go on when a unit failed for another reason than its test's outcome.

        A test that finds no equilibrium fails alike in every run (a RuntimeError, left out of
        the fit and said in ``failures``); any other error (a damaged cache entry, a lost
        worker, a full disk) would leave the fit without a value an undamaged run has.
        """
        broken = [f for f in self.failures if f.key in self.broken]
        if broken:
            f = broken[0]
            more = f" (and {len(broken) - 1} more)" if len(broken) > 1 else ""
            raise RuntimeError(
                f"the {self.what.removesuffix('s')} {f.key} ({f.specimen} at {f.sigma:g} kPa,"
                f" f_p {f.fp:g}, mu_r {f.mu_r:g})"
                f" failed on a worker{more}: {f.error}; no answer is computed without it"
            )

    def _take(self, unit: CalibrationUnit, outcome) -> UnitRow | None:
        """A unit's row; a test that fails (no equilibrium) is left out of the fit (None), and said."""
        if not isinstance(outcome, Failed):
            self.busy_s += outcome.wall_time_s
            self.ran += 1
            return outcome
        exc = outcome.error
        if type(exc) is not RuntimeError:  # not the test's own outcome (no equilibrium)
            self.broken.add(unit.key)
        error = f"{type(exc).__name__}: {exc}".splitlines()[0]
        self.failures.append(UnitFailure.of(unit, error=error, traceback=outcome.traceback))
        return None

    def info(self) -> ClusterRecord:
        """What is recorded of the cluster and the work: workers, tests run and reused, times."""
        cluster = self.executor.cluster_info()  # None: not a Dask cluster (inline, one worker)
        return ClusterRecord(
            scheduler=self.options.scheduler,
            workers=None if cluster is None else cluster.workers,
            local_cluster=False if cluster is None else cluster.local_cluster,
            tests_run=self.ran,
            tests_reused=self.reused,
            tests_failed=len(self.failures),
            test_time_sum_s=self.busy_s,
            wall_time_tests_s=self.wall_s,
        )

    def close(self) -> None:
        self.executor.close()


__all__ = ["ClusterRecord", "UnitFailure", "UnitRunner"]
