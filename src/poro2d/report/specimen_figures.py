"""Figures of a prepared specimen: its state by bands of equal height, its local porosity.

Both are drawn from what the measurements return (:func:`poro2d.measure.specimen_state.specimen_state`,
:func:`poro2d.measure.specimen_porosity.measure_specimen`), so the criterion saves them
beside the numbers they show.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import EllipseCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Rectangle

from poro2d.errors import InputError
from poro2d.measure.laguerre import LaguerreCells
from poro2d.measure.specimen_porosity import PorosityDetails, SpecimenPorosity
from poro2d.measure.specimen_state import SpecimenStateResult
from poro2d.report.figure_file import BLUE, BLUISH_GREEN, ORANGE, VERMILION, new_figure, save_figure

#: the local porosity figure writes each circle's value when there are at most this many circles
MAX_LABELLED_CIRCLES = 60


def plot_specimen_state(state: SpecimenStateResult, path: str | os.PathLike, title: str = "") -> Path:
    """Porosity per band and sigma_v, sigma_h, geostatic sigma_v against height; K0 in the legend.

    ``state``: the record of :func:`poro2d.measure.specimen_state.specimen_state`.
    """
    rows = state.bands
    z = np.array([r.z_mid_m for r in rows]) * 1e3
    fig, (a1, a2) = new_figure(1, 2, sharey=True, figsize=(9.0, 4.8), layout="constrained")
    _porosity_profile(a1, [r.porosity for r in rows], z)
    a1.axvline(state.porosity_mean, color="0.5", ls=":", lw=1)
    a1.set_xlabel("porosity of the band $n$ [-]")
    a1.set_ylabel("height of the band's middle [mm]")
    a1.set_title(f"porosity: mean {state.porosity_mean:.4f}, range {state.porosity_range:.4f}", fontsize=10)
    kpa = 1e-3
    a2.plot([r.sigma_v_pa * kpa for r in rows], z, "o-", color=VERMILION, label=r"$\sigma_v$ (disks)")
    a2.plot([r.sigma_h_pa * kpa for r in rows], z, "s-", color=BLUISH_GREEN, label=r"$\sigma_h$ (disks)")
    a2.plot([r.sigma_v_geostatic_pa * kpa for r in rows], z, "--", color="black",
            label=r"geostatic: $F_{top}/W + \rho_s g (1 - n)(H - z)$")  # fmt: skip
    k0 = state.k0_mean
    a2.set_title(
        rf"stress; $K_0 = \sigma_h / \sigma_v$: mean {k0:.3f}" if k0 is not None else "stress", fontsize=10
    )
    a2.set_xlabel("stress [kPa] (compression positive)")
    a2.legend(fontsize=8, frameon=False, loc="upper right")
    for a in (a1, a2):
        a.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title, fontsize=11)
    return save_figure(fig, path)


def porosity_axis(porosity: list[float]) -> tuple[float, float]:
    """The porosity axis of a profile (bands bottom to top), scaled to the packing: the top band counts
    the gap under the plate, so it sets the axis only when it lies within the spread of the bands
    below it (at least 0.02) of their range; a margin of 15 % of the range (at least 0.01) either side."""
    below = porosity[:-1] if len(porosity) > 2 else porosity
    lo, hi = min(below), max(below)
    top, reach = porosity[-1], max(hi - lo, 0.02)
    if lo - reach <= top <= hi + reach:
        lo, hi = min(lo, top), max(hi, top)
    pad = max(0.15 * (hi - lo), 0.01)
    return lo - pad, hi + pad


def _porosity_profile(ax, porosity: list[float], z: np.ndarray) -> None:
    """The porosity per band against height on the packing's scale; a band beyond it (the top one,
    with the gap under the plate) is not joined to the rest but drawn at the axis' edge as an
    arrow with its value."""
    lo, hi = porosity_axis(porosity)
    n = np.asarray(porosity, dtype=float)
    inside = (n >= lo) & (n <= hi)
    ax.plot(np.where(inside, n, np.nan), z, "o-", color=BLUE)
    ax.set_xlim(lo, hi)
    for value, h in zip(n[~inside], z[~inside], strict=True):
        right = value > hi
        inset = 0.03 * (hi - lo)  # the arrow inside the axes, pointing past its edge
        edge = hi - inset if right else lo + inset
        ax.plot([edge], [h], ">" if right else "<", color=VERMILION, ms=9, zorder=5)
        ax.annotate(f"{value:.3f}\n(gap under\nthe plate)", (edge, h), xytext=(-8 if right else 8, -8),
                    textcoords="offset points", ha="right" if right else "left", va="top",
                    fontsize=8, color=VERMILION)  # fmt: skip


def plot_local_porosity(
    pos: Any,
    radius: Any,
    width: Any,
    plate_y: Any,
    measures: SpecimenPorosity,
    path: str | os.PathLike,
    title: str | None = None,
) -> Path:
    """The Laguerre cells coloured by local porosity, with the measurement regions.

    Drawn in mm: cells (colour range 0-0.5, values outside it clipped in the drawing only),
    disk outlines, the free surface, the plate, the interior rectangle and its circles with
    their porosity, and a box with the summary numbers. ``measures`` is what
    :func:`poro2d.measure.specimen_porosity.measure_specimen` returned for these disks and
    this box (it checked them). PNG (or the suffix's format).
    """
    pos, radius = np.asarray(pos, dtype=float), np.asarray(radius, dtype=float)
    width, plate_y = float(width), float(plate_y)
    if measures.details is None:
        raise InputError("measures", "a SpecimenPorosity without details", "the result of measure_specimen")
    d = measures.details
    map_h = 11.0 * plate_y / width
    fig = Figure(figsize=(11.0, map_h + 1.9), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplot_mosaic(
        [["map", "map", "map"], ["legend", "bar", "text"]],
        height_ratios=[map_h, 1.3],
        width_ratios=[1.0, 1.0, 1.9],
    )
    ax = axes["map"]
    cells = _draw_cells(ax, d.cells)
    _draw_disks(ax, pos, radius)
    handles = _draw_regions(ax, d, plate_y, width)
    ax.set_xlim(0.0, width * 1e3)
    ax.set_ylim(0.0, plate_y * 1e3 * 1.02)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(title or "local porosity (Laguerre cells) and interior measurement circles", fontsize=11)
    axes["legend"].axis("off")
    axes["legend"].legend(handles=handles, loc="center left", fontsize=8, frameon=False)
    _draw_colorbar(fig, axes["bar"], cells)
    axes["text"].axis("off")
    axes["text"].text(0.0, 0.5, _summary_text(measures), ha="left", va="center", fontsize=8.5,
                      family="monospace", transform=axes["text"].transAxes,
                      bbox={"boxstyle": "round", "facecolor": "white", "edgecolor": "0.6"})  # fmt: skip
    return save_figure(fig, path)


def _draw_cells(ax, cells: LaguerreCells):
    keep = cells.area > 0
    polys = [p * 1e3 for p, k in zip(cells.polygons(), keep, strict=True) if k]
    coll = PolyCollection(polys, cmap="viridis", edgecolors="face", linewidths=0.2)
    coll.set_array(cells.local_porosity[keep])
    coll.set_clim(0.0, 0.5)
    ax.add_collection(coll)
    return coll


def _draw_disks(ax, pos: np.ndarray, radius: np.ndarray) -> None:
    size = 2e3 * radius
    ax.add_collection(EllipseCollection(
        size, size, np.zeros_like(size), units="xy", offsets=pos * 1e3, offset_transform=ax.transData,
        facecolors="none", edgecolors="black", linewidths=0.25, alpha=0.6,
    ))  # fmt: skip


def _draw_regions(ax, d: PorosityDetails, plate_y: float, width: float) -> list:
    """Interior rectangle, circles (with their value, when few enough to read), free surface
    and plate; returns the legend's handles."""
    x0, y0, x1, y1 = (v * 1e3 for v in d.interior.rect)
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor="white", lw=1.4, ls="--"))
    R = d.interior.circle_radius_m * 1e3
    labelled = d.interior.count <= MAX_LABELLED_CIRCLES
    for (cx, cy), value in zip(d.interior.centres * 1e3, d.interior.porosity, strict=True):
        ax.add_patch(Circle((cx, cy), R, fill=False, edgecolor=VERMILION, lw=1.3))
        if labelled:
            label_box = {"boxstyle": "round,pad=0.15", "facecolor": "white", "alpha": 0.8, "lw": 0}
            ax.text(cx, cy, f"{value:.3f}", ha="center", va="center", fontsize=7.5, bbox=label_box)
    ax.plot(d.surface_x * 1e3, d.surface_h * 1e3, color=ORANGE, lw=0.9)
    ax.plot([0.0, width * 1e3], [plate_y * 1e3] * 2, color="black", lw=2.5)
    return [
        Line2D([], [], color="black", lw=2.5, label="top plate"),
        Line2D([], [], color=ORANGE, lw=0.9, label=r"free surface $h(x)$"),
        Line2D([], [], color="0.35", ls="--", lw=1.4, label="interior: margin from walls, surface"),
        Line2D([], [], color=VERMILION, lw=1.3, label="measurement circles (porosity)"),
    ]


