"""``poro2d relation``: the grading's n2D(nLab) relation from the criterion at several densities."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.markup import escape

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, Table

if TYPE_CHECKING:
    from poro2d.sweep.results import RelationResult

console = OutputConsole()
#: the relation's table
COLUMNS = ("nLab", "Dr", "n2D DEM (box n')", "interior n", "fit", "Eq. 12", "LIM 2D-3D", "LIM 2D-Lab", "flag")


def relation_cmd(
    config: Path = opt.config(help="Criterion config; optional \\[relation] table."),
    preset: str = opt.preset(),
    points: int = typer.Option(
        None, "--points", help="Laboratory porosities from n_max to n_min (default 5)."
    ),
    n_max: float = typer.Option(None, "--n-max", help="Loosest laboratory porosity (paper: 0.4571)."),
    n_min: float = typer.Option(None, "--n-min", help="Densest laboratory porosity (paper: 0.3253)."),
    out: Path = opt.out("relation-out"),
    scheduler: str = opt.scheduler(),
    workers: int = opt.workers(),
    quick: bool = typer.Option(False, "--quick", help="Small specimen (0.08 m x 0.04 m, 2 layers)."),
    mode: str = typer.Option(
        None, "--mode", help="density (default): preparation friction from the state; paper: fixed 0.05."
    ),
    seeds: int = typer.Option(None, "--seeds", help="Specimens per state and per calibration point (3)."),
    dashboard: str = opt.dashboard(),
    quiet: bool = opt.quiet(help="No progress bar."),
) -> None:
    """The grading's n2D(nLab) relation from the criterion at several relative densities.

    Density mode (default): the criterion is first calibrated (preparation friction ->
    accepted n2D, the grading's densest and loosest 2D states), every laboratory state is
    mapped between them by its relative density, and checked by the criterion over seeds.
    """
    from poro2d.io_utils import check_output_dir
    from poro2d.report.relation_figure import draw_relation
    from poro2d.store import Store
    from poro2d.sweep.relation import RelationCase, run_relation

    def banner() -> None:  # once every input is checked: a refusal is the only line
        console.print(f"criterion relation{' (quick)' if quick else ''} -> {out}")

    options = opt.job_options(workers, scheduler, quiet, dashboard)
    check_output_dir("--out", out)  # a bad folder is named before the config is read
    given = {"points": points, "n_max": n_max, "n_min": n_min, "seeds": seeds}
    with opt.named_as_typed(given):  # an option's value named as the user typed it
        case = RelationCase.from_config(config, preset=preset, mode=mode, quick=quick, **given)
    store = Store(out)
    rel = run_relation(case, store, options=options, announce=banner)
    draw_relation(rel, store)
    print_relation(rel, out)
    if rel.failed_cases:
        console.print(f"[bold red]{rel.failed_cases} case(s) failed[/]; tracebacks in {out}/**/error.txt")
        raise typer.Exit(1)


def register(app: typer.Typer) -> None:
    app.command("relation")(relation_cmd)


def print_relation(rel: RelationResult | dict, out: Path) -> None:
    from poro2d.sweep.results import RelationResult
    from poro2d.typed_result import part

    rel = part(RelationResult, rel)  # a relation's dict (relation.json as read) typed
    t = Table(title="n2D(nLab) from the criterion")
    for c in COLUMNS:
        t.add_column(c, justify="right")

    def f(v) -> str:
        return "" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.4f}"

    for p in rel.points:
        dem = f(p.n2d_dem)
        if rel.mode == "density" and dem:
            dem += f" +- {p.n2d_sd:.4f} ({p.seeds_converged}/{p.seeds})"
        inner = f(getattr(p, "n2d_interior", None))  # a paper-mode point has none
        if inner and p.n2d_interior_sd is not None:
            inner += f" +- {p.n2d_interior_sd:.4f}"
        fits = (f(p.n2d_fit), f(p.n2d_parabolic), f(p.n2d_lim_3d), f(p.n2d_lim_lab))
        t.add_row(f"{p.n_lab:.4f}", f"{p.relative_density:.2f}", dem, inner, *fits, p.flag or "ok")
    console.print(t)
    if rel.mode == "density":
        console.print(
            f"grading's 2D extremes (criterion end state): n2D,min {rel.n2d_min:.4f} (densest "
            f"preparation), n2D,max {rel.n2d_max:.4f} (loosest); mu_prep per state: "
            + ", ".join(f"{p.mu_prep:.3f}" for p in rel.points)
        )
        dropped = rel.calibration.dropped or []
        if dropped:
            console.print(
                f"[yellow]left out of the calibration (no seed could be prepared): mu_prep = {dropped}[/]; "
                "the extremes are those of the frictions that were"
            )
        sp = rel.spread
        if sp is not None:
            console.print(
                f"loose - dense: {sp.n2d_loose_minus_dense:+.4f} +- {sp.sd:.4f} (measured, not a fit); "
                f"{'monotone' if sp.monotone else 'NOT monotone'} in nLab"
            )
            d = sp.interior_loose_minus_dense  # the packing's own porosity, no gap under the plate
            if d is not None and math.isfinite(d):
                order = "monotone" if sp.interior_monotone else "NOT monotone"
                console.print(
                    f"interior porosity, loose - dense: {d:+.4f} +- {sp.interior_sd:.4f}; {order} in nLab"
                )
    fit = rel.fit
    if fit is not None:
        console.print(
            f"fit: n2D = {fit.a:.4f} nLab^2 + {fit.b:.4f} nLab (Eq. 12: 0.42, 0.25); "
            f"rms residual {fit.rms_residual:.4g}, max {fit.max_abs_residual:.4g}"
        )
    else:
        console.print(f"[yellow]{escape(rel.fit_note)}[/]")
    if rel.state_maps:
        print_state_maps(rel)
    console.print(f"figure {out}/relation.png, table {out}/relation.csv")


def print_state_maps(rel: RelationResult) -> None:
    """Each state's answer (the relative-density map's) beside the state-parameter map's."""
    maps = rel.state_maps
    first = maps[0]
    t = Table(title=f"the state parameter at p' = {first.test_stress_kpa:g} kPa")
    for c in ("nLab", "Dr", "lab psi/span", "answer n2D", "answer psi/span (2D)", "state map n2D"):
        t.add_column(c, justify="right")
    for p, m in zip(rel.points, maps, strict=True):
        by_state = "" if m.n2d_by_state is None else f"{m.n2d_by_state:.4f}"
        if by_state and not m.state_within_ends:
            by_state += " (beyond the ends)"
        t.add_row(
            f"{p.n_lab:.4f}", f"{p.relative_density:.2f}", f"{m.psi_norm_lab:+.3f}",
            f"{p.n2d_target:.4f}",
            "" if m.psi_norm_by_dr is None else f"{m.psi_norm_by_dr:+.3f}", by_state or "no 2D line",
        )  # fmt: skip
    console.print(t)
    console.print(
        f"laboratory line: {escape(first.lab_line)}; the answers stay the relative-density map's "
        "(docs/equivalence.md)" + ("" if first.e_cs_2d is not None else f"; {escape(first.note)}"),
        soft_wrap=True,
    )
