"""Reporters: what a run does between its blocks of compiled steps.

A reporter has a ``period`` (steps) and ``report(sim, step) -> stop?``, called at every multiple
of its period counted from the start of :meth:`~poro2d.dem.Simulation.run` (``step``: the steps
of this run so far). The engine runs compiled blocks up to the next step any reporter is due at,
so reporters decide only where blocks end (which changes no number) and what is read there.
Reporters due at the same step are called in the order given, all of them, and the run stops
after them when any returned True. The laboratory tests' own reporters (a curve's rows,
checkpoints, progress, stop tests) are in :mod:`poro2d.labtest.reporters`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from poro2d.errors import InputError


class Reporter(Protocol):
    """Called every ``period`` steps of a run: ``report(sim, step)``; True stops the run."""

    period: int

    def report(self, sim: Any, step: int) -> bool | None: ...


@dataclass
class Every:
    """The simplest reporter: ``call(sim)`` every ``period`` steps; its True stops the run."""

    period: int
    call: Callable[[Any], bool | None]

    def report(self, sim: Any, step: int) -> bool | None:
        return self.call(sim)


def next_event(reporters: Sequence[Reporter], step: int, steps: int) -> int:
    """The first step after ``step`` (at most ``steps``) at which a reporter is due."""
    return min([steps] + [(step // r.period + 1) * r.period for r in reporters])


def report_due(reporters: Sequence[Reporter], sim: Any, step: int) -> bool:
    """Call every reporter due at ``step``, in order; True when one of them asks to stop."""
    stop = False
    for r in reporters:
        if step % r.period == 0:
            stop = bool(r.report(sim, step)) or stop
    return stop


def run_blocks(
    advance: Callable[[int], tuple[int, bool]],
    steps: int,
    reporters: Sequence[Reporter],
    engine: Any,
    block: int | None = None,
) -> int:
    """Run ``steps`` steps of ``engine`` as ``advance(n)`` calls of at most ``block`` steps that end
    where a reporter is due, the due reporters called after each; the steps run.

    ``advance(n)`` runs up to n steps and returns the steps run and whether the engine stopped by
    itself (its own stop test met): the run ends there, before the reporters. Every engine, the
    walled one and the periodic cell, runs its reporters so.
    """
    done = 0
    while done < steps:
        n = min(block or steps, next_event(reporters, done, steps) - done)
        ran, stopped = advance(n)
        done += ran
        if stopped or report_due(reporters, engine, done):
            break
    return done


def check_reporters(reporters: Sequence[Reporter]) -> None:
    """Refuse a reporter without a positive whole period (named as the engine's input)."""
    for r in reporters:
        period = getattr(r, "period", None)
        if not (
            isinstance(period, (int, np.integer)) and period >= 1 and callable(getattr(r, "report", None))
        ):
            raise InputError(
                "reporters", type(r).__name__, "reporters with a period (an integer >= 1) and report()"
            )


__all__ = ["Every", "Reporter", "check_reporters", "next_event", "report_due"]
