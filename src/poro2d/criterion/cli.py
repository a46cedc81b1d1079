"""``poro2d criterion``: the paper's Fig. 3 from a config file or the paper preset."""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.console import OutputConsole, Table

console = OutputConsole()


def register(app: typer.Typer) -> None:
    @app.command("criterion")
    def criterion_cmd(
        config: Path = typer.Option(
            None, "--config", "-c", help="TOML config with \\[specimen], \\[grading], \\[criterion] tables."
        ),
        preset: str = typer.Option(None, "--preset", help="Built-in case: 'paper'."),
        out: Path = typer.Option(Path("criterion-out"), "--out", "-o", help="Output folder (resumable)."),
        seed: int = typer.Option(None, "--seed", help="Random seed (overrides the config)."),
        n_lab: float = typer.Option(None, "--n-lab", help="Laboratory porosity (overrides the config)."),
        trial: float = typer.Option(None, "--trial-porosity", help="First trial n2D instead of Eq. 12."),
        threads: int = typer.Option(None, "--threads", help="Threads for the DEM kernels."),
        quiet: bool = typer.Option(False, "--quiet", help="No progress bars."),
    ) -> None:
        """Find the final 2D porosity with the criterion of the paper's Fig. 3."""
        from poro2d.criterion.config import build, load_config
        from poro2d.criterion.protocol import PorosityCriterion
        from poro2d.errors import InputError
        from poro2d.io_utils import check_output_dir
        from poro2d.specimen.compaction import check_feasible

        check_output_dir("--out", out)
        cfg, base = load_config(config, preset)
        if seed is not None:
            if seed < 0:
                raise InputError("--seed", seed, "an integer >= 0")
            cfg["seed"] = seed
        spec, grading, settings, sd = build(cfg, base, n_lab=n_lab, trial_porosity=trial, threads=threads)
        check_feasible(spec, grading, settings.initial_trial())
        crit = PorosityCriterion(spec, grading, settings, seed=sd, out=out, progress=not quiet, config=cfg)
        result = crit.run()
        print_result(result, out)
        if not result["converged"]:
            # one line, whole: the reason names the trial, the stage or check, the ratio
            what = "failed" if result.get("failed_trial") else "not converged"
            console.print(f"[bold red]criterion {what}:[/] {result['message']}", soft_wrap=True)
            raise typer.Exit(1)


def print_result(result: dict, out: Path) -> None:
    t = Table(title=f"criterion (Fig. 3): nLab = {result['n_lab']}")
    for col in ("trial n2D", "disks", "F_top N/m", "F_bottom N/m", "G N/m", "plate", "dz (mm)", "n'",
                "|n'-n2D|", "accepted"):  # fmt: skip
        t.add_column(col, justify="right")
    for r in result["iterations"]:
        t.add_row(
            f"{r['trial_porosity']:.3f}", str(r["particle_count"]), f"{r['f_top_n_per_m']:.4g}",
            f"{r['f_bottom_n_per_m']:.4g}", f"{r['self_weight_n_per_m']:.4g}", r["plate_moved"],
            f"{1e3 * r['plate_displacement_m']:.3f}", _num(r["new_porosity"]),
            _num(r["porosity_change"]), _verdict(r),
        )  # fmt: skip
    console.print(t)
    console.print(f"{result['message']}; results in {out}/result.json")


def _num(x) -> str:
    """A porosity for the table; a trial refused before its plate stage has none."""
    return "-" if x is None else f"{x:.4f}"


def _verdict(r: dict) -> str:
    if r["accepted"]:
        return "yes"
    return f"refused ({r.get('failed_stage') or r.get('failed_check')})" if r.get("refused") else "no"
