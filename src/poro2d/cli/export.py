"""``poro2d export``: an accepted specimen for LAMMPS, YADE, PFC2D or as a CSV table."""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.console import OutputConsole, Table, shown
from poro2d.store import claims

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "export"

console = OutputConsole()

TARGETS = ("lammps", "yade", "pfc", "csv")


@claims(KIND, "out")
def export_cmd(
    specimen: str = typer.Argument(
        ...,
        help="Specimen checkpoint (.npz), a folder holding specimen.npz, or a relation, density-mode "
        "criterion or sand folder (with --n-lab or --dr).",
    ),
    to: str = typer.Option(..., "--to", help="Target: lammps, yade, pfc or csv."),
    out: Path = typer.Option(..., "--out", "-o", help="Output folder."),
    ratio: float = typer.Option(
        1e-3,
        "--ratio",
        help="Stop ratio written into the LAMMPS and YADE scripts (max unbalanced force).",
    ),
    n_lab: float = typer.Option(
        None, "--n-lab", help="The state by its laboratory porosity (a folder of states)."
    ),
    dr: float = typer.Option(None, "--dr", help="The state by its relative density (a folder of states)."),
    seed: int = typer.Option(None, "--seed", help="The state's specimen by its seed (default 0)."),
) -> None:
    """Write an accepted specimen for another DEM code (disks, walls, contact properties)."""
    from poro2d.errors import InputError, check_range
    from poro2d.interop import csv_table, lammps, pfc, yade
    from poro2d.interop.exported import export_specimen
    from poro2d.interop.state_specimen import dr_text

    if to not in TARGETS:
        raise InputError("--to", to, "one of " + ", ".join(TARGETS))
    check_range("--ratio", ratio, 0.0, 1.0, lo_open=True)
    spec, state = export_specimen(specimen, out, n_lab=n_lab, dr=dr, seed=seed)
    writers = {
        "lammps": lambda: lammps.write_specimen(spec, out, ratio=ratio),
        "yade": lambda: yade.write_specimen(spec, out, ratio=ratio),
        "pfc": lambda: pfc.write_specimen(spec, out),
        "csv": lambda: csv_table.write_specimen(spec, out),
    }
    paths = writers[to]()
    t = Table(title=f"export --to {to}")
    t.add_column("file")
    t.add_column("bytes", justify="right")
    for p in paths:
        t.add_row(shown(str(p)), f"{p.stat().st_size:,}")
    console.print(t)
    if to == "pfc" and pfc.pfc4_refusal(spec):
        console.print(pfc.pfc4_refusal(spec))
    if state is not None:
        where = shown(f"seed {state.seed} of {state.record}: {state.folder}")
        console.print(f"state n_lab = {state.n_lab:g} (Dr = {dr_text(state.relative_density)}), {where}")
    console.print(
        f"{spec.n} disks, {len(spec.walls)} walls; thickness t = {spec.thickness:g} m "
        "(disk masses rho pi r^2 t); SI units; see docs/export.md"
    )


def register(app: typer.Typer) -> None:
    app.command("export")(export_cmd)
