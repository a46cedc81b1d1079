"""The laboratory tests' reporters on the engine (:mod:`poro2d.dem.reporters`).

A test's stage runs the engine once with the reporters it needs, each on its own period: the
curve's rows (:class:`CurveRecorder`), the progress display (:class:`ProgressReporter`), the
saved state a killed run continues from (:class:`Checkpointer`), the ParaView time series asked
for (:class:`SeriesRecorder`) and the test that ends the stage (:class:`StopTest`). They are
called in the order given, so a stage that checkpoints before its stop test saves its state at
the step it stops at too, as the test's files expect.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from poro2d.dem.reporters import Every, Reporter
from poro2d.labtest.vtk_series import VtkSeries
from poro2d.store import Checkpoints, Store

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


#: ``clock(engine) -> (stage step, time in s, the test's measure)``: where a stage is now
ClockFn = Callable[[Any], tuple[int, float, float]]


@dataclass
class SeriesRecorder:
    """Writes ``frame(engine)`` as a step of ``series`` (at ``clock(engine)``) every ``period``
    steps of its stage; ``start``: the stage's steps before this run (a run resumed from a
    checkpoint), so that its steps fall where an uninterrupted run's do. It reads the engine only.
    """

    period: int
    series: VtkSeries
    frame: Callable[[Any], Any]
    clock: ClockFn
    start: int = 0

    def report(self, sim: Any, step: int) -> None:
        stage_step, time, value = self.clock(sim)
        self.series.write(self.frame(sim), stage_step, time, value)


def series_reporters(
    every: int, store: Store | None, measure: str, engine: Any, frame: Callable[[Any], Any], clock: ClockFn,
) -> list[Reporter]:  # fmt: skip
    """The reporters of a stage's ParaView series (:mod:`poro2d.labtest.vtk_series`): none when
    ``every`` is 0 or nothing is kept (``store`` None); else one :class:`SeriesRecorder` every
    ``every`` steps, the stage's first state written now when the stage starts afresh.
    """
    if not every or store is None:
        return []
    start = clock(engine)[0]
    series = VtkSeries.open(store, measure, start)
    recorder = SeriesRecorder(every, series, frame, clock, start=start)
    if start == 0:
        recorder.report(engine, 0)
    return [recorder]


#: ends the run when ``done(sim)`` says so, asked every ``period`` steps: ``StopTest(period, done)``
StopTest = Every


__all__ = [
    "Checkpointer", "ClockFn", "CurveRecorder", "ProgressFn", "ProgressReporter", "SeriesRecorder",
    "StopTest", "series_reporters",
]  # fmt: skip
