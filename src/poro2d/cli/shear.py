"""``poro2d shear``: direct shear tests on a specimen, the Mohr-Coulomb fit and Fig. 8."""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, Table

if TYPE_CHECKING:
    from poro2d.shear.results import ShearSeriesResult

console = OutputConsole()

SHEAR_KEYS_EXTRA = {"normal_stress_kpa", "specimen", "lab", "workers", "rate_check"}


def parse_stresses(
    text: str, parameter: str = "--normal-stress", bounds: tuple[float, float] | None = None
) -> list[float]:
    """'50,100,200' -> [50.0, 100.0, 200.0] (kPa), each in the range a test can hold (``bounds``,
    kPa; default the shear test's).

    An empty item (``50,,100``, a trailing comma) is refused: it is a value left out, and
    the tests run would not be the ones asked for.
    """
    from poro2d.errors import InputError
    from poro2d.shear.settings import NORMAL_STRESS_RANGE_KPA

    lo, hi = bounds or NORMAL_STRESS_RANGE_KPA
    allowed = f"comma-separated numbers in [{lo:g}, {hi:g}] kPa, e.g. 50,100,200"
    vals = []
    for part in str(text).split(","):
        try:
            v = float(part.strip())
        except ValueError:
            raise InputError(parameter, text, allowed, f"{part.strip()!r} is not a number") from None
        if not lo <= v <= hi:  # NaN fails too
            raise InputError(parameter, text, allowed, f"{part.strip()} is out of range")
        vals.append(v)
    return vals


def load_shear_config(path: Path | None) -> tuple[dict, Path | None]:
    """The ``[shear]`` table of a TOML config (the criterion's config file may hold it too)."""
    from poro2d.config import check_keys, load_toml
    from poro2d.criterion.config import TOP_KEYS
    from poro2d.shear.settings import ShearSettings

    if path is None:
        return {}, None
    cfg = load_toml(path)
    check_keys("config", cfg, TOP_KEYS)
    table = cfg.get("shear") or {}
    import dataclasses

    names = {f.name for f in dataclasses.fields(ShearSettings)}
    check_keys("shear", table, names | SHEAR_KEYS_EXTRA)
    return dict(table), Path(path).resolve().parent


def check_extra_types(extra: dict) -> None:
    """Types of the ``[shear]`` keys that are not ShearSettings fields."""
    from poro2d.errors import InputError, check_int, is_number

    for key in ("specimen", "lab"):
        if key in extra and not isinstance(extra[key], str):
            raise InputError(f"shear.{key}", extra[key], "a path (a string)")
    if "workers" in extra:
        check_int("shear.workers", extra["workers"], 1)
    if "rate_check" in extra and not isinstance(extra["rate_check"], bool):
        raise InputError("shear.rate_check", extra["rate_check"], "true or false")
    if "normal_stress_kpa" in extra:
        v = extra["normal_stress_kpa"]
        if not (is_number(v) or (isinstance(v, list) and v and all(is_number(x) for x in v))):
            raise InputError("shear.normal_stress_kpa", v, "a number or a list of numbers in kPa")


def print_stiffness_note(tests) -> None:
    """kappa = kn / (sigma t) and the overlap at the peak per stress: how much strain is the contacts'."""
    rows = [t for t in tests if t.stiffness_number is not None]
    if not rows:
        return
    parts = [
        f"{t.normal_stress_kpa:g} kPa: kappa {t.stiffness_number:.0f}, overlap / d "
        f"{t.mean_overlap_ratio_at_peak:.1e}"
        for t in rows
    ]
    console.print(
        "stiffness number kappa = kn / (sigma t) and mean overlap at the peak: "
        + "; ".join(parts)
        + " (an elastic strain of about 1 / kappa rides on the plate's rise: docs/shear.md)",
        soft_wrap=True,
    )


