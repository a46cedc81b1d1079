"""What a calibration writes: result.json, the fit and posterior figures, a ready config, a report."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from poro2d.io_utils import atomic_path, write_json

FIT_PNG = "calibration_fit.png"
POSTERIOR_PNG = "calibration_posterior.png"
CONFIG_TOML = "calibrated.toml"


def write_outputs(out: Path, result, post, surrogates, lab, found, digests, base) -> None:
    """Figures, config and report first; ``result.json`` last (its presence says: finished)."""
    import matplotlib

    matplotlib.use("Agg")
    _fit_figure(out / FIT_PNG, result, lab, found, digests, base, out)
    _posterior_figure(out / POSTERIOR_PNG, result, post)
    _config(out / CONFIG_TOML, result, lab)
    from poro2d.report.calibration_report import write_calibration_report

    write_calibration_report(out, result)
    write_json(out / "result.json", result)


def _best_curves(result, lab, found, digests, base, out: Path) -> dict[float, list]:
    """The curves of the design point nearest the best parameters, per normal stress (all specimens)."""
    from poro2d.calibration.units import unit_curve, unit_job

    best = result.best
    nearest = min(
        result.evaluations,
        key=lambda e: (
            (math.log(e["particle_friction"] / best["particle_friction"])) ** 2
            + (e["rolling_friction"] - best["rolling_friction"]) ** 2
        ),
    )
    curves: dict[float, list] = {}
    for s in lab.normal_stresses():
        for label, path in found.items():
            job = unit_job(
                path,
                digests[label],
                s,
                base,
                nearest["particle_friction"],
                nearest["rolling_friction"],
                out / "cache",
            )
            curve = unit_curve(job)
            if curve is not None:
                curves.setdefault(s, []).append(curve)
    return curves, nearest


def _fit_figure(path: Path, result, lab, found, digests, base, out: Path) -> None:
    import matplotlib.pyplot as plt

    fig, (ax_peak, ax_curve) = plt.subplots(1, 2, figsize=(11, 4.2))
    obs = [o for o in result.posterior["observables"] if o["observable"] == "peak"]
    s = np.array([o["normal_stress_kpa"] for o in obs])
    ax_peak.plot(s, [o["lab_kpa"] for o in obs], "ks", label="laboratory peak")
    ax_peak.errorbar(
        s,
        [o["model_kpa"] for o in obs],
        yerr=[2 * o["noise_sd_kpa"] for o in obs],
        fmt="o",
        color="#b2182b",
        capsize=3,
        label="calibrated model (surrogate, +-2 sd)",
    )
    ends = [o for o in result.posterior["observables"] if o["observable"] == "end"]
    if ends:
        se = [o["normal_stress_kpa"] for o in ends]
        ax_peak.plot(se, [o["lab_kpa"] for o in ends], "k^", mfc="none", label="laboratory end")
        ax_peak.plot(se, [o["model_kpa"] for o in ends], "v", color="#2166ac", label="model end")
    ax_peak.set_xlabel("normal stress (kPa)")
    ax_peak.set_ylabel("shear stress (kPa)")
    ax_peak.set_xlim(left=0)
    ax_peak.set_ylim(bottom=0)
    ax_peak.legend(fontsize=8)
    b = result.best
    ax_peak.set_title(f"f_p = {b['particle_friction']:.3g}, mu_r = {b['rolling_friction']:.3g}", fontsize=10)
    curves, nearest = _best_curves(result, lab, found, digests, base, out)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, sigma in enumerate(lab.normal_stresses()):
        c = colors[k % len(colors)]
        for j, (d, t) in enumerate(curves.get(sigma, [])):
            ax_curve.plot(
                d * 1e3, t, color=c, lw=0.8, alpha=0.7, label=f"model {sigma:g} kPa" if j == 0 else None
            )
        if sigma in lab.curves:
            d, t = lab.curves[sigma]
            ax_curve.plot(d * 1e3, t, "k--", lw=1.0, label="laboratory" if k == 0 else None)
        else:
            ax_curve.axhline(lab.peaks[sigma], color=c, ls=":", lw=1.0)
    ax_curve.set_xlabel("shear displacement (mm)")
    ax_curve.set_ylabel("shear stress (kPa)")
    ax_curve.set_title(
        f"curves at the design point nearest the best (f_p = {nearest['particle_friction']:.3g}, "
        f"mu_r = {nearest['rolling_friction']:.3g})",
        fontsize=9,
    )
    ax_curve.legend(fontsize=7)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120, format="png")
    plt.close(fig)


def _posterior_figure(path: Path, result, post) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.2, 4.8))
    fp, mu_r = post.fp_values, post.mu_r_values
    mesh = ax.pcolormesh(fp, mu_r, post.density / post.density.max(), shading="auto", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="posterior density / its maximum")
    ev = result.evaluations
    ax.plot(
        [e["particle_friction"] for e in ev],
        [e["rolling_friction"] for e in ev],
        "w.",
        ms=7,
        mec="k",
        label="evaluated design points",
    )
    b = result.best
    ax.plot(b["particle_friction"], b["rolling_friction"], "r*", ms=13, label="posterior maximum")
    lo, hi = result.intervals["particle_friction"]
    ax.axvspan(lo, hi, color="w", alpha=0.12)
    lo, hi = result.intervals["rolling_friction"]
    ax.axhspan(lo, hi, color="w", alpha=0.12)
    ax.set_xscale("log")
    from matplotlib.ticker import FormatStrFormatter

    ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(FormatStrFormatter("%g"))
    ax.tick_params(axis="x", which="minor", labelsize=7)
    ax.set_xlabel("particle friction f_p")
    ax.set_ylabel("rolling friction mu_r")
    ax.set_title(
        f"posterior (correlation {result.posterior['correlation']:+.2f}); shaded: "
        f"{result.level:.0%} intervals",
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120, format="png")
    plt.close(fig)


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | float):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return '"' + str(v).replace("\\", "\\\\").replace('"', '\\"') + '"'


def _config(path: Path, result, lab) -> None:
    """A config with the calibrated values: ``[shear]`` for ``poro2d shear --config``, ``[specimen]``
    for a new specimen (``poro2d criterion``) to export with ``poro2d export``."""
    b = result.best
    shear = {k: v for k, v in result.settings.items() if v is not None}
    shear.update(
        particle_friction=b["particle_friction"],
        rolling_friction=b["rolling_friction"],
        normal_stress_kpa=lab.normal_stresses(),
    )
    fp_lo, fp_hi = result.intervals["particle_friction"]
    mr_lo, mr_hi = result.intervals["rolling_friction"]
    lines = [
        "# poro2d calibrate: the posterior maximum of particle and rolling friction",
        f"# ({result.level:.0%} intervals: f_p {fp_lo:.3g} to {fp_hi:.3g}, mu_r {mr_lo:.3g} to {mr_hi:.3g});"
        " see result.json and calibration.md before using them",
        "",
        "[specimen]",
        f"friction_particle = {_toml_value(b['particle_friction'])}",
        f"rolling_friction = {_toml_value(b['rolling_friction'])}",
        "",
        "[shear]",
    ] + [f"{k} = {_toml_value(v)}" for k, v in shear.items()]
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n")


__all__ = ["CONFIG_TOML", "FIT_PNG", "POSTERIOR_PNG", "write_outputs"]
