"""The paper's Fig. 1 (all conversions) and Fig. 2 (LIM lines and the parabola).

Figures are built on :class:`matplotlib.figure.Figure` with an Agg canvas, so nothing
here touches pyplot's global state or needs a display.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from poro2d import porosity as P
from poro2d.errors import InputError, check_range
from poro2d.report.figure_file import (
    BLUE,
    BLUISH_GREEN,
    GREY,
    ORANGE,
    REDDISH_PURPLE,
    SKY_BLUE,
    VERMILION,
    new_figure,
    save_figure,
)

# name, function of n_lab, style
_STYLE = {
    "densest_state": dict(color=BLUE, ls="-"),
    "densest_state_modified": dict(color=SKY_BLUE, ls="-"),
    "densest_state_modified_alt": dict(color=REDDISH_PURPLE, ls="--", zorder=5),
    "loosest_state": dict(color=VERMILION, ls="-"),
    "interval_mapping": dict(color=ORANGE, ls="-"),
    "combination": dict(color=REDDISH_PURPLE, ls="-"),
    "lim_lab": dict(color=BLUISH_GREEN, ls="-", lw=3.0, alpha=0.55),
    "lim_3d": dict(color=GREY, ls="-"),
    "quasi_3d": dict(color=BLUISH_GREEN, ls=":", lw=2.0),
    "parabolic": dict(color="black", ls="-", lw=2.2),
}


def _eq2_label(reading: str) -> str:
    label = f"Densest State modified\n(Eq. 2, $\\nu$ {reading.replace('_', ' ')})"
    if reading == "solid_fraction":
        label = label[:-1] + "; near LIM 2D-Lab)"
    return label


def _check_extremes(n_max: float, n_min: float) -> None:
    P.relative_density(n_min, n_max, n_min)  # validates both, raises InputError


def _fig1_curves(
    x: np.ndarray, n_max: float, n_min: float, nu_reading: str, lattice_exact: bool
) -> list[tuple[str, str, np.ndarray]]:
    """Every method's line as (style key, legend label, n2D): the limits follow from all of them."""
    other = "solid_fraction" if nu_reading == "printed" else "printed"
    lim_lab = P.lim_lab(x, n_max, n_min, lattice_exact=lattice_exact)
    quasi = P.quasi_3d(x, n_max, n_min, lattice_exact=lattice_exact)
    return [
        ("densest_state", "Densest State (Eq. 1)", P.densest_state(x)),
        ("densest_state_modified", _eq2_label(nu_reading), P.densest_state_modified(x, n_min, nu_reading)),
        ("densest_state_modified_alt", _eq2_label(other), P.densest_state_modified(x, n_min, other)),
        ("loosest_state", "Loosest State (Eq. 3)", P.loosest_state(x)),
        ("interval_mapping", "Interval Mapping (Eq. 4)", P.interval_mapping(x)),
        ("combination", "Combination (Eq. 5)", P.combination(x, n_max, n_min)),
        ("lim_lab", "LIM 2D-Lab (Eqs. 6-7)", lim_lab),
        ("quasi_3d", "Quasi 3D (Eqs. 8-11)\n(same line as LIM 2D-Lab)", quasi),
        ("lim_3d", "LIM 2D-3D (Sec. 2.2)", P.lim_3d(x)),
        ("parabolic", "Parabola (Eq. 12)", P.parabolic(x)),
    ]


def _fig1_negative_band(ax, lo_y: float, pad: float) -> None:
    """Shade n2D < 0: several methods go negative there, and the reader must see that it is impossible."""
    ax.axhspan(lo_y - pad, 0.0, color=VERMILION, alpha=0.07, lw=0)
    ax.axhline(0.0, color="0.2", lw=1.0)
    ax.text(
        0.99,
        0.02,
        r"$n_{2D} < 0$: physically impossible",
        transform=ax.transAxes,
        color=VERMILION,
        fontsize=9,
        ha="right",
        va="bottom",
    )


def _fig1_mark(ax, mark_n_lab: float, y_text: float) -> None:
    """A vertical line at the user's n_lab, to read every method's n2D off the same abscissa."""
    check_range("mark_n_lab", mark_n_lab, 0.0, 1.0, hi_open=True)
    _mark_line(ax, mark_n_lab, y_text, va="top")


