"""``run_biaxial_series``: biaxial tests at several confining stresses, each on replicate specimens.

Every test of every stress is one job of the executor, so two processes stay busy over the
whole series; each finished test is read back on a rerun (:mod:`poro2d.biaxial.record`).
Per stress the files are those of :func:`poro2d.biaxial.run.run_biaxial` in a folder of their
own (``sigma3_100kPa/``); over the stresses, the pooled angles and the Mohr-Coulomb envelope
of the peak circles (:mod:`poro2d.biaxial.envelope`), one figure with every curve.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from poro2d.biaxial.angles import smoothed
from poro2d.biaxial.case import BiaxialCase
from poro2d.biaxial.envelope import envelope, peak_circle
from poro2d.biaxial.lab import LabCurve
from poro2d.biaxial.parts import (
    DEFINITIONS,
    ENVELOPE_DEFINITION,
    AngleSpread,
    Definitions,
    StressSummary,
    angle_spreads,
    spread_of,
)
from poro2d.biaxial.results import BiaxialResult, BiaxialSeriesResult, BiaxialTestResult
from poro2d.biaxial.run import (
    KIND,
    MAX_REPLICATES,
    check_run,
    execute_tests,
    lab_curve,
    replicate_cases,
    replicate_jobs,
    summarize,
    write_study,
)
from poro2d.biaxial.settings import CONFINING_RANGE_KPA
from poro2d.errors import InputError, check_int, check_range, is_number
from poro2d.execute import RunOptions
from poro2d.io_utils import Provenance
from poro2d.store import Store, claimed

#: the most confining stresses one series runs
MAX_STRESSES = 20


def stress_folder(sigma_kpa: float) -> str:
    """The folder of one confining stress in a series (``sigma3_100kPa``)."""
    return f"sigma3_{sigma_kpa:g}kPa"


def check_confining(values) -> list[float]:
    """Two or more different confining stresses (kPa) in :data:`CONFINING_RANGE_KPA`, sorted."""
    if isinstance(values, str | bytes) or not isinstance(values, Sequence) or is_number(values):
        raise InputError("confining_kpa", values, "a list of confining stresses in kPa")
    stresses = [check_range("confining stress (kPa)", v, *CONFINING_RANGE_KPA) for v in values]
    if not 2 <= len(stresses) <= MAX_STRESSES or len(set(stresses)) != len(stresses):
        raise InputError(
            "confining_kpa", stresses, f"2 to {MAX_STRESSES} different values (one stress: run_biaxial)"
        )
    return sorted(stresses)


@dataclass(frozen=True)
class BiaxialSeriesCase:
    """A biaxial series as one value, checked when made: ``case`` (its specimen and settings; its
    own sigma_3 is not used), or a list of cases, one per replicate specimen; the confining
    stresses (kPa); ``replicates`` specimens at each (quick specimens of seed, seed + 1, ...;
    1 with a list of cases); ``lab``: laboratory curves (a CSV path, read here, or a
    :class:`LabCurve`), recorded in the result."""

    case: BiaxialCase | Sequence[BiaxialCase]
    confining_kpa: Sequence[float]
    replicates: int = 1
    lab: str | os.PathLike | LabCurve | None = None

    def __post_init__(self) -> None:
        n = check_int("replicates", self.replicates, 1, MAX_REPLICATES)
        object.__setattr__(self, "confining_kpa", tuple(check_confining(self.confining_kpa)))
        cases = replicate_cases(self.case, n)
        object.__setattr__(self, "case", self.case if isinstance(self.case, BiaxialCase) else tuple(cases))
        object.__setattr__(self, "lab", lab_curve(self.lab))

    def cases(self) -> dict[float, list[BiaxialCase]]:
        """Each confining stress's replicate cases."""
        base = replicate_cases(self.case, self.replicates)
        return {s: [replace(c, confining_kpa=s) for c in base] for s in self.confining_kpa}


def run_biaxial_series(
    series: BiaxialSeriesCase,
    store: Store | None = None,
    *,
    options: RunOptions = RunOptions(),
    config: dict | None = None,
) -> BiaxialSeriesResult:
    """Biaxial tests of ``series``: its case at each of its confining stresses, on its replicates.

    ``store``: the series' ``result.json`` and per stress a folder
    (``sigma3_100kPa/``) holding what :func:`run_biaxial` keeps; a rerun into it reads finished
    tests back and runs the rest (a folder holding another test, another setting, is refused).
    None: nothing kept. ``options``: where all the tests run (``workers`` processes, default one
    per test and at most one per core, or a running ``scheduler``) and whether bars show.
    Returns the :class:`BiaxialSeriesResult` (``studies``: each stress's :class:`BiaxialResult`
    with its tests and curves). Call it under ``if __name__ == "__main__":`` in a script (the
    tests run in spawned processes).
    """
    if not isinstance(series, BiaxialSeriesCase):
        raise InputError("series", type(series).__name__, "a BiaxialSeriesCase")
    cases = series.cases()
    workers = check_run(store, options, [c for cs in cases.values() for c in cs])
    with claimed(store, KIND):
        return _run(cases, store, series.lab, workers, options, config)


