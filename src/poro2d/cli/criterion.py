"""``poro2d criterion``: the paper's Fig. 3 from a config file or the paper preset, in either mode.

The options make one :class:`~poro2d.criterion.run.CriterionCase`; both modes run through
:func:`poro2d.sweep.density_criterion.run_criterion_modes`; paper
mode's table is the criterion layer's (:func:`poro2d.criterion.table.print_result`), which
``poro2d paper`` prints too.
"""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, Table, shown
from poro2d.criterion.table import print_result
from poro2d.store import Store
from poro2d.sweep.results import DensityStateResult

console = OutputConsole()

#: what paper mode's answer does not depend on, said after every paper-mode run
PAPER_MODE_NOTE = (
    "[yellow]paper mode:[/] the specimen is prepared at the fixed friction_prep, so the accepted n2D "
    "does not follow the laboratory density (nLab only sets Eq. 12's first trial); for the answer at "
    "your density give both laboratory extremes (--n-max/--n-min or \\[density]) or use poro2d sand"
)

#: the option that sets each argument of ``CriterionCase.from_config`` a refusal may name
OPTION_NAMES = {"n_lab": "--n-lab", "trial_porosity": "--trial-porosity", "threads": "--threads",
                "n_max": "--n-max", "n_min": "--n-min"}  # fmt: skip

#: --mode's help: both modes, and when each is the default
MODE_HELP = (
    "density (friction from Dr; the default when both laboratory extremes are given) or paper "
    "(preparation friction 0.05; the default otherwise)."
)


def register(app: typer.Typer) -> None:
    @app.command("criterion")
    def criterion_cmd(
        config: Path = opt.config(help="TOML config with \\[specimen], \\[grading], \\[criterion] tables."),
        preset: str = opt.preset(),
        out: Path = opt.out("criterion-out"),
        seed: int = typer.Option(None, "--seed", help="Random seed (overrides the config)."),
        n_lab: float = typer.Option(None, "--n-lab", help="Laboratory porosity (overrides the config)."),
        trial: float = typer.Option(None, "--trial-porosity", help="First trial n2D instead of Eq. 12."),
        threads: int = opt.threads(),
        mode: str = typer.Option(None, "--mode", help=MODE_HELP),
        n_max: float = typer.Option(None, "--n-max", help="Density mode: loosest laboratory porosity."),
        n_min: float = typer.Option(None, "--n-min", help="Density mode: densest laboratory porosity."),
        seeds: int = typer.Option(None, "--seeds", help="Density mode: specimens per state (3)."),
        quiet: bool = opt.quiet(),
        vtk_every: int = opt.vtk_every(),
    ) -> None:
        """Find the final 2D porosity with the criterion of the paper's Fig. 3.

        Paper mode runs it once, as the paper does. Density mode first calibrates the
        grading (preparation friction -> accepted n2D, cached), sets the preparation friction
        from the laboratory relative density and runs the criterion over seeds.
        """
        from poro2d.criterion.run import CriterionCase
        from poro2d.execute.options import RunOptions
        from poro2d.io_utils import check_output_dir
        from poro2d.report.criterion_figures import draw_criterion
        from poro2d.sweep.density_criterion import run_criterion_modes

        check_output_dir("--out", out)  # a bad folder is named before the config is read
        series = opt.checked_vtk_every(vtk_every)
        given = {"n_lab": n_lab, "trial_porosity": trial, "threads": threads, "n_max": n_max, "n_min": n_min}
        with opt.named_as_typed(given, OPTION_NAMES):  # an option's value named as the user typed it
            case = CriterionCase.from_config(
                config, preset=preset, seed=seed, mode=mode, seeds=seeds, **given, **series
            )
        store = Store(out)
        result = run_criterion_modes(case, store, options=RunOptions(progress=not quiet))
        if isinstance(result, DensityStateResult):
            print_density(result, out)
            return
        draw_criterion(result, store)
        print_result(result, store)
        console.print(PAPER_MODE_NOTE, soft_wrap=True)
        if not result.converged:
            # one line, whole: the reason names the trial, the stage or check, the ratio
            what = "failed" if result.failed_trial else "not converged"
            console.print(f"[bold red]criterion {what}:[/] {shown(result.message)}", soft_wrap=True)
            raise typer.Exit(1)


def print_density(res: DensityStateResult, out: Path) -> None:
    """The density-controlled criterion's answer: its state, friction and accepted n2D over seeds."""
    t = Table(title=f"criterion, density mode: nLab = {res.n_lab} (Dr = {res.relative_density:.3f})")
    for col in ("2D target", "mu_prep", "accepted n2D (mean +- sd)", "interior n (mean +- sd)", "per seed",
                "converged", "n2D,min", "n2D,max"):  # fmt: skip
        t.add_column(col, justify="right")
    mean = res.final_porosity_mean
    inner = res.interior_porosity_mean
    t.add_row(
        f"{res.n2d_target:.4f}", f"{res.mu_prep:.3f}",
        "" if mean != mean else f"{mean:.4f} +- {res.final_porosity_sd:.4f}",
        "" if inner is None or inner != inner else f"{inner:.4f} +- {res.interior_porosity_sd:.4f}",
        ", ".join(f"{v:.2f}" for v in res.final_porosity_per_seed),
        f"{res.seeds_converged}/{res.seeds}", f"{res.n2d_min:.4f}", f"{res.n2d_max:.4f}",
    )  # fmt: skip
    console.print(t)
    replaced = res.sweeps.seeds_replaced or []  # None in a density.json of an older poro2d
    for r in replaced:
        by = "no seed left to replace it" if r.replaced_by is None else f"replaced by seed {r.replaced_by}"
        console.print(f"seed {r.seed} not accepted ({shown(r.reason)}): {by}", soft_wrap=True)
    console.print(f"results in {out}/density.json (calibration {out}/calibration.json)", soft_wrap=True)
    if not res.converged:
        asked = res.seeds - sum(r.replaced_by is not None for r in replaced)
        states = shown(f"{out}/states")
        console.print(f"[bold red]criterion: {res.seeds_converged} of {asked} seeds accepted[/] "
                      f"({res.seeds - asked} replaced; see {states})", soft_wrap=True)  # fmt: skip
        raise typer.Exit(1)
