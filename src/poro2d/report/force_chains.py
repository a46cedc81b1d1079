"""Contact force chains like the paper's Figs. 5-7: line width proportional to force."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PatchCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

from poro2d.io_utils import atomic_path  # noqa: E402


def _nice(x: float) -> float:
    if x <= 0:
        return 1.0
    e = 10 ** np.floor(np.log10(x))
    for m in (1, 2, 5, 10):
        if m * e >= x * 0.999:
            return float(m * e)
    return float(10 * e)


def plot_force_chains(
    sim,
    path: str | os.PathLike,
    title: str = "",
    box: tuple[float, float, float, float] | None = None,
    max_width: float = 4.0,
    per_thickness: bool = True,
    show_disks: bool = True,
    notes: list[str] | None = None,
) -> Path:
    """Draw every touching contact as a line, width proportional to its force.

    Disk-disk contacts run centre to centre, disk-wall contacts from the centre to
    the contact point. Forces are shown per metre of thickness (N/m, the paper's
    unit) unless ``per_thickness`` is False. Walls are drawn in dark grey; the
    legend gives the force of three line widths.
    """
    c = sim.contacts()
    p = sim.particles
    t = p.thickness if per_thickness else 1.0
    unit = "N/m" if per_thickness else "N"
    f = c.magnitude / t
    pp = c.kind == 0
    seg_a = p.pos[c.i]
    seg_b = np.where(pp[:, None], p.pos[np.where(pp, c.j, 0)], c.point)
    fmax = float(f.max()) if len(f) else 0.0
    ref = _nice(fmax) if fmax > 0 else 1.0
    widths = max_width * f / ref

    if box is None:
        x0, y0 = p.pos.min(axis=0) - p.radius.max()
        x1, y1 = p.pos.max(axis=0) + p.radius.max()
    else:
        x0, y0, x1, y1 = box
    aspect = (y1 - y0) / (x1 - x0)
    fig_w = 9.0
    fig, ax = plt.subplots(figsize=(fig_w, fig_w * aspect + 1.6))
    if show_disks:
        disks = PatchCollection(
            [Circle(xy, r) for xy, r in zip(p.pos, p.radius, strict=True)],
            facecolor="#f2efe6", edgecolor="#c9c2ad", linewidth=0.2,
        )  # fmt: skip
        ax.add_collection(disks)
    order = np.argsort(f)  # strongest on top
    lc = LineCollection(
        np.stack([seg_a, seg_b], axis=1)[order], linewidths=widths[order], colors="#b2182b", capstyle="round"
    )
    ax.add_collection(lc)
    # walls, clipped to the drawing area
    for w in range(sim.walls.n):
        a, b = sim.walls.p0[w], sim.walls.p1[w]
        ax.plot([a[0], b[0]], [a[1], b[1]], color="#333333", lw=2.5, solid_capstyle="butt", zorder=5)
    pad = 0.02 * (x1 - x0)
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(y0 - pad, y1 + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    handles = [
        Line2D([], [], color="#b2182b", lw=max_width * v / ref, label=f"{v:,.3g} {unit}")
        for v in (ref, ref / 2, ref / 10)
    ]
    handles.append(Line2D([], [], color="#333333", lw=2.5, label="wall"))
    ax.legend(
        handles=handles, title="contact force", loc="upper center", bbox_to_anchor=(0.5, -0.14),
        ncol=len(handles), frameon=False, fontsize=9,
    )  # fmt: skip
    full = title
    if notes:
        full += "\n" + "; ".join(notes)
    ax.set_title(full, fontsize=10)
    fig.tight_layout()
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=150, format=path.suffix.lstrip(".") or "png")
    plt.close(fig)
    return path
