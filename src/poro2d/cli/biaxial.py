"""``poro2d biaxial``: biaxial tests at a confining stress on replicate specimens."""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.console import OutputConsole, Table

console = OutputConsole()


def register(app: typer.Typer) -> None:
    @app.command("biaxial")
    def biaxial_cmd(
        specimen: list[str] = typer.Argument(
            None, help="Specimen checkpoints or criterion/sand folders, one per replicate; or --quick."
        ),
        quick: bool = typer.Option(
            False, "--quick", help="The built-in quick specimen (0.05 m x 0.10 m, about 320 disks) of --seed."
        ),
        confining: float = typer.Option(100.0, "--confining", help="Confining stress sigma_3 (kPa)."),
        strain: float = typer.Option(
            None, "--strain", help="Axial strain where the test ends (default 0.20)."
        ),
        strain_rate: float = typer.Option(
            None, "--strain-rate", help="Axial strain rate (1/s, default 0.2)."
        ),
        replicates: int = typer.Option(
            None, "--replicates", "-r", help="With --quick: specimens of seeds S, S+1, ..."
        ),
        seed: int = typer.Option(None, "--seed", help="With --quick: the first specimen's seed (default 0)."),
        particle_friction: float = typer.Option(
            None, "--particle-friction", help="Disk friction for the tests (default: the specimen's)."
        ),
        rolling_friction: float = typer.Option(
            None,
            "--rolling-friction",
            help="Disk rolling friction mu_r for the tests (default: the specimen's).",
        ),
        lab: Path = typer.Option(
            None, "--lab", help="Your laboratory curves (CSV, docs/biaxial.md), overlaid."
        ),
        out: Path = typer.Option(Path("biaxial-out"), "--out", "-o", help="Output folder."),
        processes: int = typer.Option(
            None, "--processes", "-p", help="Worker processes (default one per replicate)."
        ),
        quiet: bool = typer.Option(False, "--quiet", help="No progress bars."),
    ) -> None:
        """Biaxial tests: peak and critical-state friction angles, dilatancy, their spread over replicates."""
        from poro2d.biaxial import BiaxialCase, BiaxialSettings, run_biaxial
        from poro2d.biaxial.settings import CONFINING_RANGE_KPA
        from poro2d.cli.shear import check_friction_options
        from poro2d.errors import InputError, check_int, check_range
        from poro2d.io_utils import check_output_dir
        from poro2d.store import Store

        check_output_dir("--out", out)
        check_range("--confining", confining, *CONFINING_RANGE_KPA)
        if bool(quick) == bool(specimen):
            raise InputError(
                "SPECIMEN.../--quick", specimen or None, "one of them: specimen paths, or --quick"
            )
        if not quick and seed is not None:
            raise InputError("--seed", seed, "only with --quick (a specimen file has its own disks)")
        if not quick and replicates is not None:
            raise InputError(
                "--replicates", replicates, "only with --quick (give one specimen path per replicate)"
            )
        n = check_int("--replicates", replicates, 1, 50) if replicates is not None else 1
        first = check_int("--seed", seed, 0, 2**31 - 1) if seed is not None else 0
        check_friction_options(particle_friction, rolling_friction)  # the ranges shear takes
        changes = {"max_strain": strain, "strain_rate": strain_rate, "particle_friction": particle_friction,
                   "rolling_friction": rolling_friction}  # fmt: skip
        options = {k: v for k, v in changes.items() if v is not None}
        try:
            settings = BiaxialSettings(**options)
        except InputError as exc:  # named as the option the user typed
            names = {"max_strain": "--strain", "strain_rate": "--strain-rate"}
            raise InputError(names.get(exc.parameter, exc.parameter), exc.value, exc.allowed) from None
        if quick:
            case = BiaxialCase.quick(confining, first, settings)
        else:
            case = [BiaxialCase.of(p, confining, settings) for p in specimen]
        config = {"quick": quick, "specimens": specimen or None, "seed": first if quick else None,
                  "confining_kpa": confining, "settings": options}  # fmt: skip
        try:
            result = run_biaxial(case, Store(out), replicates=n, lab=lab, processes=processes,
                                 progress=not quiet, config=config)  # fmt: skip
        except RuntimeError as exc:
            console.print(f"[bold red]failed:[/] {exc}")
            raise typer.Exit(1) from None
        print_result(result, out)


def print_result(result, out: Path) -> None:
    """The number to take away first, then each replicate and the checks."""
    console.print(f"[bold]{result.headline()}[/]")
    if not result.critical_state_reached:
        console.print(f"[yellow]{result.critical_state_note}[/]")
    t = Table(title="replicates")
    for col in ("replicate", "phi peak deg", "eps_1 peak %", "phi end deg", "critical", "psi max deg",
                "eps_v end %", "sigma_3 err %", "time s"):  # fmt: skip
        t.add_column(col, justify="right")
    for s in result.summaries:
        t.add_row(
            str(s.replicate), f"{s.peak_friction_angle_deg:.1f}", f"{100 * s.axial_strain_at_peak:.1f}",
            f"{s.critical_state_friction_angle_deg:.1f}", "yes" if s.critical_state_reached else "not yet",
            f"{s.max_dilatancy_angle_deg:.1f}", f"{100 * s.end_volumetric_strain:+.2f}",
            f"{100 * s.sigma_3_max_error:.1f}", f"{s.wall_time_s:.0f}",
        )  # fmt: skip
    console.print(t)
    console.print(f"psi_max = {result.max_dilatancy_angle.text()} (sin psi = -d eps_v / d eps_s)")
    test = result.tests[0] if result.tests else None
    if test is not None:
        c = test.checks
        console.print(
            f"inertial number I = {c.inertial_number_at_confining:.1e} at sigma_3 "
            f"(limit {c.inertial_limit:g}); "
            f"strain rate {test.strain_rate_per_s:g} 1/s; specimen {test.consolidation.box.width:.3g} m x "
            f"{test.consolidation.box.height:.3g} m, walls not periodic (box-scale numbers, docs/biaxial.md)"
        )
    if result.lab is not None:
        console.print(f"lab ({result.lab.source}): phi_peak = {result.lab.peak_friction_angle_deg:.1f} deg, "
                      f"phi_end = {result.lab.end_friction_angle_deg:.1f} deg")  # fmt: skip
    console.print(
        f"results in {out}/result.json, curves.csv, biaxial.png; each replicate in {out}/replicate<k>/"
    )
