"""The grading a run used: the laboratory curve, its cuts, and the disks that were drawn.

:func:`grading_figure`: one panel, laboratory sizes on a log axis: the sieve curve as given
(by mass), the curve after the ``d_min_mm`` / ``d_max_mm`` cuts (renormalised: the soil the
specimen is made of), the cuts as vertical lines, and the drawn disks of one specimen
(percent passing by area, the 2D counterpart of mass).

:func:`plot_realised`: a curve against the disks drawn from it, at the curve's own sieve
sizes in the model (the check of :func:`poro2d.grading.realised_curve`).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.ticker import FuncFormatter

from poro2d.grading import GradingCurve, realised_curve
from poro2d.report.figure_file import DPI, ORANGE, VERMILION, new_figure, save_figure
from poro2d.store import Store


def draw_grading(result, case, store: Store) -> Path:
    """``fig_grading.png`` of a sand run (a :class:`~poro2d.sand.result.SandResult` of ``case``, a
    :class:`~poro2d.sand.case.SandCase`): the grading it used beside the one its first kept
    specimen realised (read from that specimen's state in ``store``)."""
    kept = next((k for k in result.seed_results if k.folder), None)
    radii = None if kept is None else store.child(kept.folder).load_state("specimen.npz").particles.radius
    return grading_figure(
        case.config.table("grading"),
        case.base_dir,
        case.grading,
        radii,
        store.path("fig_grading.png"),
        title=case.name,
    )


def uncut_curve(table: dict, base_dir: str | os.PathLike | None, used: GradingCurve) -> GradingCurve:
    """The grading of a config table before its cuts (the used curve if it has none)."""
    if "d_min_mm" not in table and "d_max_mm" not in table:
        return used
    whole = {k: v for k, v in table.items() if k not in ("d_min_mm", "d_max_mm")}
    return GradingCurve.from_config(whole, base_dir=base_dir)


def drawn_curve(radii: np.ndarray, sizes_m: np.ndarray) -> np.ndarray:
    """Percent passing by area of disks of ``radii`` at diameters ``sizes_m``."""
    d = np.sort(2.0 * np.asarray(radii))
    cum = np.concatenate(([0.0], np.cumsum((d / 2.0) ** 2)))
    return 100.0 * cum[np.searchsorted(d, sizes_m, side="right")] / cum[-1]


def grading_figure(
    table: dict,
    base_dir: str | os.PathLike | None,
    used: GradingCurve,
    radii: np.ndarray | None,
    path: str | os.PathLike,
    *,
    title: str = "",
) -> Path:
    """Write the grading figure (module docstring) to ``path``; returns the path."""
    whole = uncut_curve(table, base_dir, used)
    up = used.upscale
    fig, ax = new_figure(figsize=(7.0, 4.4))
    ax.semilogx(
        whole.sizes * 1e3 / up, whole.percent, "-o", color="0.55", ms=4, label="laboratory curve (mass)"
    )
    if whole is not used:
        ax.semilogx(used.sizes * 1e3 / up, used.percent, "-s", color="k", ms=4, label="after the cuts (mass)")
        for name in ("d_min_mm", "d_max_mm"):
            if name in table:
                ax.axvline(float(table[name]) / up, color=ORANGE, ls="--", lw=1)
        ax.plot([], [], color=ORANGE, ls="--", label=r"cuts ($d_{min}$, $d_{max}$)")
    if radii is not None and len(radii):
        d = np.geomspace(used.d_min_m, used.d_max_m, 60)
        ax.semilogx(d * 1e3 / up, drawn_curve(radii, d), color=VERMILION, lw=2,
                    label=f"drawn disks, one specimen ({len(radii)}, by area)")  # fmt: skip
    plain = FuncFormatter(lambda v, _: f"{v:g}")  # 0.2, not 2 x 10^-1
    ax.set_xlabel("laboratory size [mm]")
    ax.set_ylabel("percent passing [%]")
    ax.set_ylim(0, 100)
    ax.grid(True, which="both", alpha=0.3)
    if up != 1.0:
        top = ax.secondary_xaxis("top", functions=(lambda x: x * up, lambda x: x / up))
        top.xaxis.set_major_formatter(plain)
        top.xaxis.set_minor_formatter(plain)
        top.set_xlabel(rf"disk diameter in the model [mm] (up-scaling $\times${up:g})")
    # after the secondary axis, which resets the parent's tick labels
    ax.xaxis.set_major_formatter(plain)
    ax.xaxis.set_minor_formatter(plain)
    ax.legend(loc="upper left", fontsize=8)
    spread = used.d_max_m / used.d_min_m
    ax.set_title(f"{title}: $C_u$ = {used.uniformity:.2f}, $d_{{max}}/d_{{min}}$ = {spread:.0f}")
    fig.tight_layout()
    return save_figure(fig, path)


def plot_realised(curve: GradingCurve, radii, path: str | os.PathLike, *, title: str | None = None) -> Path:
    """Write the requested and realised curves (log diameter axis) to ``path``; returns the path."""
    realised = realised_curve(curve, radii)  # checks the radii
    r = np.asarray(radii, dtype=float)
    dev = float(np.max(np.abs(realised - curve.percent)))
    d_mm = curve.sizes * 1e3

    fig, ax = new_figure(figsize=(6.4, 4.2), dpi=DPI)
    ax.semilogx(d_mm, curve.percent, "-o", color="k", ms=4, label="requested (by mass)")
    ax.semilogx(d_mm, realised, "s", color=VERMILION, mfc="none", ms=7, label="realised (by area)")
    ax.set_xlabel(r"diameter in the model $d$ [mm]")
    ax.set_ylabel("percent passing [%]")
    ax.set_ylim(0, 100)
    ax.set_xticks(d_mm, [f"{v:.3g}" for v in d_mm])
    ax.set_xticks([], minor=True)
    ax.grid(True, alpha=0.3)
    if curve.upscale != 1.0:
        up = curve.upscale
        top = ax.secondary_xaxis("top", functions=(lambda x: x / up, lambda x: x * up))
        top.set_xticks(d_mm / up, [f"{v:.3g}" for v in d_mm / up])
        top.set_xticks([], minor=True)
        top.set_xlabel(f"laboratory size [mm] (up-scaling factor {up:g})")
    ax.legend(loc="upper left", title=f"{r.size} disks, max deviation {dev:.2f} %-points")
    if title:
        ax.set_title(title)
    fig.tight_layout()
    return save_figure(fig, path)


__all__ = ["drawn_curve", "grading_figure", "plot_realised", "uncut_curve"]
