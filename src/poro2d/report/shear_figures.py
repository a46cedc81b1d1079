"""Direct shear figures in the style of the paper's Fig. 8.

(a) shear stress against shear displacement, one curve per normal stress (the
vertical plate displacement below); (b) peak strength against normal stress with
the Mohr-Coulomb line(s). Laboratory data, when given, are drawn as open markers
and dashed lines. The ``draw_*`` functions draw them, and each test's force chains at its
peak, from a finished run's result and the data files its store keeps.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from poro2d.report.figure_file import BLUISH_GREEN, PALETTE, VERMILION, new_figure, save_figure
from poro2d.report.force_chains import plot_force_chains
from poro2d.shear.fit import mohr_coulomb
from poro2d.shear.lab import LabData
from poro2d.shear.outputs import lab_fit
from poro2d.shear.peak_frame import PeakFrame
from poro2d.shear.results import ReplicateShearResult, ShearSeriesResult, ShearTestResult
from poro2d.shear.shear_stage import PEAK_FRAME
from poro2d.store import Store

#: the colours of the normal stresses (or series), in turn
COLORS = list(PALETTE)
#: the axes' labels of the curves
TAU_LABEL = r"shear stress $\tau$ (kPa)"
DILATION_LABEL = "vertical plate\ndisplacement $u_y$ (mm)\n(+ = dilation)"


def draw_peak_forces(store: Store) -> None:
    """``forces_peak.png`` of a finished test, from the state its run kept at the smoothed peak
    (``peak_frame.npz``, removed once drawn: the figure is what the folder keeps of it)."""
    frame = PeakFrame.load(store, PEAK_FRAME)
    test = store.read_result("result.json", ShearTestResult.from_dict) if frame is not None else None
    if test is None:
        return
    b = test.consolidation.box
    plot_force_chains(
        frame.contacts, frame.pos, frame.radius, frame.walls, store.path("forces_peak.png"),
        thickness=frame.thickness, box=(-0.02 * b.width, 0.0, b.width + b.max_displacement, b.height),
        title=rf"direct shear at $\sigma'_n$ = {test.normal_stress_kpa:g} kPa, at the peak: "
              f"$u_x$ = {frame.displacement_mm:.2f} mm",
        notes=[rf"$\tau_{{peak}}$ = {test.peak_shear_stress_kpa:.1f} kPa (smoothed over "
               f"{1e3 * test.settings.peak_window:g} mm)"],
    )  # fmt: skip
    store.remove(PEAK_FRAME)


def draw_shear_series(result: ShearSeriesResult, store: Store, lab: LabData | None = None) -> None:
    """Each test's ``forces_peak.png``, then ``fig8a_shear_curves.png`` (curves, peaks marked) and
    ``fig8b_peak_strength.png`` (the fits); ``lab``: the laboratory data the series was given."""
    for t in result.tests:
        draw_peak_forces(store.child(t.folder))
    tests, s = result.tests, result.settings
    sig, tau = [t.normal_stress_kpa for t in tests], [t.peak_shear_stress_kpa for t in tests]
    peaks = {t.normal_stress_kpa: (t.shear_displacement_at_peak_m, t.peak_shear_stress_kpa) for t in tests}
    plot_shear_curves(
        result.curves, store.path("fig8a_shear_curves.png"), lab=lab, peaks=peaks,
        smoothing_note=f"$v$ = {1e3 * s.velocity:g} mm/s; peaks (dots) smoothed over "
                       f"{1e3 * s.peak_window:g} mm",
    )  # fmt: skip
    plot_peak_strength(
        sig, tau, mohr_coulomb(np.array(sig), np.array(tau)) if len(sig) >= 2 else None,
        store.path("fig8b_peak_strength.png"), lab=lab, lab_fit=lab_fit(lab),
        fit_origin=mohr_coulomb(np.array(sig), np.array(tau), through_origin=True),
    )  # fmt: skip


def draw_replicate_shear(result: ReplicateShearResult, store: Store, lab: LabData | None = None) -> None:
    """Every specimen's figures in its folder, then Fig. 8 over the specimens: mean curves with
    +- sd bands, peaks with the pooled fit."""
    for label, series in result.series.items():
        draw_shear_series(series, store.child(label), lab)
    bands = {r.normal_stress_kpa: curve_band([s.curves[r.normal_stress_kpa] for s in result.series.values()])
             for r in result.per_normal_stress}  # fmt: skip
    plot_replicate_curves(bands, store.path("fig8a_shear_curves_replicates.png"), len(result.series), lab=lab)
    peaks_png = store.path("fig8b_peak_strength_replicates.png")
    plot_replicate_peaks(result, peaks_png, lab=lab, lab_fit=lab_fit(lab))


def plot_shear_curves(
    curves: dict[float, dict[str, np.ndarray]],
    path: str | os.PathLike,
    lab=None,
    peaks: dict[float, tuple[float, float]] | None = None,
    title: str = "Direct shear: shear stress - shear displacement",
    smoothing_note: str = "",
) -> Path:
    """Fig. 8(a). ``curves[sigma]`` has arrays ``shear_displacement_mm``, ``shear_stress_kpa``
    and optionally ``plate_displacement_mm``; ``peaks[sigma] = (d_m, tau_kpa)`` are marked;
    ``lab`` is a :class:`poro2d.shear.lab.LabData`."""
    dil = any(PLATE in c for c in curves.values())
    fig, axes = _curves_figure(dil)
    ax = axes[0]
    for k, sigma in enumerate(sorted(curves)):
        c = curves[sigma]
        col = COLORS[k % len(COLORS)]
        ax.plot(c["shear_displacement_mm"], c["shear_stress_kpa"], color=col, lw=1.2,
                label=rf"DEM, $\sigma'_n$ = {sigma:g} kPa")  # fmt: skip
        if peaks and sigma in peaks:
            d, t = peaks[sigma]
            ax.plot([1e3 * d], [t], marker="o", color=col, ms=6, mec="k", zorder=5)
        if dil and PLATE in c:
            axes[1].plot(c["shear_displacement_mm"], c[PLATE], color=col, lw=1.0)
    if lab is not None and lab.curves:
        sig_sorted = sorted(curves)
        for sigma in sorted(lab.curves):
            d, t = lab.curves[sigma]
            k = (
                sig_sorted.index(sigma)
                if sigma in sig_sorted
                else len(sig_sorted) + sorted(lab.curves).index(sigma)
            )
            ax.plot(1e3 * d, t, ls="--", marker="o", mfc="none", ms=3, color=COLORS[k % len(COLORS)],
                    lw=1.0, label=rf"lab, $\sigma'_n$ = {sigma:g} kPa")  # fmt: skip
    ax.set_ylabel(TAU_LABEL)
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=8, ncol=2)
    ttl = title + (f"\n{smoothing_note}" if smoothing_note else "")
    ax.set_title(ttl, fontsize=10)
    return _finish_curves(fig, axes, dil, path)


def plot_peak_strength(
    sigma_kpa,
    peak_kpa,
    fit,
    path: str | os.PathLike,
    fit_origin=None,
    lab=None,
    lab_fit=None,
    title: str = "Direct shear: peak strength - normal stress",
) -> Path:
    """Fig. 8(b): DEM peaks, the least-squares Mohr-Coulomb line (angle in the legend),
    optionally the line through the origin and the laboratory points with their line."""
    s = np.asarray(sigma_kpa, float)
    t = np.asarray(peak_kpa, float)
    fig, ax = new_figure(figsize=(6.5, 5.0))
    smax = float(max(s.max(), max(lab.peaks) if lab is not None else 0.0)) * 1.1
    xs = np.linspace(0.0, smax, 50)
    ax.plot(s, t, "o", color=VERMILION, ms=7, mec="k", label="DEM peaks", zorder=5)
    if fit is not None:
        ax.plot(xs, fit.predict(xs), color=VERMILION, lw=1.4,
                label=rf"DEM: $\varphi$ = {fit.friction_angle_deg:.1f}°, $c$ = {fit.cohesion_kpa:.1f} kPa, "
                      f"$R^2$ = {fit.r2:.3f}")  # fmt: skip
    if fit_origin is not None:
        ax.plot(xs, fit_origin.predict(xs), color=VERMILION, lw=1.0, ls=":",
                label=rf"DEM, $c$ = 0: $\varphi$ = {fit_origin.friction_angle_deg:.1f}°")  # fmt: skip
    return _finish_peaks(fig, ax, xs, smax, lab, lab_fit, title, path)


def _finish_peaks(fig, ax, xs, smax: float, lab, lab_fit, title: str, path) -> Path:
    """Laboratory peaks and line (when given), axes, legend and title of a Fig. 8(b); saves it."""
    if lab is not None:
        ls = sorted(lab.peaks)
        ax.plot(
            ls,
            [lab.peaks[v] for v in ls],
            "s",
            mfc="none",
            mec=BLUISH_GREEN,
            ms=7,
            mew=1.5,
            label="lab peaks",
        )
        if lab_fit is not None:
            ax.plot(xs, lab_fit.predict(xs), color=BLUISH_GREEN, lw=1.2, ls="--",
                    label=rf"lab: $\varphi$ = {lab_fit.friction_angle_deg:.1f}°, "
                          f"$c$ = {lab_fit.cohesion_kpa:.1f} kPa")  # fmt: skip
    ax.set_xlim(0, smax)
    ax.set_ylim(bottom=0)
    ax.set_xlabel(r"normal stress $\sigma'_n$ (kPa)")
    ax.set_ylabel(r"peak shear stress $\tau_{peak}$ (kPa)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


@dataclass(frozen=True)
class CurveBand:
    """The mean shear stress curve over specimens with its sd, on a common displacement grid, and
    the mean vertical plate displacement with its sd (None when a curve lacks it)."""

    shear_displacement_mm: np.ndarray
    mean_kpa: np.ndarray
    sd_kpa: np.ndarray
    plate_mean_mm: np.ndarray | None = None
    plate_sd_mm: np.ndarray | None = None


def curve_band(curves: list[dict[str, np.ndarray]], points: int = 200) -> CurveBand:
    """Mean and sd over specimens of shear stress curves (and of the plate's displacement, when
    every curve has it), on their common displacement range."""
    end = min(float(c["shear_displacement_mm"][-1]) for c in curves)
    x = np.linspace(0.0, end, points)
    tau = _mean_sd(curves, x, "shear_stress_kpa")
    plate = _mean_sd(curves, x, PLATE) if all(PLATE in c for c in curves) else (None, None)
    return CurveBand(x, *tau, *plate)


#: the curve's column of the vertical plate displacement (+ = dilation)
PLATE = "plate_displacement_mm"


def _mean_sd(
    curves: list[dict[str, np.ndarray]], x: np.ndarray, column: str
) -> tuple[np.ndarray, np.ndarray]:
    """Mean and sample sd over ``curves`` of ``column`` interpolated at ``x`` (sd 0 for one curve)."""
    ys = np.array([np.interp(x, c["shear_displacement_mm"], c[column]) for c in curves])
    sd = ys.std(axis=0, ddof=1) if len(curves) > 1 else np.zeros_like(x)
    return ys.mean(axis=0), sd


def plot_replicate_curves(
    bands: dict[float, CurveBand], path: str | os.PathLike, n_specimens: int, lab=None
) -> Path:
    """Fig. 8(a) over specimens: the mean curve per normal stress with a band of one sd either side,
    and below it the dilation panel (the mean vertical plate displacement against the shear
    displacement, with its band) when the curves hold it."""
    dil = all(b.plate_mean_mm is not None for b in bands.values())
    fig, axes = _curves_figure(dil)
    ax = axes[0]
    for k, sigma in enumerate(sorted(bands)):
        b, col = bands[sigma], COLORS[k % len(COLORS)]
        _band(
            ax,
            b.shear_displacement_mm,
            b.mean_kpa,
            b.sd_kpa,
            col,
            rf"DEM, $\sigma'_n$ = {sigma:g} kPa (mean)",
        )
        if dil:
            _band(axes[1], b.shear_displacement_mm, b.plate_mean_mm, b.plate_sd_mm, col, None)
    if lab is not None and lab.curves:
        for k, sigma in enumerate(sorted(lab.curves)):
            d, t = lab.curves[sigma]
            ax.plot(1e3 * d, t, ls="--", marker="o", mfc="none", ms=3, color=COLORS[k % len(COLORS)],
                    lw=1.0, label=rf"lab, $\sigma'_n$ = {sigma:g} kPa")  # fmt: skip
    ax.set_ylabel(TAU_LABEL)
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=8, ncol=2)
    ax.set_title(rf"Direct shear over {n_specimens} specimens: mean and $\pm$ sd band", fontsize=10)
    return _finish_curves(fig, axes, dil, path)


def _curves_figure(dil: bool):
    """The axes of a Fig. 8(a): shear stress, and the dilation panel below it when ``dil``."""
    fig, axes = new_figure(
        2 if dil else 1, 1, figsize=(7.5, 7.0 if dil else 4.8), sharex=True,
        gridspec_kw={"height_ratios": [2.2, 1]} if dil else None, squeeze=False,
    )  # fmt: skip
    return fig, list(axes[:, 0])


def _band(ax, x, mean, sd, colour: str, label: str | None) -> None:
    ax.plot(x, mean, color=colour, lw=1.4, label=label)
    ax.fill_between(x, mean - sd, mean + sd, color=colour, alpha=0.2, lw=0)


def _finish_curves(fig, axes: list, dil: bool, path) -> Path:
    """Grids, the dilation panel's labels and the shared displacement axis of a Fig. 8(a); saves it."""
    for a in axes:
        a.grid(alpha=0.3)
    if dil:
        axes[1].set_ylabel(DILATION_LABEL)
        axes[1].axhline(0.0, color="k", lw=0.5)
    axes[-1].set_xlabel(r"shear displacement $u_x$ (mm)")
    axes[-1].set_xlim(left=0)
    fig.tight_layout()
    return save_figure(fig, path)


