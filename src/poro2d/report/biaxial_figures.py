"""The biaxial test's figure: stress ratio and volumetric strain against axial strain.

(a) the mobilized friction sin(phi) = (sigma_1 - sigma_3) / (sigma_1 + sigma_3) against the
axial strain, one line per replicate, the mean over the replicates' end windows (where the
critical state is read) as a dotted line; (b) the volumetric strain (compression positive, so dilation goes
down) against the axial strain. Laboratory curves, when the user gives them, are drawn in
black, dashed. A series (:func:`plot_biaxial_series`) draws every confining stress in a colour of
its own, its replicates overlaid, beside the peak circles of Mohr and their envelope. Made from
arrays: no file is opened here. :func:`draw_biaxial` and :func:`draw_biaxial_series` draw them from
a finished run's result into its store, once the run has returned.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from poro2d.biaxial.lab import LabCurve
from poro2d.biaxial.results import BiaxialResult, BiaxialSeriesResult
from poro2d.biaxial.series import sigma_3_at_peak, stress_folder
from poro2d.report.figure_file import new_figure, save_figure
from poro2d.report.shear_figures import COLORS
from poro2d.store import Store

#: the figure of one confining stress, and of a series
FIGURE = "biaxial.png"
SERIES_FIGURE = "biaxial_series.png"
#: the axes' labels of the curves
SIN_PHI = r"$\sin\varphi = (\sigma_1 - \sigma_3) / (\sigma_1 + \sigma_3)$"
AXIAL_STRAIN = r"axial strain $\varepsilon_1$ (%)"


def draw_biaxial(result: BiaxialResult, store: Store, lab: LabCurve | None = None) -> None:
    """``biaxial.png`` of a run at one confining stress: its replicates' curves, the mean of their
    end windows, and ``lab``'s curves (the laboratory CSV the run was given) overlaid."""
    starts = [t.critical_window[0] for t in result.tests]
    end_mean = sum(t.critical_state_sin_phi for t in result.tests) / len(result.tests)
    lab_arrays = None
    if lab is not None:
        lab_arrays = {"axial_strain": lab.axial_strain, "stress_ratio": lab.stress_ratio,
                      "volumetric_strain": lab.volumetric_strain}  # fmt: skip
    plot_biaxial(
        [(f"replicate {k + 1}", t.curve) for k, t in enumerate(result.tests)], store.path(FIGURE),
        title=rf"biaxial test, $\sigma_3$ = {result.confining_stress_kpa:g} kPa, "
              f"replicates: {result.replicates}",
        critical=(end_mean, min(starts)), lab=lab_arrays,
        lab_label=f"laboratory ({os.path.basename(lab.source)})" if lab is not None else "laboratory",
    )  # fmt: skip


def draw_biaxial_series(result: BiaxialSeriesResult, store: Store, lab: LabCurve | None = None) -> None:
    """Every stress's ``biaxial.png`` in its folder, then the series' ``biaxial_series.png``."""
    for study in result.studies:
        draw_biaxial(study, store.child(stress_folder(study.confining_stress_kpa)), lab)
    plot_biaxial_series(
        [(st.confining_stress_kpa, [t.curve for t in st.tests]) for st in result.studies],
        store.path(SERIES_FIGURE),
        title=f"biaxial tests, replicates: {result.replicates} per stress",
        envelope=(result.envelope.friction_angle_deg, result.envelope.cohesion_kpa),
        peaks=[(t.confining_stress_kpa, sigma_3_at_peak(t), t.peak_sin_phi)
               for st in result.studies for t in st.tests],
    )  # fmt: skip


