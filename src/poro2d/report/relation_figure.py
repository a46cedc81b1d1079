"""The figure of a grading's relation n2D(nLab): the criterion's points against the conversions.

Drawn from an analysed relation (the :class:`poro2d.sweep.results.RelationResult` of
:func:`poro2d.sweep.relation.analyse`, or one read back): the DEM points, hollow where the criterion
did not converge, the parabola fitted to them, Eq. 12 and the other conversion methods
(those the relation's table compares, in its order). :func:`draw_relation` draws a finished
``poro2d relation`` run's figures into its store.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from poro2d import porosity as P
from poro2d.report.figure_file import (
    BLUE,
    BLUISH_GREEN,
    GREY,
    REDDISH_PURPLE,
    VERMILION,
    new_figure,
    save_figure,
)
from poro2d.store import Store
from poro2d.sweep.results import RelationResult


def write_relation_figure(rel, out: Path, title: str = "") -> list[Path]:
    """``relation.png`` and ``relation.svg`` in ``out``; returns both paths."""
    paths = [out / "relation.png", out / "relation.svg"]
    save_figure(plot_relation(rel, title), *paths)
    return paths


def draw_relation(rel: RelationResult, store: Store) -> list[Path]:
    """``relation.png`` and ``relation.svg`` of a relation run in its store; returns both paths."""
    title = "2D porosity from the criterion vs laboratory porosity"
    return write_relation_figure(
        rel, store.root, title + (" (quick: 0.08 m x 0.04 m box)" if rel.quick else "")
    )


def plot_relation(rel, title: str = "") -> Figure:
    """DEM points (hollow = not converged), the fit, Eq. 12 and other methods vs nLab."""
    hi, lo = rel.n_max, rel.n_min
    pts = rel.points
    xs = [p.n_lab for p in pts] + [hi, lo]
    pad = 0.08 * (max(xs) - min(xs))
    x = np.linspace(min(xs) - pad, max(xs) + pad, 201)
    fig, ax = new_figure(figsize=(9.5, 6.0), layout="constrained")
    ax.axvspan(lo, hi, color="0.5", alpha=0.07, lw=0)
    _method_curves(ax, x, hi, lo, rel.fit)
    _dem_points(ax, rel)
    failed = [p for p in pts if not _finite(p.n2d_dem)]
    for p in failed:
        ax.axvline(p.n_lab, color=VERMILION, ls=":", lw=1.0)
    ax.set_xlim(x[0], x[-1])
    ax.set_xlabel(r"laboratory porosity $n_{Lab}$ [-]   (shaded: between $n_{min}$ and $n_{max}$)")
    ax.set_ylabel(r"2D porosity $n_{2D}$ [-]")
    head = title or "2D porosity from the criterion vs laboratory porosity"
    sub = f"n_max = {hi:g} (Dr = 0), n_min = {lo:g} (Dr = 1)"
    if rel.mode == "density":
        seeds = max((p.seeds for p in pts), default=0)
        sub += f"; density-controlled preparation, {seeds} seed(s) per state"
    if failed:
        sub += f"; {len(failed)} failed case(s) dotted"
    ax.set_title(f"{head}\n{sub}", fontsize=11)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8.5, frameon=False)
    return fig


def _finite(v) -> bool:
    """Whether ``v`` is a number (a failed case's n2D is None, as its file keeps NaN)."""
    return v is not None and math.isfinite(v)


def _method_curves(ax, x: np.ndarray, hi: float, lo: float, fit) -> None:
    """Eq. 12 and the other conversion methods over ``x``, and the parabola fitted to the DEM."""
    curves = (  # label, n2D of nLab, style
        (r"Parabola, Eq. 12 ($0.42\,n^2 + 0.25\,n$)", P.parabolic, dict(color="black", lw=2.0)),
        ("LIM 2D-3D (Sec. 2.2)", P.lim_3d, dict(color=GREY, lw=1.4)),
        ("LIM 2D-Lab (Eqs. 6-7)", lambda v: P.lim_lab(v, hi, lo), dict(color=BLUISH_GREEN, lw=1.4)),
        ("Densest State (Eq. 1)", P.densest_state, dict(color=BLUE, lw=1.2, ls="--")),
    )
    for label, n2d, style in curves:
        ax.plot(x, n2d(x), label=label, **style)
    if fit is not None:
        label = rf"fit to DEM: ${fit.a:.3f}\,n^2 + {fit.b:.3f}\,n$ (rms {fit.rms_residual:.4f})"
        ax.plot(x, fit.a * x * x + fit.b * x, color=VERMILION, lw=2.0, ls="-.", label=label)


def _interior_points(ax, ok: list) -> None:
    """The accepted specimens' interior porosity (the packing's own) beside the box porosity."""
    ins = [p for p in ok if _finite(p.n2d_interior)]
    if ins:
        label = r"DEM interior porosity (2 $d_{50}$ clear of walls, surface; mean $\pm$ sd)"
        ax.errorbar([p.n_lab for p in ins], [p.n2d_interior for p in ins],
                    yerr=[p.n2d_interior_sd for p in ins], fmt="s", color=REDDISH_PURPLE, ms=6, capsize=3,
                    label=label)  # fmt: skip


def _dem_points(ax, rel) -> None:
    """Accepted points (with seed error bars in density mode), unconverged ones hollow, Dr labels."""
    pts = rel.points
    ok = [p for p in pts if p.converged]
    bad = [p for p in pts if not p.converged and _finite(p.n2d_dem)]
    ox, oy = [p.n_lab for p in ok], [p.n2d_dem for p in ok]
    if ok and rel.mode == "density":
        label = r"DEM criterion, density-controlled (mean accepted $n_{2D} \pm$ sd over seeds)"
        ax.errorbar(ox, oy, yerr=[p.n2d_sd for p in ok], fmt="o", color=VERMILION, ms=8, capsize=4,
                    label=label)  # fmt: skip
        ax.axhline(rel.n2d_max, color="0.4", lw=0.8, ls=":", label="2D extremes (calibrated)")
        ax.axhline(rel.n2d_min, color="0.4", lw=0.8, ls=":")
        _interior_points(ax, ok)
    elif ok:
        ax.plot(ox, oy, "o", color=VERMILION, ms=8, label=r"DEM criterion (accepted $n_{2D}$)")
    if bad:
        ax.plot([p.n_lab for p in bad], [p.n2d_dem for p in bad], "o", mfc="none", mec=VERMILION,
                mew=1.8, ms=9, label="DEM, not converged (last n')")  # fmt: skip
    for p in pts:
        if _finite(p.n2d_dem):
            ax.annotate(f"$D_r$={p.relative_density:.2f}", (p.n_lab, p.n2d_dem),
                        textcoords="offset points", xytext=(6, -12), fontsize=8, color="0.25")  # fmt: skip


__all__ = ["plot_relation", "write_relation_figure"]
