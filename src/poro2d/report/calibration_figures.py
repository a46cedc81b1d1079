"""The calibration's figures: the fit against the laboratory, and the posterior.

``calibration_fit.png`` and ``calibration_posterior.png`` of ``poro2d calibrate``, drawn from
the :class:`poro2d.calibration.run.CalibrationResult`, its posterior grid and the curves the
calibration found for its best design point (the calibration reads those from its cache).
:func:`draw_calibration` draws both, and the report, into a finished calibration's store.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib import rcParams
from matplotlib.ticker import FormatStrFormatter

from poro2d.calibration.outputs import FIT_PNG, POSTERIOR_PNG
from poro2d.report.calibration_report import write_calibration_report
from poro2d.report.figure_file import BLUE, VERMILION, new_figure, save_figure
from poro2d.store import Store


def draw_calibration(result, store: Store) -> None:
    """``calibration_fit.png``, ``calibration_posterior.png`` and the report (``calibration.md``,
    ``.html``) of a calibration just run into ``store`` (its ``drawing``: the posterior, the curves)."""
    d = result.drawing
    plot = plot_biaxial_calibration_fit if result.biaxial else plot_calibration_fit
    plot(result, d.lab, d.curves, d.nearest, store.path(FIT_PNG))
    plot_calibration_posterior(result, d.post, store.path(POSTERIOR_PNG))
    write_calibration_report(store.root, result)


def plot_calibration_fit(result, lab, curves: dict[float, list], nearest, path: str | os.PathLike) -> Path:
    """Left: laboratory peaks (and ends) against the calibrated model's; middle: the model's curves
    at the design point ``nearest`` the best parameters (``curves[sigma]``: (d, tau) per specimen)
    against the laboratory curves, or its peak as a dotted line where the laboratory gave no curve;
    right, when the dilation was fitted: the plate's rise at the end, laboratory against model (mm).

    ``result`` is a :class:`poro2d.calibration.run.CalibrationResult`, ``lab`` its laboratory data
    (one series, or repeats with ``series``: each drawn; the points are their means).
    """
    dilation = [o for o in result.posterior.observables if o.observable == "dilation"]
    if dilation:
        fig, (ax_peak, ax_curve, ax_dil) = new_figure(1, 3, figsize=(15, 4.2))
        _plot_dilation(ax_dil, dilation)
    else:
        fig, (ax_peak, ax_curve) = new_figure(1, 2, figsize=(11, 4.2))
    obs = [o for o in result.posterior.observables if o.observable == "peak"]
    s = np.array([o.normal_stress_kpa for o in obs])
    ax_peak.plot(s, [o.lab for o in obs], "ks", label="laboratory peak")
    _model_points(ax_peak, s, obs)
    ends = [o for o in result.posterior.observables if o.observable == "end"]
    if ends:
        se = [o.normal_stress_kpa for o in ends]
        ax_peak.plot(se, [o.lab for o in ends], "k^", mfc="none", label="laboratory end")
        ax_peak.plot(se, [o.model for o in ends], "v", color=BLUE, label="model end")
    ax_peak.set_xlabel("normal stress (kPa)")
    ax_peak.set_ylabel("shear stress (kPa)")
    ax_peak.set_xlim(left=0)
    ax_peak.set_ylim(bottom=0)
    ax_peak.legend(fontsize=8)
    _best_title(ax_peak, result)
    for k, sigma in enumerate(lab.normal_stresses()):
        c = _model_curves(ax_curve, k, sigma, curves, 1e3)
        for i, series in enumerate(getattr(lab, "series", (lab,))):  # every laboratory repeat
            first = k == 0 and i == 0
            if sigma in series.curves:
                d, t = series.curves[sigma]
                ax_curve.plot(d * 1e3, t, "k--", lw=1.0, label="laboratory" if first else None)
            else:
                ax_curve.axhline(series.peaks[sigma], color=c, ls=":", lw=1.0)
    _curves_axes(ax_curve, nearest, "shear displacement (mm)", "shear stress (kPa)")
    fig.tight_layout()
    return save_figure(fig, path)


def _best_title(ax, result) -> None:
    b = result.best
    ax.set_title(rf"$f_p$ = {b.particle_friction:.3g}, $\mu_r$ = {b.rolling_friction:.3g}", fontsize=10)


def _model_curves(ax, k: int, sigma: float, curves: dict[float, list], scale: float) -> str:
    """The model's curves at the ``k``-th stress ``sigma`` (x times ``scale``) in its colour, returned."""
    colors = rcParams["axes.prop_cycle"].by_key()["color"]
    c = colors[k % len(colors)]
    for j, (x, y) in enumerate(curves.get(sigma, [])):
        ax.plot(scale * x, y, color=c, lw=0.8, alpha=0.7, label=f"model {sigma:g} kPa" if j == 0 else None)
    return c


