"""One executor for every parallel step: jobs as values, three backends (inline, local processes, Dask).

:mod:`poro2d.execute.jobs` holds the values (``Job``, ``Failed``), :mod:`~poro2d.execute.executor`
the executor and its backend spec, :mod:`~poro2d.execute.local` the inline and process
backends with their live progress queue, :mod:`~poro2d.execute.dask_cluster` the Dask
backend, :mod:`~poro2d.execute.cluster_options` the checks of a command's cluster options and
:mod:`~poro2d.execute.options` the ``RunOptions`` every ``run_*`` takes.
"""

from poro2d.execute.executor import Backend, Executor
from poro2d.execute.jobs import Failed, Job, JobsFailed, results_or_raise
from poro2d.execute.options import RunOptions

__all__ = ["Backend", "Executor", "Failed", "Job", "JobsFailed", "RunOptions", "results_or_raise"]
