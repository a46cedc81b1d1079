"""``poro2d biaxial``: biaxial tests at one or several confining stresses on replicate specimens."""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, Table

console = OutputConsole()


def register(app: typer.Typer) -> None:
    @app.command("biaxial")
    def biaxial_cmd(
        specimen: list[str] = opt.specimens(
            help="Specimen checkpoints or criterion/sand folders, one per replicate; or --quick."
        ),
        quick: bool = opt.quick(
            help="The built-in quick specimen (0.05 m x 0.10 m, about 320 disks) of --seed."
        ),
        confining: str = typer.Option(
            None, "--confining", help="Confining stresses sigma_3 in kPa: 100, or 50,100,200 (default 100)."
        ),
        strain: float = typer.Option(
            None, "--strain", help="Axial strain where the test ends (default 0.20)."
        ),
        strain_rate: float = typer.Option(
            None,
            "--strain-rate",
            help="Axial strain rate (1/s; default 0.2, slower in a box too wide for its walls to follow).",
        ),
        replicates: int = typer.Option(
            None, "--replicates", "-r", help="With --quick: specimens of seeds S, S+1, ..."
        ),
        seed: int = typer.Option(None, "--seed", help="With --quick: the first specimen's seed (default 0)."),
        particle_friction: float = opt.particle_friction(),
        rolling_friction: float = opt.rolling_friction(),
        stiffness_number: float = opt.stiffness_number(
            help="Scale the disks' kn and ks so that kappa = kn / (sigma_3 t) is this "
            "(>= 1000: rigid grains; default: the specimen's stiffness).",
        ),
        lab: Path = opt.lab(help="Your laboratory curves (CSV, docs/biaxial.md), overlaid."),
        out: Path = opt.out("biaxial-out", "Output folder."),
        workers: int = opt.tests_workers("test, at most one per core"),
        scheduler: str = opt.tests_scheduler(),
        config: Path = opt.config(help="TOML config with a \\[biaxial] table."),
        quiet: bool = opt.quiet(),
        vtk_every: int = opt.vtk_every(),
    ) -> None:
        """Biaxial tests at one or several confining stresses: peak and critical-state friction angles,
        dilatancy and their spread over replicates; the peak envelope over the stresses."""
        from poro2d.biaxial.config import load_biaxial_config
        from poro2d.cli.shear import check_friction_options
        from poro2d.errors import InputError
        from poro2d.io_utils import check_output_dir
        from poro2d.store import Store

        check_output_dir("--out", out)
        table = load_biaxial_config(config)
        run = table.run
        stresses = confining_stresses(confining, run.get("confining_kpa"))
        quick = quick or bool(run.get("quick", False))
        specimen = specimen or (None if quick else table.specimens())
        first, n = check_replicates(quick, specimen, seed, replicates, run)
        check_friction_options(particle_friction, rolling_friction)  # the ranges shear takes
        changes = {"max_strain": strain, "strain_rate": strain_rate, "particle_friction": particle_friction,
                   "rolling_friction": rolling_friction, "stiffness_number": stiffness_number,
                   **opt.checked_vtk_every(vtk_every)}  # fmt: skip
        options = {k: v for k, v in changes.items() if v is not None}
        settings = build_settings(table, options)
        case = make_case(quick, specimen, stresses[0], first, settings)
        recorded = {"quick": quick, "specimens": specimen or None, "seed": first if quick else None,
                    "confining_kpa": stresses[0] if len(stresses) == 1 else stresses,
                    "settings": {**table.settings, **options}}  # fmt: skip
        if config is not None:
            recorded["config_file"] = str(config)
        jobs = opt.job_options(workers if workers is not None else run.get("workers"), scheduler, quiet)
        kw = {"replicates": n, "lab": lab if lab is not None else table.path("lab"), "options": jobs,
              "config": recorded}  # fmt: skip
        try:  # a strain rate too fast for the specimen is refused before any test, named as typed
            start_and_print(case, stresses, Store(out), kw, out)
        except InputError as exc:
            if exc.parameter == "lab":  # the laboratory file, named as the user gave it
                given = "--lab" if lab is not None else "biaxial.lab"
                raise InputError(given, exc.value, exc.allowed, exc.hint) from None
            raise as_typed(exc, options, table.settings) from None


def confining_stresses(text: str | None, from_config) -> list[float]:
    """--confining (``100`` or ``50,100,200``), else the config's confining_kpa, else 100 kPa."""
    from poro2d.cli.shear import parse_stresses
    from poro2d.errors import InputError

    if text is not None:
        values, name = parse_stresses(text, "--confining"), "--confining"
    elif from_config is not None:
        values = [float(v) for v in (from_config if isinstance(from_config, list) else [from_config])]
        name = "biaxial.confining_kpa"
    else:
        return [100.0]
    if len(set(values)) != len(values):
        raise InputError(name, text if text is not None else from_config, "different confining stresses")
    return sorted(values)


