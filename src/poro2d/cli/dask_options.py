"""The Dask options that ``poro2d sweep``, ``relation``, ``sensitivity`` and ``calibrate`` share:
their help texts, and the :class:`~poro2d.execute.options.RunOptions` they make."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from poro2d.execute.options import RunOptions

SCHEDULER_HELP = "Address of a running Dask scheduler (e.g. tcp://host:8786); default: a LocalCluster."
WORKERS_HELP = "Worker processes of the LocalCluster (default: one per core, one thread each)."
DASHBOARD_HELP = "LocalCluster dashboard: HOST:PORT or none (default 127.0.0.1:0, this machine only)."


def command_options(
    workers: int | None, scheduler: str | None, dashboard: str | None, quiet: bool
) -> RunOptions:
    """``--workers``, ``--scheduler``, ``--dashboard`` (``none``: none) and ``--quiet``, checked."""
    from poro2d.execute.cluster_options import check_dashboard
    from poro2d.execute.options import RunOptions

    return RunOptions(workers, scheduler, check_dashboard(dashboard), progress=not quiet)