def _run(cases: dict[float, list[BiaxialCase]], store, lab, workers, options, config) -> BiaxialSeriesResult:
    t0 = time.perf_counter()
    jobs = {
        s: replicate_jobs(cs, None if store is None else store.child(stress_folder(s)), f"{s:g} kPa, ")
        for s, cs in cases.items()
    }
    flat = [job for js in jobs.values() for job in js]
    tests = iter(execute_tests(flat, workers, options))
    wall = time.perf_counter() - t0
    studies = []
    for s, cs in cases.items():
        study = summarize(cs, [next(tests) for _ in cs], lab, workers, wall, config)
        if store is not None:
            write_study(store.child(stress_folder(s)), study)
        studies.append(study)
    result = summarize_series(studies, workers, time.perf_counter() - t0, config)
    if store is not None:
        store.write_result("result.json", result)
    return result


def _summary(study: BiaxialResult) -> StressSummary:
    return StressSummary.of(study, folder=stress_folder(study.confining_stress_kpa))


def sigma_3_at_peak(test: BiaxialTestResult) -> float:
    """The side walls' stress (kPa) where the peak is read, smoothed as sin(phi) is there: the
    peak's circle is the one the specimen stood on, even where the servo let sigma_3 drift."""
    c = test.curve
    if c is None:
        return test.confining_stress_kpa
    s3 = smoothed(c.axial_strain, c.sigma_3_kpa, test.settings.smoothing_strain)
    return float(np.interp(test.axial_strain_at_peak, c.axial_strain, s3))


def _held_note(tests: list[BiaxialTestResult]) -> str:
    """Whether sigma_3 stayed on its target in every test, and the worst mean error if not."""
    off = [t for t in tests if not t.checks.sigma_3_held]
    if not off:
        return "sigma_3 held in every test"
    worst = max(t.checks.sigma_3_mean_error for t in off)
    return (
        f"sigma_3 not held in {len(off)} of {len(tests)} tests (mean error up to {100 * worst:.0f} %): "
        "the side walls lag behind a dilating specimen; a larger servo_max_speed or a slower strain_rate "
        "(docs/biaxial.md)"
    )


def summarize_series(studies: list[BiaxialResult], workers: int, wall: float, config) -> BiaxialSeriesResult:
    """The series' result from each stress's study: pooled angles and the peak envelope."""
    tests = [t for st in studies for t in st.tests]
    circles = [peak_circle(sigma_3_at_peak(t), t.peak_sin_phi) for t in tests]
    s1, s3 = [c[0] for c in circles], [c[1] for c in circles]
    missed = [f"{st.confining_stress_kpa:g} kPa" for st in studies if not st.critical_state_reached]
    note = (
        "every test reached the critical state"
        if not missed
        else f"not yet at critical state in some replicate(s) at {', '.join(missed)}: their end angles are "
        "not critical-state angles (a longer --strain, or a larger specimen)"
    )
    first = studies[0]
    return BiaxialSeriesResult(
        confining_stresses_kpa=[st.confining_stress_kpa for st in studies], replicates=first.replicates,
        stresses=[_summary(st) for st in studies], **angle_spreads(tests),
        envelope=envelope(s1, s3), envelope_through_origin=envelope(s1, s3, through_origin=True),
        envelope_definition=ENVELOPE_DEFINITION, critical_state_reached=not missed, critical_state_note=note,
        sigma_3_held=all(t.checks.sigma_3_held for t in tests), sigma_3_note=_held_note(tests),
        definitions=Definitions(**DEFINITIONS), settings=first.settings, specimens=first.specimens,
        processes=workers, wall_time_s=wall, config=config or {}, provenance=Provenance.now(), lab=first.lab,
        plastic_max_dilatancy_angle=spread_of(AngleSpread, [t.plastic_max_dilatancy_angle_deg
                                                            for t in tests]),
        studies=list(studies),
    )  # fmt: skip


__all__ = [
    "MAX_STRESSES",
    "BiaxialSeriesCase",
    "check_confining",
    "run_biaxial_series",
    "stress_folder",
    "summarize_series",
]
