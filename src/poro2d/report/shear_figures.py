"""Direct shear figures in the style of the paper's Fig. 8.

(a) shear stress against shear displacement, one curve per normal stress (the
vertical plate displacement below); (b) peak strength against normal stress with
the Mohr-Coulomb line(s). Laboratory data, when given, are drawn as open markers
and dashed lines.
"""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from poro2d.io_utils import atomic_path  # noqa: E402

_COLORS = ["#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#666666"]


def _save(fig, path: str | os.PathLike) -> Path:
    path = Path(path)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=150, format=path.suffix.lstrip(".") or "png")
    plt.close(fig)
    return path


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
    dil = any("plate_displacement_mm" in c for c in curves.values())
    fig, axes = plt.subplots(
        2 if dil else 1, 1, figsize=(7.5, 7.0 if dil else 4.8), sharex=True,
        gridspec_kw={"height_ratios": [2.2, 1]} if dil else None, squeeze=False,
    )  # fmt: skip
    ax = axes[0, 0]
    for k, sigma in enumerate(sorted(curves)):
        c = curves[sigma]
        col = _COLORS[k % len(_COLORS)]
        ax.plot(c["shear_displacement_mm"], c["shear_stress_kpa"], color=col, lw=1.2,
                label=f"DEM, {sigma:g} kPa")  # fmt: skip
        if peaks and sigma in peaks:
            d, t = peaks[sigma]
            ax.plot([1e3 * d], [t], marker="o", color=col, ms=6, mec="k", zorder=5)
        if dil:
            axes[1, 0].plot(c["shear_displacement_mm"], c["plate_displacement_mm"], color=col, lw=1.0)
    if lab is not None and lab.curves:
        sig_sorted = sorted(curves)
        for sigma in sorted(lab.curves):
            d, t = lab.curves[sigma]
            k = (
                sig_sorted.index(sigma)
                if sigma in sig_sorted
                else len(sig_sorted) + sorted(lab.curves).index(sigma)
            )
            ax.plot(1e3 * d, t, ls="--", marker="o", mfc="none", ms=3, color=_COLORS[k % len(_COLORS)],
                    lw=1.0, label=f"lab, {sigma:g} kPa")  # fmt: skip
    ax.set_ylabel("shear stress (kPa)")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    ttl = title + (f"\n{smoothing_note}" if smoothing_note else "")
    ax.set_title(ttl, fontsize=10)
    if dil:
        axes[1, 0].set_ylabel("plate displacement (mm)\n(+ = dilation)")
        axes[1, 0].grid(alpha=0.3)
        axes[1, 0].axhline(0.0, color="k", lw=0.5)
    axes[-1, 0].set_xlabel("shear displacement (mm)")
    axes[-1, 0].set_xlim(left=0)
    return _save(fig, path)


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
    fig, ax = plt.subplots(figsize=(6.5, 5.0))
    smax = float(max(s.max(), max(lab.peaks) if lab is not None else 0.0)) * 1.1
    xs = np.linspace(0.0, smax, 50)
    ax.plot(s, t, "o", color="#d95f02", ms=7, mec="k", label="DEM peaks", zorder=5)
    if fit is not None:
        ax.plot(xs, fit.predict(xs), color="#d95f02", lw=1.4,
                label=f"DEM: phi = {fit.friction_angle_deg:.1f} deg, c = {fit.cohesion_kpa:.1f} kPa, "
                      f"R2 = {fit.r2:.3f}")  # fmt: skip
    if fit_origin is not None:
        ax.plot(xs, fit_origin.predict(xs), color="#d95f02", lw=1.0, ls=":",
                label=f"DEM, c = 0: phi = {fit_origin.friction_angle_deg:.1f} deg")  # fmt: skip
    if lab is not None:
        ls = sorted(lab.peaks)
        ax.plot(
            ls, [lab.peaks[v] for v in ls], "s", mfc="none", mec="#1b9e77", ms=7, mew=1.5, label="lab peaks"
        )
        if lab_fit is not None:
            ax.plot(xs, lab_fit.predict(xs), color="#1b9e77", lw=1.2, ls="--",
                    label=f"lab: phi = {lab_fit.friction_angle_deg:.1f} deg, "
                          f"c = {lab_fit.cohesion_kpa:.1f} kPa")  # fmt: skip
    ax.set_xlim(0, smax)
    ax.set_ylim(bottom=0)
    ax.set_xlabel("normal stress (kPa)")
    ax.set_ylabel("peak shear stress (kPa)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title(title, fontsize=10)
    return _save(fig, path)


__all__ = ["plot_peak_strength", "plot_shear_curves"]
