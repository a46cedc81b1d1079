"""``poro2d paper``: the paper's case study in one resumable command (:func:`poro2d.paper.run_paper`)."""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, shown
from poro2d.execute.options import RunOptions
from poro2d.paper import PaperCase, PaperSummary, run_paper, specimen_lines
from poro2d.store import Store

console = OutputConsole()


def register(app: typer.Typer) -> None:
    @app.command("paper")
    def paper_cmd(
        out: Path = opt.out("paper-out"),
        quick: bool = typer.Option(
            False, "--quick", help="Reduced specimen for a first look (about a minute)."
        ),
        lab: Path = typer.Option(None, "--lab", help="Laboratory direct shear CSV to overlay (Fig. 8)."),
        seed: int = typer.Option(0, "--seed", help="Random seed of the first specimen."),
        replicates: int = typer.Option(
            3, "--replicates", help="Specimens (seeds) for the direct shear tests; 1 for one specimen."
        ),
        threads: int = opt.threads(help="Threads for the DEM kernels (default: all cores)."),
        quiet: bool = opt.quiet(),
    ) -> None:
        """Run the paper's case study: conversions, criterion (Fig. 3), direct shear (Fig. 8), report."""
        case = PaperCase(quick=quick, seed=seed, replicates=replicates, lab=lab, threads=threads)
        summary = run_paper(case, Store(out), options=RunOptions(progress=not quiet))
        if not summary.criterion.converged:
            raise typer.Exit(1)
        say_specimens(summary)
        if summary.specimens_short:  # the answer above is printed and written, over fewer specimens
            raise typer.Exit(1)


def say_specimens(summary: PaperSummary) -> None:
    """The replicate seeds refused and what took their places, and how many specimens were sheared:
    an error when fewer than asked for (the command then exits 1, as ``poro2d sand`` does)."""
    lines = specimen_lines(summary)
    if not summary.seeds_replaced and not summary.specimens_short:
        return  # every seed asked for accepted: nothing to say
    for line in lines[:-1]:
        console.print(f"[bold red]{shown(line)}[/]", soft_wrap=True)
    if summary.specimens_short:
        console.print(
            f"[bold red]error:[/] {shown(lines[-1])}: the answer is over fewer specimens than asked for "
            "(results.json and the report say why each seed was refused)",
            soft_wrap=True,
        )
    else:
        console.print(shown(lines[-1]), soft_wrap=True)
