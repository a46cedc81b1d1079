"""The options every command shares on where its jobs run: help texts, and the
:class:`~poro2d.execute.options.RunOptions` they make."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from poro2d.execute.options import RunOptions

SCHEDULER_HELP = "Address of a running Dask scheduler (e.g. tcp://host:8786); default: a LocalCluster."
WORKERS_HELP = "Worker processes of the LocalCluster (default: one per core, one thread each)."
DASHBOARD_HELP = "LocalCluster dashboard: HOST:PORT or none (default 127.0.0.1:0, this machine only)."
#: ``--scheduler`` of the laboratory tests (shear, strength, biaxial, critical-state)
TESTS_SCHEDULER_HELP = "Address of a running Dask scheduler whose workers run the tests (default: here)."


def tests_workers_help(per: str) -> str:
    """``--workers`` of a laboratory test command, whose default is one process per ``per``."""
    return f"Worker processes on this machine (default: one per {per})."


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
