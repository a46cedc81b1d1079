"""The criterion's answer as a table: the trials of Fig. 3 (``poro2d criterion``, ``poro2d paper``).

It lives on the criterion's floor because :func:`poro2d.paper.run_paper` prints it too; the
command itself (its two modes) is :mod:`poro2d.cli.criterion`.
"""

from __future__ import annotations

from poro2d.console import OutputConsole, Table, shown
from poro2d.criterion.result import CriterionResult
from poro2d.store import Store

console = OutputConsole()


def print_result(result: CriterionResult, store: Store) -> None:
    """The trials of ``result`` as a table, its message and where ``store`` keeps it."""
    t = Table(title=f"criterion (Fig. 3): nLab = {result.n_lab}")
    for col in ("trial n2D", "disks", "F_top N/m", "F_bottom N/m", "G N/m", "plate", "dz (mm)", "n' (box)",
                "|n'-n2D|", "interior n", "gap/d50", "accepted"):  # fmt: skip
        t.add_column(col, justify="right")
    rows = [trial.to_dict() for trial in result.iterations]  # each trial as its row
    for r in rows:
        t.add_row(
            f"{r['trial_porosity']:.3f}", str(r["particle_count"]), f"{r['f_top_n_per_m']:.4g}",
            f"{r['f_bottom_n_per_m']:.4g}", f"{r['self_weight_n_per_m']:.4g}", r["plate_moved"],
            f"{1e3 * r['plate_displacement_m']:.3f}", _fixed_or_dash(r["new_porosity"]),
            _fixed_or_dash(r["porosity_change"]), _interior(r),
            _fixed_or_dash(r.get("surface_gap_mean_d50"), 2), _verdict(r),
        )  # fmt: skip
    console.print(t)
    for r in rows:
        if r.get("overfull_m"):
            console.print(
                f"trial {r['iteration']} (n2D = {r['trial_porosity']:.4f}): over-full box, the specimen "
                f"stood {1e3 * r['overfull_m']:.3g} mm above H; n' from where the plate settled",
                soft_wrap=True,
            )
    if result.preparation_note:
        console.print(f"preparation: {result.preparation_note}", soft_wrap=True)
    console.print(f"{shown(result.message)}; results in {store.root}/result.json")
    if result.interior_porosity is not None:
        under_lid = result.settings.acceptance == "fill"
        what = (
            "under the lid: the box the specimen fills"
            if under_lid
            else "the paper's, gap under the plate included"
        )
        console.print(
            f"accepted specimen: box porosity n' {result.box_porosity:.4f} ({what}), interior porosity "
            f"{result.interior_porosity:.4f} +- "
            f"{result.interior_porosity_std:.4f} (the packing's own; docs/porosity.md)",
            soft_wrap=True,
        )


def _interior(r: dict) -> str:
    """The interior porosity of a trial's decision state with its spread over the circles."""
    if r.get("interior_porosity") is None:
        return "-"
    return f"{r['interior_porosity']:.4f}+-{r['interior_porosity_std']:.4f}"


def _fixed_or_dash(x, digits: int = 4) -> str:
    """A value for the table with ``digits`` decimals; a trial refused before its plate stage
    has none ("-")."""
    return "-" if x is None else f"{x:.{digits}f}"


def _verdict(r: dict) -> str:
    if r["accepted"]:
        return "yes"
    return f"refused ({r.get('failed_stage') or r.get('failed_check')})" if r.get("refused") else "no"