def check_replicates(quick: bool, specimen, seed, replicates, run: dict) -> tuple[int, int]:
    """(first seed, replicates): --seed and --replicates with --quick only, the config's as defaults."""
    from poro2d.errors import InputError, check_int

    if bool(quick) == bool(specimen):
        raise InputError("SPECIMEN.../--quick", specimen or None, "one of them: specimen paths, or --quick")
    if not quick and seed is not None:
        raise InputError("--seed", seed, "only with --quick (a specimen file has its own disks)")
    if not quick and replicates is not None:
        raise InputError(
            "--replicates", replicates, "only with --quick (give one specimen path per replicate)"
        )
    n = check_int("--replicates", replicates, 1, 50) if replicates is not None else run.get("replicates", 1)
    first = check_int("--seed", seed, 0, 2**31 - 1) if seed is not None else run.get("seed", 0)
    if not quick and (n != 1 or "seed" in run):
        key = "biaxial.replicates" if n != 1 else "biaxial.seed"
        raise InputError(
            key, run.get(key.split(".")[1]), "only with quick = true (one specimen path per replicate)"
        )
    return first, n


#: the option that sets each setting
OPTION_NAMES = {
    "max_strain": "--strain",
    "strain_rate": "--strain-rate",
    "stiffness_number": "--stiffness-number",
    "vtk_every": "--vtk-every",
}


def build_settings(table, options: dict):
    """BiaxialSettings from the config's table, the options winning; an error named as typed."""
    from poro2d.errors import InputError

    try:
        return table.build(**options)
    except InputError as exc:
        raise as_typed(exc, options, table.settings) from None


def as_typed(exc, options: dict, config: dict):
    """``exc`` naming what the user typed for its setting: the option, else the config's key."""
    from poro2d.errors import InputError

    if exc.parameter in options:
        name = OPTION_NAMES.get(exc.parameter, exc.parameter)
    elif exc.parameter in config:
        name = f"biaxial.{exc.parameter}"
    else:
        return exc
    return InputError(name, exc.value, exc.allowed, exc.hint)


def make_case(quick: bool, specimen, sigma: float, first: int, settings):
    """The case of the quick specimen of ``first``, or one case per specimen path."""
    from poro2d.biaxial import BiaxialCase

    if quick:
        return BiaxialCase.quick(sigma, first, settings)
    return [BiaxialCase.of(p, sigma, settings) for p in specimen]


def start_and_print(case, stresses: list[float], store, kw: dict, out: Path) -> None:
    """One stress: run_biaxial; several: run_biaxial_series; the figures drawn from the result; the
    answer printed (a failed test: exit 1)."""
    from poro2d.biaxial import BiaxialSeriesCase, run_biaxial, run_biaxial_series
    from poro2d.biaxial.run import lab_curve
    from poro2d.report.biaxial_figures import draw_biaxial, draw_biaxial_series
    from poro2d.report.fabric_figures import draw_biaxial_fabric

    kw = dict(kw, lab=lab_curve(kw.get("lab")))  # read once: the run records it, the figure draws it
    try:
        if len(stresses) == 1:
            result = run_biaxial(case, store, **kw)
            draw_biaxial(result, store, kw["lab"])
        else:
            series = BiaxialSeriesCase(case, stresses, kw.pop("replicates"), kw.pop("lab"))
            result = run_biaxial_series(series, store, **kw)
            draw_biaxial_series(result, store, series.lab)
        draw_biaxial_fabric(result, store)
    except RuntimeError as exc:
        console.print(f"[bold red]failed:[/] {exc}")
        raise typer.Exit(1) from None
    tests = result.tests if len(stresses) == 1 else [t for study in result.studies for t in study.tests]
    off = [t for t in tests if not t.checks.sigma_3_held]
    if off:  # said first: the angles below are not those of a test at constant sigma_3
        worst = max(t.checks.sigma_3_mean_error for t in off)
        console.print(
            f"[bold red]sigma_3 not held[/] in {len(off)} of {len(tests)} tests (mean error up to "
            f"{100 * worst:.0f} %, tolerance {100 * off[0].checks.stress_tolerance:g} %): these are not "
            "constant-sigma_3 angles; rerun with a slower --strain-rate (docs/biaxial.md)"
        )
    if len(stresses) == 1:
        print_result(result, out)
    else:
        print_series(result, out)
    if off:
        raise typer.Exit(1)


