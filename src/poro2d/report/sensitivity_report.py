"""The figure and the report section of the sensitivity study (``poro2d sensitivity``).

Both read only the study's result dict (as written to ``sensitivity.json``), so a
report can be rebuilt from the file; the typed study (a ``SensitivityResult``, or the dict of
its typed parts being written) is read as that dict. Values that were undefined (no converged
seed) come back from JSON as ``None`` and are shown as such.
"""

from __future__ import annotations

import math
from pathlib import Path

from poro2d.io_utils import as_json, float_or_nan
from poro2d.report.document import Block
from poro2d.report.figure_file import BLUE, BLUISH_GREEN, REDDISH_PURPLE, VERMILION, new_figure, save_figure


def draw_sensitivity(result, store) -> list[Path]:
    """``sensitivity.png`` and ``.svg`` of a finished study (a :class:`SensitivityResult`) in its store."""
    return plot_sensitivity(result.to_dict(), store.path("sensitivity"))


def _ok(p: dict) -> bool:
    return math.isfinite(float_or_nan(p.get("n2d_mean")))


def plot_sensitivity(sens: dict, stem: Path) -> list[Path]:
    """Two panels, written as ``stem.png`` and ``stem.svg``: n2D against Cu and against mu_prep."""
    sens = as_json(sens)  # the dict of sensitivity.json
    paper = sens["paper"]
    target, tol = float(paper["accepted_porosity"]), float(sens["answer"]["tolerance"])
    fig, (ax1, ax2) = new_figure(1, 2, sharey=True, figsize=(12.0, 5.2), layout="constrained")
    for ax in (ax1, ax2):
        ax.axhspan(target - tol, target + tol, color=BLUISH_GREEN, alpha=0.12, lw=0)
        label = rf"paper: accepted $n_{{2D}}$ = {target:g} ($\pm$ {tol:g})"
        ax.axhline(target, color=BLUISH_GREEN, lw=1.5, label=label)
        ax.grid(True, alpha=0.3)
    _grading_panel(ax1, sens)
    _mu_panel(ax2, sens)
    s = sens["settings"]
    fig.suptitle(
        f"Accepted 2D porosity, paper protocol ($n_{{Lab}}$ = {s['n_lab']:g}, "
        f"first trial {s['first_trial']:g} "
        rf"from {s['first_trial_from']}); mean $\pm$ sd over {s['seeds']} seed(s)"
        + ("; quick box" if s.get("quick") else ""),
        fontsize=11,
    )
    paths = [stem.with_suffix(".png"), stem.with_suffix(".svg")]
    save_figure(fig, *paths)
    return paths


def _errorbar(ax, pts: list[dict], x: str, **kw) -> None:
    ok = [p for p in pts if _ok(p)]
    if ok:
        ax.errorbar([p[x] for p in ok], [p["n2d_mean"] for p in ok],
                    yerr=[float_or_nan(p["n2d_sd"]) for p in ok], capsize=4, **kw)  # fmt: skip
    for p in pts:
        if p["unconverged"]:
            y = p["n2d_mean"] if _ok(p) else ax.get_ylim()[0]
            ax.annotate(f"{p['n']}/{p['seeds']} converged", (p[x], y), textcoords="offset points",
                        xytext=(5, 8), fontsize=8, color=VERMILION)  # fmt: skip


def _grading_panel(ax, sens: dict) -> None:
    pts = sens["points"]["grading"]
    family = [p for p in pts if p["cu_nominal"] is not None]
    ref = [p for p in pts if p["cu_nominal"] is None]
    label = "log-linear grading, same mean disk area"
    _errorbar(ax, family, "cu", fmt="o-", color=BLUE, ms=7, label=label)
    _errorbar(ax, ref, "cu", fmt="*", color=VERMILION, ms=15,
              label=f"poro2d's reference grading ($C_u$ = {ref[0]['cu']:.2f})" if ref else None)  # fmt: skip
    ax.set_xlabel(r"coefficient of uniformity $C_u = d_{60} / d_{10}$ [-]")
    ax.set_ylabel(r"accepted 2D porosity $n_{2D}$ [-]")
    ax.set_title(rf"grading width at $\mu_{{prep}}$ = {sens['settings']['mu_prep']:g}", fontsize=10)
    ax.legend(loc="best", fontsize=8.5, frameon=False)


