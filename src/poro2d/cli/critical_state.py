"""``poro2d critical-state``: the steady-state friction and solid fraction of a periodic cell.

Named for what it measures (the critical state of the disks, the reference of the box tests),
not for how (a Lees-Edwards cell in simple shear).
"""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.cli import options as opt
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
    "stiffness_number": "--stiffness-number",
    "vtk_every": "--vtk-every",
    "kn_particle": "--calibrated particle_kn",
    "ks_particle": "--calibrated particle_ks",
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
        particle_friction: float = opt.particle_friction(
            help="Particle friction f_p (default 0.5, or the calibrated one)."
        ),
        rolling_friction: float = opt.rolling_friction(
            help="Rolling friction mu_r (against R = r_i r_j / (r_i + r_j); default 0, or the calibrated)."
        ),
        pressure: str = typer.Option(
            "100",
            "--pressure",
            help="Normal pressure P (kPa), or several, 25,50,100,200,400: the critical-state line e_cs(p').",
        ),
        calibrated: Path = typer.Option(
            None,
            "--calibrated",
            help="A calibrated.toml of poro2d calibrate: its f_p and mu_r (and kn, ks where calibrated).",
        ),
        sand: Path = typer.Option(
            None,
            "--sand",
            help="A poro2d sand folder: its 2D ends and answer held against the line (psi at each p').",
        ),
        lab_line: str = typer.Option(
            None,
            "--lab-line",
            help="The laboratory's critical-state line (toyoura, or a CSV p_kpa,e_cs) for --sand: "
            "the state-parameter map beside the Dr map.",
        ),
        stiffness_number: float = opt.stiffness_number(
            help="kappa = kn / (P t) held at every pressure (contacts scaled with P; >= 1000: rigid grains)."
        ),
        inertial: float = typer.Option(1e-3, "--inertial", help="Inertial number I (sets the shear rate)."),
        strain: float = typer.Option(3.0, "--strain", help="Shear strain gamma where the run ends."),
        window_start: float = typer.Option(
            1.0, "--window-start", help="Gamma where the steady window starts."
        ),
        seed: int = typer.Option(0, "--seed", help="The first seed."),
        seeds: int = typer.Option(1, "--seeds", "-n", help="Seeds S, S+1, ...: the spread over them."),
        out: Path = opt.out("critical-state-out", "Output folder."),
        workers: int = opt.tests_workers("seed, at most one per core"),
        scheduler: str = opt.tests_scheduler(),
        quiet: bool = opt.quiet(),
        vtk_every: int = opt.vtk_every(),
    ) -> None:
        """Steady-state friction tau/sigma and solid fraction of the disks, free of any box."""
        from poro2d.cli.critical_state_held import held_states, print_held
        from poro2d.cli.shear import parse_stresses
        from poro2d.critical_state import CriticalStateCase, CriticalStateStudy, run_critical_states
        from poro2d.critical_state.case import CASE_RANGES
        from poro2d.critical_state.line import MAX_PRESSURES, run_critical_state_line
        from poro2d.critical_state.run import MAX_SEEDS
        from poro2d.errors import InputError, check_int
        from poro2d.report.critical_state_figures import draw_critical_state, draw_critical_state_line
        from poro2d.report.fabric_figures import draw_critical_state_fabric

        rule = CASE_RANGES["pressure_kpa"]
        PRESSURE_RANGE_KPA = (rule.lo, rule.hi)
        from poro2d.io_utils import check_output_dir
        from poro2d.store import Store

        check_output_dir("--out", out)
        curve = _grading(grading)
        n = check_int("--seeds", seeds, 1, MAX_SEEDS)
        run = opt.job_options(workers, scheduler, quiet)
        pressures = parse_stresses(pressure, "--pressure", PRESSURE_RANGE_KPA)
        if len(pressures) > MAX_PRESSURES or len(set(pressures)) != len(pressures):
            raise InputError("--pressure", pressure, f"at most {MAX_PRESSURES} distinct pressures")
        options = _case_options(calibrated, particle_friction, rolling_friction)
        options.update(
            pressure_kpa=pressures[0], inertial_number=inertial, strain=strain, window_start=window_start,
            seed=seed, disks=disks, stiffness_number=stiffness_number,
        )  # fmt: skip
        try:
            case = CriticalStateCase(grading=curve, **options, **opt.checked_vtk_every(vtk_every))
            for p in pressures[1:]:  # each pressure's case checked before any work
                case.at_pressure(p)
        except InputError as exc:  # named as the option the user typed
            raise InputError(OPTION_NAMES.get(exc.parameter, exc.parameter), exc.value, exc.allowed) from None
        config = {
            "grading": grading, **options, "pressure_kpa": pressures, "seeds": n,
            "calibrated": None if calibrated is None else str(calibrated),
        }  # fmt: skip
        held = held_states(sand, lab_line, pressures)
        store = Store(out)
        try:
            if len(pressures) == 1:
                result = run_critical_states(CriticalStateStudy(case, n), store, options=run, config=config)
                draw_critical_state(result, store)
            else:
                result = run_critical_state_line(
                    case, pressures, store, seeds=n, options=run, config=config,
                    marks=held.marks if held else None, span=held.span if held else None,
                )  # fmt: skip
                draw_critical_state_line(result, store)
            draw_critical_state_fabric(result, store)
        except RuntimeError as exc:
            console.print(f"[bold red]failed:[/] {exc}")
            raise typer.Exit(1) from None
        if len(pressures) == 1:
            print_result(result, out)
        else:
            print_line(result, out)
            if held is not None:
                print_held(result, held)