def print_result(result, out: Path) -> None:
    """The number to take away first, then each replicate and the checks."""
    console.print(f"[bold]{result.headline()}[/]")
    if not result.critical_state_reached:
        console.print(f"[yellow]{result.critical_state_note}[/]")
    t = Table(title="replicates")
    for col in ("replicate", "phi peak deg", "eps_1 peak %", "phi end deg", "critical", "psi max deg",
                "psi_p max deg", "kappa", "overlap/d peak %", "eps_v end %", "sigma_3 err %",
                "time s"):  # fmt: skip
        t.add_column(col, justify="right")
    for s in result.summaries:
        t.add_row(
            str(s.replicate), f"{s.peak_friction_angle_deg:.1f}", f"{100 * s.axial_strain_at_peak:.1f}",
            f"{s.critical_state_friction_angle_deg:.1f}", "yes" if s.critical_state_reached else "not yet",
            f"{s.max_dilatancy_angle_deg:.1f}", _number(s.plastic_max_dilatancy_angle_deg, 1),
            _number(s.stiffness_number, 0), _number(s.mean_overlap_ratio_at_peak, 2, 100.0),
            f"{100 * s.end_volumetric_strain:+.2f}", f"{100 * s.sigma_3_max_error:.1f}",
            f"{s.wall_time_s:.0f}",
        )  # fmt: skip
    console.print(t)
    console.print(f"psi_max = {result.max_dilatancy_angle.text()} (sin psi = -d eps_v / d eps_s)")
    print_elastic(result.plastic_max_dilatancy_angle, result.stiffness_number, result.tests)
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


def print_series(result, out: Path) -> None:
    """The pooled angles and the envelope first, then a row per stress and the envelope through the origin."""
    console.print(f"[bold]{result.headline()}[/]")
    if not result.critical_state_reached:
        console.print(f"[yellow]{result.critical_state_note}[/]")
    if not result.sigma_3_held:
        console.print(f"[yellow]{result.sigma_3_note}[/]")
    t = Table(title="per confining stress (over its replicates)")
    for col in ("sigma_3 kPa", "phi peak deg", "phi end deg", "critical", "psi max deg", "psi_p max deg",
                "kappa", "overlap/d peak %", "eps_1 peak %"):  # fmt: skip
        t.add_column(col, justify="right")
    for s in result.stresses:
        strain = s.axial_strain_at_peak
        t.add_row(
            f"{s.confining_stress_kpa:g}", s.peak_friction_angle.text(),
            s.critical_state_friction_angle.text(), "yes" if s.critical_state_reached else "not yet",
            s.max_dilatancy_angle.text(),
            s.plastic_max_dilatancy_angle.text() if s.plastic_max_dilatancy_angle is not None else "-",
            _number(s.stiffness_number.mean if s.stiffness_number else None, 0),
            _number(s.mean_overlap_ratio_at_peak.mean if s.mean_overlap_ratio_at_peak else None, 2, 100.0),
            f"{100 * strain.min:.1f}-{100 * strain.max:.1f}",
        )  # fmt: skip
    console.print(t)
    env, env0 = result.envelope, result.envelope_through_origin
    if env.friction_angle_deg is not None:
        console.print(
            f"peak envelope (tangent to {env.points} peak circles): phi = {env.friction_angle_deg:.2f} deg, "
            f"c = {env.cohesion_kpa:.2f} kPa, R2 = {env.r2:.4f}; through the origin phi = "
            f"{env0.friction_angle_deg:.2f} deg"
        )
    console.print(f"psi_max pooled = {result.max_dilatancy_angle.text()} (sin psi = -d eps_v / d eps_s)")
    tests = [t for study in result.studies for t in study.tests]
    print_elastic(result.plastic_max_dilatancy_angle, None, tests)
    console.print(
        f"results in {out}/result.json, biaxial_series.png; each stress in {out}/sigma3_<s>kPa/ "
        "(its result.json, curves.csv, biaxial.png, replicate<k>/)"
    )


def _number(value: float | None, digits: int, scale: float = 1.0) -> str:
    """``scale * value`` with ``digits`` decimals, "-" if None (a test read back from before it was kept)."""
    return "-" if value is None else f"{scale * value:.{digits}f}"


def print_elastic(plastic, kappa, tests) -> None:
    """The plastic psi_max, the stiffness number and the probe's compliances (docs/biaxial.md)."""
    if plastic is not None:
        console.print(f"plastic psi_max = {plastic.text()} (the contacts' elastic strain taken out)")
    if kappa is not None:
        console.print(f"stiffness number kappa = kn / (sigma_3 t) = {kappa.text(0)}")
    probes = [t.elastic_probe for t in tests if t.elastic_probe is not None and t.elastic_probe.reached]
    if probes:
        c1 = [p.axial_compliance for p in probes]
        cc1 = [p.contact_axial_compliance for p in probes]
        console.print(
            f"unloading probe ({probes[0].unload:g} of the deviator after shearing, {len(probes)} test(s)): "
            f"d eps_1 / d sigma_1 = {min(c1):.3g}-{max(c1):.3g} /MPa measured, "
            f"{min(cc1):.3g}-{max(cc1):.3g} /MPa in the contacts' elastic strain"
        )
