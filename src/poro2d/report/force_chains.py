"""Contact force chains like the paper's Figs. 5-7: line width proportional to force.

:func:`plot_force_chains` draws from plain data: a :class:`poro2d.dem.contacts.ContactSet`,
the disks' positions and radii and the wall segments, so a stored state (a frame saved
during a direct shear test, say) is drawn without a simulation.
:func:`plot_simulation_force_chains` takes those from a live :class:`poro2d.dem.Simulation`.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.collections import LineCollection, PatchCollection
from matplotlib.lines import Line2D
from matplotlib.patches import Circle

from poro2d.dem.contacts import ContactSet
from poro2d.errors import InputError, check_range
from poro2d.report.figure_file import VERMILION, new_figure, save_figure

FORCE_COLOR = VERMILION
WALL_COLOR = "#333333"


def _nice(x: float) -> float:
    if x <= 0:
        return 1.0
    e = 10 ** np.floor(np.log10(x))
    for m in (1, 2, 5, 10):
        if m * e >= x * 0.999:
            return float(m * e)
    return float(10 * e)


def _check_inputs(contacts, pos, radius, walls) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The arrays as float arrays of the expected shapes; an InputError names the first bad one."""
    if not isinstance(contacts, ContactSet):
        raise InputError(
            "contacts", type(contacts).__name__, "a poro2d.dem.contacts.ContactSet",
            "for a Simulation use plot_simulation_force_chains",
        )  # fmt: skip
    pos = np.asarray(pos, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 2 or not np.all(np.isfinite(pos)):
        raise InputError("pos", f"array of shape {pos.shape}", "finite disk centres, shape (n, 2)")
    radius = np.asarray(radius, dtype=float)
    if radius.shape != (pos.shape[0],) or not np.all(radius > 0):
        raise InputError("radius", f"array of shape {radius.shape}", f"{pos.shape[0]} positive radii")
    walls = np.zeros((0, 2, 2)) if walls is None else np.asarray(walls, dtype=float)
    if walls.ndim != 3 or walls.shape[1:] != (2, 2):
        raise InputError("walls", f"array of shape {walls.shape}", "wall segments, shape (m, 2, 2)")
    n = pos.shape[0]
    pp = contacts.kind == 0
    if len(contacts) and (contacts.i.min() < 0 or contacts.i.max() >= n or np.any(contacts.j[pp] >= n)):
        raise InputError("contacts", f"{len(contacts)} contacts", f"disk indices in [0, {n})")
    return pos, radius, walls


def _contact_lines(contacts: ContactSet, pos: np.ndarray) -> np.ndarray:
    """One segment per contact: centre to centre (disk-disk), centre to contact point (disk-wall)."""
    pp = contacts.kind == 0
    seg_a = pos[contacts.i]
    seg_b = np.where(pp[:, None], pos[np.where(pp, contacts.j, 0)], contacts.point)
    return np.stack([seg_a, seg_b], axis=1)


def force_text(value: float) -> str:
    """A force of the legend as a reader writes it: 5,000 and 2.5, not 5e+03; a power of ten in
    mathtext beyond a million or below a thousandth."""
    if value == 0 or 1e-3 <= abs(value) < 1e6:
        return f"{value:,.0f}" if abs(value) >= 100 else f"{value:.3g}"
    exponent = int(np.floor(np.log10(abs(value))))
    return rf"${value / 10**exponent:.3g} \times 10^{{{exponent}}}$"


def _legend(ax, ref: float, max_width: float, unit: str) -> None:
    """Three line widths with their force, and the wall, below the drawing."""
    handles = [
        Line2D([], [], color=FORCE_COLOR, lw=max_width * v / ref, label=f"{force_text(v)} {unit}")
        for v in (ref, ref / 2, ref / 10)
    ]
    handles.append(Line2D([], [], color=WALL_COLOR, lw=2.5, label="wall"))
    ax.legend(
        handles=handles, title="contact force", loc="upper center", bbox_to_anchor=(0.5, -0.14),
        ncol=len(handles), frameon=False, fontsize=9,
    )  # fmt: skip


def plot_force_chains(
    contacts: ContactSet,
    pos,
    radius,
    walls,
    path: str | os.PathLike,
    *,
    thickness: float | None = None,
    title: str = "",
    box: tuple[float, float, float, float] | None = None,
    max_width: float = 4.0,
    show_disks: bool = True,
    notes: list[str] | None = None,
) -> Path:
    """Draw every touching contact as a line, width proportional to its force.

    ``pos`` (n, 2) and ``radius`` (n,) are the disks the contacts index, ``walls`` the wall
    segments as an (m, 2, 2) array (or None). Disk-disk contacts run centre to centre,
    disk-wall contacts from the centre to the contact point. With the disks' ``thickness``
    (m) forces are shown per metre of thickness (N/m, the paper's unit), without it in N.
    ``box`` = (x0, y0, x1, y1) is the drawn area (default: the disks). Walls are drawn in
    dark grey; the legend gives the force of three line widths.
    """
    pos, radius, walls = _check_inputs(contacts, pos, radius, walls)
    t = 1.0 if thickness is None else check_range("thickness", thickness, 0.0, None, lo_open=True)
    unit = "N" if thickness is None else "N/m"
    f = contacts.magnitude / t
    fmax = float(f.max()) if len(f) else 0.0
    ref = _nice(fmax) if fmax > 0 else 1.0
    widths = max_width * f / ref
    if box is None:
        x0, y0 = pos.min(axis=0) - radius.max()
        x1, y1 = pos.max(axis=0) + radius.max()
    else:
        x0, y0, x1, y1 = box
    fig_w = 9.0
    fig, ax = new_figure(figsize=(fig_w, fig_w * (y1 - y0) / (x1 - x0) + 1.6))
    if show_disks:
        disks = PatchCollection(
            [Circle(xy, r) for xy, r in zip(pos, radius, strict=True)],
            facecolor="#f2efe6", edgecolor="#c9c2ad", linewidth=0.2,
        )  # fmt: skip
        ax.add_collection(disks)
    order = np.argsort(f)  # strongest on top
    lines = _contact_lines(contacts, pos)[order]
    ax.add_collection(LineCollection(lines, linewidths=widths[order], colors=FORCE_COLOR, capstyle="round"))
    for a, b in walls:
        ax.plot([a[0], b[0]], [a[1], b[1]], color=WALL_COLOR, lw=2.5, solid_capstyle="butt", zorder=5)
    pad = 0.02 * (x1 - x0)  # walls beyond the drawing area are clipped by the limits
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(y0 - pad, y1 + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    _legend(ax, ref, max_width, unit)
    ax.set_title(title + ("\n" + "; ".join(notes) if notes else ""), fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def wall_segments(walls) -> np.ndarray:
    """The segments of a :class:`poro2d.dem.Walls` as an (m, 2, 2) array."""
    return np.stack([walls.p0, walls.p1], axis=1)


def plot_simulation_force_chains(
    sim,
    path: str | os.PathLike,
    title: str = "",
    box: tuple[float, float, float, float] | None = None,
    max_width: float = 4.0,
    per_thickness: bool = True,
    show_disks: bool = True,
    notes: list[str] | None = None,
) -> Path:
    """:func:`plot_force_chains` of a simulation's current contacts, disks and walls.

    Forces per metre of the disks' thickness (N/m) unless ``per_thickness`` is False.
    """
    p = sim.particles
    return plot_force_chains(
        sim.contacts(), p.pos, p.radius, wall_segments(sim.walls), path,
        thickness=p.thickness if per_thickness else None, title=title, box=box, max_width=max_width,
        show_disks=show_disks, notes=notes,
    )  # fmt: skip


__all__ = ["force_text", "plot_force_chains", "plot_simulation_force_chains", "wall_segments"]