def plot_replicate_peaks(summary, path: str | os.PathLike, lab=None, lab_fit=None) -> Path:
    """Fig. 8(b) over specimens: peaks mean +- sd, every specimen's peaks, the pooled fit."""
    rows = summary.per_normal_stress
    s = np.array([r.normal_stress_kpa for r in rows])
    fig, ax = new_figure(figsize=(6.5, 5.0))
    smax = float(max(s.max(), max(lab.peaks) if lab is not None else 0.0)) * 1.1
    xs = np.linspace(0.0, smax, 50)
    for r in rows:
        ax.plot([r.normal_stress_kpa] * r.n, r.peaks_kpa, ".", color="0.55", ms=5, zorder=3)
    ax.errorbar(s, [r.peak_mean_kpa for r in rows], yerr=[r.peak_sd_kpa for r in rows], fmt="o",
                color=VERMILION, mec="k", ms=7, capsize=4, zorder=5,
                label=rf"DEM peaks, mean $\pm$ sd over {len(summary.specimens)} specimens")  # fmt: skip
    for fit, ls in ((summary.fit, "-"), (summary.fit_through_origin, ":")):
        if fit is None:
            continue
        tan = math.tan(math.radians(fit.friction_angle_deg))
        ci = fit.friction_angle_ci_deg
        txt = f" [{ci[0]:.1f}, {ci[1]:.1f}]" if ci else ""
        c = f", $c$ = {fit.cohesion_kpa:.1f} kPa" if not fit.through_origin else ", $c$ = 0"
        ax.plot(xs, fit.cohesion_kpa + tan * xs, color=VERMILION, lw=1.3 if ls == "-" else 1.0, ls=ls,
                label=rf"$\varphi$ = {fit.friction_angle_deg:.1f}°{txt} ({fit.level:.0%}){c}")  # fmt: skip
    title = "Direct shear: peak strength over specimens"
    return _finish_peaks(fig, ax, xs, smax, lab, lab_fit, title, path)


__all__ = [
    "COLORS",
    "CurveBand",
    "curve_band",
    "draw_peak_forces",
    "draw_replicate_shear",
    "draw_shear_series",
    "plot_peak_strength",
    "plot_replicate_curves",
    "plot_replicate_peaks",
    "plot_shear_curves",
]
