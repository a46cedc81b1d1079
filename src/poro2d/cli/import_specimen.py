"""``poro2d import``: a specimen from another DEM code, checked by the criterion as it stands."""

from __future__ import annotations

from pathlib import Path

import typer

from poro2d.cli import options as opt
from poro2d.console import OutputConsole, Table, shown
from poro2d.store import claims

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "import"

console = OutputConsole()


#: import options that give what a file does not say: (option as typed, key of the defaults, limit,
#: the value it stands for as ``SpecimenData.locate`` names it)
IMPORT_OPTIONS = (
    ("--thickness", "thickness", "thickness", ("thickness", None)),
    ("--density", "solid_density", "density", ("density", 0)),
    ("--kn", "kn_particle", "kn", ("kn", 0)),
    ("--ks", "ks_particle", "ks", ("ks", 0)),
    ("--friction", "friction_particle", "mu", ("mu", 0)),
    ("--wall-friction", "friction_wall", "mu", ("wall:top:mu", None)),
)
#: the longest equilibrium stage ``--max-steps`` may ask for
MAX_STEPS_LIMIT = 100_000_000


@claims(KIND, "out")
def import_cmd(
    file: Path = typer.Argument(
        ..., help="disks.csv (walls.csv beside it), a LAMMPS data file or a checkpoint."
    ),
    out: Path = opt.out("import-out", "Output folder."),
    ratio: float = typer.Option(1e-3, "--ratio", help="Equilibrium: max unbalanced-force ratio."),
    max_steps: int = typer.Option(400_000, "--max-steps", help="Step limit of each stage."),
    thickness: float = typer.Option(None, "--thickness", help="Disk thickness (m) if the file has none."),
    density: float = typer.Option(
        None,
        "--density",
        help="Disk density (kg/m3) if the file has none (a LAMMPS file's masses otherwise).",
    ),
    kn: float = typer.Option(None, "--kn", help="Disk kn (N/m) if the file has none."),
    ks: float = typer.Option(None, "--ks", help="Disk ks (N/m) if the file has none."),
    mu: float = typer.Option(None, "--friction", help="Disk friction if the file has none."),
    wall_mu: float = typer.Option(None, "--wall-friction", help="Wall friction if the file has none."),
    window: float = typer.Option(
        None,
        "--window",
        help="Force window: F_top below this fraction of G (default: the file's, else the paper's 0.01).",
    ),  # fmt: skip
    threads: int = typer.Option(1, "--threads", help="Threads for the DEM kernels."),
    quiet: bool = opt.quiet(),
) -> None:
    """Bring a specimen into poro2d and run the criterion's check on it as it stands."""
    import numba

    from poro2d.criterion.protocol import CriterionSettings
    from poro2d.errors import check_int, check_range
    from poro2d.interop.check import check_specimen, read_specimen
    from poro2d.interop.validate import LIMITS, check_value
    from poro2d.io_utils import Provenance, check_output_dir
    from poro2d.store import Store

    check_range("--ratio", ratio, 0.0, 1.0, lo_open=True)
    check_int("--max-steps", max_steps, 1000, MAX_STEPS_LIMIT)
    check_int("--threads", threads, 1, numba.config.NUMBA_NUM_THREADS)
    values = {"--thickness": thickness, "--density": density, "--kn": kn, "--ks": ks, "--friction": mu,
              "--wall-friction": wall_mu}  # fmt: skip
    given = {}
    for option, key, limit, _ in IMPORT_OPTIONS:
        if values[option] is not None:
            given[key] = check_value(option, values[option], LIMITS[limit])
    if window is not None:
        check_value("--window", window, LIMITS["window"], "a fraction of G in")
    check_output_dir("--out", out)
    spec = read_specimen(file, {**given, "density_given": "solid_density" in given})
    _refuse_options_the_file_overrides(spec, values, given)
    fraction = window if window is not None else (spec.force_fraction or CriterionSettings.force_fraction)
    window_from = "--window" if window is not None else ("the file" if spec.force_fraction else "the paper's")

    store = Store(out)

    def save_state(sim, report) -> None:
        store.save_state("specimen.npz", sim, extra={"stage": "imported", "source": str(file)})

    sim, report = check_specimen(
        spec, settings=CriterionSettings(force_fraction=fraction), ratio=ratio, max_steps=max_steps,
        threads=threads, progress=not quiet, at_equilibrium=save_state,
    )  # fmt: skip
    report["window_from"] = window_from
    if "plate" in report:
        store.save_state("after_plate.npz", sim, extra={"stage": "after_plate", "source": str(file)})
    report["provenance"] = Provenance.now().to_dict()
    store.write_json("check.json", report)
    print_check(report, out)
    if not report["passes"]:
        raise typer.Exit(1)


def _refuse_options_the_file_overrides(spec, values: dict, given: dict) -> None:
    """An option is for what the file does not say: one the file overrides would be ignored
    without a word, so it is refused, naming where the file gives the value."""
    from poro2d.errors import InputError

    for option, key, _, located in IMPORT_OPTIONS:
        if key not in given:
            continue
        where = spec.locate(*located) if spec.locate else f"{spec.source} (a checkpoint)"
        if where != option:
            raise InputError(option, values[option], f"not given: the file sets it ({where})")


def register(app: typer.Typer) -> None:
    app.command("import")(import_cmd)


def print_check(report: dict, out: Path) -> None:
    t = Table(title=f"criterion check: {report['disks']} disks, n = {report['box_porosity']:.4f}")
    columns = ("F_top N/m", "F_bottom N/m", "side friction up N/m", "G N/m", "limit N/m", "equilibrium")
    for col in (*columns, "passes"):
        t.add_column(col, justify="right")
    eq = report["equilibrium"]
    fraction = report["criterion_settings"]["force_fraction"]
    t.add_row(
        f"{report['f_top_n_per_m']:.4g}", f"{report['f_bottom_n_per_m']:.4g}",
        f"{report['side_friction_up_n_per_m']:.4g}", f"{report['self_weight_n_per_m']:.4g}",
        f"{report['force_limit_n_per_m']:.4g}",
        f"{'yes' if eq['converged'] else 'no'} (ratio {eq['max_ratio']:.2g}, {eq['steps']} steps)",
        "yes" if report["passes"] else "no",
    )  # fmt: skip
    console.print(t)
    console.print(f"window: 0 < F_top < {100 * fraction:g} % of G ({report.get('window_from', 'given')})")
    plate = report.get("plate")
    if plate:
        console.print(
            f"the plate settles {'' if plate['plate_settled'] else 'NOT '}after moving {plate['moved']} by "
            f"{1e3 * plate['plate_displacement_m']:.4g} mm: n' = {plate['new_porosity']:.4f}, "
            f"F_top = {plate['f_top_after_n_per_m']:.4g} N/m"
        )
    console.print(shown(f"results in {out}/check.json; the specimen as checked in {out}/specimen.npz"))