def _draw_colorbar(fig, cax, cells) -> None:
    bar = fig.colorbar(cells, cax=cax, orientation="horizontal", extend="both")
    bar.set_label(r"local porosity $1 - \pi r^2 / A_{cell}$ [-]", fontsize=9)
    cax.set_box_aspect(0.08)


def _summary_text(m: SpecimenPorosity) -> str:
    """The numbers of the figure, label and value aligned in two columns."""
    mm = 1e3
    touching = f"{m.plate_touching_disks} disk{'s' if m.plate_touching_disks != 1 else ''}"
    g, mn = m.surface_gap_mean_m * mm, m.surface_gap_mean_d50
    rows = [
        ("box porosity n' (W x plate height)", f"{m.box_porosity:.4f}"),
        (
            f"interior, {m.interior_regions} circles",
            f"{m.interior_porosity:.4f} ± {m.interior_porosity_std:.4f}",
        ),
        (
            "interior rectangle / Laguerre",
            f"{m.interior_rect_porosity:.4f} / {m.laguerre_interior_porosity:.4f}",
        ),
        (
            "margin, circle radius, d50",
            f"{m.margin_d50:g} d50, {m.circle_radius_m * mm:.1f} mm, {m.d50_m * mm:.2f} mm",
        ),
        ("plate gap: mean, max", f"{g:.2f} mm ({mn:.2f} d50), {m.surface_gap_max_m * mm:.2f} mm"),
        ("plate in contact", f"{100 * m.plate_contact_fraction:.1f} % of the width, {touching} touching"),
    ]
    width = max(len(label) for label, _ in rows)
    return "\n".join(f"{label:<{width}}  {value}" for label, value in rows)


__all__ = ["MAX_LABELLED_CIRCLES", "plot_local_porosity", "plot_specimen_state", "porosity_axis"]
