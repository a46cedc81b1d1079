"""The periodic reference's figures: stress ratio and solid fraction against shear strain, and
the critical-state line (void ratio against the mean stress on a log axis).

(a) tau / sigma_yy against gamma, one line per seed; (b) the solid fraction. The start of the
steady-state window is a vertical line, the study's means over it dotted horizontal lines.
Made from arrays (each series needs ``gamma``, ``stress_ratio`` and ``solid_fraction``): no
file is opened here. :func:`draw_critical_state` and :func:`draw_critical_state_line` draw them
from a finished run's result into its store.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from poro2d.critical_state.case import CriticalStateCase
from poro2d.critical_state.line import CriticalStateLineResult, pressure_folder
from poro2d.critical_state.results import CriticalStateResult, CriticalStateTestResult
from poro2d.report.figure_file import new_figure, save_figure
from poro2d.report.shear_figures import COLORS
from poro2d.store import Store

#: the figure of a run or a study, and of a line
FIGURE = "critical_state.png"
LINE_FIGURE = "critical_state_line.png"


def _title(case: CriticalStateCase) -> str:
    return (
        rf"periodic shear: $f_p$ = {case.particle_friction:g}, $\mu_r$ = {case.rolling_friction:g}, "
        f"$P$ = {case.pressure_kpa:g} kPa, $I$ = {case.inertial_number:g}, {case.disks} disks"
    )


def draw_critical_state(result: CriticalStateTestResult | CriticalStateResult, store: Store) -> None:
    """``critical_state.png`` of one run (its series) or of a study (every seed's, its means dotted)."""
    case = result.case
    if isinstance(result, CriticalStateTestResult):
        series, steady = [(f"seed {case.seed}", result.series)], None
    else:
        series = [(f"seed {s}", t.series) for s, t in zip(result.seeds, result.tests, strict=True)]
        steady = (result.stress_ratio.mean, result.solid_fraction.mean)
    plot_critical_state(
        series, store.path(FIGURE), title=_title(case), window=case.window_start, steady=steady
    )


def draw_critical_state_line(result: CriticalStateLineResult, store: Store) -> None:
    """Every pressure's ``critical_state.png`` in its folder, then the line's e-log p figure."""
    for study in result.studies:
        draw_critical_state(study, store.child(pressure_folder(study.case.pressure_kpa)))
    plot_critical_state_line(result, store.path(LINE_FIGURE))


def plot_critical_state(
    series: Sequence[tuple[str, Any]], path: str | os.PathLike, *, title: str, window: float,
    steady: tuple[float, float] | None = None,
) -> Path:  # fmt: skip
    """The figure of ``series`` (label, series); ``window``: gamma where the steady window
    starts; ``steady``: (stress ratio, solid fraction) means to draw, or None."""
    fig, (ax, bx) = new_figure(2, 1, figsize=(7.0, 6.5), sharex=True)
    for k, (label, s) in enumerate(series):
        col = COLORS[k % len(COLORS)]
        ax.plot(s.gamma, s.stress_ratio, color=col, lw=0.8, label=label)
        bx.plot(s.gamma, s.solid_fraction, color=col, lw=0.8)
    for axis in (ax, bx):
        axis.axvline(window, color="0.5", lw=0.8, ls="--")
        axis.grid(alpha=0.3)
    if steady is not None:
        ax.axhline(steady[0], color="k", lw=0.8, ls=":", label=f"steady mean {steady[0]:.3f}")
        bx.axhline(steady[1], color="k", lw=0.8, ls=":")
    ax.set_ylabel(r"stress ratio $\tau / \sigma_{yy}$")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8, loc="lower right")
    bx.set_ylabel("solid fraction")
    bx.set_xlabel(r"shear strain $\gamma$")
    fig.tight_layout()
    return save_figure(fig, path)


def plot_critical_state_line(result: Any, path: str | os.PathLike) -> Path:
    """The critical-state line of ``result`` (a ``CriticalStateLineResult``): (a) e against p' on a
    log axis, every seed a dot, each pressure's mean with the seeds' sd, the fitted line, and the
    result's marks (2D states held against the line: a specimen's ends, a state as mapped) as
    horizontal lines, loose of the line above it; (b) tau / sigma_yy against p'."""
    fig, (ax, bx) = new_figure(2, 1, figsize=(7.0, 7.0), sharex=True, height_ratios=(3, 2))
    for k, point in enumerate(result.points):
        p, e = point.mean_stress_kpa, point.void_ratio
        ax.plot(p.values, e.values, ".", color="0.6", ms=4, label="a seed" if k == 0 else None)
        ax.errorbar(p.mean, e.mean, yerr=e.sd or 0.0, fmt="o", color=COLORS[0], ms=6, capsize=3,
                    label=r"mean $\pm$ sd over seeds" if k == 0 else None)  # fmt: skip
        sr = point.stress_ratio
        bx.errorbar(p.mean, sr.mean, yerr=sr.sd or 0.0, fmt="o", color=COLORS[1], ms=6, capsize=3)
    lo = min(pt.mean_stress_kpa.min for pt in result.points)
    hi = max(pt.mean_stress_kpa.max for pt in result.points)
    grid = np.geomspace(lo / 1.3, hi * 1.3, 50)
    line = result.line
    ax.plot(grid, [line.void_ratio_at(g) for g in grid], color="k", lw=1.0, label=line.text())
    for k, mark in enumerate(result.marks or []):
        style = ("--", ":", "-.")[k % 3]
        ax.axhline(mark.void_ratio, color=COLORS[(k + 2) % len(COLORS)], lw=1.0, ls=style,
                   label=f"{mark.label}: e = {mark.void_ratio:.4f}")  # fmt: skip
    ax.set_xscale("log")
    ax.set_ylabel(r"2D void ratio $e = (1 - \phi) / \phi$ ($\phi$: solid fraction)")
    c = result.case
    kappa = "" if c.stiffness_number is None else rf", $\kappa$ = {c.stiffness_number:g} at every $p$"
    ax.set_title(
        rf"critical-state line: $f_p$ = {c.particle_friction:g}, $\mu_r$ = {c.rolling_friction:g}, "
        f"$I$ = {c.inertial_number:g}, {c.disks} disks{kappa}",
        fontsize=9,
    )
    ax.legend(fontsize=8)
    bx.set_ylabel(r"$\tau / \sigma_{yy}$")
    bx.set_xlabel(r"mean stress $p'$ (kPa)")
    for axis in (ax, bx):
        axis.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return save_figure(fig, path)


__all__ = [
    "FIGURE",
    "LINE_FIGURE",
    "draw_critical_state",
    "draw_critical_state_line",
    "plot_critical_state",
    "plot_critical_state_line",
]