def register(app: typer.Typer) -> None:
    @app.command("shear")
    def shear_cmd(
        specimen: str = typer.Option(
            None, "--specimen", "-s", help="Specimen checkpoint (.npz) or a criterion output folder."
        ),
        normal_stress: str = typer.Option(
            None, "--normal-stress", "-n", help="Normal stresses in kPa, e.g. 50,100,200."
        ),
        lab: Path = opt.lab(help="Laboratory CSV (curves or peaks), optional."),
        out: Path = opt.out("shear-out"),
        velocity: float = typer.Option(None, "--velocity", help="Shear velocity of the lower half (m/s)."),
        max_displacement: float = opt.max_displacement(),
        stop_after_peak: float = typer.Option(
            None, "--stop-after-peak", help="End once the smoothed peak lies this far behind (m; 0: never)."
        ),
        particle_friction: float = opt.particle_friction(),
        rolling_friction: float = opt.rolling_friction(),
        rate_check: bool = typer.Option(
            False, "--rate-check", help="Repeat every test at half the velocity."
        ),
        workers: int = opt.tests_workers("test, at most two per core"),
        scheduler: str = opt.tests_scheduler(),
        config: Path = opt.config(help="TOML config with a \\[shear] table."),
        quiet: bool = opt.quiet(),
        vtk_every: int = opt.vtk_every(),
    ) -> None:
        """Direct shear tests (the paper's Fig. 8): peak strengths, friction angle, figures."""
        from poro2d.io_utils import check_output_dir
        from poro2d.report.fabric_figures import draw_shear_fabric
        from poro2d.report.shear_figures import draw_shear_series
        from poro2d.shear.lab import read_lab_csv
        from poro2d.shear.run import ShearSeriesCase, run_shear
        from poro2d.store import Store

        check_output_dir("--out", out)
        check_friction_options(particle_friction, rolling_friction)
        series = opt.checked_vtk_every(vtk_every)
        table, base = load_shear_config(config)
        extra = {k: table.pop(k) for k in list(table) if k in SHEAR_KEYS_EXTRA}
        check_extra_types(extra)
        run = opt.job_options(workers if workers is not None else extra.get("workers"), scheduler, quiet)
        options = {
            "velocity": velocity,
            "max_displacement": max_displacement,
            "stop_after_peak": stop_after_peak,
            "particle_friction": particle_friction,
            "rolling_friction": rolling_friction,
        }
        recorded = {"shear": table, **extra, "cli": options}
        lab_path = resolve_path("--lab", lab, extra.get("lab"), base)
        lab_data = read_lab_csv(lab_path) if lab_path is not None else None  # the run's and the figures'
        store = Store(out)
        try:
            with options_as_typed(options, table):
                case = ShearSeriesCase(
                    resolve_path("--specimen", specimen, extra.get("specimen"), base, required=True),
                    resolve_stresses(normal_stress, extra),
                    settings_from_options(
                        table,
                        velocity,
                        max_displacement,
                        stop_after_peak,
                        particle_friction=particle_friction,
                        rolling_friction=rolling_friction,
                        **series,
                    ),  # fmt: skip
                    lab=lab_data,
                    rate_check=rate_check or bool(extra.get("rate_check", False)),
                    config=recorded,
                )
            result = run_shear(case, store, options=run)
        except RuntimeError as exc:
            console.print(f"[bold red]failed:[/] {exc}")
            raise typer.Exit(1) from None
        draw_shear_series(result, store, lab_data)
        draw_shear_fabric(result, store)
        print_result(result, out)


@contextmanager
def options_as_typed(options: dict, table: dict):
    """A setting's refusal named as the user typed it: ``--velocity`` for an option given,
    ``shear.velocity`` for a key of the config's table."""
    from poro2d.errors import InputError

    try:
        yield
    except InputError as exc:
        if options.get(exc.parameter) is not None:
            name = "--" + exc.parameter.replace("_", "-")
        elif exc.parameter in table:
            name = f"shear.{exc.parameter}"
        else:
            raise
        raise InputError(name, exc.value, exc.allowed, exc.hint) from None


