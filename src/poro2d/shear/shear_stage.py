"""The shear stage of a direct shear test: the lower half moves, one row per record.

Every ``record_interval`` of shear displacement one row of the curve is recorded (and,
with ``keep_peak``, the state kept for the peak's force chains); every
``checkpoint_interval`` the whole engine state and the rows so far are saved in
``shear_checkpoint.npz``, so a killed test continues from there bit for bit; every
``vtk_every`` steps, when asked, a step of the ParaView series (``vtk/``). These are the
stage's reporters on the engine (:mod:`poro2d.labtest.reporters`), with the stop test last.
"""

from __future__ import annotations

import math
import time

import numpy as np

from poro2d.dem import Simulation
from poro2d.dem.export import frame_of
from poro2d.dem.reporters import Every, Reporter
from poro2d.labtest.reporters import Checkpointer, CurveRecorder, ProgressReporter, StopTest, series_reporters
from poro2d.measure.fabric import FabricRoses, rose
from poro2d.shear.box import SplitBox
from poro2d.shear.controllers import ProgressFn, ShearDrive
from poro2d.shear.curve import ShearRow, curve_row, peak_passed
from poro2d.shear.fit import peak
from poro2d.shear.peak_frame import PeakFrame, PeakTracker
from poro2d.shear.settings import ShearSettings
from poro2d.store import Store

#: the files that let a killed shear stage continue: the engine state and the peak's frame
CHECKPOINT = "shear_checkpoint.npz"
PEAK_FRAME = "peak_frame.npz"


