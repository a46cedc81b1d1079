"""``run_critical_state``: one periodic shear run; ``run_critical_states``: its spread over seeds.

A run builds the case's cell (:mod:`poro2d.critical_state.cell`), compresses it to the
pressure, then shears it at the rate of the case's inertial number with the height servoed
to the pressure, recording a row every ``record_strain``; the steady state is read over the
window (:mod:`poro2d.critical_state.steady`). Every input is checked (the case's own
``__post_init__``) before any work. Seeds run as jobs of the one executor, on local processes.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from poro2d.critical_state.case import CriticalStateCase
from poro2d.critical_state.cell import (
    barostat_gain,
    compress,
    loose_cell,
    mean_diameter,
    mean_overlap_ratio,
    shear_rate,
)
from poro2d.critical_state.record import SERIES_CSV, folder_stage, stored_run
from poro2d.critical_state.results import (
    CriticalStateResult,
    CriticalStateTestResult,
    SeedSummary,
    Spread,
    void_ratio,
)
from poro2d.critical_state.series import COLUMNS, CellSeries, row_of
from poro2d.critical_state.steady import read_steady
from poro2d.dem.export import frame_of_cell
from poro2d.dem.reporters import Every, drive_blocks
from poro2d.errors import InputError, check_int
from poro2d.execute import Job, RunOptions
from poro2d.execute.batch import complete_jobs
from poro2d.io_utils import Provenance
from poro2d.labtest.reporters import CurveRecorder, ProgressReporter, series_reporters
from poro2d.measure.fabric import ROSE_FILE, FabricRoses, cell_fabric, cell_rose
from poro2d.store import Store, claimed

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "critical-state"
#: the most seeds one call runs
MAX_SEEDS = 50
#: the share of the progress bar the compression takes (the rest is the shear)
COMPRESS_SHARE = 0.05

Report = Callable[[str, float], None]


def _shear(
    cell, case: CriticalStateCase, rate: float, report: Report | None, store: Store | None = None
) -> tuple[CellSeries, int, int, float, FabricRoses | None]:
    """Shear to the case's strain, a row every record_strain; returns the series, steps, rebuilds,
    the mean overlap over d of the rows' ends in the steady window (a snapshot alone swings
    with the pressure's fluctuations) and the contact orientations at the largest stress ratio
    and at the end. With ``case.vtk_every`` and a ``store``, the shear's ParaView series too
    (:func:`_series`)."""
    pressure = case.pressure_kpa * 1e3
    cell.shear(rate, pressure, barostat_gain(cell, case), rate)
    per_row = max(1, round(case.record_strain / (rate * cell.dt)))
    steps = math.ceil(case.strain / (per_row * rate * cell.dt)) * per_row
    blocks, overlaps, roses, d = [], [], [], mean_diameter(cell)

    def advance(n: int) -> tuple[int, bool]:
        blocks.append(cell.run(n))
        return n, False

    sheared = _series(cell, case, per_row, store, lambda: sum(b.steps for b in blocks))

    def overlap(c) -> None:  # over the steady window's rows
        if c.strain >= case.window_start:
            overlaps.append(mean_overlap_ratio(c))

    def row(c) -> dict[str, float]:  # the fabric of the cell now, its orientations kept for the rose
        contacts = c.contacts()
        roses.append(cell_rose(contacts))
        return row_of(c.strain, blocks[-1], rate, d, case.solid_density, cell_fabric(contacts, c.n))

    recorder = CurveRecorder(per_row, row)
    share = ProgressReporter(
        per_row, report, "shear", lambda _, k: COMPRESS_SHARE + (1.0 - COMPRESS_SHARE) * k / steps
    )
    drive_blocks(advance, steps, [recorder, Every(per_row, overlap), share, *sheared], cell)
    mean = float(np.mean(overlaps)) if overlaps else mean_overlap_ratio(cell)
    series = CellSeries.of_rows(recorder.rows)
    at_peak = int(np.argmax(series.stress_ratio)) if len(roses) else 0
    fabric = FabricRoses.of("gamma", series.gamma, roses, at_peak) if roses else None
    return series, steps, sum(b.rebuilds for b in blocks), mean, fabric


def _series(cell, case: CriticalStateCase, per_row: int, store: Store | None, ran: Callable[[], int]) -> list:
    """The reporters of the shear's ParaView series: a step every ``vtk_every`` steps rounded to
    whole rows (a row is the mean of the block before it, so a block must end only at rows),
    at the shear strain gamma; ``ran()``: the steps sheared so far."""
    every = per_row * max(1, round(case.vtk_every / per_row)) if case.vtk_every else 0
    clock = lambda c: (ran(), c.time, c.strain)  # noqa: E731
    return series_reporters(every, store, "shear_strain", cell, frame_of_cell, clock)


def run_critical_state(
    case: CriticalStateCase, store: Store | None = None, *, report: Report | None = None
) -> CriticalStateTestResult:
    """One periodic shear run of ``case``: its steady state and the series.

    ``store``: where ``series.csv`` and ``result.json`` go, bound to the case by ``test.json``
    (:mod:`poro2d.critical_state.record`): a finished run of the case is read back, a folder of
    another case's run refused (None: nothing kept; the figure is drawn from the result by
    ``draw_critical_state`` (``report/critical_state_figures.py``)). ``report(phase, fraction)``:
    told how far the run is. Raises RuntimeError if the compression does not reach the pressure.
    """
    if not isinstance(case, CriticalStateCase):
        raise InputError("case", type(case).__name__, "a CriticalStateCase")
    if store is not None and not isinstance(store, Store):
        raise InputError("store", type(store).__name__, "a poro2d.store.Store or None")
    if store is None:
        return _compute(case, report)
    done = stored_run(store, case)  # a folder of another case's run is refused here, before any step
    if done is None:
        done = _compute(case, report, store)
        # the series first: the result, written by the stage, is the marker of a finished run
        store.write_csv(SERIES_CSV, done.series.rows(), header=list(COLUMNS))
        if done.roses is not None:
            store.write_result(ROSE_FILE, done.roses)
        folder_stage(store, case).run(lambda: done)
    return done


def _compute(
    case: CriticalStateCase, report: Report | None, store: Store | None = None
) -> CriticalStateTestResult:
    """Build, compress and shear the cell; read its steady state (only its ParaView series kept in
    ``store``, when the case asks for one)."""
    t0 = time.perf_counter()
    cell = loose_cell(case)
    compression = compress(
        cell, case, None if report is None else lambda f: report("compress", COMPRESS_SHARE * f)
    )
    rate = shear_rate(cell, case)
    series, steps, rebuilds, overlap, roses = _shear(cell, case, rate, report, store)
    wall = time.perf_counter() - t0
    state = read_steady(series, case.window_start, case.blocks, case.mu_drift_limit, case.solid_drift_limit)
    return CriticalStateTestResult.of(
        state,
        disks=cell.n,
        mean_diameter_m=mean_diameter(cell),
        cell_width_m=cell.width,
        cell_height_m=cell.height,
        shear_rate_per_s=rate,
        dt_s=cell.dt,
        compression_steps=compression,
        shear_steps=steps,
        rebuilds=rebuilds,
        wall_time_s=wall,
        particle_steps_per_s=cell.n * (compression + steps) / wall,
        case=case,
        provenance=Provenance.now(),
        stiffness_number=case.kappa(),
        mean_overlap_ratio=overlap,
        series=series,
        roses=roses,
    )


@dataclass(frozen=True)
class SeedJob:
    """One seed's run (a value that pickles: a worker process runs it), kept in ``store`` (None:
    nothing kept)."""

    case: CriticalStateCase
    label: str
    store: Store | None = None

    def stored(self) -> CriticalStateTestResult | None:
        """The run when its store holds it finished (read here: no process started); a folder
        holding another case's run is refused here, before any seed runs."""
        return None if self.store is None else stored_run(self.store, self.case)


