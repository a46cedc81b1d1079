"""The progress display of every command: rich's live bars on a terminal, plain lines in a log.

One family with one look: :class:`StepProgress` (a run of DEM steps), :class:`CountProgress`
(the cases of a sweep, a calibration's tests) and :class:`JobsProgress` (the jobs of the
executor's local processes, :mod:`poro2d.execute.local`, one bar each). On a terminal each
draws the same bars, redrawn in place: the label, the bar, what it counts, a note, the
elapsed time and the ETA. Written to a file or a pipe, rich's live display would leave only
its last state, cut to 80 columns; there every display prints plain lines of one format instead (see
:func:`progress_line`): at most one every :data:`LINE_INTERVAL_S` seconds while it runs,
and one when it ends, e.g.::

    layer 2: 52,000/400,000 steps (13 %), 54,971 steps/s, 6.16 M p-steps/s, ratio 8.18e-04, elapsed 0:00:01
    sweep: 3/10 cases (30 %), 1 failed, elapsed 0:12:40, eta 0:29:33
    direct shear: 50 kPa done, 100 kPa shearing 42 %, 200 kPa consolidating, elapsed 0:03:10

A display only reads what it is told; it never changes a computation.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TaskProgressColumn,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

LINE_INTERVAL_S = 10.0  # least time between two progress lines in a log


def live_console() -> Console | None:
    """rich's console on stderr if it is an interactive terminal (live bars), else None."""
    console = Console(stderr=True)
    return console if console.is_interactive else None


def clock_text(seconds: float) -> str:
    """Seconds as h:mm:ss."""
    s = int(seconds)
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}"


def progress_line(label: str, parts: Sequence[str], elapsed_s: float, eta_s: float | None = None) -> str:
    """The one format of a progress line: ``label: part, part, elapsed h:mm:ss[, eta h:mm:ss]``."""
    clock = [f"elapsed {clock_text(elapsed_s)}"] + ([f"eta {clock_text(eta_s)}"] if eta_s is not None else [])
    return f"{label}: " + ", ".join([*parts, *clock])


def _bars(console: Console, *middle) -> Progress:
    """rich's live bars with the columns every display shares around its own ``middle`` ones."""
    return Progress(
        TextColumn("[bold]{task.description}"), BarColumn(), *middle,
        TimeElapsedColumn(), TextColumn("eta"), TimeRemainingColumn(),
        console=console,
    )  # fmt: skip


class ProgressLines:
    """Plain progress lines on stderr: at most one every ``interval`` seconds, plus forced ones.

    ``interval`` defaults to :data:`LINE_INTERVAL_S` at the time of the call. The first
    periodic line comes one interval after the start, so a stage shorter than that writes
    a single line: its last. ``state`` (what the line reports, without the clock) keeps
    a forced last line from repeating the line just written.
    """

    def __init__(self, interval: float | None = None, clock: Callable[[], float] = time.monotonic) -> None:
        self.interval = float(LINE_INTERVAL_S if interval is None else interval)
        self._clock = clock
        self._last = clock()
        self._state: object = None

    def write(self, text: str, force: bool = False, state: object = None) -> bool:
        """Write ``text`` as one line if an interval has passed (or ``force``); True if written."""
        now = self._clock()
        if not force and now - self._last < self.interval:
            return False
        if force and state is not None and state == self._state:
            return False  # the same news as the line before
        self._last = now
        self._state = state
        print(text, file=sys.stderr, flush=True)  # sys.stderr of the moment: it may have been redirected
        return True


class _Display:
    """What every display does: bars on a terminal or lines in a log, started and stopped once.

    A subclass defines what its bars show (``_columns``, ``_add_tasks``, ``_draw``), its line
    (``line``) and what a line reports without the clock (``_news``: a forced last line repeats
    no line just written). Usable as a
    context manager; ``enabled=False`` shows nothing.
    """

    def __init__(self, label: str, enabled: bool = True) -> None:
        self.label = label
        self.enabled = enabled
        self._t0 = time.perf_counter()
        self._progress: Progress | None = None
        self._lines: ProgressLines | None = None

    def start(self) -> None:
        self._t0 = time.perf_counter()
        if not self.enabled:
            return
        console = live_console()
        if console is None:
            self._lines = ProgressLines()
            return
        self._progress = _bars(console, *self._columns())
        self._progress.start()
        self._add_tasks(self._progress)

    def stop(self) -> None:
        if self._lines is not None:
            self._lines.write(self.line(), force=True, state=self._news())
        elif self._progress is not None:
            self._progress.stop()

    def __enter__(self):
        self.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def elapsed(self) -> float:
        return time.perf_counter() - self._t0

    def _refresh(self, force: bool = False) -> None:
        """Show the new state: redraw the bars, or a line if one is due (or ``force``)."""
        if self._lines is not None:
            self._lines.write(self.line(), force=force, state=self._news())
        elif self._progress is not None:
            self._draw(self._progress)


