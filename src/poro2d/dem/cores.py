"""Cores lent to the engine between kernel blocks: more threads, never other numbers.

The engine gives the same numbers, bit for bit, on one thread or on up to ``partitions``
threads (docs/engine.md, "Partitions and threads"), and it sets its thread count afresh at
every kernel block. So a process that runs one case of many may give that case more threads
while it runs, when the cores of finished cases fall idle: it installs a *lender*, a
callable that says how many threads a simulation of this process may take now, and every
:class:`~poro2d.dem.simulation.Simulation` asks it at its next block. The lender only
raises a simulation's own ``threads``; the engine still caps the count at its
``partitions``, at numba's thread pool, and at one thread below ``parallel_min_particles``.

A run is not cut into more blocks for it (where a block ends is kept in a checkpoint's kernel
settings): a case takes lent threads where its run's blocks end anyway, at its reporters (the
laboratory stages settle in blocks of 500 steps, ``poro2d.labtest.settle``) or at its next run.
"""

from __future__ import annotations

from collections.abc import Callable

#: the engine's partitions unless a simulation is given others: the most threads a case can use
#: without a change of round-off
DEFAULT_PARTITIONS = 2

Lender = Callable[[], int]

#: this process's lender (None: no cores lent, every simulation keeps its own ``threads``)
_lender: Lender | None = None


#: core-seconds the kernel blocks of this process took beyond one thread since the lender was installed
_lent_seconds = 0.0


def lend_cores(lender: Lender | None) -> Lender | None:
    """Install ``lender`` for the simulations of this process (None: none); returns the one before.
    The count of lent core-seconds starts again from zero."""
    global _lender, _lent_seconds
    before, _lender, _lent_seconds = _lender, lender, 0.0
    return before


def note_block(threads: int, seconds: float) -> None:
    """A kernel block ran ``seconds`` on ``threads`` threads: count what it took beyond one."""
    global _lent_seconds
    if _lender is not None:
        _lent_seconds += max(threads - 1, 0) * seconds


def lent_core_seconds() -> float:
    """Core-seconds taken beyond one thread since the lender was installed (what the cores lent did)."""
    return _lent_seconds


def lending() -> bool:
    """Whether a lender is installed in this process."""
    return _lender is not None


def cores_lent() -> int:
    """The threads the installed lender grants now (1 without a lender, or when it fails)."""
    if _lender is None:
        return 1
    try:
        return max(1, int(_lender()))
    except Exception:  # noqa: BLE001 - a lender that fails lends nothing; the case goes on
        return 1


__all__ = [
    "DEFAULT_PARTITIONS",
    "Lender",
    "cores_lent",
    "lend_cores",
    "lending",
    "lent_core_seconds",
    "note_block",
]