class ShearStage:
    """Shear ``sim`` (consolidated, or from the checkpoint in ``store``) to ``max_displacement``,
    or until the peak is passed by ``stop_after_peak``: past it the curve only serves the
    residual part of Fig. 8, and it is a third or more of a test's cost.

    ``box``: the split box ``sim`` stands in; ``y_plate0``: the plate's height after
    consolidation (the dilation's zero); ``store``: where the checkpoint (through its
    :class:`~poro2d.store.Checkpoints`) and the peak's frame are kept (None: nowhere);
    ``threads``: for a state read back from the checkpoint;
    ``keep_peak``: keep the state at the peak (its force chains, its overlap); ``progress(phase,
    fraction)``: called at every record.

    After :meth:`run`: ``rows`` (the curve), ``sim`` (the final state) and ``peak.frame``
    (the state at the smoothed peak, when ``keep_peak``).
    """

    def __init__(
        self,
        sim: Simulation,
        box: SplitBox,
        settings: ShearSettings,
        y_plate0: float,
        store: Store | None = None,
        threads: int = 1,
        keep_peak: bool = True,
        progress: ProgressFn | None = None,
    ) -> None:
        s = settings
        self.box, self.settings = box, s
        self.threads, self.keep_peak, self.progress = threads, keep_peak, progress
        self.t0 = time.perf_counter()
        self.store = store
        self.checkpoints = None if store is None else store.checkpoints(CHECKPOINT)
        self.y_plate0 = y_plate0
        self.sim, self.rows, self.step0, self.wall_before = self._start(sim)
        dx_step = s.velocity * self.sim.dt
        self.every = max(1, int(round(s.record_interval / dx_step)))
        self.total = int(math.ceil(s.max_displacement / dx_step / self.every)) * self.every
        self.ck_every = max(1, int(round(s.checkpoint_interval / (self.every * dx_step))))
        self.rho = float(np.mean(self.sim.particles.density)) * self.sim.density_scale
        self.peak = PeakTracker(s.peak_window)
        self.peak.restore(store, PEAK_FRAME, self.rows)
        self.roses: list[np.ndarray] = []  # the contact orientations of the rows recorded in this run

    def _start(self, sim: Simulation) -> tuple[Simulation, list[ShearRow], int, float]:
        """(simulation, rows, step shearing began at, wall time so far): resumed or new."""
        saved = None if self.checkpoints is None else self.checkpoints.resume(threads=self.threads)
        if saved is not None:
            resumed, meta = saved
            rows = [ShearRow.from_dict(row) for row in meta["rows"]]
            return resumed, rows, meta["step0"], meta.get("wall_time_s", 0.0)
        ShearDrive(self.settings.velocity).start(sim)
        return sim, [], sim.step_count, 0.0

    def _row(self, sim: Simulation) -> ShearRow:
        """The curve's row now; its contacts stay for the peak's frame of the same record."""
        self.contacts = sim.contacts()
        self.roses.append(rose(self.contacts))
        return curve_row(sim, self.box, self.settings, self.contacts, self.y_plate0, self.step0, self.rho)

    def _keep_peak(self, sim: Simulation) -> None:
        """Queue the last record's frame; keep the frame at the smoothed peak found so far."""
        x_mm = self.rows[-1].shear_displacement_mm
        self.peak.add(PeakFrame.capture(sim, self.contacts, len(self.rows) - 1, x_mm))
        self.peak.settle(self.rows, x_mm * 1e-3)

    def _checkpoint(self) -> dict:
        """Where the stage is, saved with the engine's state (the peak's frame saved first, so a
        resumed run still draws the peak's forces)."""
        self.peak.save(self.store, PEAK_FRAME)
        wall = self.wall_before + time.perf_counter() - self.t0
        rows = [row.to_dict() for row in self.rows]
        return {"stage": "shear", "rows": rows, "step0": self.step0, "wall_time_s": wall}

    def reporters(self, remaining: int) -> list[Reporter]:
        """What a record does, in order: the row, the peak's frame, the progress, a checkpoint every
        ``ck_every`` records (not at the end: ``remaining`` steps are left to run), the stop test;
        the ParaView series, when asked, on its own period before the stop test."""
        every = self.every
        peak = [Every(every, self._keep_peak)] if self.keep_peak else []
        share = ProgressReporter(
            every, self.progress, "shearing", lambda sm, _: (sm.step_count - self.step0) / self.total
        )
        saved = Checkpointer(every * self.ck_every, self.checkpoints, self._checkpoint, remaining)
        stop = StopTest(every, lambda _: self.peak_passed())
        series = series_reporters(
            self.settings.vtk_every, self.store, "shear_displacement", self.sim, frame_of, self._clock
        )
        return [CurveRecorder(every, self._row, self.rows), *peak, share, saved, *series, stop]

    def _clock(self, sim: Simulation) -> tuple[int, float, float]:
        """The stage's step, the engine's time (s) and the shear displacement (m) now."""
        return sim.step_count - self.step0, sim.time, self.box.shear_displacement(sim)

    def peak_passed(self) -> bool:
        """True once the smoothed peak lies ``stop_after_peak`` behind the last record.

        The rows alone decide it, so a resumed test stops where an uninterrupted one does.
        """
        s = self.settings
        if s.stop_after_peak <= 0.0:
            return False
        x = np.array([r.shear_displacement_mm for r in self.rows]) * 1e-3
        tau = np.array([r.shear_stress_kpa for r in self.rows])
        return peak_passed(x, peak(x, tau, s.peak_window).x, s)

    def fabric_roses(self) -> FabricRoses | None:
        """The contact orientations at the smoothed peak and at the end (the peak's None when it was
        recorded before the checkpoint this run resumed from); None without rows."""
        if not self.rows:
            return None
        x = np.array([r.shear_displacement_mm for r in self.rows])
        tau = np.array([r.shear_stress_kpa for r in self.rows])
        k = peak(1e-3 * x, tau, self.settings.peak_window)[0]
        return FabricRoses.of("shear_displacement_mm", x, self.roses, k)

    def run(self) -> float:
        """Shear to the end; returns the stage's wall time (s), resumed parts included."""
        remaining = self.total - (self.sim.step_count - self.step0)
        if remaining > 0 and not (self.rows and self.peak_passed()):
            self.sim.run(remaining, reporters=self.reporters(remaining))
        self.peak.settle(self.rows, None)
        return self.wall_before + time.perf_counter() - self.t0


def remove_stage_files(store: Store) -> None:
    """The checkpoint of a test in ``store``, once its results are written (the peak's frame stays
    until its figure is drawn: ``draw_peak_forces`` (``report/shear_figures.py``))."""
    store.checkpoints(CHECKPOINT).clear()


__all__ = ["CHECKPOINT", "PEAK_FRAME", "ShearStage", "remove_stage_files"]
