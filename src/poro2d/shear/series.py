"""Direct shear tests at several normal stresses on one specimen, and the Mohr-Coulomb fit."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from poro2d.errors import InputError, check_range
from poro2d.execute import RunOptions
from poro2d.io_utils import Provenance
from poro2d.shear.box_dominated import box_dominated_count
from poro2d.shear.box_scale import box_scale
from poro2d.shear.case import ShearCase
from poro2d.shear.fit import mohr_coulomb, smooth
from poro2d.shear.outputs import folder_name, lab_fit, write_tables
from poro2d.shear.parts import (
    LabComparison,
    QuasiStatic,
    RateCheck,
    RateCheckRow,
    ShearTestSummary,
)
from poro2d.shear.pool import ShearJob, execute_jobs
from poro2d.shear.results import ShearSeriesResult, ShearTestResult
from poro2d.shear.settings import NORMAL_STRESS_RANGE_KPA, ShearSettings, half_velocity
from poro2d.specimen.saved import Specimen
from poro2d.store import Store

RATE_CHECK_NOTE = (
    "relative_change compares the smoothed peaks; mean_abs_change_before_peak the "
    "smoothed curves from half a window to the earlier of the two peaks, over the peak. "
    "Runs whose state differs only by round-off also differ by a few percent after the "
    "peak forms (the packing's trajectory is chaotic), so a peak change of that size is "
    "not by itself a rate effect; see docs/shear.md"
)


def check_stresses(normal_stresses_kpa) -> list[float]:
    """Different normal stresses (kPa) in ``NORMAL_STRESS_RANGE_KPA``, sorted."""
    lo, hi = NORMAL_STRESS_RANGE_KPA
    stresses = [check_range("normal stress (kPa)", v, lo, hi) for v in normal_stresses_kpa]
    if not stresses:
        raise InputError("normal stress", [], "at least one value (kPa)")
    if len(set(stresses)) != len(stresses):
        raise InputError("normal stress", stresses, "different values")
    return sorted(stresses)


class ShearSeries:
    """Direct shear tests at several normal stresses, in parallel processes, with the fit.

    ``specimen``: a :class:`~poro2d.specimen.saved.Specimen`, or its path (read once,
    here). With ``store`` it keeps ``result.json`` (per test and overall), ``peaks.csv``,
    ``curves.csv`` and one sub-store per test (see :class:`DirectShearTest`; Fig. 8 is drawn from
    the result by ``draw_shear_series`` (``report/shear_figures.py``)); with ``rate_check``
    every test is repeated at half the velocity under ``rate_check/`` and the change of the peak
    is reported. Finished tests are skipped on a rerun; a killed test resumes from its
    checkpoint. ``store=None``: nothing is kept.
    """

    def __init__(
        self,
        specimen: Specimen | str | Path,
        normal_stresses_kpa,
        settings: ShearSettings | None = None,
        store: Store | None = None,
        lab=None,
        rate_check: bool = False,
        rate_tolerance: float = 0.02,
        options: RunOptions = RunOptions(),
        config: dict | None = None,
        keep_peak: bool = True,
    ) -> None:
        self.specimen = Specimen.of(specimen)
        self.stresses = check_stresses(normal_stresses_kpa)
        self.settings = settings if settings is not None else ShearSettings()
        self.store = store
        self.lab = lab
        self.rate_check = bool(rate_check)
        self.rate_tolerance = check_range("rate_tolerance", rate_tolerance, 0.0, 1.0, lo_open=True)
        self.options = options
        self.config = config or {}
        self.keep_peak = keep_peak
        self.jobs = self._jobs()
        # the tests are about equally long: one process per test (up to twice the cores)
        # leaves no core idle at the end (3 tests on 2 cores take 1.5 test times, not 2)
        self.processes = options.local_workers(len(self.jobs), per_core=2)
        self._bind_tests()

    @property
    def specimen_digest(self) -> str:
        """Digest of the specimen's state (:func:`poro2d.dem.checkpoint.state_digest`)."""
        return self.specimen.digest

    def _bind_tests(self) -> None:
        """Validate every test (box size, then what each folder holds) before anything is written."""
        if self.store is None:
            return
        stages = [job.test().stage() for job in self.jobs]
        for stage in stages:
            stage.check()
        for stage in stages:
            stage.bind()

    def _folder(self, *parts: str) -> str | None:
        """The folder of a test's store, as a string a worker makes its store from."""
        return None if self.store is None else str(self.store.child(*parts).root)

    def _jobs(self) -> list[ShearJob]:
        base = ShearCase(self.specimen, self.stresses[0], self.settings)
        jobs = [
            ShearJob(("test", sig), base.at(sig), self._folder(folder_name(sig)), self.keep_peak)
            for sig in self.stresses
        ]
        if self.rate_check:  # the half is made only here: a velocity near the floor runs without it
            half = base.with_settings(velocity=half_velocity(self.settings.velocity))
            jobs += [
                ShearJob(("rate", sig), half.at(sig), self._folder("rate_check", folder_name(sig)), False)
                for sig in self.stresses
            ]
        return jobs

    def run(self) -> ShearSeriesResult:
        """Run the tests (finished ones are read back), then the fit, the tables and ``result.json``."""
        t0 = time.perf_counter()
        return self.finish(execute_jobs(self.jobs, self.processes, self.options), t0)

    # ------------------------------------------------------------------ results
    def finish(self, results: list[ShearTestResult], t0: float) -> ShearSeriesResult:
        """Fit, tables and ``result.json`` from the tests' results, in the order of :attr:`jobs`
        (a test per stress, then the rate check's reruns)."""
        n = len(self.stresses)
        tests = results[:n]
        sig = np.array([t.normal_stress_kpa for t in tests])
        tau = np.array([t.peak_shear_stress_kpa for t in tests])
        fit = mohr_coulomb(sig, tau) if len(sig) >= 2 else None
        fit0 = mohr_coulomb(sig, tau, through_origin=True)
        s = self.settings
        summary = [self._test_summary(t) for t in tests]
        result = ShearSeriesResult(
            normal_stresses_kpa=self.stresses,
            tests=summary,
            friction_angle_deg=fit.friction_angle_deg if fit else None,
            cohesion_kpa=fit.cohesion_kpa if fit else None,
            r2=fit.r2 if fit else None,
            fit=fit,
            friction_angle_through_origin_deg=fit0.friction_angle_deg,
            fit_through_origin=fit0,
            quasi_static=self._quasi_static(tests),
            peak_definition=f"maximum of the shear stress curve smoothed by a centred moving average over "
            f"{1e3 * s.peak_window:g} mm of shear displacement",
            shear_stress_definition="horizontal force of the disks on the upper half (upper walls, upper "
            "lip, top plate friction) / (W t), W the box width (no area correction)",
            settings=s,
            velocity_m_per_s=s.velocity,
            density_scale=s.density_scale,
            specimen=self.specimen.source,
            specimen_digest=self.specimen.digest,
            specimen_meta=self.specimen.extra,
            processes=self.processes,
            config=self.config,
            box_dominated_tests=box_dominated_count(summary),
        )
        width, height = self.specimen.box()
        result.box_scale = box_scale(width, height, self.specimen.arrays["particles.radius"])
        if self.rate_check:
            result.rate_check = self._rate_check(tests, results[n:], sig, fit)
        if self.lab is not None:
            result.lab = self._lab_part(fit)
        result.wall_time_s = time.perf_counter() - t0
        result.provenance = Provenance.now()
        curves = {t.normal_stress_kpa: t.curve for t in tests}
        if self.store is not None:
            write_tables(self.store, curves, summary)
            self.store.write_json("result.json", result)
        result.curves = curves
        return result

    @staticmethod
    def _test_summary(t: ShearTestResult) -> ShearTestSummary:
        """One test's line of the series' result."""
        # tests written before a test said why it ended lack ``ended_by`` (None)
        return ShearTestSummary.of(
            t, consolidation_normal_stress_error=t.consolidation.normal_stress_error,
            folder=folder_name(t.normal_stress_kpa),
        )  # fmt: skip

    def _quasi_static(self, tests: list[ShearTestResult]) -> QuasiStatic:
        s = self.settings
        # a stored infinity reads back as null (JSON has no infinity): the check failed
        max_i = max(math.inf if t.max_inertial_number is None else t.max_inertial_number for t in tests)
        return QuasiStatic(
            max_inertial_number=max_i,
            inertial_limit=s.inertial_limit,
            inertial_number_ok=max_i < s.inertial_limit,
            inertial_number_definition="I = gamma_dot d_mean sqrt(rho_s density_scale / sigma_n), "
            f"gamma_dot = v / ({s.shear_zone_factor:g} d_mean) (a thin shear zone: conservative), "
            "sigma_n the measured plate stress at each record",
        )

    def _rate_check(
        self, tests: list[ShearTestResult], halves: list[ShearTestResult], sig: np.ndarray, fit
    ) -> RateCheck:
        """How the peaks change at half the velocity (the reruns under ``rate_check/``, one per test)."""
        rows = []
        for t, h in zip(tests, halves, strict=True):
            rows.append(RateCheckRow(
                normal_stress_kpa=t.normal_stress_kpa,
                peak_kpa=t.peak_shear_stress_kpa,
                peak_half_velocity_kpa=h.peak_shear_stress_kpa,
                relative_change=h.peak_shear_stress_kpa / t.peak_shear_stress_kpa - 1.0,
                shear_displacement_at_peak_m=t.shear_displacement_at_peak_m,
                shear_displacement_at_peak_half_velocity_m=h.shear_displacement_at_peak_m,
                max_inertial_number_half_velocity=h.max_inertial_number,
                mean_abs_change_before_peak=self._pre_peak_change(t, h),
                wall_time_s=h.wall_time_s,
            ))  # fmt: skip
        worst = max(abs(r.relative_change) for r in rows)
        fit_h = mohr_coulomb(sig, [r.peak_half_velocity_kpa for r in rows]) if len(sig) >= 2 else None
        return RateCheck(
            velocity_m_per_s=self.settings.velocity,
            half_velocity_m_per_s=0.5 * self.settings.velocity,
            tests=rows,
            max_abs_relative_change=worst,
            tolerance=self.rate_tolerance,
            passed=worst < self.rate_tolerance,
            friction_angle_half_velocity_deg=fit_h.friction_angle_deg if fit_h else None,
            friction_angle_change_deg=(fit_h.friction_angle_deg - fit.friction_angle_deg)
            if (fit_h and fit)
            else None,
            max_mean_abs_change_before_peak=max(r.mean_abs_change_before_peak for r in rows),
            note=RATE_CHECK_NOTE,
        )

    def _pre_peak_change(self, t: ShearTestResult, h: ShearTestResult) -> float:
        """Mean |tau_half - tau| / tau_peak of the smoothed curves up to the earlier peak."""
        w = self.settings.peak_window
        a, b = t.curve, h.curve
        xa = a["shear_displacement_mm"] * 1e-3
        xb = b["shear_displacement_mm"] * 1e-3
        ya = smooth(xa, a["shear_stress_kpa"], w)
        yb = np.interp(xa, xb, smooth(xb, b["shear_stress_kpa"], w))
        end = min(t.shear_displacement_at_peak_m, h.shear_displacement_at_peak_m)
        m = (xa >= 0.5 * w) & (xa <= end)
        if not m.any():
            return math.nan
        return float(np.mean(np.abs(yb[m] - ya[m])) / t.peak_shear_stress_kpa)

    def _lab_part(self, fit) -> LabComparison:
        """The laboratory data, their fit and the difference of the friction angles."""
        lab = self.lab
        ls = lab.normal_stresses()
        lf = lab_fit(lab)
        return LabComparison(
            source=lab.source,
            kind=lab.kind,
            peaks=lab.peak_rows(),
            fit=lf,
            friction_angle_deg=lf.friction_angle_deg if lf else None,
            cohesion_kpa=lf.cohesion_kpa if lf else None,
            friction_angle_difference_deg=fit.friction_angle_deg - lf.friction_angle_deg
            if (fit and lf)
            else None,
            fit_through_origin=mohr_coulomb(ls, [lab.peaks[v] for v in ls], through_origin=True),
        )


__all__ = ["ShearSeries", "check_stresses"]