def resolve_path(option: str, given, from_config: str | None, base: Path | None, required: bool = False):
    """The command line's path, else the config's (relative to the config file), else None."""
    from poro2d.errors import InputError

    if given is not None:
        return given
    if from_config is not None:
        return str((base / from_config).resolve()) if base is not None else from_config
    if required:
        raise InputError(option, None, "a specimen checkpoint or criterion output folder")
    return None


def resolve_stresses(option_text: str | None, extra: dict) -> list[float]:
    """--normal-stress, else the config's normal_stress_kpa, else the paper's 50, 100, 200 kPa."""
    if option_text is not None:
        return parse_stresses(option_text)
    if "normal_stress_kpa" in extra:
        v = extra["normal_stress_kpa"]
        text = ",".join(str(x) for x in (v if isinstance(v, list) else [v]))
        return parse_stresses(text, "shear.normal_stress_kpa")
    return [50.0, 100.0, 200.0]


def check_friction_options(particle_friction: float | None, rolling_friction: float | None) -> None:
    """--particle-friction and --rolling-friction in the ranges ShearSettings takes, named as typed."""
    from poro2d.errors import check_range
    from poro2d.shear.settings import MAX_FRICTION, MAX_ROLLING_FRICTION

    if particle_friction is not None:
        check_range("--particle-friction", particle_friction, 0.0, MAX_FRICTION)
    if rolling_friction is not None:
        check_range("--rolling-friction", rolling_friction, 0.0, MAX_ROLLING_FRICTION)


def settings_from_options(
    table: dict,
    velocity: float | None,
    max_displacement: float | None,
    stop_after_peak: float | None = None,
    particle_friction: float | None = None,
    rolling_friction: float | None = None,
    vtk_every: int | None = None,
):
    """ShearSettings from the config's [shear] table, the command line's options winning
    (--velocity, --max-displacement, --stop-after-peak, --particle-friction, --rolling-friction,
    --vtk-every)."""
    from poro2d.config import dataclass_from_table
    from poro2d.shear.settings import ShearSettings

    return dataclass_from_table(
        ShearSettings, "shear", table, velocity=velocity, max_displacement=max_displacement,
        stop_after_peak=stop_after_peak, particle_friction=particle_friction,
        rolling_friction=rolling_friction, vtk_every=vtk_every,
    )  # fmt: skip


def _sci(v) -> str:
    """A number in scientific notation; a stored infinity or NaN reads back as None."""
    return "inf" if v is None else f"{v:.2e}"


def residual_cells(residual) -> tuple[str, str]:
    """The residual read where dilation stopped, on the plate's and the plane's normal stress:
    two cells of the table ("not reached" when the plate never stopped; "-" for a test of an
    earlier poro2d, which did not read it)."""
    if residual is None:
        return "-", "-"
    if not residual.reached:
        return "not reached", "not reached"
    plane = residual.plane_stress_ratio
    return f"{residual.stress_ratio:.3f}", "-" if plane is None else f"{plane:.3f}"


def print_residual_note(tests) -> None:
    """What the residual columns are, and where each test's stretch lies."""
    read = [t for t in tests if t.residual_dilation_stopped is not None]
    if not read:
        return
    first = read[0].residual_dilation_stopped
    stretches = "; ".join(f"{t.normal_stress_kpa:g} kPa: {t.residual_dilation_stopped.status}" for t in read)
    console.print(
        f"resid. t/s: the residual tau/sigma where dilation stopped (the plate's net slope against the "
        f"shear displacement within {first.rate_limit:g} over the final stretch and its halves, at least "
        f"{1e3 * first.min_stretch_m:.3g} mm long), on the plate's and on the shear plane's normal stress "
        f"({stretches})"
    )


