"""``poro2d sand``: a user's soil, from its laboratory description to the 2D porosity to use."""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, Table, shown

console = OutputConsole()


def print_preflight(case, pf) -> None:
    """The pre-flight table, printed before any DEM work."""
    from poro2d.sand.result import lab_text

    t = Table(title=f"pre-flight: {shown(case.name)}")
    t.add_column("quantity")
    t.add_column("value", justify="right")
    rows = [
        ("laboratory state", lab_text(case.lab)),
        (
            "grading",
            f"d {pf.d_min_m * 1e3:.3g}-{pf.d_max_m * 1e3:.3g} mm in the model (x{pf.upscale:g}), "
            f"d50 {pf.d50_m * 1e3:.3g} mm, Cu {pf.cu:.2f}, d_max/d_min {pf.size_ratio:.0f}",
        ),
        (
            "full box",
            f"{pf.box.width:g} x {pf.box.height:g} m, {pf.box.layers} layers, about {pf.box.disks:.0f} disks",
        ),
        ("layer band", f"{pf.box.band_height * 1e3:.1f} mm = {pf.band_over_d_max:.1f} d_max"),
        (
            "calibration box",
            f"{pf.calibration_box.width:g} x {pf.calibration_box.height:g} m, "
            f"{pf.calibration_box.layers} layers, about {pf.calibration_box.disks:.0f} disks",
        ),
        (
            "time step",
            f"{pf.time_step_s:.3g} s ({pf.time_step_s / pf.time_step_paper_s:.2f} x the paper grading's)",
        ),
        (
            "jamming porosity",
            "n/a: " + pf.jamming.note
            if pf.jamming.porosity is None
            else f"{pf.jamming.porosity:.4f} +- {pf.jamming.sd:.4f} "
            f"({pf.jamming.seeds} seeds, {pf.jamming.disks} disks)",
        ),
        (
            "first trial (densest preparation)",
            f"{pf.first_trial:.3f} (Eq. 12 would start at {pf.eq12_trial:.3f})",
        ),
        ("cases", f"calibration {pf.cases_calibration} at most, specimens {pf.cases_specimens}"),
        ("estimated particle-steps", f"{pf.particle_steps.calibration + pf.particle_steps.specimens:.3g}"),
        (
            "estimated run time",
            f"{pf.seconds.total / 60:.0f} min on {pf.workers} core(s) (a model: "
            "the run prints its measured pace)",
        ),
    ]
    for k, v in rows:
        t.add_row(k, shown(v))
    console.print(t)
    if pf.suggestion:
        console.print(f"[bold]budget:[/] {shown(pf.suggestion)}", soft_wrap=True)
    for note in pf.notes:
        console.print(f"[yellow]note:[/] {shown(note)}", soft_wrap=True)


def print_result(res, out: Path) -> None:
    """The answer: the interior porosity first, then n', the friction, every seed."""
    from poro2d.sand.result import mean_sd_text, state_text, used_seeds, warnings

    head = f"{res.soil.name} at {state_text(res.state)}"
    if res.interior_porosity_mean is not None:  # None: no seed accepted (as sand.json keeps NaN)
        console.print(
            f"[bold]interior porosity {res.interior_porosity_mean:.4f} +- {res.interior_porosity_sd:.4f}[/] "
            f"({res.seeds_accepted} of {res.seeds} seeds{used_seeds(res)}): the 2D porosity of {shown(head)}",
            soft_wrap=True,
        )
    if res.answer_error is not None:
        console.print(f"the answer's {res.answer_error.text()}", soft_wrap=True)
    if res.state_reached is not None:
        console.print(f"the {res.state_reached.text()}", soft_wrap=True)
    t = Table(title="poro2d sand")
    for col in ("seed", "accepted", "interior n", "box n'", "disks", "specimen folder"):
        t.add_column(col, justify="right")
    for k in res.specimens:
        t.add_row(
            str(k.seed),
            "yes" if k.accepted else "no",
            _f(k.interior_porosity),
            _f(k.box_porosity),
            str(k.particle_count or ""),
            shown(str(out / k.folder)) if k.folder else "",
        )
    console.print(t)
    console.print(
        f"box porosity n' {mean_sd_text(res.box_porosity_mean, res.box_porosity_sd)}; "
        f"mu_prep {res.mu_prep:.3f}; "
        f"2D extremes {res.n2d_min:.4f}-{res.n2d_max:.4f}; jamming porosity "
        + ("n/a" if res.jamming_porosity is None else f"{res.jamming_porosity:.4f}"),
        soft_wrap=True,
    )
    console.print(
        f"summary: {shown(str(out / 'summary.md'))} (also summary.csv, sand.json, fig_grading.png)",
        soft_wrap=True,
    )
    for r in res.seeds_replaced:
        by = "" if r.replaced_by is None else f"; replaced by seed {r.replaced_by}"
        console.print(f"[bold red]seed {r.seed} not accepted:[/] {shown(r.reason + by)}", soft_wrap=True)
    if res.state_map is not None:
        from poro2d.critical_state.state_table import state_map_lines

        for line in state_map_lines(res.state_map):
            console.print(shown(line), soft_wrap=True)
    for w in warnings(res):
        if not w.startswith("seed"):  # the refused seeds were named above, with why
            console.print(f"[yellow]note:[/] {shown(w)}", soft_wrap=True)


