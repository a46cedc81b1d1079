"""The options several commands share, each spelled once: output folder, config, progress, where
the jobs run (and the :class:`~poro2d.execute.options.RunOptions` they make), and the disk
frictions of a laboratory test.

Each is a function that returns a new option, since a command's option is its own; the help
text is the one every command that takes the option shows, or the command's own where it says
more.
"""

from __future__ import annotations

from contextlib import contextmanager
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

if TYPE_CHECKING:
    from poro2d.execute.options import RunOptions

SCHEDULER_HELP = "Address of a running Dask scheduler (e.g. tcp://host:8786); default: a LocalCluster."
WORKERS_HELP = "Worker processes of the LocalCluster (default: one per core, one thread each)."
DASHBOARD_HELP = "LocalCluster dashboard: HOST:PORT or none (default 127.0.0.1:0, this machine only)."
#: ``--scheduler`` of the laboratory tests (shear, strength, biaxial, critical-state)
TESTS_SCHEDULER_HELP = "Address of a running Dask scheduler whose workers run the tests (default: here)."


def out(default: str, text: str = "Output folder (resumable).") -> Any:
    """``--out``/``-o``, the folder the command writes, ``default`` when not given."""
    return typer.Option(Path(default), "--out", "-o", help=text)


def tests_workers(per: str) -> Any:
    """``--workers`` of a laboratory test command, whose default is one process per ``per``."""
    return workers(help=f"Worker processes on this machine (default: one per {per}).")


# each of these makes the option afresh; help= given to it says the command's own help
config = partial(typer.Option, None, "--config", "-c")
quiet = partial(typer.Option, False, "--quiet", help="No progress bars.")
workers = partial(typer.Option, None, "--workers", help=WORKERS_HELP)
scheduler = partial(typer.Option, None, "--scheduler", help=SCHEDULER_HELP)
tests_scheduler = partial(scheduler, help=TESTS_SCHEDULER_HELP)
dashboard = partial(typer.Option, None, "--dashboard", help=DASHBOARD_HELP)
preset = partial(typer.Option, None, "--preset", help="Built-in case: 'paper'.")
threads = partial(typer.Option, None, "--threads", help="Threads for the DEM kernels.")
max_displacement = partial(typer.Option, None, "--max-displacement", help="Shear displacement (m).")
particle_friction = partial(
    typer.Option, None, "--particle-friction", help="Disk friction for the tests (default: the specimen's)."
)
rolling_friction = partial(
    typer.Option,
    None,
    "--rolling-friction",
    help="Disk rolling friction mu_r for the tests (default: the specimen's).",
)


def job_options(
    workers: int | None, scheduler: str | None, quiet: bool, dashboard: str | None = None
) -> RunOptions:
    """The :class:`~poro2d.execute.options.RunOptions` of a command's ``--workers``, ``--scheduler``,
    ``--quiet`` and ``--dashboard`` (``none``: none), checked: a bad value is refused naming its
    option, a scheduler that does not answer before any work."""
    from poro2d.execute.cluster_options import check_dashboard
    from poro2d.execute.options import RunOptions

    options = RunOptions(workers, scheduler, check_dashboard(dashboard), progress=not quiet)
    if scheduler is not None:
        from poro2d.execute.dask_cluster import check_reachable

        check_reachable(scheduler)
    return options


# the laboratory tests' own arguments and options (shear, strength, biaxial, critical-state,
# calibrate); the help given to each says the command's own
specimens = partial(typer.Argument, None)
specimen_options = partial(typer.Option, None, "--specimen", "-s")
quick = partial(typer.Option, False, "--quick")
seed = partial(typer.Option, None, "--seed")
replicates = partial(typer.Option, None, "--replicates")
max_strain = partial(typer.Option, None, "--max-strain")
lab = partial(typer.Option, None, "--lab")
stiffness_number = partial(typer.Option, None, "--stiffness-number")


def range_option(flag: str, text: str) -> Any:
    """A search range ``flag`` given as ``LOW,HIGH`` (None: the command's default); ``text``: its help."""
    return typer.Option(None, flag, help=text)


# the porosity conversions' options (convert, plot relations), each with the command's own help
nu_reading = partial(typer.Option, "--nu-reading")
lattice_exact = partial(typer.Option, "--lattice-exact")


# the ParaView time series of a laboratory test's run (criterion, shear, biaxial, critical-state)
vtk_every = partial(
    typer.Option,
    None,
    "--vtk-every",
    help="A ParaView series (vtk/series.pvd), a step every N engine steps (0: none; docs/paraview.md).",
)


def checked_vtk_every(value: int | None) -> dict[str, int]:
    """``--vtk-every`` as the settings' ``vtk_every`` ({} when not given), refused on one line when
    negative or beyond any run's steps (:data:`poro2d.labtest.settings.MAX_VTK_EVERY`)."""
    from poro2d.errors import check_int
    from poro2d.labtest.settings import MAX_VTK_EVERY

    return {} if value is None else {"vtk_every": check_int("--vtk-every", value, 0, MAX_VTK_EVERY)}


@contextmanager
def named_as_typed(given: dict[str, Any], names: dict[str, str] | None = None):
    """A refusal of one of ``given``'s arguments (a Python name, e.g. ``n_max``) raised again naming
    the option the user typed (``--n-max``, or ``names[parameter]``); a refusal of an argument the
    user left out (a config's value, named by its key) passes as it is."""
    from poro2d.errors import InputError

    try:
        yield
    except InputError as exc:
        if given.get(exc.parameter) is None:
            raise
        option = (names or {}).get(exc.parameter, "--" + exc.parameter.replace("_", "-"))
        raise InputError(option, exc.value, exc.allowed, exc.hint) from None
