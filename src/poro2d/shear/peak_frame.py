"""The force chains at the peak of a direct shear test: a stored frame and how it is chosen.

The peak is a maximum of the *smoothed* curve, which is known only once the records half
a window past it exist. So every record's state is kept as a :class:`PeakFrame` (plain
arrays: disks, walls, contacts) until its smoothed value is final; :class:`PeakTracker`
keeps the frame of the largest one. The frame is saved beside the shear checkpoint, so a
resumed test still finds it, and at the end of the shear: the figure of the peak's forces is
drawn from it once the test has returned (``draw_peak_forces`` (``report/shear_figures.py``)).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from poro2d.dem import Simulation
from poro2d.dem.contacts import ContactSet
from poro2d.shear.curve import ShearRow
from poro2d.shear.fit import smooth
from poro2d.store import Store

_CONTACT_FIELDS = ("i", "j", "kind", "point", "normal", "fn", "fs", "force", "branch")


@dataclass
class PeakFrame:
    """The disks, wall segments and contacts of one record (``record``-th row of the curve)."""

    pos: np.ndarray
    radius: np.ndarray
    thickness: float
    walls: np.ndarray  # (m, 2, 2) wall segments
    contacts: ContactSet
    record: int
    displacement_mm: float

    @classmethod
    def capture(cls, sim: Simulation, contacts: ContactSet, record: int, displacement_mm: float) -> PeakFrame:
        """A copy of the simulation's state (``contacts`` are its current contacts)."""
        p, w = sim.particles, sim.walls
        return cls(
            pos=p.pos.copy(), radius=p.radius.copy(), thickness=float(p.thickness),
            walls=np.stack([w.p0, w.p1], axis=1), contacts=contacts, record=int(record),
            displacement_mm=float(displacement_mm),
        )  # fmt: skip

    def to_arrays(self) -> dict[str, np.ndarray]:
        """The frame as named arrays (the keys of ``peak_frame.npz``)."""
        data = {
            "pos": self.pos, "radius": self.radius, "thickness": np.float64(self.thickness),
            "wall_p0": self.walls[:, 0], "wall_p1": self.walls[:, 1],
        }  # fmt: skip
        for k in _CONTACT_FIELDS:
            data["c_" + k] = getattr(self.contacts, k)
        data["record"] = np.float64(self.record)
        data["displacement_mm"] = np.float64(self.displacement_mm)
        return data

    @classmethod
    def from_arrays(cls, data: dict) -> PeakFrame:
        return cls(
            pos=data["pos"], radius=data["radius"], thickness=float(data["thickness"]),
            walls=np.stack([data["wall_p0"], data["wall_p1"]], axis=1),
            contacts=ContactSet(**{k: data["c_" + k] for k in _CONTACT_FIELDS}),
            record=int(data["record"]), displacement_mm=float(data["displacement_mm"]),
        )  # fmt: skip

    def save(self, store: Store, name: str) -> None:
        store.write_arrays(name, **self.to_arrays())

    @classmethod
    def load(cls, store: Store, name: str) -> PeakFrame | None:
        """The frame kept in ``store`` as ``name``; None when it is missing or damaged."""
        data = store.read_arrays(name)
        return None if data is None else cls.from_arrays(data)


class PeakTracker:
    """The frame at the maximum of the smoothed shear stress, found while the curve grows.

    ``add`` queues a record's frame; ``settle(rows, upto)`` finalises every queued frame
    whose window ends before the displacement ``upto`` (all of them with None) and keeps
    the largest smoothed value's frame.
    """

    def __init__(self, window: float) -> None:
        self.window = window
        self.pending: deque[PeakFrame] = deque()
        self.value = -math.inf
        self.frame: PeakFrame | None = None
        self.saved = True  # nothing new to save

    def restore(self, store: Store | None, name: str, rows: list[ShearRow]) -> None:
        """Continue from the frame saved with a shear checkpoint (if any)."""
        frame = PeakFrame.load(store, name) if store is not None and rows else None
        if frame is None:
            return
        self.frame = frame
        xs, ys = _curve(rows)
        self.value = float(smooth(xs, ys, self.window)[self.frame.record])

    def add(self, frame: PeakFrame) -> None:
        self.pending.append(frame)

    def settle(self, rows: list[ShearRow], upto: float | None) -> None:
        xs, ys = _curve(rows)
        half = 0.5 * self.window
        while self.pending and (upto is None or xs[self.pending[0].record] + half <= upto):
            fr = self.pending.popleft()
            k = fr.record
            lo = np.searchsorted(xs, xs[k] - half, side="left")
            hi = np.searchsorted(xs, xs[k] + half, side="right")
            v = float(ys[lo:hi].mean())
            if v > self.value:
                self.value, self.frame, self.saved = v, fr, False

    def save(self, store: Store | None, name: str) -> None:
        """Save a frame found since the last save (a resumed test still draws it)."""
        if store is not None and self.frame is not None and not self.saved:
            self.frame.save(store, name)
            self.saved = True


def _curve(rows: list[ShearRow]) -> tuple[np.ndarray, np.ndarray]:
    """Shear displacement (m) and shear stress (kPa) of the records so far."""
    xs = np.array([r.shear_displacement_mm for r in rows]) * 1e-3
    ys = np.array([r.shear_stress_kpa for r in rows])
    return xs, ys


__all__ = ["PeakFrame", "PeakTracker"]