def _mark_line(ax, n_lab: float, y: float, **text) -> None:
    """A dotted vertical line at the user's ``n_lab``, named at height ``y``."""
    ax.axvline(n_lab, color="0.4", ls=":", lw=1.2)
    ax.text(n_lab, y, f" $n_{{Lab}}$ = {n_lab:g}", color="0.3", fontsize=9, **text)


def _finish(ax, title: str, **legend) -> None:
    """The axes' labels (laboratory against 2D porosity), ``title``, grid and legend of both figures."""
    ax.set_xlabel(r"laboratory porosity $n_{Lab}$ [-]")
    ax.set_ylabel(r"2D porosity $n_{2D}$ [-]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(**legend)


def fig1_relations(
    n_max: float = P.PAPER_N_MAX,
    n_min: float = P.PAPER_N_MIN,
    *,
    nu_reading: str = "printed",
    lattice_exact: bool = False,
    mark_n_lab: float | None = None,
    num: int = 201,
) -> Figure:
    """Fig. 1: 2D porosity of every method against n_lab over [n_min, n_max]."""
    _check_extremes(n_max, n_min)
    if nu_reading not in P.NU_READINGS:
        raise InputError("nu_reading", nu_reading, " or ".join(P.NU_READINGS))
    x = np.linspace(n_min, n_max, num)
    curves = _fig1_curves(x, n_max, n_min, nu_reading, lattice_exact)

    fig, ax = new_figure(figsize=(10.5, 6.0), layout="constrained")
    lo_y = min(0.0, min(float(np.nanmin(y)) for _, _, y in curves))
    hi_y = max(float(np.nanmax(y)) for _, _, y in curves)
    pad = 0.04 * (hi_y - lo_y)
    _fig1_negative_band(ax, lo_y, pad)
    for key, label, y in curves:
        ax.plot(x, y, label=label, **{"lw": 1.8, **_STYLE[key]})
    if mark_n_lab is not None:
        _fig1_mark(ax, mark_n_lab, hi_y + pad * 0.5)
    ax.set_xlim(n_min, n_max)
    ax.set_ylim(lo_y - pad, hi_y + pad)
    title = (
        "Fig. 1: 2D vs laboratory porosity, all methods\n"
        f"($n_{{Lab,max}}$ = {n_max:g}, $n_{{Lab,min}}$ = {n_min:g})"
    )
    _finish(
        ax, title, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9, frameon=False, labelspacing=0.8
    )
    return fig


def _fig2_lines(
    ax, x: np.ndarray, n_max: float, n_min: float, lattice_exact: bool
) -> tuple[np.ndarray, np.ndarray]:
    """The two LIM lines solid only where they are defined (dashed beyond), and the parabola.

    Returns both LIM lines: the y limits are taken from them.
    """
    lab = P.lim_lab(x, n_max, n_min, lattice_exact=lattice_exact)
    inside = (x >= n_min) & (x <= n_max)
    st = _STYLE["lim_lab"]
    ax.plot(x, lab, color=st["color"], ls="--", lw=1.2, alpha=0.8)
    ax.plot(
        x[inside],
        lab[inside],
        color=st["color"],
        lw=2.5,
        label=f"LIM 2D-Lab (Eq. 7), solid over [{n_min:g}, {n_max:g}]",
    )
    l3 = P.lim_3d(x)
    seg = (x >= P.FCC_3D) & (x <= P.SIMPLE_CUBIC_3D)
    ax.plot(x, l3, color=GREY, ls="--", lw=1.2, alpha=0.8)
    ax.plot(x[seg], l3[seg], color=GREY, lw=2.5, label="LIM 2D-3D, solid from FCC to SC")
    ax.plot(x, P.parabolic(x), color="black", lw=2.2, label=r"Parabola $0.42\,n^2 + 0.25\,n$ (Eq. 12)")
    return lab, l3


def _fig2_construction_points(ax) -> None:
    """The three points Eq. 12 was built on, each with the parabola's miss, so the fit can be checked."""
    pts = [
        (0.0, 0.0, "origin"),
        (P.FCC_3D, P.HEXAGONAL_2D, "FCC / hexagonal"),
        (P.SIMPLE_CUBIC_3D, P.SQUARE_2D, "simple cubic / square"),
    ]
    ax.plot(
        [p[0] for p in pts],
        [p[1] for p in pts],
        "o",
        ms=9,
        mfc="none",
        mec=VERMILION,
        mew=2,
        label="construction points of Eq. 12",
    )
    for px, py, name in pts:
        dev = float(P.parabolic(px)) - py
        txt = f"{name}\n({px:.4f}, {py:.4f})"
        if px > 0:
            txt += f"\nparabola {dev:+.1e}"
        ax.annotate(
            txt,
            (px, py),
            xytext=(-12, 14) if px > 0 else (12, 10),
            textcoords="offset points",
            ha="right" if px > 0 else "left",
            fontsize=8.5,
            color=VERMILION,
        )


def _fig2_mark(ax, mark_n_lab: float, n_max: float, n_min: float, lattice_exact: bool, x_max: float) -> None:
    """The three lines' values at the user's n_lab, printed too: the gap between them is the point."""
    check_range("mark_n_lab", mark_n_lab, 0.0, x_max)
    marks = [
        ("LIM 2D-3D", float(P.lim_3d(mark_n_lab)), GREY),
        ("parabola", float(P.parabolic(mark_n_lab)), "black"),
        (
            "LIM 2D-Lab",
            float(P.lim_lab(mark_n_lab, n_max, n_min, lattice_exact=lattice_exact)),
            BLUISH_GREEN,
        ),
    ]
    for _, y, c in marks:
        ax.plot([mark_n_lab], [y], "s", color=c, ms=6, zorder=6)
    lines = [f"at $n_{{Lab}}$ = {mark_n_lab:g}:"] + [f"{name}: {y:.3f}" for name, y, _ in marks]
    ax.text(
        0.98,
        0.04,
        "\n".join(lines),
        transform=ax.transAxes,
        ha="right",
        va="bottom",
        fontsize=9,
        bbox=dict(boxstyle="round", fc="white", ec="0.6"),
    )
    _mark_line(ax, mark_n_lab, 0.005)


def fig2_lim_parabola(
    n_max: float = P.PAPER_N_MAX,
    n_min: float = P.PAPER_N_MIN,
    *,
    lattice_exact: bool = False,
    mark_n_lab: float | None = None,
    x_max: float = 0.5,
    num: int = 201,
) -> Figure:
    """Fig. 2: LIM_2D-Lab, LIM_2D-3D and the parabola of Eq. 12, with its three points."""
    _check_extremes(n_max, n_min)
    x = np.linspace(0.0, x_max, num)
    fig, ax = new_figure(figsize=(9.5, 6.0), layout="constrained")
    lab, l3 = _fig2_lines(ax, x, n_max, n_min, lattice_exact)
    _fig2_construction_points(ax)
    if mark_n_lab is not None:
        _fig2_mark(ax, mark_n_lab, n_max, n_min, lattice_exact, x_max)
    ax.axhline(0.0, color="0.2", lw=1.0)
    ax.set_xlim(0.0, x_max)
    y_all = np.concatenate([lab, l3, P.parabolic(x)])
    # The dashed extensions of the LIM lines run far below zero; keep the view on the
    # physical range and show only the start of the negative part.
    ax.set_ylim(max(-0.08, min(-0.02, float(y_all.min()) - 0.01)), float(y_all.max()) + 0.02)
    _finish(ax, "Fig. 2: LIM 2D-Lab, LIM 2D-3D and the parabola of Eq. 12", loc="upper left", fontsize=9)
    return fig


def write_relation_figures(
    out_dir: str | Path,
    n_max: float = P.PAPER_N_MAX,
    n_min: float = P.PAPER_N_MIN,
    *,
    nu_reading: str = "printed",
    lattice_exact: bool = False,
    mark_n_lab: float | None = None,
) -> list[Path]:
    """Write fig1_relations.png/.svg and fig2_lim_parabola.png/.svg; return the paths."""
    out = Path(out_dir)
    figs = {
        "fig1_relations": fig1_relations(
            n_max,
            n_min,
            nu_reading=nu_reading,
            lattice_exact=lattice_exact,
            mark_n_lab=mark_n_lab,
        ),
        "fig2_lim_parabola": fig2_lim_parabola(
            n_max, n_min, lattice_exact=lattice_exact, mark_n_lab=mark_n_lab
        ),
    }
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for stem, fig in figs.items():
        png, svg = out / f"{stem}.png", out / f"{stem}.svg"
        save_figure(fig, png, svg)
        written += [png, svg]
    return written