def _run_job(job: SeedJob, report) -> CriticalStateTestResult:
    return run_critical_state(job.case, job.store, report=report)


@dataclass(frozen=True)
class CriticalStateStudy:
    """A critical-state study as one value, checked when made: ``case`` on ``seeds`` seeds
    (case.seed, case.seed + 1, ...)."""

    case: CriticalStateCase
    seeds: int = 3

    def __post_init__(self) -> None:
        if not isinstance(self.case, CriticalStateCase):
            raise InputError("case", type(self.case).__name__, "a CriticalStateCase")
        n = check_int("seeds", self.seeds, 1, MAX_SEEDS)
        if self.case.seed + n - 1 > 2**31 - 1:
            raise InputError("seeds", n, f"at most {2**31 - self.case.seed} from seed {self.case.seed}")

    def cases(self) -> list[CriticalStateCase]:
        """The case of each seed, in order."""
        return [self.case.with_seed(self.case.seed + k) for k in range(self.seeds)]


def run_critical_states(
    study: CriticalStateStudy,
    store: Store | None = None,
    *,
    options: RunOptions = RunOptions(),
    config: dict | None = None,
) -> CriticalStateResult:
    """The study's case on each of its seeds: each number's spread over them.

    ``store``: where ``result.json`` and ``series.csv`` (every seed's rows) go, and each seed's
    run as it finishes, in ``seed<N>/`` (a rerun after a kill reads the finished seeds back);
    ``options``: where the seeds run (``workers`` processes, default one per seed and at most
    one per core, or a running ``scheduler``) and whether bars show. Several processes spawn
    workers that import the calling script: call it under
    ``if __name__ == "__main__":`` in a script.
    """
    if not isinstance(study, CriticalStateStudy):
        raise InputError("study", type(study).__name__, "a CriticalStateStudy")
    if store is not None and not isinstance(store, Store):
        raise InputError("store", type(store).__name__, "a poro2d.store.Store or None")
    with claimed(store, KIND):
        return _study(study.cases(), store, options, config)