class StepProgress(_Display):
    """Progress of one run of steps; ``update`` from the driver between blocks."""

    def __init__(self, label: str, total_steps: int, n_particles: int) -> None:
        super().__init__(label)
        self.total = max(int(total_steps), 1)
        self.n = n_particles
        self._task = None
        self._done = 0
        self._ratio: float | None = None

    def _columns(self) -> tuple:
        steps = TextColumn("{task.completed:>9,.0f}/{task.total:,.0f} steps")
        return steps, TextColumn("{task.fields[speed]}"), TextColumn("{task.fields[ratio]}")

    def _add_tasks(self, progress: Progress) -> None:
        self._task = progress.add_task(self.label, total=self.total, speed="", ratio="")

    def _speed(self) -> float:
        """Steps per second so far."""
        dt = self.elapsed()
        return self._done / dt if dt > 0 else 0.0

    def update(self, done: int, ratio: float | None = None) -> None:
        """``done`` steps so far; ``ratio`` the unbalanced-force ratio of the last stop test, if any."""
        self._done = int(done)
        if ratio is not None:
            self._ratio = float(ratio)
        self._refresh()

    def _draw(self, progress: Progress) -> None:
        sps = self._speed()
        speed = f"{sps:,.0f} steps/s {sps * self.n / 1e6:,.2f} M p-steps/s"
        rtxt = f"ratio {self._ratio:.2e}" if self._ratio is not None else ""
        progress.update(self._task, completed=self._done, speed=speed, ratio=rtxt)

    def _news(self) -> object:
        return self._done

    def line(self) -> str:
        """The state as one plain line (label, steps, percent, speed, ratio, elapsed)."""
        sps = self._speed()
        parts = [
            f"{self._done:,}/{self.total:,} steps ({100.0 * self._done / self.total:.0f} %)",
            f"{sps:,.0f} steps/s",
            f"{sps * self.n / 1e6:,.2f} M p-steps/s",
        ]
        if self._ratio is not None:
            parts.append(f"ratio {self._ratio:.2e}")
        return progress_line(self.label, parts, self.elapsed())


class CountProgress(_Display):
    """Progress over a number of items (the cases of a sweep), as a context manager.

    A rich bar on a terminal; in a log, lines such as
    ``sweep: 3/10 cases (30 %), 1 failed, elapsed 0:12:40, eta 0:29:33``.
    """

    def __init__(self, label: str, total: int, unit: str = "cases", enabled: bool = True) -> None:
        super().__init__(label, enabled)
        self.total = int(total)
        self.unit = unit
        self.done = 0
        self.note = ""
        self._task = None

    def _columns(self) -> tuple:
        return MofNCompleteColumn(), TextColumn("{task.fields[note]}")

    def _add_tasks(self, progress: Progress) -> None:
        self._task = progress.add_task(self.label, total=self.total, note="")

    def advance(self, note: str = "") -> None:
        """One more item done; ``note`` (plain text, e.g. '2 failed') is shown beside the count."""
        self.done += 1
        self.note = note
        self._refresh()

    def _draw(self, progress: Progress) -> None:
        progress.update(self._task, completed=self.done, note=f"[red]{self.note}[/]" if self.note else "")

    def _news(self) -> object:
        return (self.done, self.note)

    def line(self) -> str:
        dt = self.elapsed()
        parts = [f"{self.done}/{self.total} {self.unit} ({100.0 * self.done / max(self.total, 1):.0f} %)"]
        if self.note:
            parts.append(self.note)
        eta = dt / self.done * (self.total - self.done) if 0 < self.done < self.total else None
        return progress_line(self.label, parts, dt, eta)


class JobsProgress(_Display):
    """One bar per job of a pool (a phase and, while it has one, a fraction), as a context manager.

    In a log one line for all the jobs, e.g.
    ``direct shear: 50 kPa done, 100 kPa shearing 42 %, 200 kPa consolidating, elapsed 0:03:10``.
    """

    def __init__(self, label: str, names: Sequence[str], enabled: bool = True) -> None:
        super().__init__(label, enabled)
        self.names = list(names)
        self._phase = ["waiting"] * len(self.names)
        self._fraction: list[float | None] = [None] * len(self.names)
        self._ended = [False] * len(self.names)
        self._changed = 0  # the job whose bar is redrawn
        self._tasks: list = []

    def _columns(self) -> tuple:
        return TaskProgressColumn(), TextColumn("{task.fields[phase]}")

    def _add_tasks(self, progress: Progress) -> None:
        self._tasks = [progress.add_task(name, total=1.0, phase="waiting") for name in self.names]

    def update(self, index: int, phase: str, fraction: float | None = None) -> None:
        """Job ``index`` is in ``phase``, ``fraction`` of the way through it (None: not measured)."""
        self._phase[index], self._fraction[index] = phase, fraction
        self._changed = index
        self._refresh()

    def done(self, index: int, text: str = "done") -> None:
        """Job ``index`` has ended; ``text`` says how (its bar is then full; in a log, a line at once)."""
        self._phase[index], self._fraction[index] = text, None
        self._ended[index] = True
        self._changed = index
        self._refresh(force=True)

    def _draw(self, progress: Progress) -> None:
        i = self._changed
        completed = 1.0 if self._ended[i] else (self._fraction[i] or 0.0)
        progress.update(self._tasks[i], completed=completed, phase=self._phase[i])

    def _news(self) -> object:
        return tuple(
            zip(self._phase, (None if f is None else round(100 * f) for f in self._fraction), strict=True)
        )

    def line(self) -> str:
        parts = [
            f"{name} {phase}" + (f" {100.0 * frac:.0f} %" if frac is not None else "")
            for name, phase, frac in zip(self.names, self._phase, self._fraction, strict=True)
        ]
        return progress_line(self.label, parts, self.elapsed())