def _f(v) -> str:
    return "" if v is None else f"{v:.4f}"


def sand_cmd(
    config: Path = typer.Argument(
        ..., help="Sand config: \\[soil], \\[grading], \\[lab] (and \\[specimen], \\[sand])."
    ),
    out: Path = opt.out("sand-out"),
    seeds: int = typer.Option(None, "--seeds", help="Specimens at full size (default 3, or \\[sand] seeds)."),
    budget: float = typer.Option(
        None, "--budget", help="Target run time in minutes: the pre-flight says what fits."
    ),
    preflight_only: bool = typer.Option(
        False, "--preflight", help="Print the pre-flight and stop (no DEM work)."
    ),
    workers: int = opt.workers(help="Worker processes (default: one per core)."),
    scheduler: str = opt.scheduler(help="Address of a running Dask scheduler."),
    quiet: bool = opt.quiet(),
) -> None:
    """The density-aware 2D porosity of your soil at its laboratory state, over seeds.

    From a grading and e_max/e_min (or n_max/n_min) with the state as e, n, Dr or dry
    density: a pre-flight (disks, time step, jamming porosity, run time), a calibration in a
    small box, specimens at full size, and the interior porosity to use in other codes.
    """
    from poro2d.execute.options import RunOptions
    from poro2d.report.grading_figure import draw_grading
    from poro2d.sand.case import load_sand_case
    from poro2d.sand.run import check_soil, run_sand
    from poro2d.store import Store

    options = RunOptions(workers, scheduler, progress=not quiet)  # --workers, --scheduler checked first
    if preflight_only:
        case, pf = check_soil(config, seeds=seeds, workers=workers, budget_minutes=budget)
        print_preflight(case, pf)
        return
    cases = []  # the soil as checked, handed over with its pre-flight: the grading figure's

    def preflight(case, pf) -> None:
        cases.append(case)
        print_preflight(case, pf)

    store = Store(out)
    res = run_sand(
        load_sand_case(config, seeds=seeds, budget_minutes=budget),
        store,
        options=options,
        announce=lambda line: console.print(shown(line), soft_wrap=True),
        on_preflight=preflight,
    )
    draw_grading(res, cases[0], store)
    print_result(res, out)
    if not res.converged:
        console.print(
            f"[bold red]error:[/] {res.seeds_accepted} of {res.seeds} seeds accepted, with "
            f"{sum(r.replaced_by is not None for r in res.seeds_replaced)} replaced (\\[sand] replacements "
            "at most): the answer is over fewer specimens (summary.md says why each was refused)",
            soft_wrap=True,
        )
        raise typer.Exit(1)


def register(app: typer.Typer) -> None:
    app.command("sand")(sand_cmd)


__all__ = ["print_preflight", "print_result", "register", "sand_cmd"]