def _curves_axes(ax, nearest, xlabel: str, ylabel: str) -> None:
    """The labels, title and legend of the panel of curves at the design point ``nearest`` the best."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(
        rf"curves at the design point nearest the best ($f_p$ = {nearest.particle_friction:.3g}, "
        rf"$\mu_r$ = {nearest.rolling_friction:.3g})",
        fontsize=9,
    )
    ax.legend(fontsize=7)


def _model_points(ax, s, observed: list) -> None:
    """The calibrated model's values of ``observed`` at the stresses ``s``, with two noise sd either side."""
    ax.errorbar(
        s,
        [o.model for o in observed],
        yerr=[2 * o.noise_sd for o in observed],
        fmt="o",
        color=VERMILION,
        capsize=3,
        label=r"calibrated model (surrogate, $\pm$2 sd)",
    )


def _plot_dilation(ax, dilation: list) -> None:
    """The dilation targets (mm) against normal stress: the laboratory's and the model's (+-2 sd)."""
    s = [o.normal_stress_kpa for o in dilation]
    ax.plot(s, [o.lab for o in dilation], "ks", label="laboratory")
    _model_points(ax, s, dilation)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlim(left=0)
    ax.set_xlabel("normal stress (kPa)")
    ax.set_ylabel("plate rise at the end (mm; + dilation)")
    ax.set_title("dilation", fontsize=10)
    ax.legend(fontsize=8)


