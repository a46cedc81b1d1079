"""``poro2d strength``: peak and residual friction angles and dilation against mu_r and f_p."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, Table

if TYPE_CHECKING:
    from poro2d.shear.results import StrengthResult
    from poro2d.specimen.specimen_set import SpecimenSet

console = OutputConsole()

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "strength"


def parse_values(text: str, option: str, hi: float) -> list[float]:
    """'0,0.1,0.2' -> [0.0, 0.1, 0.2], each in [0, hi], all different; refused on one line."""
    from poro2d.errors import InputError

    allowed = f"comma-separated different numbers in [0, {hi:g}], e.g. 0,0.1,0.2"
    values = []
    for part in str(text).split(","):
        try:
            if "_" in part:  # float() reads 0_1 as 1: a typing mistake, not a number
                raise ValueError(part)
            v = float(part.strip())
        except ValueError:
            raise InputError(option, text, allowed, f"{part.strip()!r} is not a number") from None
        if not 0.0 <= v <= hi:  # NaN fails too
            raise InputError(option, text, allowed, f"{part.strip()} is out of range")
        values.append(v)
    if len(set(values)) != len(values):
        raise InputError(option, text, allowed, "a value is repeated")
    return values


def quick_specimens(out: Path, seeds: int, progress: bool) -> SpecimenSet:
    """The paper's quick specimen (``poro2d paper --quick``) of seed 0 and those of the next seeds,
    by their labels.

    The criterion and its replicate runs are the paper's own stages, resumable in ``out``.
    """
    from poro2d.criterion.config import paper_config
    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.criterion.replicates import accepted_and_replicates
    from poro2d.report.criterion_figures import draw_specimens
    from poro2d.store import Store

    cfg = paper_config(True, 0)
    spec, grading, settings, seed = cfg.build(threads=1)
    crit = PorosityCriterion(spec, grading, settings, seed=seed, store=Store(out / "criterion"),
                             progress=progress, config=cfg.as_config())  # fmt: skip
    try:
        result = crit.run()
        if not result.converged:
            raise RuntimeError(f"the quick specimen was not accepted: {result.message}")
        specimens, _ = accepted_and_replicates(crit.spec, crit.grading, crit.settings, result.final_porosity,
                                               crit.seed, seeds, Store(out), progress=progress)  # fmt: skip
    finally:  # the specimens' figures, drawn from the states their runs kept
        draw_specimens(Store(out))
    return specimens


def one_box(specimens: SpecimenSet) -> SpecimenSet:
    """``specimens``, refused unless all are in one box: the study takes them as seeds of one
    specimen, and another box's angles would be counted as seed scatter.

    The widths must be the same; the heights may differ by the plate's settling, less than a
    largest disk (replicate seeds of one state differ by a fraction of one).
    """
    import numpy as np

    from poro2d.errors import InputError

    values = specimens.contents()
    w0, h0 = values[0].box()
    for label, value in zip(specimens, values, strict=True):
        w, h = value.box()
        d_max = 2.0 * max(float(np.max(v.arrays["particles.radius"])) for v in (values[0], value))
        if abs(w - w0) > 1e-9 * w0 or abs(h - h0) > d_max:
            first = specimens[next(iter(specimens))]
            raise InputError(
                "SPECIMEN...", str(specimens[label]), f"replicate specimens of one box, as {first}",
                f"its box is {w:.4g} m x {h:.4g} m, that one's {w0:.4g} m x {h0:.4g} m",
            )  # fmt: skip
    return specimens


#: the most tests a strength grid starts unless asked for more: the quick grid is 72 (8 cases,
#: 3 specimens, 3 stresses, minutes); a grid of hundreds of cases is hours of work, which a
#: typo in --mu-r or --friction should not start unannounced
MAX_TESTS = 300


def register(app: typer.Typer) -> None:
    @app.command("strength")
    def strength_cmd(
        specimen: list[str] = opt.specimens(
            help="Replicate specimens (checkpoints or criterion folders), one per seed; or --quick."
        ),
        quick: bool = opt.quick(help="The paper's quick specimen on --seeds seeds, a short grid (minutes)."),
        seeds: int = typer.Option(None, "--seeds", help="With --quick: replicate specimens (default 3)."),
        mu_r: str = typer.Option(None, "--mu-r", help="Rolling frictions, e.g. 0,0.1,0.2,0.4."),
        friction: str = typer.Option(None, "--friction", help="Particle frictions f_p, e.g. 0.5,1,3."),
        normal_stress: str = typer.Option(None, "--normal-stress", "-n", help="Normal stresses (kPa)."),
        max_displacement: float = opt.max_displacement(),
        out: Path = opt.out("strength-out"),
        workers: int = opt.tests_workers("test, at most two per core"),
        scheduler: str = opt.tests_scheduler(),
        max_tests: int = typer.Option(
            MAX_TESTS,
            "--max-tests",
            help="Most direct shear tests the grid may start (cases x specimens x stresses); "
            "a larger grid is refused before any work.",
        ),
        quiet: bool = opt.quiet(),
    ) -> None:
        """Peak and residual friction angles and dilation against rolling and particle friction."""
        from poro2d.cli.shear import parse_stresses
        from poro2d.errors import InputError, check_int
        from poro2d.io_utils import check_output_dir
        from poro2d.report.strength_figure import draw_strength
        from poro2d.shear import strength as st
        from poro2d.shear.settings import MAX_FRICTION, MAX_ROLLING_FRICTION, ShearSettings
        from poro2d.specimen.specimen_set import SpecimenSet
        from poro2d.store import Store

        # everything is checked before the first specimen or test is made
        check_output_dir("--out", out)
        if bool(quick) == bool(specimen):
            raise InputError(
                "SPECIMEN.../--quick", specimen or None, "one of them: specimen paths, or --quick"
            )
        if seeds is not None and not quick:
            raise InputError("--seeds", seeds, "only with --quick (give one specimen path per replicate)")
        n_seeds = check_int("--seeds", seeds, 1, 20) if seeds is not None else st.QUICK_SEEDS
        mu_values = parse_values(mu_r, "--mu-r", MAX_ROLLING_FRICTION) if mu_r else list(st.QUICK_MU_R)
        fp_values = (
            parse_values(friction, "--friction", MAX_FRICTION) if friction else list(st.QUICK_FRICTION)
        )
        stresses = parse_stresses(normal_stress) if normal_stress else list(st.QUICK_NORMAL_STRESSES)
        run = opt.job_options(workers, scheduler, quiet)
        check_int("--max-tests", max_tests, 1, 1_000_000)
        n_tests = len(mu_values) * len(fp_values) * (n_seeds if quick else len(specimen)) * len(stresses)
        if n_tests > max_tests:
            raise InputError(
                "--max-tests", max_tests, f"at least the grid's {n_tests} tests",
                f"{len(mu_values)} mu_r x {len(fp_values)} f_p x {n_seeds if quick else len(specimen)} "
                f"specimen(s) x {len(stresses)} stresses; raise --max-tests to run them all",
            )  # fmt: skip
        shear = dict(st.QUICK_STRENGTH_SHEAR) if quick else {"stop_after_peak": 0.0}
        if max_displacement is not None:
            shear["max_displacement"] = max_displacement
        settings = ShearSettings(**shear)
        # the given specimens: each one the criterion accepted, read whole, before the folder is claimed
        labelled = {f"specimen{k + 1}": p for k, p in enumerate(specimen or [])}
        given = None if quick else one_box(SpecimenSet.accepted(labelled, "SPECIMEN").read())
        config = {"quick": quick, "seeds": n_seeds if quick else None, "specimens": specimen or None,
                  "mu_r": mu_values, "particle_friction": fp_values, "normal_stress_kpa": stresses,
                  "shear": shear}  # fmt: skip
        store = Store(out)
        with store.claim(KIND):
            if quick:
                console.print(f"[bold]quick specimens[/] (the paper's quick preset), {n_seeds} seed(s)")
                specimens = quick_specimens(out / "specimens", n_seeds, not quiet)
            else:
                specimens = given
            study = st.StrengthStudy(specimens, mu_values, fp_values, stresses, settings, store=store,
                                     options=run, config=config)  # fmt: skip
            console.print(
                f"[bold]direct shear[/] over {len(study.cases)} (mu_r, f_p) cases x {len(specimens)} "
                f"specimen(s) x {len(stresses)} normal stresses on {study.processes} processes"
            )
            try:
                result = study.run()
            except RuntimeError as exc:
                console.print(f"[bold red]failed:[/] {exc}")
                raise typer.Exit(1) from None
            draw_strength(result, study.store)
        print_strength(result, out)


def _deg(mean, sd) -> str:
    if mean is None:
        return "-"
    return f"{mean:.1f}" + ("" if sd is None else f" +- {sd:.1f}")


def _stopped(case) -> str:
    """A case's residual where dilation stopped: plate / plane (k tests), "not reached", or "-"
    (a study of an earlier poro2d)."""
    from poro2d.shear.parts import StrengthCase
    from poro2d.typed_result import part

    case = part(StrengthCase, case)  # a row read back as its dict, too
    k = case.tests_dilation_stopped
    if k is None:
        return "-"
    if not k:
        return "not reached"
    plane = case.residual_dilation_stopped_plane_ratio_mean
    return (
        f"{case.residual_dilation_stopped_ratio_mean:.3f} / "
        + ("-" if plane is None else f"{plane:.3f}")
        + f" ({k})"
    )


def stiffness_note(cases) -> str | None:
    """The contacts' stiffness over the study in one line: kappa's extent and the largest overlap."""
    ranges = [(c.stiffness_number_min, c.stiffness_number_max) for c in cases if c.stiffness_number_min]
    overlaps = [c.mean_overlap_ratio_at_peak_max for c in cases if c.mean_overlap_ratio_at_peak_max]
    if not ranges:
        return None
    lo, hi = min(r[0] for r in ranges), max(r[1] for r in ranges)
    text = f"kappa = kn / (sigma t) {lo:.0f} to {hi:.0f}"
    if overlaps:
        text += f", mean overlap / d at the peak up to {max(overlaps):.1e}"
    return text + ": below kappa 1000 psi max carries the contacts' elastic strain (docs/critical-state.md)"


def print_strength(result: StrengthResult, out: Path) -> None:
    from poro2d.shear.box_scale import box_scale_of
    from poro2d.shear.residual import DILATION_RATE_LIMIT

    scale = box_scale_of(result)
    label = f"{scale.label()} " if scale is not None and scale.label() else ""
    t = Table(title=f"{label}strength against rolling and particle friction (mean +- sd over specimens)")
    for col in ("mu_r", "f_p", "phi peak deg", "phi residual deg", "psi max deg", "tau/sigma residual",
                "t/s dilation stopped"):  # fmt: skip
        t.add_column(col, justify="right")
    for r in result.cases:
        t.add_row(
            f"{r.mu_r:g}", f"{r.particle_friction:g}",
            _deg(r.peak_friction_angle_mean_deg, r.peak_friction_angle_sd_deg),
            _deg(r.residual_friction_angle_mean_deg, r.residual_friction_angle_sd_deg),
            _deg(r.max_dilation_angle_mean_deg, r.max_dilation_angle_sd_deg),
            f"{r.residual_stress_ratio_mean:.3f}", _stopped(r),
        )  # fmt: skip
    console.print(t)
    if any(r.tests_dilation_stopped is not None for r in result.cases):
        console.print(
            "tau/sigma residual: over the last fifth of each curve, whether or not the plate still rises; "
            "t/s dilation stopped: over the tests whose plate stopped rising (net d plate / d shear within "
            f"{DILATION_RATE_LIMIT:g} over a final stretch), on the plate's / the shear plane's normal "
            "stress, with how many did"
        )
    stiffness = stiffness_note(result.cases)
    if stiffness:
        console.print(stiffness)
    if scale is not None:
        console.print(scale.note())
        if scale.warning():
            console.print(f"warning: {scale.warning()}")
    console.print(
        f"results in {out}/strength.json, strength.csv, strength_tests.csv; figure fig_strength.png"
    )
