"""The biaxial test's figure: stress ratio and volumetric strain against axial strain.

(a) the mobilized friction sin(phi) = (sigma_1 - sigma_3) / (sigma_1 + sigma_3) against the
axial strain, one line per replicate, the mean over the replicates' end windows (where the
critical state is read) as a dotted line; (b) the volumetric strain (compression positive, so dilation goes
down) against the axial strain. Laboratory curves, when the user gives them, are drawn in
black, dashed. Made from arrays: no file is opened here.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from poro2d.report.figure_file import save_figure  # noqa: E402
from poro2d.report.shear_figures import COLORS  # noqa: E402


def plot_biaxial(
    curves: Sequence[tuple[str, Mapping[str, np.ndarray]]],
    path: str | os.PathLike,
    *,
    title: str,
    critical: tuple[float, float] | None = None,
    lab: Mapping[str, np.ndarray | None] | None = None,
    lab_label: str = "laboratory",
) -> Path:
    """The figure of ``curves`` (label, arrays ``axial_strain``, ``sin_phi``, ``volumetric_strain``).

    ``critical``: (sin phi, start of the window as axial strain) of the critical state, drawn as
    a line; ``lab``: arrays ``axial_strain``, ``stress_ratio`` and ``volumetric_strain`` (or None).
    """
    fig, (ax, bx) = plt.subplots(
        2, 1, figsize=(7.0, 7.0), sharex=True, gridspec_kw={"height_ratios": [1.6, 1]}
    )
    for k, (label, c) in enumerate(curves):
        col = COLORS[k % len(COLORS)]
        ax.plot(100 * c["axial_strain"], c["sin_phi"], color=col, lw=1.0, label=label)
        bx.plot(100 * c["axial_strain"], 100 * c["volumetric_strain"], color=col, lw=1.0)
    if critical is not None:
        s_cs, start = critical
        ax.axhline(s_cs, color="0.4", lw=0.8, ls=":", label=f"mean from {100 * start:.0f} %: {s_cs:.3f}")
    if lab is not None:
        e1 = 100 * np.asarray(lab["axial_strain"])
        ax.plot(e1, lab["stress_ratio"], "k--", lw=1.2, label=lab_label)
        if lab.get("volumetric_strain") is not None:
            bx.plot(e1, 100 * np.asarray(lab["volumetric_strain"]), "k--", lw=1.2)
    ax.set_ylabel("sin(phi) = (sigma_1 - sigma_3) / (sigma_1 + sigma_3)")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3)
    bx.axhline(0.0, color="0.6", lw=0.6)
    bx.set_xlabel("axial strain eps_1 (%)")
    bx.set_ylabel("volumetric strain eps_v (%)\n(compression +)")
    bx.grid(alpha=0.3)
    fig.tight_layout()
    return save_figure(fig, path)


__all__ = ["plot_biaxial"]
