"""How strength depends on the micro-parameters: direct shear over a grid of (mu_r, f_p), over seeds.

Every case (a rolling friction mu_r and a particle friction f_p) runs the same direct shear
tests on every replicate specimen (:class:`poro2d.shear.replicates.ReplicateShear`), and all
tests of all cases share one process pool. Each test's folder is bound to its specimen,
normal stress and settings (``test.json``): a rerun reads finished tests back and resumes a
killed one, and a folder of other settings is refused. Per case the study reports:

* peak friction angle: the Mohr-Coulomb line (with cohesion) through each specimen's peaks,
  mean and sd over the specimens, and the pooled fit over all peaks with its interval;
* residual friction angle: per test the mean shear stress over the mean measured normal stress
  over the last ``RESIDUAL_FRACTION`` of the shear displacement, and per specimen the line
  through the origin fitted to those (sigma, tau) points;
* dilation: per test the largest mean slope of the plate rise over a ``peak_window`` of
  shear displacement, as an angle psi_max = atan(max d(dy) / d(dx)).

The tests run to the full displacement (``stop_after_peak = 0``) so every curve has the same
residual window. docs/shear.md ("Strength against mu_r and f_p") has the measured numbers.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from poro2d.errors import InputError, check_range
from poro2d.execute import RunOptions
from poro2d.io_utils import Provenance
from poro2d.shear.box_scale import box_scale
from poro2d.shear.case import ShearCase
from poro2d.shear.fit import mohr_coulomb
from poro2d.shear.parts import StrengthCase, StrengthDefinitions
from poro2d.shear.replicates import ReplicateShear, mohr_coulomb_ci
from poro2d.shear.residual import TAIL_FRACTION, dilation_stopped_residual
from poro2d.shear.results import ReplicateShearResult, StrengthResult
from poro2d.shear.settings import MAX_FRICTION, MAX_ROLLING_FRICTION, ShearSettings
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store

#: the part of each test's shear displacement, at its end, that the residual strength averages
RESIDUAL_FRACTION = TAIL_FRACTION
#: the quick study: the paper's quick specimen sheared over a fifth of its 80 mm width (16 mm, about
#: 4.6 d50): over 8 mm the curves with rolling resistance were still rising at the end (docs/shear.md)
QUICK_STRENGTH_SHEAR = {"max_displacement": 0.016, "stop_after_peak": 0.0}
QUICK_MU_R = (0.0, 0.1, 0.2, 0.4)
QUICK_FRICTION = (0.5, 3.0)
QUICK_NORMAL_STRESSES = (50.0, 100.0, 200.0)
QUICK_SEEDS = 3


def case_label(mu_r: float, friction: float) -> str:
    """The folder of a case: ``mur0.1_fp3``."""
    return f"mur{mu_r:g}_fp{friction:g}"


def check_grid(name: str, values, hi: float) -> list[float]:
    """Different values in [0, hi], sorted; at least one."""
    out = [check_range(name, v, 0.0, hi) for v in values]
    if not out:
        raise InputError(name, [], "at least one value")
    if len(set(out)) != len(out):
        raise InputError(name, out, "different values")
    return sorted(out)


# ---------------------------------------------------------------------- per test
def residual_point(curve: Mapping[str, np.ndarray]) -> tuple[float, float]:
    """(mean normal stress, mean shear stress) in kPa over the last RESIDUAL_FRACTION of the curve."""
    x = curve["shear_displacement_mm"]
    tail = x >= (1.0 - RESIDUAL_FRACTION) * x[-1]
    return float(curve["normal_stress_kpa"][tail].mean()), float(curve["shear_stress_kpa"][tail].mean())


def max_dilation_angle(curve: Mapping[str, np.ndarray], window_m: float) -> float:
    """atan of the largest mean slope of the plate rise over ``window_m`` of shear displacement (deg).

    The slope is the secant (dy(x + w/2) - dy(x - w/2)) / w, for every recorded x at least half
    a window from the ends: the plate's record is a jittery servo signal whose step-to-step
    slope is noise, and a moving average of a curve sampled at a fixed interval does not cure
    it (the window holds one sample more or less from row to row).
    """
    x = curve["shear_displacement_mm"] * 1e-3
    dy = curve["plate_displacement_mm"] * 1e-3
    centre = x[(x >= x[0] + 0.5 * window_m) & (x <= x[-1] - 0.5 * window_m)]
    if centre.size == 0:  # a curve shorter than the window: its overall slope
        return math.degrees(math.atan(float((dy[-1] - dy[0]) / (x[-1] - x[0]))))
    rise = np.interp(centre + 0.5 * window_m, x, dy) - np.interp(centre - 0.5 * window_m, x, dy)
    return math.degrees(math.atan(float(rise.max() / window_m)))


# ---------------------------------------------------------------------- per case
def _mean_sd(values: list[float]) -> tuple[float, float | None]:
    v = np.asarray(values, float)
    return float(v.mean()), (float(v.std(ddof=1)) if v.size > 1 else None)


def case_summary(rep: ReplicateShear, summary: ReplicateShearResult, mu_r: float, friction: float,
                 window_m: float, d_mean_m: Mapping[str, float]
                 ) -> tuple[StrengthCase, list[dict]]:  # fmt: skip
    """One case's row (means and spreads over the specimens) and its rows of ``strength_tests.csv``.

    ``d_mean_m``: each specimen's mean disk diameter by label (the residual stretch's length).
    """
    tests = []
    per_specimen = []
    for label, res in summary.series.items():
        res_pts = []
        psis = []
        for t in res.tests:
            sigma = t.normal_stress_kpa
            curve = res.curves[sigma]
            s_res, tau_res = residual_point(curve)
            psi = max_dilation_angle(curve, window_m)
            stopped = dilation_stopped_residual(curve, d_mean_m[label])
            res_pts.append((s_res, tau_res))
            psis.append(psi)
            tests.append({
                "mu_r": mu_r, "particle_friction": friction, "specimen": label, "normal_stress_kpa": sigma,
                "peak_shear_stress_kpa": t.peak_shear_stress_kpa,
                "peak_stress_ratio": t.peak_stress_ratio,
                "residual_normal_stress_kpa": s_res, "residual_shear_stress_kpa": tau_res,
                "residual_stress_ratio": tau_res / s_res, "max_dilation_angle_deg": psi,
                "end_shear_displacement_m": t.end_shear_displacement_m,
                "residual_dilation_stopped_ratio": stopped.stress_ratio,
                "residual_dilation_stopped_plane_ratio": stopped.plane_stress_ratio,
                "residual_dilation_stopped_from_mm": stopped.start_mm if stopped.reached else None,
                "stiffness_number": t.stiffness_number,
                "mean_overlap_ratio_at_peak": t.mean_overlap_ratio_at_peak,
            })  # fmt: skip
        s, tau = np.array(res_pts).T
        per_specimen.append({
            "peak": res.friction_angle_deg,
            "residual": mohr_coulomb(s, tau, through_origin=True).friction_angle_deg,
            "dilation": float(np.mean(psis)),
        })  # fmt: skip
    spread = {}  # each angle's mean and sd over the specimens, by its name in the file
    for key, name in (("peak", "peak_friction_angle"), ("residual", "residual_friction_angle"),
                      ("dilation", "max_dilation_angle")):  # fmt: skip
        values = [p[key] for p in per_specimen if p[key] is not None]
        spread[f"{name}_mean_deg"], spread[f"{name}_sd_deg"] = _mean_sd(values) if values else (None, None)
    pooled = summary.fit
    res_fit = mohr_coulomb_ci(
        [r["residual_normal_stress_kpa"] for r in tests], [r["residual_shear_stress_kpa"] for r in tests],
        through_origin=True,
    )  # fmt: skip
    row = StrengthCase(
        mu_r=mu_r,
        particle_friction=friction,
        specimens=len(per_specimen),
        **spread,
        peak_friction_angle_pooled_deg=pooled.friction_angle_deg if pooled else None,
        peak_friction_angle_pooled_ci_deg=pooled.friction_angle_ci_deg if pooled else None,
        cohesion_pooled_kpa=pooled.cohesion_kpa if pooled else None,
        residual_friction_angle_pooled_deg=res_fit.friction_angle_deg,
        residual_friction_angle_pooled_ci_deg=res_fit.friction_angle_ci_deg,
        residual_stress_ratio_mean=float(np.mean([r["residual_stress_ratio"] for r in tests])),
        **dilation_stopped_means(tests),
        **stiffness_extent(tests),
    )
    return row, tests


def stiffness_extent(tests: list[dict]) -> dict:
    """A case's kappa over its tests, lowest and highest, and its largest mean overlap / d at a
    peak (absent when its tests did not record them)."""
    kappa = [t["stiffness_number"] for t in tests if t.get("stiffness_number") is not None]
    overlap = [
        t["mean_overlap_ratio_at_peak"] for t in tests if t.get("mean_overlap_ratio_at_peak") is not None
    ]
    out = {}
    if kappa:
        out["stiffness_number_min"], out["stiffness_number_max"] = float(min(kappa)), float(max(kappa))
    if overlap:
        out["mean_overlap_ratio_at_peak_max"] = float(max(overlap))
    return out


def dilation_stopped_means(tests: list[dict]) -> dict:
    """A case's mean residual tau/sigma where dilation stopped, on the plate and on the plane, over
    the tests that reached it (None when none did), and how many did."""
    plate = [
        r["residual_dilation_stopped_ratio"]
        for r in tests
        if r["residual_dilation_stopped_ratio"] is not None
    ]
    plane = [r["residual_dilation_stopped_plane_ratio"] for r in tests
             if r["residual_dilation_stopped_plane_ratio"] is not None]  # fmt: skip
    return {
        "residual_dilation_stopped_ratio_mean": float(np.mean(plate)) if plate else None,
        "residual_dilation_stopped_plane_ratio_mean": float(np.mean(plane)) if plane else None,
        "tests_dilation_stopped": len(plate),
    }


# ---------------------------------------------------------------------- the study
def read_specimens(specimens: SpecimenSet, normal_stresses_kpa, settings: ShearSettings) -> SpecimenSet:
    """The specimens read (each once, for every case) and checked with every stress as a test would
    take them, before any case binds a folder.

    A case's series writes its tests' records as it is built, so a bad second specimen found
    while building the cases would leave the first one's folders behind.
    """
    if not specimens:
        raise InputError("specimens", "none", "at least one specimen")
    found = specimens.read()
    for value in found.contents():
        for sigma in normal_stresses_kpa:
            ShearCase(value, sigma, settings)  # checks only
    return found


class StrengthStudy:
    """Direct shear over the grid ``mu_r`` x ``friction`` on every specimen, in one process pool.

    ``specimens``: the replicate specimens by label (read once here); ``settings``: the shear
    settings every case starts from (its ``particle_friction`` and ``rolling_friction`` are
    the case's). With ``store`` it keeps ``<case>/`` (a :class:`ReplicateShear` each),
    ``strength.csv`` (one row per case), ``strength_tests.csv`` (one per test),
    ``strength.json`` and ``fig_strength.png`` (``store=None``: nothing is kept).
    """

    def __init__(self, specimens: SpecimenSet, mu_r, friction, normal_stresses_kpa,
                 settings: ShearSettings | None = None, *, store: Store | None = None,
                 options: RunOptions = RunOptions(), config: dict | None = None) -> None:  # fmt: skip
        self.mu_r = check_grid("mu_r", mu_r, MAX_ROLLING_FRICTION)
        self.friction = check_grid("particle friction", friction, MAX_FRICTION)
        base = settings if settings is not None else ShearSettings()
        self.settings = base
        values = read_specimens(specimens, normal_stresses_kpa, base)
        scales = [box_scale(*v.box(), v.arrays["particles.radius"]) for v in values.contents()]
        self.box_scale = min(scales, key=lambda b: b.width_over_d_max)
        self.d_mean_m = {
            label: float(2.0 * np.mean(v.arrays["particles.radius"]))
            for label, v in zip(values, values.contents(), strict=True)
        }
        self.store = store
        self.options = options
        self.config = config or {}
        self.cases = {
            (m, f): ReplicateShear(
                values,
                normal_stresses_kpa,
                replace(base, rolling_friction=m, particle_friction=f),
                store=store.child(case_label(m, f)) if store is not None else None,
                options=RunOptions(progress=False),
                config=self.config,
                keep_peak=False,
            )  # fmt: skip
            for m in self.mu_r
            for f in self.friction
        }
        njobs = sum(len(rep.jobs()) for rep in self.cases.values())
        self.processes = options.local_workers(njobs, per_core=2)

    def run(self) -> StrengthResult:
        from poro2d.shear.pool import execute_jobs

        t0 = time.perf_counter()
        jobs = [replace(j, series=f"{case_label(*case)} {j.series}")
                for case, rep in self.cases.items() for j in rep.jobs()]  # fmt: skip
        results = execute_jobs(jobs, self.processes, self.options)  # in job order: a case after the other
        rows, tests, start = [], [], 0
        for case, rep in self.cases.items():
            count = len(rep.jobs())
            summary = rep.finish(results[start : start + count], t0)
            start += count
            row, case_tests = case_summary(rep, summary, *case, self.settings.peak_window, self.d_mean_m)
            rows.append(row)
            tests += case_tests
        result = StrengthResult(
            cases=rows,
            mu_r=self.mu_r,
            particle_friction=self.friction,
            specimens=list(next(iter(self.cases.values())).series),
            settings=self.settings,
            definitions=StrengthDefinitions.from_dict(DEFINITIONS),
            wall_time_s=time.perf_counter() - t0,
            processes=self.processes,
            config=self.config,
            provenance=Provenance.now(),
            box_scale=self.box_scale,
        )
        if self.store is not None:
            self._write(self.store, result, tests)
        return result

    @staticmethod
    def _write(store: Store, result: StrengthResult, tests: list[dict]) -> None:
        """The study's tables and ``strength.json`` (its figure is drawn from the result:
        ``draw_strength`` (``report/strength_figure.py``))."""
        rows = result.cases
        store.write_csv("strength_tests.csv", tests)
        store.write_csv("strength.csv", [{k: v for k, v in r.to_dict().items() if not k.endswith("_ci_deg")}
                                         for r in rows])  # fmt: skip
        store.write_result("strength.json", result)


DEFINITIONS = {
    "peak_friction_angle": "Mohr-Coulomb line (with cohesion) through one specimen's smoothed peaks over the "
    "normal stresses; mean and sd over the specimens; pooled: one line through every specimen's peaks, "
    "95 % Student-t interval",
    "residual_friction_angle": f"per test mean shear stress / mean measured normal stress over the last "
    f"{RESIDUAL_FRACTION:.0%} of the shear displacement; per specimen atan of the slope of the line "
    "through the origin fitted to those points; mean and sd over the specimens",
    "max_dilation_angle": "per test atan of the largest mean slope of the plate rise over peak_window of "
    "shear displacement (a secant); per specimen the mean over the normal stresses",
}


__all__ = ["RESIDUAL_FRACTION", "StrengthStudy", "case_label", "max_dilation_angle", "residual_point"]
