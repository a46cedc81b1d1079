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
        mode: str = typer.Option(
            None, "--mode", help="paper (default: preparation friction 0.05) or density (friction from Dr)."
        ),
        n_max: float = typer.Option(None, "--n-max", help="Density mode: loosest laboratory porosity."),
        n_min: float = typer.Option(None, "--n-min", help="Density mode: densest laboratory porosity."),
        seeds: int = typer.Option(None, "--seeds", help="Density mode: specimens per state (3)."),
        quiet: bool = typer.Option(False, "--quiet", help="No progress bars."),
    ) -> None:
        """Find the final 2D porosity with the criterion of the paper's Fig. 3.

        Paper mode runs it once, as the paper does. Density mode first calibrates the
        grading (preparation friction -> accepted n2D, cached), sets the preparation friction
        from the laboratory relative density and runs the criterion over seeds.
        """
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
        dens = density_settings(cfg, mode, n_max, n_min, seeds, preset=config is None)
        spec, grading, settings, sd = build(cfg, base, n_lab=n_lab, trial_porosity=trial, threads=threads)
        check_feasible(spec, grading, settings.initial_trial())
        if dens["mode"] == "density":
            _density_mode(cfg, base, settings.n_lab, dens, out, quiet)
            return
        crit = PorosityCriterion(spec, grading, settings, seed=sd, out=out, progress=not quiet, config=cfg)
        result = crit.run()
        print_result(result, out)
        if not result["converged"]:
            # one line, whole: the reason names the trial, the stage or check, the ratio
            what = "failed" if result.get("failed_trial") else "not converged"
            console.print(f"[bold red]criterion {what}:[/] {result['message']}", soft_wrap=True)
            raise typer.Exit(1)


DENSITY_KEYS = {"mode", "n_max", "n_min", "mu_prep", "seeds"}


def density_settings(cfg: dict, mode, n_max, n_min, seeds, *, preset: bool) -> dict:
    """Mode and density-mode settings from ``[density]`` and the options (options win)."""
    from poro2d import porosity as P
    from poro2d.config import check_keys
    from poro2d.errors import InputError, check_int, check_range

    t = dict(cfg.get("density") or {})
    check_keys("density", t, DENSITY_KEYS)
    mode = mode if mode is not None else t.get("mode", "paper")
    if mode not in ("paper", "density"):
        raise InputError("mode", mode, "paper or density")
    out = {"mode": mode, "mu_prep": t.get("mu_prep")}
    if mode == "paper":
        return out
    hi = n_max if n_max is not None else t.get("n_max", P.PAPER_N_MAX if preset else None)
    lo = n_min if n_min is not None else t.get("n_min", P.PAPER_N_MIN if preset else None)
    if hi is None or lo is None:
        raise InputError("density.n_max/n_min", (hi, lo), "both laboratory extremes",
                         "set them in [density] or with --n-max/--n-min")  # fmt: skip
    out["n_max"] = check_range("n_max", hi, 0.0, 1.0, lo_open=True, hi_open=True)
    out["n_min"] = check_range("n_min", lo, 0.0, 1.0, lo_open=True, hi_open=True)
    out["seeds"] = check_int("seeds", seeds if seeds is not None else t.get("seeds", 3), 1, 50)
    return out


def _density_mode(cfg: dict, base_dir, n_lab: float, dens: dict, out: Path, quiet: bool) -> None:
    """The density-controlled criterion (it runs its specimens on the sweep runner)."""
    from poro2d.sweep.density import run_density_state

    res = run_density_state(
        {k: v for k, v in cfg.items() if k != "density"}, base_dir, n_lab, dens["n_max"], dens["n_min"],
        out, seeds=dens["seeds"], mus=dens["mu_prep"], progress=not quiet,
    )  # fmt: skip
    t = Table(title=f"criterion, density mode: nLab = {res['n_lab']} (Dr = {res['relative_density']:.3f})")
    for col in ("2D target", "mu_prep", "accepted n2D (mean +- sd)", "per seed", "converged", "n2D,min",
                "n2D,max"):  # fmt: skip
        t.add_column(col, justify="right")
    mean = res["final_porosity_mean"]
    t.add_row(
        f"{res['n2d_target']:.4f}", f"{res['mu_prep']:.3f}",
        "" if mean != mean else f"{mean:.4f} +- {res['final_porosity_sd']:.4f}",
        ", ".join(f"{v:.2f}" for v in res["final_porosity_per_seed"]),
        f"{res['seeds_converged']}/{res['seeds']}", f"{res['n2d_min']:.4f}", f"{res['n2d_max']:.4f}",
    )  # fmt: skip
    console.print(t)
    console.print(f"results in {out}/density.json (calibration {out}/calibration.json)", soft_wrap=True)
    if not res["converged"]:
        console.print(f"[bold red]criterion not converged for every seed[/] (see {out}/states)")
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