def plot_biaxial_calibration_fit(
    result, lab, curves: dict[float, list], nearest, path: str | os.PathLike
) -> Path:
    """The fit of a calibration against laboratory biaxial tests (every value dimensionless).

    Left: the peak and end stress ratios (sigma_1 - sigma_3) / (sigma_1 + sigma_3) against sigma_3,
    laboratory and calibrated model (+-2 noise sd); middle: the stress ratio against axial strain of
    the design point ``nearest`` the best (``curves[sigma]``: (axial strain, ratio) per specimen)
    with the laboratory curves (``lab``: a :class:`poro2d.biaxial.lab.LabTests`); right, when the
    laboratory gave it: the volumetric strain at the end (compression positive).
    """
    fitted = result.posterior.observables
    volumetric = [o for o in fitted if o.observable == "end_volumetric"]
    panels = 3 if volumetric else 2
    fig, axes = new_figure(1, panels, figsize=(5 * panels, 4.2))
    ax_ratio, ax_curve = axes[0], axes[1]
    for name, marker, label in (("peak_ratio", "s", "peak"), ("end_ratio", "^", "end")):
        _plot_targets(ax_ratio, [o for o in fitted if o.observable == name], marker, label)
    ax_ratio.set_ylabel(r"stress ratio $(\sigma_1 - \sigma_3) / (\sigma_1 + \sigma_3)$")
    _best_title(ax_ratio, result)
    for k, sigma in enumerate(lab.confining_stresses()):
        _model_curves(ax_curve, k, sigma, curves, 100)
        curve = lab.curves[sigma]
        ax_curve.plot(
            100 * curve.axial_strain,
            curve.stress_ratio,
            "k--",
            lw=1.0,
            label="laboratory" if k == 0 else None,
        )
    _curves_axes(ax_curve, nearest, "axial strain (%)", "stress ratio")
    if volumetric:
        _plot_targets(axes[2], volumetric, "s", "end")
        axes[2].axhline(0.0, color="0.6", lw=0.6)
        axes[2].set_ylabel("volumetric strain at the end (+ contraction)")
        axes[2].set_title("volumetric strain", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def _plot_targets(ax, observed: list, marker: str, label: str) -> None:
    """Dimensionless targets against sigma_3: the laboratory's and the model's (+-2 noise sd)."""
    if not observed:
        return
    s = [o.normal_stress_kpa for o in observed]
    ax.plot(s, [o.lab for o in observed], "k" + marker, mfc="none", label=f"laboratory {label}")
    ax.errorbar(
        s, [o.model for o in observed], yerr=[2 * o.noise_sd for o in observed],
        fmt=marker, capsize=3, label=rf"model {label} (surrogate, $\pm$2 sd)",
    )  # fmt: skip
    ax.set_xlabel(r"confining stress $\sigma_3$ (kPa)")
    ax.set_xlim(left=0)
    ax.legend(fontsize=8)


def plot_calibration_posterior(result, post, path: str | os.PathLike) -> Path:
    """The posterior density over (f_p, mu_r) with the evaluated design points, its maximum and
    the intervals of ``result`` shaded; ``post`` holds the grid (``fp_values``, ``mu_r_values``,
    ``density``), or, when the disks' stiffnesses were calibrated too, the sampler's chain
    (``chain``, ``ranges``): then a corner of pairwise marginals (:func:`plot_posterior_corner`)."""
    if getattr(post, "chain", None) is not None:
        return plot_posterior_corner(result, post, path)
    fig, ax = new_figure(figsize=(6.2, 4.8))
    fp, mu_r = post.fp_values, post.mu_r_values
    mesh = ax.pcolormesh(fp, mu_r, post.density / post.density.max(), shading="auto", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="posterior density / its maximum")
    ev = result.evaluations
    ax.plot(
        [e.particle_friction for e in ev],
        [e.rolling_friction for e in ev],
        "w.",
        ms=7,
        mec="k",
        label="evaluated design points",
    )
    b = result.best
    ax.plot(b.particle_friction, b.rolling_friction, "r*", ms=13, label="posterior maximum")
    if result.intervals.particle_friction is not None:  # None: unknown (``unidentified``)
        lo, hi = result.intervals.particle_friction
        ax.axvspan(lo, hi, color="w", alpha=0.12)
        lo, hi = result.intervals.rolling_friction
        ax.axhspan(lo, hi, color="w", alpha=0.12)
    ax.set_xscale("log")
    ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(FormatStrFormatter("%g"))
    ax.tick_params(axis="x", which="minor", labelsize=7)
    ax.set_xlabel(r"particle friction $f_p$")
    ax.set_ylabel(r"rolling friction $\mu_r$")
    ax.set_title(
        f"posterior (correlation {result.posterior.correlation:+.2f}); shaded: "
        f"{result.level:.0%} intervals" + (" (unknown: not shaded)" if result.unidentified else ""),
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    return save_figure(fig, path)


#: the label and the key in a result of each axis of a posterior (``post.ranges.axes``)
_AXES = {
    "fp": (r"particle friction $f_p$", "particle_friction"),
    "mu_r": (r"rolling friction $\mu_r$", "rolling_friction"),
    "kn": (r"disk $k_n$ (N/m)", "particle_kn"),
    "ks": (r"disk $k_s$ (N/m)", "particle_ks"),
}
#: bins per axis of the corner's histograms
CORNER_BINS = 30


def plot_posterior_corner(result, post, path: str | os.PathLike) -> Path:
    """A corner of the sampled posterior: each parameter's marginal on the diagonal (its interval of
    ``result`` shaded), each pair's joint histogram below it with the design points and the maximum.

    Drawn in design coordinates, so that the logarithmic axes (f_p, kn, ks) are evenly binned; the
    ticks are labelled in the parameters' values."""
    axes = post.ranges.axes
    d = len(axes)
    fig, grid = new_figure(d, d, figsize=(2.2 * d, 2.2 * d), squeeze=False)
    design = post.ranges.to_unit(*zip(*(e.parameters(axes) for e in result.evaluations), strict=True))
    best = post.ranges.to_unit(*(getattr(result.best, _AXES[a][1]) for a in axes))[0]
    for i in range(d):
        for j in range(d):
            ax = grid[i][j]
            if j > i:
                ax.axis("off")
            elif i == j:
                _corner_marginal(ax, result, post, axes[i])
            else:
                ax.hist2d(post.chain[:, j], post.chain[:, i], bins=CORNER_BINS, range=[[0, 1], [0, 1]],
                          cmap="viridis")  # fmt: skip
                ax.plot(design[:, j], design[:, i], "w.", ms=4, mec="k")
                ax.plot(best[j], best[i], "r*", ms=9)
                _corner_ticks(ax.set_yticks, ax.set_yticklabels, post, axes[i])
            if j <= i:  # the tick labels in the parameters' values, on the bottom row only
                _corner_ticks(ax.set_xticks, ax.set_xticklabels, post, axes[j], shown=i == d - 1)
            if i == d - 1:
                ax.set_xlabel(_AXES[axes[j]][0], fontsize=8)
            if j == 0 and i > 0:
                ax.set_ylabel(_AXES[axes[i]][0], fontsize=8)
    fig.suptitle(
        f"posterior sampled with emcee ({len(post.chain):,} samples); white: design points, red: maximum;"
        f" shaded: {result.level:.0%} intervals",
        fontsize=9,
    )
    fig.tight_layout()
    return save_figure(fig, path)


def _corner_marginal(ax, result, post, axis: str) -> None:
    """One parameter's marginal histogram, its interval shaded when known."""
    k = post.ranges.axes.index(axis)
    ax.hist(post.chain[:, k], bins=CORNER_BINS, range=(0, 1), color="0.4")
    interval = getattr(result.intervals, _AXES[axis][1])
    if interval is not None:
        lo, hi = post.ranges.to_unit(*_at_axis(result, post, axis, interval))[:, k]
        ax.axvspan(lo, hi, color=BLUE, alpha=0.2)
    ax.set_yticks([])
    ax.set_xlim(0, 1)


def _at_axis(result, post, axis: str, values) -> list:
    """Parameter columns for :meth:`to_unit` that hold ``values`` on ``axis`` (the best elsewhere)."""
    return [
        np.asarray(values, float) if a == axis else np.full(len(values), getattr(result.best, _AXES[a][1]))
        for a in post.ranges.axes
    ]


def _corner_ticks(set_ticks, set_labels, post, axis: str, shown: bool = True) -> None:
    """Ticks at 0, 1/2 and 1 of a design coordinate, labelled with the parameter's values there
    (``shown`` False: unlabelled)."""
    ticks = np.array([0.0, 0.5, 1.0])
    set_ticks(ticks)
    labels = [f"{v:.3g}" for v in post.ranges.axis_values(axis, ticks)] if shown else [""] * len(ticks)
    set_labels(labels, fontsize=7)


__all__ = [
    "draw_calibration",
    "plot_calibration_fit",
    "plot_calibration_posterior",
    "plot_posterior_corner",
]
