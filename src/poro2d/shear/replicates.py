"""Direct shear on replicate specimens: strengths over seeds, a fit with confidence intervals.

A granular specimen's peak strength carries round-off chaos: two specimens that differ
only in their seed (or in round-off) give peaks a few kPa apart, and a friction angle
from one specimen is one sample. Here the same tests run on several specimens (one per
seed); per normal stress the peak strength is reported as mean +- sd over the seeds, and
the Mohr-Coulomb line is fitted to every (sigma, tau) point, with Student-t confidence
intervals of phi and c (and of phi through the origin). All tests of all specimens run
in one process pool, so both cores stay busy.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from poro2d.errors import InputError, check_range
from poro2d.execute import RunOptions
from poro2d.io_utils import Provenance
from poro2d.shear.box_dominated import box_dominated_count
from poro2d.shear.fit import mohr_coulomb
from poro2d.shear.parts import FitInterval, StressPeaks
from poro2d.shear.pool import ShearJob
from poro2d.shear.results import ReplicateShearResult, ShearSeriesResult, ShearTestResult
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store
from poro2d.typed_result import part


def mohr_coulomb_ci(sigma_kpa, tau_kpa, through_origin: bool = False, level: float = 0.95) -> FitInterval:
    """The least-squares Mohr-Coulomb line with ``level`` confidence intervals of phi and c.

    Intervals from the slope's and intercept's standard errors and Student's t with
    n - 2 degrees of freedom (n - 1 through the origin); phi's interval is the arctangent
    of the slope's. ``None`` intervals when the points leave no degree of freedom.
    """
    from scipy import stats

    level = check_range("confidence level", level, 0.0, 1.0, lo_open=True, hi_open=True)
    s = np.asarray(sigma_kpa, float).ravel()
    t = np.asarray(tau_kpa, float).ravel()
    fit = mohr_coulomb(s, t, through_origin=through_origin)
    df = s.size - (1 if through_origin else 2)
    out = FitInterval(**fit.to_dict(), level=level, dof=df)
    if df < 1:
        return out
    resid = t - fit.predict(s)
    s2 = float(np.sum(resid**2)) / df
    q = float(stats.t.ppf(0.5 + 0.5 * level, df))
    if through_origin:
        se_slope = math.sqrt(s2 / float(np.dot(s, s)))
    else:
        sxx = float(np.sum((s - s.mean()) ** 2))
        se_slope = math.sqrt(s2 / sxx)
        se_c = math.sqrt(s2 * (1.0 / s.size + s.mean() ** 2 / sxx))
        out.cohesion_ci_kpa = [fit.cohesion_kpa - q * se_c, fit.cohesion_kpa + q * se_c]
    lo, hi = fit.tan_phi - q * se_slope, fit.tan_phi + q * se_slope
    out.friction_angle_ci_deg = [math.degrees(math.atan(lo)), math.degrees(math.atan(hi))]
    return out


def summarize_replicate_peaks(
    series: dict[str, ShearSeriesResult], level: float = 0.95
) -> ReplicateShearResult:
    """Per normal stress mean +- sd of the peaks over specimens, pooled fits with intervals.

    ``series``: label -> the result of one :class:`ShearSeries` (its ``tests`` list). The
    summary's run fields (wall time, processes, config, provenance) are left for the caller.
    """
    if not series:
        raise InputError("replicates", 0, "at least one specimen's tests")
    series = {label: part(ShearSeriesResult, res) for label, res in series.items()}  # a dict read back, too
    by_sigma: dict[float, list[float]] = {}
    for res in series.values():
        for t in res.tests:
            by_sigma.setdefault(float(t.normal_stress_kpa), []).append(float(t.peak_shear_stress_kpa))
    rows = []
    for sig in sorted(by_sigma):
        v = np.array(by_sigma[sig])
        rows.append(StressPeaks(
            normal_stress_kpa=sig,
            peak_mean_kpa=float(v.mean()),
            peak_sd_kpa=float(v.std(ddof=1)) if v.size > 1 else 0.0,
            n=int(v.size),
            peaks_kpa=v.tolist(),
        ))  # fmt: skip
    sig = np.concatenate([[r.normal_stress_kpa] * r.n for r in rows])
    tau = np.concatenate([r.peaks_kpa for r in rows])
    phis = [r.friction_angle_deg for r in series.values() if r.friction_angle_deg is not None]
    return ReplicateShearResult(
        specimens=list(series),
        per_normal_stress=rows,
        fit=mohr_coulomb_ci(sig, tau, level=level) if np.unique(sig).size >= 2 else None,
        fit_through_origin=mohr_coulomb_ci(sig, tau, through_origin=True, level=level),
        friction_angle_per_specimen_deg=phis,
        friction_angle_mean_deg=float(np.mean(phis)) if phis else None,
        friction_angle_sd_deg=float(np.std(phis, ddof=1)) if len(phis) > 1 else None,
        method="peaks of every specimen pooled; Student-t intervals of the least-squares line",
        box_dominated_tests=box_dominated_count([t for r in series.values() for t in r.tests]),
    )


class ReplicateShear:
    """The same direct shear tests on several specimens, in one process pool, then the summary.

    ``specimens``: the specimens by label (a :class:`~poro2d.specimen.specimen_set.SpecimenSet`;
    each read once, here or in its series when the set is not read yet); with ``store`` each
    specimen's tests are kept in ``<label>/`` as a :class:`ShearSeries` keeps them, and the
    summary in ``replicates.json`` and ``replicates.csv`` (``store=None``: nothing is kept).
    """

    def __init__(self, specimens: SpecimenSet, normal_stresses_kpa, settings=None, *,
                 store: Store | None = None, lab=None, options: RunOptions = RunOptions(),
                 config: dict | None = None, keep_peak: bool = True) -> None:  # fmt: skip
        from poro2d.shear.series import ShearSeries

        if not specimens:
            raise InputError("specimens", "none", "at least one specimen")
        self.store = store
        self.options = options
        self.config = config or {}
        self.series = {
            label: ShearSeries(
                specimens.specimen(label),
                normal_stresses_kpa,
                settings,
                store=store.child(label) if store is not None else None,
                lab=lab,
                options=RunOptions(workers=1, progress=False),
                config=self.config,
                keep_peak=keep_peak,
            )  # fmt: skip
            for label in specimens
        }
        njobs = sum(len(s.jobs) for s in self.series.values())
        self.processes = options.local_workers(njobs, per_core=2)

    def jobs(self) -> list[ShearJob]:
        """Every specimen's tests as pool jobs, a specimen after the other (a caller may pool several)."""
        return [replace(j, series=label) for label, s in self.series.items() for j in s.jobs]

    def run(self) -> ReplicateShearResult:
        from poro2d.shear.pool import execute_jobs

        t0 = time.perf_counter()
        return self.finish(execute_jobs(self.jobs(), self.processes, self.options), t0)

    def finish(self, results: list[ShearTestResult], t0: float) -> ReplicateShearResult:
        """Each specimen's fit and files, then the summary, from the results in the order of :meth:`jobs`."""
        per, start = {}, 0
        for label, s in self.series.items():
            per[label] = s.finish(results[start : start + len(s.jobs)], t0)
            start += len(s.jobs)
        summary = summarize_replicate_peaks(per)
        summary.wall_time_s = time.perf_counter() - t0
        summary.processes = self.processes
        summary.config = self.config
        summary.provenance = Provenance.now()
        summary.series = per
        if self.store is None:
            return summary
        self.store.write_csv("replicates.csv", [{k: v for k, v in r.to_dict().items() if k != "peaks_kpa"}
                                                for r in summary.per_normal_stress])  # fmt: skip
        self.store.write_json("replicates.json", summary.to_dict())
        return summary


__all__ = ["ReplicateShear", "mohr_coulomb_ci", "summarize_replicate_peaks"]