def box_warning(tests) -> str | None:
    """The warning that tests are box-dominated (poro2d.shear.box_dominated), one line naming each; None
    when none is."""
    flagged = [t for t in tests if t.box_dominated]
    if not flagged:
        return None
    each = "; ".join(f"{t.normal_stress_kpa:g} kPa: {t.box_note.removeprefix('box-dominated: ')}"
                     for t in flagged)  # fmt: skip
    return (
        f"warning: {len(flagged)} of {len(tests)} tests are box-dominated, their tau/sigma is the box's, "
        f"not the soil's ({each})"
    )


def print_result(result: ShearSeriesResult, out: Path) -> None:
    warning = box_warning(result.tests)
    if warning:  # before the answer: a reader who stops at the table must not miss it
        console.print(warning, style="bold red", markup=False, soft_wrap=True)
    t = Table(title="direct shear")
    for col in (
        "sigma_n kPa",
        "peak kPa",
        "d_peak mm",
        "tau/sigma",
        "end kPa",
        "dy_end mm",
        "resid. t/s plate",
        "resid. t/s plane",
        "max I",
        "time s",
    ):
        t.add_column(col, justify="right")
    for r in result.tests:
        t.add_row(
            f"{r.normal_stress_kpa:g}", f"{r.peak_shear_stress_kpa:.2f}",
            f"{1e3 * r.shear_displacement_at_peak_m:.2f}", f"{r.peak_stress_ratio:.3f}",
            f"{r.end.shear_stress_kpa:.2f}", f"{r.end.plate_displacement_mm:.3f}",
            *residual_cells(r.residual_dilation_stopped),
            _sci(r.max_inertial_number), f"{r.wall_time_s:.0f}",
        )  # fmt: skip
    console.print(t)
    print_stiffness_note(result.tests)
    print_residual_note(result.tests)
    from poro2d.shear.box_scale import box_scale_of

    scale = box_scale_of(result)
    label = f"{scale.label()} " if scale is not None and scale.label() else ""
    if result.friction_angle_deg is not None:
        console.print(
            f"Mohr-Coulomb: {label}phi = {result.friction_angle_deg:.2f} deg, "
            f"c = {result.cohesion_kpa:.2f} kPa, R2 = {result.r2:.4f}; "
            f"through the origin phi = {result.friction_angle_through_origin_deg:.2f} deg"
        )
    on_plane = [t for t in result.tests if t.plane_load_fraction_at_peak is not None]
    if on_plane:
        fractions = [t.plane_load_fraction_at_peak for t in on_plane]
        ratios = [t.peak_stress_ratio / t.plane_load_fraction_at_peak for t in on_plane]
        console.print(
            f"the shear plane carries {100 * min(fractions):.0f}-{100 * max(fractions):.0f} % of the plate's "
            f"normal stress at the peaks (side wall friction: below 100 % it holds load up, above it drags "
            f"a dilating upper half down; lab boxes 65-85 %): peak tau/sigma on the plane "
            f"{min(ratios):.3f}-{max(ratios):.3f}"
        )
    if scale is not None:
        console.print(scale.note())
        if scale.warning():
            console.print(f"warning: {scale.warning()}")
    qs = result.quasi_static
    console.print(f"max inertial number {_sci(qs.max_inertial_number)} (limit {qs.inertial_limit:g})")
    rc = result.rate_check
    if rc is not None:
        console.print(
            f"rate check (v/2): largest peak change {100 * rc.max_abs_relative_change:.2f} % "
            f"(tolerance {100 * rc.tolerance:g} %): {'passed' if rc.passed else 'NOT passed'}"
        )
    lab = result.lab
    if lab is not None and lab.friction_angle_deg is not None:
        console.print(
            f"lab: phi = {lab.friction_angle_deg:.2f} deg; "
            f"DEM - lab = {lab.friction_angle_difference_deg:+.2f} deg"
        )
    console.print(f"results in {out}/result.json, figures fig8a_shear_curves.png, fig8b_peak_strength.png")
