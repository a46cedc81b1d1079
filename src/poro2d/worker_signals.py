"""Ctrl-C in the worker processes of a local Dask cluster: left to the command that started them.

A Ctrl-C at a terminal reaches every process of its group: the command and each worker
process of its local cluster. A worker that takes it as an interruption dies with a
traceback of its own (dozens of lines, for a worker still starting, before the command's
one-line message). The command alone handles it: it closes its cluster, which stops the
workers. The worker processes ignore SIGINT from the moment they import poro2d.
"""

from __future__ import annotations

import multiprocessing
import signal

#: how distributed names the process a nanny starts for its worker
DASK_WORKER_PROCESS = "Dask Worker process"


def ignore_interrupts_in_dask_worker() -> bool:
    """Ignore SIGINT if this process is a Dask worker process; True if it is one."""
    if not multiprocessing.current_process().name.startswith(DASK_WORKER_PROCESS):
        return False
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    return True