def _study(cases, store, options, config) -> CriticalStateResult:
    t0 = time.perf_counter()
    tests, workers = seed_runs(cases, options, [seed_store(store, c) for c in cases])
    result = study_of(cases, tests, workers, time.perf_counter() - t0, config)
    if store is not None:
        write_study(store, cases, result)
    return result


def seed_runs(
    cases: list[CriticalStateCase], options: RunOptions, stores: list[Store | None]
) -> tuple[list[CriticalStateTestResult], int]:
    """Every case one job of the executor (local processes: default one per case, at most one per
    core), kept in its store of ``stores`` (None: nothing kept) where finished ones are read back;
    the results in the cases' order and the number of workers. Raises if any failed."""
    workers = options.local_workers(len(cases))
    jobs = [SeedJob(c, _label(c, cases), s) for c, s in zip(cases, stores, strict=True)]
    results = complete_jobs(
        [Job(_run_job, (job,), job.label, reports=True) for job in jobs], title="critical state",
        what="periodic shear run(s)", options=options, workers=workers, finished=[j.stored() for j in jobs],
    )  # fmt: skip
    return results, workers


def seed_store(store: Store | None, case: CriticalStateCase) -> Store | None:
    """Where a study kept in ``store`` keeps ``case``'s run: ``seed<N>/`` (None: nothing kept)."""
    return None if store is None else store.child(f"seed{case.seed}")


def _label(case: CriticalStateCase, cases: list[CriticalStateCase]) -> str:
    """``seed 3``, or ``100 kPa seed 3`` when the jobs hold several pressures."""
    several = len({c.pressure_kpa for c in cases}) > 1
    return f"{case.pressure_kpa:g} kPa seed {case.seed}" if several else f"seed {case.seed}"


def write_study(store: Store, cases: list[CriticalStateCase], result: CriticalStateResult) -> None:
    """A study's ``series.csv`` (every seed's rows), then ``result.json``."""
    rows = [{"seed": c.seed, **r} for c, t in zip(cases, result.tests, strict=True) for r in t.series.rows()]
    store.write_csv(SERIES_CSV, rows, header=["seed", *COLUMNS])
    store.write_result("result.json", result)


def study_of(cases, tests, workers, wall, config) -> CriticalStateResult:
    """The study's result from its seeds' results."""
    missed = [c.seed for c, t in zip(cases, tests, strict=True) if not t.steady]
    note = (
        "every seed reached a steady state"
        if not missed
        else (
            f"not steady for seed(s) {', '.join(map(str, missed))}: their numbers are not the critical state"
        )
    )
    summaries = [SeedSummary.of(t, seed=c.seed) for c, t in zip(cases, tests, strict=True)]
    spreads = ("stress_ratio", "friction_angle_deg", "solid_fraction", "inertial_number", "coordination")
    return CriticalStateResult(
        seeds=[c.seed for c in cases],
        **{k: Spread.of([getattr(t, k) for t in tests]) for k in (*spreads, "mean_overlap_ratio")},
        steady=not missed,
        note=note,
        summaries=summaries,
        case=cases[0],
        processes=workers,
        wall_time_s=wall,
        config=config or {},
        provenance=Provenance.now(),
        void_ratio=Spread.of([void_ratio(t.solid_fraction) for t in tests]),
        stiffness_number=cases[0].kappa(),
        contact_anisotropy=steady_anisotropy(tests, cases[0].window_start),
        tests=list(tests),
    )


def steady_anisotropy(tests: list[CriticalStateTestResult], window_start: float) -> Spread | None:
    """Each seed's mean contact anisotropy a_c over its steady window, as a spread; None when a
    series did not record it (a run of an earlier poro2d read back)."""
    means = []
    for t in tests:
        if t.series is None:
            return None
        a_c = t.series.a_c[t.series.window(window_start)]
        if not (a_c.size and np.isfinite(a_c).all()):
            return None
        means.append(float(np.mean(a_c)))
    return Spread.of(means)


__all__ = [
    "MAX_SEEDS",
    "CriticalStateStudy",
    "SeedJob",
    "run_critical_state",
    "run_critical_states",
    "seed_runs",
    "seed_store",
    "study_of",
    "write_study",
]