def _mu_panel(ax, sens: dict) -> None:
    mu0 = sens["settings"]["mu_prep"]
    _errorbar(ax, sens["points"]["mu_prep"], "mu_prep", fmt="s-", color=REDDISH_PURPLE, ms=6,
              label=r"calibration: $n'$ of the accepted trial (first trial 0.19)")  # fmt: skip
    # like for like: the measured n' of the paper protocol's accepted trial, beside the calibration's
    ref = [p for p in sens["points"]["grading"] if p["cu_nominal"] is None]
    if ref and math.isfinite(float_or_nan(ref[0].get("measured_mean"))):
        first = sens["settings"]["first_trial"]
        ax.errorbar([mu0], [ref[0]["measured_mean"]], yerr=[float_or_nan(ref[0]["measured_sd"])], fmt="*",
                    color=VERMILION, ms=15, capsize=4,
                    label=f"paper protocol (first trial {first:g}): $n'$ of the accepted trial")  # fmt: skip
    ax.axvline(mu0, color="0.3", ls=":", lw=1.2, label=rf"paper: $\mu_{{prep}}$ = {mu0:g}")
    ax.set_xlabel(r"preparation friction $\mu_{prep}$ [-]")
    ax.set_title("preparation friction, reference grading", fontsize=10)
    ax.legend(loc="best", fontsize=8.5, frameon=False)


def _pm(p: dict) -> str:
    if not _ok(p):
        return "-"
    return f"{p['n2d_mean']:.4f} +- {float_or_nan(p['n2d_sd']):.4f}"


def report_blocks(sens: dict, figure: str | Path | None = None) -> list[Block]:
    """The report section of a sensitivity study, in the blocks of :mod:`poro2d.report.document`.

    ``figure``: the study's PNG; by default the one recorded in ``sens["figure"]``.
    """
    sens = as_json(sens)  # the dict of sensitivity.json
    s, paper = sens["settings"], sens["paper"]
    b: list[Block] = [("h2", "Why the paper gets 0.15: grading width and preparation friction")]
    b.append((
        "p",
        f"The criterion with the paper's protocol (mu_prep = {s['mu_prep']:g}, first trial "
        f"{s['first_trial']:g} from {s['first_trial_from']} at nLab = {s['n_lab']:g}) for gradings of "
        "several widths at the reference grading's mean disk area (the same number of disks), and the "
        f"reference grading at several preparation frictions; {s['seeds']} seed(s) per point "
        f"(seeds {', '.join(map(str, s['seed_list']))}), mean +- sample sd."
        + (" Quick mode: a reduced box, not the paper's." if s.get("quick") else ""),
    ))  # fmt: skip
    g_rows = [
        [p["label"], p["cu"], p["d_max_mm"], _pm(p), p["n"], p["unconverged"],
         float_or_nan(p["measured_mean"]), float_or_nan(p.get("interior_mean")),
         float_or_nan(p["first_f_top_over_g_mean"])]
        for p in sens["points"]["grading"]
    ]  # fmt: skip
    b.append(("table", ["grading", "Cu", "d_max (mm)", "accepted n2D", "n", "unconverged", "n' accepted",
                        "interior porosity", "first trial F_top / G"], g_rows))  # fmt: skip
    m_rows = [[p["mu_prep"], _pm(p), p["n"], p["unconverged"]] for p in sens["points"]["mu_prep"]]
    b.append(("table", ["mu_prep", "n' of the accepted trial", "n", "unconverged"], m_rows))
    b.extend(_first_trial_table(sens, paper))
    fig = figure if figure is not None else sens.get("figure")
    if fig:
        b.append(("img", Path(fig), "Accepted n2D against grading width (left) and preparation friction "
                  "(right); the band is the paper's 0.15 +- 0.005"))  # fmt: skip
    b.append(("ul", list(sens["answer"]["lines"])))
    return b


def _first_trial_table(sens: dict, paper: dict) -> list[Block]:
    ref = next((p for p in sens["points"]["grading"] if p["cu_nominal"] is None), None)
    if ref is None or not math.isfinite(float_or_nan(ref.get("first_f_top_mean"))):
        return []
    paper_f = 1e3 * paper["f_top_first_trial_kn_per_m"]
    paper_g = paper["self_weight_first_trial_n_per_m"]
    rows = [
        ["first trial n2D", ref["first_trial_porosity"], paper["trials"][0]],
        ["F_top at H (N/m)", float_or_nan(ref["first_f_top_mean"]), paper_f],
        ["G (N/m)", float_or_nan(ref["first_g_mean"]), paper_g],
        ["F_top / G", float_or_nan(ref["first_f_top_over_g_mean"]), paper_f / paper_g],
        ["n' after the plate moved", float_or_nan(ref["first_n_prime_mean"]),
         paper["trials"][0] + paper["porosity_change_first_trial"]],
        ["F_top, accepted trial (N/m)", float_or_nan(ref["accepted_f_top_mean"]),
         paper["f_top_accepted_n_per_m"]],
    ]  # fmt: skip
    return [("table", ["first trial, reference grading", "poro2d (mean over seeds)", "paper"], rows)]


__all__ = ["plot_sensitivity", "report_blocks"]
