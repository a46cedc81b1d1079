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

    # sys.orig_argv: multiprocessing gives the child the parent's sys.argv before it imports
    # the main module, so only the interpreter's own command line still shows the flag
    if SPAWNED_CHILD_FLAG not in sys.orig_argv:
        return False
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    return True


class _HeldInterrupt:
    """The SIGINT handler while interrupts are held: it notes a Ctrl-C for the release."""

    def __init__(self, previous) -> None:
        self.previous = previous
        self.came = False

    def __call__(self, signum, frame) -> None:
        self.came = True


def hold_interrupts() -> _HeldInterrupt | None:
    """Hold Ctrl-C while a local cluster or a process pool starts; returns what to release.

    A Ctrl-C in the middle of the cluster's start-up left it half built, to be closed at
    exit with a traceback. Held here, it is noted and raised by :func:`release_interrupts`,
    when the cluster is whole and the command can close it. (Blocking the signal in this
    thread would not hold it: any other thread of the command, numba's or the display's,
    takes it and Python still runs its handler in the main thread.)
    """
    if threading.current_thread() is not threading.main_thread():
        return None
    held = _HeldInterrupt(signal.getsignal(signal.SIGINT))
    signal.signal(signal.SIGINT, held)
    return held


def release_interrupts(held: _HeldInterrupt | None) -> None:
    """Undo :func:`hold_interrupts`; a Ctrl-C that came meanwhile is raised now."""
    if held is None or signal.getsignal(signal.SIGINT) is not held:
        return  # nothing held, or released already
    signal.signal(signal.SIGINT, held.previous if held.previous is not None else signal.SIG_DFL)
    if held.came:
        raise KeyboardInterrupt


def forget_unhandled_interrupt() -> None:
    """Let a handled Ctrl-C end the process with its exit code, not by SIGINT.

    CPython notes a KeyboardInterrupt that leaves any code it runs through its string-running
    C interface, which compiled extensions call while they import. Even when the command
    catches that interrupt and exits with code 130, the note makes the interpreter end by
    signalling itself (exit status -2, as if nothing had handled it). Running one empty
    statement through the same interface clears the note.
    """
    import ctypes

    ctypes.pythonapi.PyRun_SimpleStringFlags(b"pass", None)
