"""``poro2d critical-state``: the steady-state friction and solid fraction of a periodic cell.

Named for what it measures (the critical state of the disks, the reference of the box tests),
not for how (a Lees-Edwards cell in simple shear).
"""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.console import OutputConsole, Table

console = OutputConsole()

#: the case's fields as the options name them, for refusals
OPTION_NAMES = {
    "disks": "--disks",
    "particle_friction": "--particle-friction",
    "rolling_friction": "--rolling-friction",
    "pressure_kpa": "--pressure",
    "inertial_number": "--inertial",
    "strain": "--strain",
    "window_start": "--window-start",
    "seed": "--seed",
}


def register(app: typer.Typer) -> None:
    @app.command("critical-state")
    def critical_state_cmd(
        grading: str = typer.Option(
            "paper",
            "--grading",
            help="A built-in grading (paper, wide_cu4, wide_cu6) or a sieve curve CSV of your soil "
            "(columns size_mm,percent_passing; docs/grading.md).",
        ),
        disks: int = typer.Option(1500, "--disks", help="About how many disks in the cell."),
        particle_friction: float = typer.Option(0.5, "--particle-friction", help="Particle friction f_p."),
        rolling_friction: float = typer.Option(
            0.0, "--rolling-friction", help="Rolling friction mu_r (against R = r_i r_j / (r_i + r_j))."
        ),
        pressure: float = typer.Option(100.0, "--pressure", help="Normal pressure P (kPa)."),
        inertial: float = typer.Option(1e-3, "--inertial", help="Inertial number I (sets the shear rate)."),
        strain: float = typer.Option(3.0, "--strain", help="Shear strain gamma where the run ends."),
        window_start: float = typer.Option(
            1.0, "--window-start", help="Gamma where the steady window starts."
        ),
        seed: int = typer.Option(0, "--seed", help="The first seed."),
        seeds: int = typer.Option(1, "--seeds", "-n", help="Seeds S, S+1, ...: the spread over them."),
        out: Path = typer.Option(Path("critical-state-out"), "--out", "-o", help="Output folder."),
        processes: int = typer.Option(
            None, "--processes", "-p", help="Worker processes (default one per seed)."
        ),
        quiet: bool = typer.Option(False, "--quiet", help="No progress bars."),
    ) -> None:
        """Steady-state friction tau/sigma and solid fraction of the disks, free of any box."""
        from poro2d.critical_state import CriticalStateCase, run_critical_states
        from poro2d.critical_state.run import MAX_SEEDS
        from poro2d.errors import InputError, check_int
        from poro2d.io_utils import check_output_dir
        from poro2d.store import Store

        check_output_dir("--out", out)
        curve = _grading(grading)
        n = check_int("--seeds", seeds, 1, MAX_SEEDS)
        if processes is not None:
            check_int("--processes", processes, 1, 64)
        options = {
            "disks": disks,
            "particle_friction": particle_friction,
            "rolling_friction": rolling_friction,
            "pressure_kpa": pressure,
            "inertial_number": inertial,
            "strain": strain,
            "window_start": window_start,
            "seed": seed,
        }
        try:
            case = CriticalStateCase(grading=curve, **options)
        except InputError as exc:  # named as the option the user typed
            raise InputError(OPTION_NAMES.get(exc.parameter, exc.parameter), exc.value, exc.allowed) from None
        config = {"grading": grading, **options, "seeds": n}
        try:
            result = run_critical_states(
                case, Store(out), seeds=n, processes=processes, progress=not quiet, config=config
            )
        except RuntimeError as exc:
            console.print(f"[bold red]failed:[/] {exc}")
            raise typer.Exit(1) from None
        print_result(result, out)


def _grading(text: str):
    """A built-in grading by name, or a user's sieve curve read from a CSV file."""
    from poro2d.errors import InputError
    from poro2d.grading import GradingCurve, preset_grading

    if text.lower().endswith(".csv") or Path(text).is_file():
        try:
            return GradingCurve.from_csv(text)
        except InputError as exc:  # named as the option the user typed, where in the file kept
            where = exc.parameter.removeprefix("csv").strip()
            raise InputError(f"--grading {where}".strip(), exc.value, exc.allowed, exc.hint) from None
    try:
        return preset_grading(text)
    except InputError as exc:
        raise InputError("--grading", text, f"{exc.allowed}, or a sieve curve .csv") from None


def print_result(result, out: Path) -> None:
    """The steady state first (one line), then each seed and how it was measured."""
    console.print(f"[bold]{result.headline()}[/]")
    if not result.steady:
        console.print(f"[yellow]{result.note}[/]")
    t = Table(title="seeds")
    for col in (
        "seed",
        "disks",
        "tau/sigma",
        "+- se",
        "phi deg",
        "solid fraction",
        "I",
        "sigma_yy kPa",
        "z",
        "steady",
        "time s",
    ):
        t.add_column(col, justify="right")
    for s in result.summaries:
        t.add_row(
            str(s.seed),
            str(s.disks),
            f"{s.stress_ratio:.3f}",
            f"{s.stress_ratio_se:.3f}",
            f"{s.friction_angle_deg:.1f}",
            f"{s.solid_fraction:.4f}",
            f"{s.inertial_number:.1e}",
            f"{s.normal_stress_kpa:.1f}",
            f"{s.coordination:.2f}",
            "yes" if s.steady else "NO",
            f"{s.wall_time_s:.0f}",
        )
    console.print(t)
    for s in result.summaries:
        if not s.steady:
            console.print(f"[yellow]seed {s.seed}: {s.note}[/]")
    c = result.case
    console.print(
        f"periodic cell (Lees-Edwards), f_p = {c.particle_friction:g}, mu_r = {c.rolling_friction:g}, "
        f"P = {c.pressure_kpa:g} kPa, I = {c.inertial_number:g}; "
        f"steady window gamma {c.window_start:g}-{c.strain:g}"
    )
    console.print(f"results in {out}/result.json, series.csv, critical_state.png")
