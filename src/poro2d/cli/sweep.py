"""``poro2d sweep``: a grid or list of cases as Dask tasks, one table of results."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.markup import escape

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, Table

console = OutputConsole()


def sweep_cmd(
    config: Path = typer.Argument(..., help="TOML config: base case tables and a \\[sweep] table."),
    out: Path = opt.out("sweep-out", "Output folder (reruns skip done cases)."),
    scheduler: str = opt.scheduler(),
    workers: int = opt.workers(),
    dashboard: str = opt.dashboard(),
    quiet: bool = opt.quiet(help="No progress bar."),
) -> None:
    """Run a grid or list of cases as Dask tasks; one table of results."""
    from poro2d.config import load_toml
    from poro2d.io_utils import check_output_dir
    from poro2d.store import Store
    from poro2d.sweep.cases import parse_sweep
    from poro2d.sweep.runner import run_sweep

    options = opt.job_options(workers, scheduler, quiet, dashboard)
    check_output_dir("--out", out)
    cfg = load_toml(config)
    sweep = parse_sweep(cfg, Path(config).resolve().parent)
    console.print(f"{len(sweep.cases)} case(s) of kind {sweep.kind!r} -> {out}")
    res = run_sweep(sweep, Store(out), options=options)
    if sweep.figures and sweep.kind == "criterion":  # [sweep] figures = true: each case's force chains
        from poro2d.report.criterion_figures import draw_stored_criterion

        for row in res.rows:
            draw_stored_criterion(Store(out).child("cases", row.case_id, "run"))
    print_summary(res, out)
    if res.failed:
        raise typer.Exit(1)


def register(app: typer.Typer) -> None:
    app.command("sweep")(sweep_cmd)


def print_summary(res, out: Path) -> None:
    s = res.summary
    t = Table(title=f"sweep: {s.cases} case(s), {s.ran} run, {s.reused} already done, {s.failed} failed")
    t.add_column("case")
    t.add_column("status")
    t.add_column("time s", justify="right")
    t.add_column("result / error")
    for r in res.rows:
        rs = r.results or {}
        if r.status == "failed":
            txt = f"[red]{escape(str(r.error))}[/]"
        elif "final_porosity" in rs:
            fp = rs.get("final_porosity")
            txt = f"n2D = {fp:.4f}" if fp is not None else f"not converged ({escape(str(rs.get('message')))})"
        else:
            txt = escape(", ".join(f"{k}={v}" for k, v in list(rs.items())[:4]))
        ts = r.time_s
        t.add_row(r.case_id, "reused" if r.extra.get("reused") else r.status, f"{ts:.1f}" if ts else "", txt)
    console.print(t)
    eff = s.parallel_efficiency
    console.print(
        f"wall {s.wall_time_s:.1f} s, case time {s.case_time_sum_s:.1f} s"
        + (f", parallel efficiency {eff:.0%}" if eff else "")
        + f"; table in {out}/results.csv"
    )
