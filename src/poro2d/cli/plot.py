"""``poro2d plot relations [--n-max X --n-min Y] [-o DIR]``: the paper's Figs. 1 and 2."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from poro2d import porosity as P
from poro2d.cli import options as opt
from poro2d.cli.convert import NuReading, OneLineUsageCommand
from poro2d.errors import InputError, check_range


def plot_relations(
    ctx: typer.Context,
    n_max: Annotated[float, typer.Option("--n-max", help="Laboratory maximum porosity.")] = P.PAPER_N_MAX,
    n_min: Annotated[float, typer.Option("--n-min", help="Laboratory minimum porosity.")] = P.PAPER_N_MIN,
    out_dir: Annotated[
        Path, typer.Option("-o", "--out-dir", help="Output directory (created if missing).")
    ] = Path("."),
    mark_n_lab: Annotated[
        float | None,
        typer.Option("--mark-n-lab", help="Mark one laboratory porosity on both figures (e.g. 0.3434)."),
    ] = None,
    nu_reading: Annotated[
        NuReading, opt.nu_reading(help="Reading of nu in Eq. 2 for the main Eq. 2 curve.")
    ] = NuReading.printed,
    lattice_exact: Annotated[bool, opt.lattice_exact(help="Exact lattice 2D extremes in Eqs. 7-11.")] = False,
) -> None:
    """Write the paper's Fig. 1 and Fig. 2 (PNG and SVG) into DIR."""
    if ctx.args:
        raise InputError(
            "option",
            ctx.args[0],
            "--n-max, --n-min, -o/--out-dir, --mark-n-lab, --nu-reading, --lattice-exact",
        )
    check_range("--n-max", n_max, 0.0, 1.0, hi_open=True)
    check_range("--n-min", n_min, 0.0, 1.0, hi_open=True)
    if not n_max > n_min:
        raise InputError("--n-max", n_max, f"greater than --n-min = {n_min}")
    if mark_n_lab is not None:
        check_range("--mark-n-lab", mark_n_lab, 0.0, 0.5)
    from poro2d.io_utils import check_output_dir
    from poro2d.locks import check_no_run
    from poro2d.report.conversion_figures import write_relation_figures

    check_output_dir("--out-dir", out_dir)
    check_no_run("--out-dir", out_dir)  # the figures would replace a run's own (the paper's Figs. 1-2)

    paths = write_relation_figures(
        out_dir,
        n_max,
        n_min,
        nu_reading=nu_reading.value,
        lattice_exact=lattice_exact,
        mark_n_lab=mark_n_lab,
    )
    for p in paths:
        typer.echo(str(p))


def register(app: typer.Typer) -> None:
    """Attach ``plot relations`` to the root app, under its ``plot`` group."""
    plot_app = None
    for group in app.registered_groups:
        if group.name == "plot" and group.typer_instance is not None:
            plot_app = group.typer_instance
            break
    if plot_app is None:
        plot_app = typer.Typer(help="Figures.", no_args_is_help=True)
        app.add_typer(plot_app, name="plot")
    plot_app.command(
        "relations",
        cls=OneLineUsageCommand,
        context_settings={"ignore_unknown_options": True, "allow_extra_args": True},
    )(plot_relations)
