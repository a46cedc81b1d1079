"""Rich progress bars that show DEM speed (steps/s, particle-steps/s) and ETA."""

from __future__ import annotations

import time

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

_console = Console(stderr=True)


class StepProgress:
    """A progress bar for one run of steps; ``update`` from the driver between blocks."""

    def __init__(self, label: str, total_steps: int, n_particles: int) -> None:
        self.total = max(int(total_steps), 1)
        self.n = n_particles
        self._progress = Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            TextColumn("{task.completed:>9,.0f}/{task.total:,.0f} steps"),
            TextColumn("{task.fields[speed]}"),
            TextColumn("{task.fields[ratio]}"),
            TimeElapsedColumn(),
            TextColumn("eta"),
            TimeRemainingColumn(),
            console=_console,
            transient=False,
            disable=not _console.is_terminal and False,
        )
        self._task = None
        self._t0 = 0.0
        self.label = label

    def start(self) -> None:
        self._t0 = time.perf_counter()
        self._progress.start()
        self._task = self._progress.add_task(self.label, total=self.total, speed="", ratio="")

    def update(self, done: int, ratio: float | None = None) -> None:
        dt = time.perf_counter() - self._t0
        sps = done / dt if dt > 0 else 0.0
        speed = f"{sps:,.0f} steps/s {sps * self.n / 1e6:,.2f} M p-steps/s"
        rtxt = f"ratio {ratio:.2e}" if ratio is not None else ""
        self._progress.update(self._task, completed=done, speed=speed, ratio=rtxt)

    def stop(self) -> None:
        self._progress.stop()
