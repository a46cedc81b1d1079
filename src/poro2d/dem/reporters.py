"""Reporters: what a run does between its blocks of compiled steps.

A reporter has a ``period`` (steps) and ``report(sim, step) -> stop?``, called at every multiple of
its period counted from the start of :meth:`~poro2d.dem.Simulation.run` (``step``: the steps of
this run so far), or, for a reporter with a ``start`` (the steps its stage ran before this run, as
when resumed from a checkpoint), where ``start + step`` is a multiple of its period. The engine
runs compiled blocks up to the next step any reporter is due at, so reporters decide only where
blocks end (which changes no number) and what is read there. Reporters due at the same step are
called in the order given, all of them, and the run stops after them when any returned True. The
laboratory tests' own reporters (a curve's rows, checkpoints, progress, stop tests) are in
:mod:`poro2d.labtest.reporters`.
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


def drive_blocks(
    advance: Callable[[int], tuple[int, bool]], steps: int, reporters: Sequence[Reporter], engine: Any,
    block: int | None = None,
) -> int:  # fmt: skip
    """Run ``steps`` steps of ``engine`` as ``advance(n)`` calls of at most ``block`` steps that end
    where a reporter is due, the due reporters called after each, all of them in order; the steps run.

    ``advance(n)`` runs up to n steps and returns the steps run and whether the engine stopped by
    itself (its own stop test met): the run ends there, before the reporters. Every engine, the
    walled one and the periodic cell, runs its reporters so.
    """
    check_reporters(reporters)
    done = 0
    while done < steps:
        due = min([steps] + [next_due(r, done) for r in reporters])
        ran, stopped = advance(min(block or steps, due - done))
        done += ran
        if stopped:
            break
        # every reporter due is told, even after one asked to stop (a checkpoint before the stop test)
        if any([r.report(engine, done) for r in reporters if (done + _start(r)) % r.period == 0]):
            break
    return done


def _start(reporter: Reporter) -> int:
    """The steps the reporter's stage ran before this run (0 unless it says)."""
    return getattr(reporter, "start", 0)


def next_due(reporter: Reporter, done: int) -> int:
    """The first step of the run after ``done`` at which ``reporter`` is due."""
    start = _start(reporter)
    return ((done + start) // reporter.period + 1) * reporter.period - start


def check_reporters(reporters: Sequence[Reporter]) -> None:
    """Refuse a reporter without a positive whole period (named as the engine's input)."""
    for r in reporters:
        period = getattr(r, "period", None)
        if not (isinstance(period, (int, np.integer)) and period >= 1 and hasattr(r, "report")):
            raise InputError(
                "reporters", type(r).__name__, "reporters with a period (an integer >= 1) and report()"
            )


__all__ = ["Every", "Reporter", "check_reporters", "drive_blocks", "next_due"]
