"""The fabric's figures: rose diagrams of the contact orientations and the anisotropies against strain.

A rose (``fabric_rose.png``) is the polar histogram of the force-carrying disk-disk contacts'
orientations at a test's peak and at its end (each contact drawn at theta and theta + 180 degrees),
as a probability density over the circle, with the second-order Fourier density
(1 / 2 pi) [1 + a_c cos 2 (theta - theta_c)] fitted to the histogram (Rothenburg & Bathurst 1989,
Geotechnique 39(4)). ``fabric.png`` shows a_c, a_n, a_t and the mechanical coordination Z_m against
a test's strain, one line per test. Both are drawn after a run, from its result's curves and the
``fabric_rose.json`` its tests kept (:mod:`poro2d.measure.fabric`); a curve of an earlier poro2d,
without fabric columns, draws nothing.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from poro2d.biaxial.results import BiaxialResult, BiaxialSeriesResult
from poro2d.biaxial.series import stress_folder
from poro2d.critical_state.line import CriticalStateLineResult, pressure_folder
from poro2d.critical_state.results import CriticalStateResult
from poro2d.measure.fabric import ROSE_FILE, FabricRoses, Rose, fourier_rose
from poro2d.report.figure_file import new_figure, save_figure
from poro2d.report.shear_figures import COLORS
from poro2d.shear.results import ShearSeriesResult
from poro2d.store import Store

#: the figures of one test (its rose) and of a run (its tests' fabric against strain)
ROSE_FIGURE = "fabric_rose.png"
CURVE_FIGURE = "fabric.png"
#: the panels of ``fabric.png``: column, axis label
PANELS = (
    ("a_c", "contact anisotropy $a_c$"),
    ("a_n", "normal-force anisotropy $a_n$"),
    ("a_t", "tangential-force anisotropy $a_t$"),
    ("z_mech", "mechanical coordination $Z_m$"),
)


def _density(rose: Rose) -> tuple[np.ndarray, np.ndarray, float]:
    """The bins' left edges over the whole circle (radians), the density of each, and the bin width."""
    counts = np.asarray(rose.counts, float)
    width = math.pi / len(counts)
    # each contact is one orientation over [0, pi): over the circle its density is halved
    density = counts / (max(counts.sum(), 1.0) * width) / 2.0
    edges = np.arange(2 * len(counts)) * width
    return edges, np.concatenate([density, density]), width


#: a rose's axis column as its title writes it: symbol, unit
AXIS_SYMBOLS = {
    "shear_displacement_mm": ("shear displacement $u$", " mm"),
    "axial_strain": (r"axial strain $\varepsilon_1$", ""),
    "gamma": (r"shear strain $\gamma$", ""),
}


def axis_at(axis: str, at: float) -> str:
    """Where along its test a rose was taken, in symbols (``u = 3.2 mm``)."""
    symbol, unit = AXIS_SYMBOLS.get(axis, (axis.replace("_", " "), ""))
    return f"{symbol} = {at:.4g}{unit}"


def plot_rose(roses: FabricRoses, path: str | os.PathLike, *, title: str) -> Path | None:
    """The rose diagram of the roses at hand (peak, end) with their fitted Fourier density; None
    when neither is at hand."""
    shown = [(name, r) for name, r in (("peak", roses.peak), ("end", roses.end)) if r is not None]
    if not shown:
        return None
    fig, axes = new_figure(1, len(shown), figsize=(4.2 * len(shown), 4.6), subplot_kw={"projection": "polar"})
    theta = np.linspace(0.0, 2.0 * math.pi, 361)
    for ax, (name, rose) in zip(np.atleast_1d(axes), shown, strict=True):
        edges, density, width = _density(rose)
        a_c, theta_c = rose.fit()
        ax.bar(
            edges, density, width=width, align="edge", color=COLORS[0], alpha=0.55, edgecolor="white", lw=0.3
        )
        ax.plot(theta, fourier_rose(np.degrees(theta), a_c, theta_c), color="k", lw=1.2)
        ax.set_title(
            f"{name}: {axis_at(roses.axis, rose.at)}, {rose.contacts} contacts\n"
            f"2nd-order fit (line): $a_c$ = {a_c:.3f}, $\\theta_c$ = {theta_c:.0f}$\\degree$", fontsize=8,
        )  # fmt: skip
        ax.set_yticklabels([])
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return save_figure(fig, path)