def _case_options(calibrated: Path | None, particle_friction, rolling_friction) -> dict:
    """The micro-parameters: a calibration's, then the options typed (they win), then the defaults."""
    from poro2d.critical_state.calibrated import calibrated_values
    from poro2d.errors import InputError

    options: dict = {}
    if calibrated is not None:
        try:
            options.update(calibrated_values(calibrated))
        except InputError as exc:
            name = (
                "--calibrated"
                if exc.parameter in ("config", "calibrated")
                else f"--calibrated {exc.parameter}"
            )
            raise InputError(name, exc.value, exc.allowed, exc.hint) from None
    if particle_friction is not None:
        options["particle_friction"] = particle_friction
    if rolling_friction is not None:
        options["rolling_friction"] = rolling_friction
    return options


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


def _table(title: str, columns: str) -> Table:
    """A table of right-justified columns (``columns``: names apart, '_' for a space in a name)."""
    t = Table(title=title)
    for col in columns.split():
        t.add_column(col.replace("_", " "), justify="right")
    return t


def print_result(result, out: Path) -> None:
    """The steady state first (one line), then each seed and how it was measured."""
    console.print(f"[bold]{result.headline()}[/]")
    if not result.steady:
        console.print(f"[yellow]{result.note}[/]")
    t = _table("seeds", "seed disks tau/sigma +-_se phi_deg solid_fraction I sigma_yy_kPa z steady time_s")
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
    if result.stiffness_number is not None:
        held = "" if c.stiffness_number is None else " (held by --stiffness-number)"
        console.print(
            f"stiffness number kappa = kn / (P t) = {result.stiffness_number:.0f}{held}, mean overlap / d = "
            f"{result.mean_overlap_ratio.text(4)}: an elastic strain of about 1 / kappa in the solid fraction"
        )
    if result.contact_anisotropy is not None:
        a_c = result.contact_anisotropy.text()
        console.print(f"contact anisotropy a_c over the steady window = {a_c} (fabric.png, docs/fabric.md)")
    console.print(f"results in {out}/result.json, series.csv, critical_state.png")


def print_line(result, out: Path) -> None:
    """The line first (one line), then a row per pressure with kappa and the overlaps."""
    console.print(f"[bold]{result.headline()}[/]")
    if not result.steady:
        console.print(f"[yellow]{result.note}[/]")
    t = _table(
        "critical state per pressure (mean +- sd over seeds)",
        "P_kPa p'_kPa e_cs solid_fraction tau/sigma phi_deg z kappa overlap/d steady",
    )
    for p in result.points:
        t.add_row(
            f"{p.pressure_kpa:g}",
            f"{p.mean_stress_kpa.mean:.1f}",
            p.void_ratio.text(4),
            f"{p.solid_fraction.mean:.4f}",
            p.stress_ratio.text(),
            f"{p.friction_angle_deg.mean:.1f}",
            f"{p.coordination.mean:.2f}",
            f"{p.stiffness_number:.0f}",
            f"{p.mean_overlap_ratio.mean:.1e}",
            "yes" if p.steady else "NO",
        )
    console.print(t)
    line = result.line
    c = result.case
    console.print(
        f"line: {line.text()}, {line.lambda_log10:.4f} per decade, residual sd {line.residual_sd:.4f} "
        f"({line.points} runs); f_p = {c.particle_friction:g}, mu_r = {c.rolling_friction:g}, "
        f"I = {c.inertial_number:g}"
        + ("" if c.stiffness_number is None else f", kappa held at {c.stiffness_number:g}")
    )
    if c.stiffness_number is None:
        console.print(
            "the slope is the linear contacts' softness (kappa falls as 1/P), not grain crushing: "
            "--stiffness-number 1000 holds kappa and shows the rigid-grain line (docs/critical-state.md)"
        )
    console.print(f"results in {out}/result.json, line.csv, critical_state_line.png, p<P>kPa/")
