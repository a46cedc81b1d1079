"""Progress displays: rich's live bars on a terminal, plain lines in a log.

On a terminal the bars are redrawn in place (DEM speed in steps/s and particle-steps/s,
ETA). Written to a file or a pipe, rich's live display would leave only its last
state, cut to 80 columns; there every display prints plain lines instead: at most one
every :data:`LINE_INTERVAL_S` seconds while it runs, and one when it ends, e.g.::

    layer 2: 52,000/400,000 steps (13 %), 54,971 steps/s, 6.16 M p-steps/s, ratio 8.18e-04, elapsed 0:00:01
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
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


class StepProgress:
    """Progress of one run of steps; ``update`` from the driver between blocks."""

    def __init__(self, label: str, total_steps: int, n_particles: int) -> None:
        self.total = max(int(total_steps), 1)
        self.n = n_particles
        self.label = label
        self._console = live_console()
        self._progress: Progress | None = None
        self._lines: ProgressLines | None = None
        self._task = None
        self._t0 = 0.0
        self._done = 0
        self._ratio: float | None = None

    def start(self) -> None:
        self._t0 = time.perf_counter()
        if self._console is None:
            self._lines = ProgressLines()
            return
        self._progress = Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            TextColumn("{task.completed:>9,.0f}/{task.total:,.0f} steps"),
            TextColumn("{task.fields[speed]}"),
            TextColumn("{task.fields[ratio]}"),
            TimeElapsedColumn(),
            TextColumn("eta"),
            TimeRemainingColumn(),
            console=self._console,
            transient=False,
        )
        self._progress.start()
        self._task = self._progress.add_task(self.label, total=self.total, speed="", ratio="")

    def _speed(self) -> tuple[float, float]:
        """(elapsed s, steps/s)."""
        dt = time.perf_counter() - self._t0
        return dt, (self._done / dt if dt > 0 else 0.0)

    def update(self, done: int, ratio: float | None = None) -> None:
        """``done`` steps so far; ``ratio`` the unbalanced-force ratio of the last stop test, if any."""
        self._done = int(done)
        if ratio is not None:
            self._ratio = float(ratio)
        if self._lines is not None:
            self._lines.write(self.line(), state=self._done)
            return
        assert self._progress is not None
        _dt, sps = self._speed()
        speed = f"{sps:,.0f} steps/s {sps * self.n / 1e6:,.2f} M p-steps/s"
        rtxt = f"ratio {self._ratio:.2e}" if self._ratio is not None else ""
        self._progress.update(self._task, completed=self._done, speed=speed, ratio=rtxt)

    def line(self) -> str:
        """The state as one plain line (label, steps, percent, speed, ratio, elapsed)."""
        dt, sps = self._speed()
        parts = [
            f"{self._done:,}/{self.total:,} steps ({100.0 * self._done / self.total:.0f} %)",
            f"{sps:,.0f} steps/s",
            f"{sps * self.n / 1e6:,.2f} M p-steps/s",
        ]
        if self._ratio is not None:
            parts.append(f"ratio {self._ratio:.2e}")
        parts.append(f"elapsed {clock_text(dt)}")
        return f"{self.label}: " + ", ".join(parts)

    def stop(self) -> None:
        if self._lines is not None:
            self._lines.write(self.line(), force=True, state=self._done)
        elif self._progress is not None:
            self._progress.stop()


class CountProgress:
    """Progress over a number of items (the cases of a sweep), as a context manager.

    A rich bar on a terminal; in a log, lines such as
    ``sweep: 3/10 cases (30 %), 1 failed, elapsed 0:12:40, eta 0:29:33``.
    """

    def __init__(self, label: str, total: int, unit: str = "cases", enabled: bool = True) -> None:
        self.label = label
        self.total = int(total)
        self.unit = unit
        self.enabled = enabled
        self.done = 0
        self.note = ""
        self._t0 = 0.0
        self._progress: Progress | None = None
        self._lines: ProgressLines | None = None
        self._task = None

    def __enter__(self) -> CountProgress:
        self._t0 = time.perf_counter()
        if not self.enabled:
            return self
        console = live_console()
        if console is None:
            self._lines = ProgressLines()
            return self
        self._progress = Progress(
            TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
            TextColumn("{task.fields[note]}"), TimeElapsedColumn(), TextColumn("eta"), TimeRemainingColumn(),
            console=console,
        )  # fmt: skip
        self._progress.start()
        self._task = self._progress.add_task(self.label, total=self.total, note="")
        return self

    def advance(self, note: str = "") -> None:
        """One more item done; ``note`` (plain text, e.g. '2 failed') is shown beside the count."""
        self.done += 1
        self.note = note
        if self._lines is not None:
            self._lines.write(self.line(), state=(self.done, note))
        elif self._progress is not None:
            self._progress.update(self._task, advance=1, note=f"[red]{note}[/]" if note else "")

    def line(self) -> str:
        dt = time.perf_counter() - self._t0
        parts = [f"{self.done}/{self.total} {self.unit} ({100.0 * self.done / max(self.total, 1):.0f} %)"]
        if self.note:
            parts.append(self.note)
        parts.append(f"elapsed {clock_text(dt)}")
        if 0 < self.done < self.total:
            parts.append(f"eta {clock_text(dt / self.done * (self.total - self.done))}")
        return f"{self.label}: " + ", ".join(parts)

    def __exit__(self, *exc) -> None:
        if self._lines is not None:
            self._lines.write(self.line(), force=True, state=(self.done, self.note))
        elif self._progress is not None:
            self._progress.stop()
