"""``poro2d calibrate``: particle and rolling friction (and optionally the disks' kn and ks) from
laboratory direct shear."""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.cli import options as opt
from poro2d.console import OutputConsole

console = OutputConsole()


def parse_range(
    option: str, text: str | None, default: tuple[float, float] | None
) -> tuple[float, float] | None:
    """``LOW,HIGH`` as two numbers (checked against the allowed range later), or the default."""
    from poro2d.errors import InputError

    if text is None:
        return default
    parts = [p.strip() for p in str(text).split(",")]
    try:
        if any("_" in p for p in parts):  # float() reads 0_5 as 5: a typing mistake, not a number
            raise ValueError(text)
        low, high = (float(p) for p in parts)
    except ValueError:
        raise InputError(option, text, "two numbers LOW,HIGH") from None
    return low, high


def register(app: typer.Typer) -> None:
    @app.command("calibrate")
    def calibrate_cmd(
        lab: list[Path] = typer.Option(
            None,
            "--lab",
            help="Laboratory direct shear CSV: peaks, or whole curves (docs/shear.md); repeat for"
            " repeats of the same tests (their mean is fitted).",
        ),
        biaxial_lab: list[Path] = typer.Option(
            None,
            "--biaxial-lab",
            help="Laboratory biaxial CSV (rows named by confining_stress_kpa); repeat for more files."
            " Instead of --lab.",
        ),
        specimen: list[str] = opt.specimen_options(
            help="A specimen (.npz or criterion folder); repeat for replicates."
        ),
        preset: str = opt.preset(help="paper: replicate specimens of the paper's case."),
        quick: bool = opt.quick(help="With --preset paper: the small specimen."),
        replicates: int = opt.replicates(help="With --preset: seeds of its specimens (1-20; default 3)."),
        seed: int = opt.seed(help="With --preset: first seed of its specimens (default 0)."),
        fp_range: str = opt.range_option("--fp-range", "Particle friction range LOW,HIGH (0.3,3)."),
        mu_r_range: str = opt.range_option("--mu-r-range", "Rolling friction range LOW,HIGH (0,0.5)."),
        kn_range: str = opt.range_option(
            "--kn-range", "Also calibrate the disks' normal stiffness kn: range LOW,HIGH (N/m)."
        ),
        ks_range: str = opt.range_option(
            "--ks-range", "Also calibrate the disks' shear stiffness ks: range LOW,HIGH (N/m)."
        ),
        points: int = typer.Option(
            12, "--points", help="Design points of round 1 (9-500; 13 with kn or ks, 18 with both)."
        ),
        refine: int = typer.Option(
            6, "--refine", help="Points of round 2, drawn from the posterior (0: none)."
        ),
        design_seed: int = typer.Option(0, "--design-seed", help="Seed of the design and of round 2's draw."),
        lab_error: float = typer.Option(
            0.0, "--lab-error", help="Laboratory error, a fraction of each value."
        ),
        level: float = typer.Option(0.95, "--level", help="Level of the credible intervals."),
        discrepancy: str = typer.Option(
            "auto",
            "--discrepancy",
            help="Model-discrepancy term: estimate (integrated over its size), none, auto (none for a"
            " laboratory file poro2d made itself, else estimate), or a fixed size in noise sd.",
        ),
        stations: int = typer.Option(
            1, "--stations", help="Readings of each lab curve up to its end (1-10; 1: the end only)."
        ),
        max_displacement: float = opt.max_displacement(),
        max_strain: float = opt.max_strain(help="With --biaxial-lab: axial strain of every test (0.2)."),
        out: Path = opt.out("calibrate-out"),
        scheduler: str = opt.scheduler(),
        workers: int = opt.workers(help="LocalCluster worker processes (default: one per core)."),
        dashboard: str = opt.dashboard(),
        keep_box_dominated: bool = typer.Option(
            False,
            "--keep-box-dominated",
            help="Fit design points whose tests are box-dominated too (left out by default): the"
            " frictions then describe the box.",
        ),
        quiet: bool = opt.quiet(),
    ) -> None:
        """Calibrate particle friction f_p and rolling friction mu_r against laboratory direct shear or
        biaxial tests."""
        from poro2d.calibration.case import DEFAULT_FP_RANGE, DEFAULT_MU_R_RANGE, CalibrationCase
        from poro2d.calibration.run import run_calibration
        from poro2d.calibration.specimens import PRESET_REPLICATES, PRESET_SEED
        from poro2d.report.calibration_figures import draw_calibration
        from poro2d.report.criterion_figures import draw_specimens
        from poro2d.store import Store

        settings = test_settings(bool(biaxial_lab), max_displacement, max_strain)
        labs = [str(p) for p in lab or []]
        options = {
            "lab": (labs[0] if len(labs) == 1 else labs) or None,
            **({"biaxial_lab": [str(p) for p in biaxial_lab]} if biaxial_lab else {}),
            "specimen": specimen or None,
            "preset": preset,
            "quick": quick,
            "replicates": PRESET_REPLICATES if replicates is None else replicates,  # as files recorded them
            "seed": PRESET_SEED if seed is None else seed,
            "fp_range": fp_range,
            "mu_r_range": mu_r_range,
            **{k: v for k, v in (("kn_range", kn_range), ("ks_range", ks_range)) if v is not None},
            "max_displacement": max_displacement,
            **({"max_strain": max_strain} if max_strain is not None else {}),
            **({"keep_box_dominated": True} if keep_box_dominated else {}),
            **({"discrepancy": discrepancy} if discrepancy != "auto" else {}),
        }
        run = opt.job_options(workers, scheduler, quiet, dashboard)  # a scheduler that does not answer: now
        ranges = {
            name: parse_range(f"--{name.replace('_', '-')}", text, default)
            for name, text, default in (("fp_range", fp_range, DEFAULT_FP_RANGE),
                                        ("mu_r_range", mu_r_range, DEFAULT_MU_R_RANGE),
                                        ("kn_range", kn_range, None), ("ks_range", ks_range, None))
        }  # fmt: skip
        case = CalibrationCase.of(
            (lab[0] if len(lab) == 1 else list(lab)) if lab else None, list(specimen or []),
            biaxial_lab=list(biaxial_lab) if biaxial_lab else None, settings=settings,
            config={"cli": options}, preset=preset, quick=quick, replicates=replicates, seed=seed, **ranges,
            points=points, refine=refine, design_seed=design_seed, lab_error=lab_error, level=level,
            stations=stations, keep_box_dominated=keep_box_dominated, discrepancy=discrepancy,
        )  # fmt: skip
        store = Store(out)
        try:
            result = run_calibration(case, store, options=run)
        except RuntimeError as exc:
            console.print(f"[bold red]failed:[/] {exc}")
            raise typer.Exit(1) from None
        finally:  # the preset specimens' figures, also when the calibration after them failed
            draw_specimens(store.child("specimens"))
        draw_calibration(result, store)
        print_result(result, out)


def test_settings(biaxial: bool, max_displacement: float | None, max_strain: float | None) -> dict | None:
    """The settings the options give every test: a shear test's displacement, or a biaxial test's
    axial strain; the option of the other kind of test is refused."""
    from poro2d.errors import InputError

    if biaxial:
        if max_displacement is not None:
            raise InputError(
                "--max-displacement", max_displacement, "nothing with --biaxial-lab (--max-strain)"
            )
        return None if max_strain is None else {"max_strain": max_strain}
    if max_strain is not None:
        raise InputError("--max-strain", max_strain, "only with --biaxial-lab (--max-displacement for --lab)")
    return None if max_displacement is None else {"max_displacement": max_displacement}


def print_result(result, out: Path) -> None:
    from poro2d.report.calibration_report import calibrated, interval_text, notes

    for name, label, _ in calibrated(result):
        console.print(f"  {label:<5} {interval_text(result, name)}")
    for note in notes(result):
        console.print(f"  {note}")
    console.print(
        f"results in {out}/result.json; config {out}/calibrated.toml; report {out}/calibration.html"
    )


__all__ = ["register"]
