"""Ctrl-C in worker processes (a local Dask cluster's, the local process pool's): left to the command.

A Ctrl-C at a terminal reaches every process of its group: the command and each worker
process of its local cluster. A worker that takes it as an interruption dies with a
traceback of its own (dozens of lines, for a worker still starting, before the command's
one-line message). The command alone handles it: it closes its cluster, which stops the
workers. Dask's worker processes ignore SIGINT from the moment they import the executor's Dask
backend, those of its local processes (:mod:`poro2d.execute.local`) from their start.
"""

from __future__ import annotations

import multiprocessing
import signal
import threading

#: how distributed names the process a nanny starts for its worker
DASK_WORKER_PROCESS = "Dask Worker process"


def ignore_interrupts_in_dask_worker() -> bool:
    """Ignore SIGINT if this process is a Dask worker process; True if it is one."""
    if not multiprocessing.current_process().name.startswith(DASK_WORKER_PROCESS):
        return False
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    return True


#: the argument multiprocessing gives a process it spawns (``python -c ... --multiprocessing-fork``)
SPAWNED_CHILD_FLAG = "--multiprocessing-fork"


def ignore_interrupts_in_spawned_child() -> bool:
    """Ignore SIGINT if this process is a child the command spawned; True if it is one.

    A spawned child imports the command's main module before anything else it runs (a Dask
    worker then imports distributed for a second or more): a Ctrl-C in that time would kill
    it with a traceback printed beside the command's one line. Called when the command line
    package is imported, this makes every child of the command ignore SIGINT from its first
    import; the command ends them itself.
    """
    import sys

    if SPAWNED_CHILD_FLAG not in sys.argv:
        return False
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    return True


def hold_interrupts() -> set | None:
    """Block SIGINT in this thread while a local cluster or a process pool starts; returns what to restore.

    A Ctrl-C in the middle of the cluster's start-up left it half built, to be closed at
    exit with a traceback. Blocked here, the signal waits until :func:`release_interrupts`,
    when the cluster is whole and the command can close it. (Dask's worker processes start
    with no signal blocked and ignore SIGINT themselves; a process pool's start from this
    thread, with it blocked.)
    """
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask"):
        return None
    return signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})


def release_interrupts(previous: set | None) -> None:
    """Undo :func:`hold_interrupts`; a Ctrl-C that came meanwhile is raised now."""
    if previous is not None and signal.SIGINT not in previous:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
