"""``poro2d sensitivity``: the accepted n2D against grading width and preparation friction."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, Table

if TYPE_CHECKING:
    from poro2d.sweep.results import SensitivityResult

console = OutputConsole()


def register(app: typer.Typer) -> None:
    @app.command("sensitivity")
    def sensitivity_cmd(
        config: Path = opt.config(
            help="Criterion config; optional \\[sensitivity] table (cu, mu_prep, seeds)."
        ),
        preset: str = opt.preset(help="Built-in case: 'paper' (the default)."),
        out: Path = opt.out("sensitivity-out"),
        quick: bool = typer.Option(
            False, "--quick", help="Small box (0.08 m x 0.04 m, 2 layers), Cu up to 3, 2 seeds."
        ),
        seeds: int = typer.Option(None, "--seeds", help="Specimens per point (default 3, quick 2)."),
        scheduler: str = opt.scheduler(help="Address of a running Dask scheduler."),
        workers: int = opt.workers(help="Worker processes of the local cluster."),
        dashboard: str = opt.dashboard(
            help="Local cluster dashboard: HOST:PORT or none (default 127.0.0.1:0)."
        ),
        quiet: bool = opt.quiet(help="No progress bar."),
    ) -> None:
        """Why the paper's case gives what it gives: the criterion in the paper's protocol
        (mu_prep 0.05, first trial from Eq. 12) against grading width (Cu) and against
        preparation friction, over seeds, beside the paper's 0.15."""
        from poro2d.errors import check_int
        from poro2d.io_utils import check_output_dir
        from poro2d.report.sensitivity_report import draw_sensitivity
        from poro2d.store import Store
        from poro2d.sweep.sensitivity import SensitivityCase, run_sensitivity

        options = opt.job_options(workers, scheduler, quiet, dashboard)
        if seeds is not None:
            check_int("--seeds", seeds, 1, 50)
        check_output_dir("--out", out)
        case = SensitivityCase.from_config(config, preset=preset, quick=quick, seeds=seeds)

        def banner() -> None:  # once every input is checked: a refusal is the only line
            console.print(f"sensitivity study{' (quick)' if quick else ''} -> {out}")

        store = Store(out)
        sens = run_sensitivity(case, store, options=options, announce=banner)
        draw_sensitivity(sens, store)
        print_sensitivity(sens, out)
        failed = sens.sweeps.failed_cases
        if failed:
            console.print(
                f"[bold red]{failed} case(s) failed[/]; tracebacks in {out}/grading/cases/*/error.txt"
            )
            raise typer.Exit(1)


def _f(v, digits: int = 4) -> str:
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{digits}f}"


def print_sensitivity(sens: SensitivityResult, out: Path) -> None:
    """The two tables of points, the answer, and where the files are."""
    t = Table(title=f"accepted n2D against grading width (mu_prep = {sens.settings.mu_prep:g})")
    for c in ("grading", "Cu", "d_max mm", "accepted n2D", "sd", "n", "unconv.", "n' accepted",
              "interior n", "1st F_top N/m", "1st G N/m", "1st F_top/G", "1st n'"):  # fmt: skip
        t.add_column(c, justify="right")
    for p in sens.points.grading:
        t.add_row(
            p.label, _f(p.cu, 3), _f(p.d_max_mm, 2), _f(p.n2d_mean), _f(p.n2d_sd),
            str(p.n), str(p.unconverged), _f(p.measured_mean), _f(p.interior_mean),
            _f(p.first_f_top_mean, 1),
            _f(p.first_g_mean, 1), _f(p.first_f_top_over_g_mean, 1), _f(p.first_n_prime_mean),
        )  # fmt: skip
    console.print(t)
    t = Table(title="n' of the accepted trial against preparation friction (reference grading)")
    for c in ("mu_prep", "n2D", "sd", "n", "unconv."):
        t.add_column(c, justify="right")
    for p in sens.points.mu_prep:
        t.add_row(f"{p.mu_prep:g}", _f(p.n2d_mean), _f(p.n2d_sd), str(p.n), str(p.unconverged))
    console.print(t)
    for line in sens.answer.lines:
        console.print(f"- {line}", highlight=False)
    tm = sens.timings
    console.print(
        f"time: grading sweep {tm.grading_s:.0f} s, mu_prep {tm.mu_prep_s:.0f} s "
        f"(calibration from {sens.calibration.source}), total {tm.total_s:.0f} s"
    )
    console.print(f"figure {out}/sensitivity.png, tables {out}/sensitivity.csv, {out}/sensitivity.json")