def plot_biaxial(
    curves: Sequence[tuple[str, Mapping[str, np.ndarray]]],
    path: str | os.PathLike,
    *,
    title: str,
    critical: tuple[float, float] | None = None,
    lab: Mapping[str, np.ndarray | None] | None = None,
    lab_label: str = "laboratory",
) -> Path:
    """The figure of ``curves`` (label, arrays ``axial_strain``, ``sin_phi``, ``volumetric_strain``, and
    ``plastic_volumetric_strain`` where a curve has it, dashed).

    ``critical``: (sin phi, start of the window as axial strain) of the critical state, drawn as
    a line; ``lab``: arrays ``axial_strain``, ``stress_ratio`` and ``volumetric_strain`` (or None).
    """
    fig, (ax, bx) = new_figure(2, 1, figsize=(7.0, 7.0), sharex=True, gridspec_kw={"height_ratios": [1.6, 1]})
    for k, (label, c) in enumerate(curves):
        col = COLORS[k % len(COLORS)]
        ax.plot(100 * c["axial_strain"], c["sin_phi"], color=col, lw=1.0, label=label)
        bx.plot(100 * c["axial_strain"], 100 * c["volumetric_strain"], color=col, lw=1.0)
        if "plastic_volumetric_strain" in c:  # the contacts' elastic strain taken out (biaxial/elastic.py)
            bx.plot(100 * c["axial_strain"], 100 * c["plastic_volumetric_strain"], color=col, lw=0.7, ls="--")
    plastic = any("plastic_volumetric_strain" in c for _, c in curves)
    if critical is not None:
        s_cs, start = critical
        ax.axhline(s_cs, color="0.4", lw=0.8, ls=":", label=f"mean from {100 * start:.0f} %: {s_cs:.3f}")
    if lab is not None:
        e1 = 100 * np.asarray(lab["axial_strain"])
        ax.plot(e1, lab["stress_ratio"], "k--", lw=1.2, label=lab_label)
        if lab.get("volumetric_strain") is not None:
            bx.plot(e1, 100 * np.asarray(lab["volumetric_strain"]), "k--", lw=1.2)
    ax.set_ylabel(SIN_PHI)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3)
    bx.axhline(0.0, color="0.6", lw=0.6)
    bx.set_xlabel(AXIAL_STRAIN)
    bx.set_ylabel("volumetric strain eps_v (%)\n(compression +" + ("; dashed: plastic)" if plastic else ")"))
    bx.grid(alpha=0.3)
    fig.tight_layout()
    return save_figure(fig, path)


def plot_biaxial_series(
    curves: Sequence[tuple[float, Sequence[Mapping[str, np.ndarray]]]],
    path: str | os.PathLike,
    *,
    title: str,
    envelope: tuple[float | None, float],
    peaks: Sequence[tuple[float, float]],
) -> Path:
    """Every stress's curves, a colour per stress (its replicates overlaid), and the peak circles.

    ``curves``: (sigma_3 in kPa, the replicates' curves); ``envelope``: (phi in degrees or None,
    c in kPa) of the Mohr-Coulomb line; ``peaks``: (the target sigma_3, the measured sigma_3 at the
    peak, sin phi at the peak) of every test, all in kPa but sin phi.
    """
    fig, axes = new_figure(1, 3, figsize=(14.0, 4.6))
    ax, bx, cx = axes
    colours = {sigma: COLORS[k % len(COLORS)] for k, (sigma, _) in enumerate(curves)}
    for sigma, reps in curves:
        for j, c in enumerate(reps):
            label = rf"$\sigma_3$ = {sigma:g} kPa" if j == 0 else None
            ax.plot(
                100 * c["axial_strain"], c["sin_phi"], color=colours[sigma], lw=0.9, alpha=0.8, label=label
            )
            bx.plot(
                100 * c["axial_strain"], 100 * c["volumetric_strain"], color=colours[sigma], lw=0.9, alpha=0.8
            )
    _circles(cx, peaks, colours, envelope)
    ax.set_xlabel(AXIAL_STRAIN)
    ax.set_ylabel(SIN_PHI)
    ax.legend(fontsize=8, loc="lower right")
    bx.axhline(0.0, color="0.6", lw=0.6)
    bx.set_xlabel(AXIAL_STRAIN)
    bx.set_ylabel("volumetric strain eps_v (%) (compression +)")
    for a in axes:
        a.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def _circles(ax, peaks, colours, envelope) -> None:
    """The peak circles of Mohr in (sigma, tau), a colour per sigma_3, and the envelope's line."""
    angle = np.linspace(0.0, np.pi, 90)
    top = 0.0
    for target, s3, sin_phi in peaks:
        s1 = s3 * (1.0 + sin_phi) / (1.0 - sin_phi)
        centre, radius = 0.5 * (s1 + s3), 0.5 * (s1 - s3)
        ax.plot(
            centre + radius * np.cos(angle), radius * np.sin(angle), color=colours.get(target, "0.3"), lw=0.8
        )
        top = max(top, s1)
    phi, c = envelope
    if phi is not None:
        sig = np.array([0.0, top])
        ax.plot(sig, c + sig * np.tan(np.radians(phi)), "k--", lw=1.0,
                label=rf"peak envelope: $\varphi$ = {phi:.1f}°, $c$ = {c:.1f} kPa")  # fmt: skip
        ax.legend(fontsize=8, loc="upper left")
    right = 1.05 * top if top > 0 else 1.0
    ax.set_xlim(0.0, right)
    ax.set_ylim(0.0, 0.55 * right)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(r"normal stress $\sigma$ (kPa)")
    ax.set_ylabel(r"shear stress $\tau$ (kPa)")


__all__ = [
    "FIGURE",
    "SERIES_FIGURE",
    "draw_biaxial",
    "draw_biaxial_series",
    "plot_biaxial",
    "plot_biaxial_series",
]
