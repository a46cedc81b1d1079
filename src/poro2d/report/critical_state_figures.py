"""The periodic reference's figure: stress ratio and solid fraction against shear strain.

(a) tau / sigma_yy against gamma, one line per seed; (b) the solid fraction. The start of the
steady-state window is a vertical line, the study's means over it dotted horizontal lines.
Made from arrays (each series needs ``gamma``, ``stress_ratio`` and ``solid_fraction``): no
file is opened here.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from poro2d.report.figure_file import save_figure  # noqa: E402
from poro2d.report.shear_figures import COLORS  # noqa: E402


def plot_critical_state(
    series: Sequence[tuple[str, Any]], path: str | os.PathLike, *, title: str, window: float,
    steady: tuple[float, float] | None = None,
) -> Path:  # fmt: skip
    """The figure of ``series`` (label, series); ``window``: gamma where the steady window
    starts; ``steady``: (stress ratio, solid fraction) means to draw, or None."""
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7.0, 6.5), sharex=True)
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
    ax.set_ylabel("stress ratio tau / sigma_yy")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8, loc="lower right")
    bx.set_ylabel("solid fraction")
    bx.set_xlabel("shear strain gamma")
    fig.tight_layout()
    return save_figure(fig, path)


__all__ = ["plot_critical_state"]
