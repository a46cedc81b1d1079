"""The laboratory tests' reporters on the engine (:mod:`poro2d.dem.reporters`).

A test's stage runs the engine once with the reporters it needs, each on its own period: the
curve's rows (:class:`CurveRecorder`), the progress display (:class:`ProgressReporter`), the
saved state a killed run continues from (:class:`Checkpointer`) and the test that ends the
stage (:class:`StopTest`). They are called in the order given, so a stage that checkpoints
before its stop test saves its state at the step it stops at too, as the test's files expect.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from poro2d.dem.reporters import Every
from poro2d.store import Checkpoints

#: ``progress(phase, fraction)``: told how far a stage is, for a progress display
ProgressFn = Callable[[str, float], None]


@dataclass
class CurveRecorder:
    """Appends ``row(sim)`` to ``rows`` every ``period`` steps (``rows`` may hold a resumed run's)."""

    period: int
    row: Callable[[Any], Any]
    rows: list = field(default_factory=list)

    def report(self, sim: Any, step: int) -> None:
        self.rows.append(self.row(sim))


@dataclass
class ProgressReporter:
    """Tells ``progress`` the stage's ``phase`` and ``fraction(sim, step)`` every ``period`` steps
    (nothing with no ``progress``: a stage lists its reporters alike, told or not)."""

    period: int
    progress: ProgressFn | None
    phase: str
    fraction: Callable[[Any, int], float]

    def report(self, sim: Any, step: int) -> None:
        if self.progress is not None:
            self.progress(self.phase, self.fraction(sim, step))


@dataclass
class Checkpointer:
    """Saves the engine's state with ``extra()`` (where the stage was) through ``checkpoints`` every
    ``period`` steps before step ``last`` of the run: at the stage's end its results are kept instead
    (nothing with no ``checkpoints``: a run that keeps nothing)."""

    period: int
    checkpoints: Checkpoints | None
    extra: Callable[[], dict]
    last: int

    def report(self, sim: Any, step: int) -> None:
        if self.checkpoints is not None and step < self.last:
            self.checkpoints.save(sim, extra=self.extra())


#: ends the run when ``done(sim)`` says so, asked every ``period`` steps: ``StopTest(period, done)``
StopTest = Every


__all__ = ["Checkpointer", "CurveRecorder", "ProgressFn", "ProgressReporter", "StopTest"]