def draw_rose(store: Store, title: str) -> None:
    """``fabric_rose.png`` of the test kept in ``store``, from its ``fabric_rose.json`` (nothing
    without it: a test of an earlier poro2d)."""
    roses = store.read_result(ROSE_FILE, FabricRoses.from_dict)
    if roses is not None:
        plot_rose(roses, store.path(ROSE_FIGURE), title=title)


def has_fabric(curve: Mapping[str, np.ndarray] | None) -> bool:
    """Whether ``curve`` recorded the fabric (a finite a_c somewhere)."""
    return curve is not None and "a_c" in curve and bool(np.isfinite(curve["a_c"]).any())


def plot_fabric(
    curves: Sequence[tuple[str, Mapping[str, np.ndarray]]], path: str | os.PathLike, *, x: str, xlabel: str,
    title: str,
) -> Path | None:  # fmt: skip
    """a_c, a_n, a_t and Z_m of each (label, curve) against its column ``x``; None when no curve
    recorded the fabric."""
    curves = [(label, c) for label, c in curves if has_fabric(c)]
    if not curves:
        return None
    fig, axes = new_figure(len(PANELS), 1, figsize=(6.5, 8.5), sharex=True)
    for k, (label, c) in enumerate(curves):
        for ax, (column, _) in zip(axes, PANELS, strict=True):
            ax.plot(c[x], c[column], color=COLORS[k % len(COLORS)], lw=0.8, label=label)
    for ax, (_, name) in zip(axes, PANELS, strict=True):
        ax.set_ylabel(name, fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    axes[0].set_title(title, fontsize=9)
    axes[-1].set_xlabel(xlabel)
    fig.tight_layout()
    return save_figure(fig, path)


def draw_shear_fabric(result: ShearSeriesResult, store: Store) -> None:
    """Each test's rose in its folder, then the series' ``fabric.png``."""
    for t in result.tests:
        draw_rose(store.child(t.folder), f"direct shear at {t.normal_stress_kpa:g} kPa")
    plot_fabric(
        [(f"{sigma:g} kPa", c) for sigma, c in sorted(result.curves.items())], store.path(CURVE_FIGURE),
        x="shear_displacement_mm", xlabel="shear displacement (mm)", title="direct shear: fabric",
    )  # fmt: skip


def draw_biaxial_fabric(result: BiaxialResult | BiaxialSeriesResult, store: Store) -> None:
    """Each replicate's rose in its folder, then ``fabric.png`` of each confining stress."""
    if isinstance(result, BiaxialSeriesResult):
        for study in result.studies:
            draw_biaxial_fabric(study, store.child(stress_folder(study.confining_stress_kpa)))
        return
    title = f"biaxial test, $\\sigma_3$ = {result.confining_stress_kpa:g} kPa"
    for k in range(len(result.tests)):
        draw_rose(store.child(f"replicate{k + 1}"), f"{title}, replicate {k + 1}")
    plot_fabric(
        [(f"replicate {k + 1}", t.curve) for k, t in enumerate(result.tests)], store.path(CURVE_FIGURE),
        x="axial_strain", xlabel="axial strain", title=f"{title}: fabric",
    )  # fmt: skip


def draw_critical_state_fabric(result: CriticalStateResult | CriticalStateLineResult, store: Store) -> None:
    """Each seed's rose in its folder, then ``fabric.png`` of each pressure."""
    if isinstance(result, CriticalStateLineResult):
        for study in result.studies:
            draw_critical_state_fabric(study, store.child(pressure_folder(study.case.pressure_kpa)))
        return
    title = f"periodic shear at {result.case.pressure_kpa:g} kPa"
    for seed in result.seeds:
        draw_rose(store.child(f"seed{seed}"), f"{title}, seed {seed}")
    plot_fabric(
        [(f"seed {s}", t.series) for s, t in zip(result.seeds, result.tests, strict=True)],
        store.path(CURVE_FIGURE), x="gamma", xlabel=r"shear strain $\gamma$", title=f"{title}: fabric",
    )  # fmt: skip


__all__ = [
    "CURVE_FIGURE",
    "ROSE_FIGURE",
    "draw_biaxial_fabric",
    "draw_critical_state_fabric",
    "draw_rose",
    "draw_shear_fabric",
    "has_fabric",
    "plot_fabric",
    "plot_rose",
]
