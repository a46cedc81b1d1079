"""The strength study's figure: friction angles and dilation against the rolling friction.

Left: peak (solid) and residual (dashed) friction angles against mu_r, one colour per
particle friction f_p, error bars one sd over the specimens. Right: the largest dilation
angle likewise.
"""

from __future__ import annotations

import os
from pathlib import Path

from poro2d.report.figure_file import new_figure, save_figure
from poro2d.report.shear_figures import COLORS


def _series(rows: list, friction: float, key: str) -> tuple[list, list, list]:
    """(mu_r, mean, sd) of one quantity for one particle friction, sorted by mu_r."""
    picked = sorted((r for r in rows if r.particle_friction == friction), key=lambda r: r.mu_r)
    picked = [r for r in picked if getattr(r, f"{key}_mean_deg") is not None]
    return (
        [r.mu_r for r in picked],
        [getattr(r, f"{key}_mean_deg") for r in picked],
        [getattr(r, f"{key}_sd_deg") or 0.0 for r in picked],
    )


def draw_strength(result, store) -> Path:
    """``fig_strength.png`` of a finished strength study (a :class:`StrengthResult`) in its store."""
    return plot_strength(result.cases, store.path("fig_strength.png"))


def plot_strength(rows: list, path: str | os.PathLike) -> Path:
    """Peak and residual friction angles (left) and max dilation angle (right) against mu_r."""
    frictions = sorted({r.particle_friction for r in rows})
    fig, (ax_phi, ax_psi) = new_figure(1, 2, figsize=(10, 4.2))
    for k, fp in enumerate(frictions):
        color = COLORS[k % len(COLORS)]
        x, y, e = _series(rows, fp, "peak_friction_angle")
        ax_phi.errorbar(x, y, yerr=e, color=color, marker="o", capsize=3, label=f"peak, $f_p$ = {fp:g}")
        x, y, e = _series(rows, fp, "residual_friction_angle")
        ax_phi.errorbar(x, y, yerr=e, color=color, marker="s", ls="--", mfc="none", capsize=3,
                        label=f"residual, $f_p$ = {fp:g}")  # fmt: skip
        x, y, e = _series(rows, fp, "max_dilation_angle")
        ax_psi.errorbar(x, y, yerr=e, color=color, marker="o", capsize=3, label=f"$f_p$ = {fp:g}")
    n = max((r.specimens for r in rows), default=0)
    ax_phi.set(xlabel=r"rolling friction $\mu_r$", ylabel=r"friction angle $\varphi$ (°)",
               title=rf"Peak and residual friction angle (mean $\pm$ sd, {n} specimens)")  # fmt: skip
    ax_psi.set(
        xlabel=r"rolling friction $\mu_r$",
        ylabel=r"largest dilation angle $\psi$ (°)",
        title="Largest dilation angle",
    )
    for ax in (ax_phi, ax_psi):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    return save_figure(fig, path)


__all__ = ["draw_strength", "plot_strength"]
