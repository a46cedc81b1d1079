"""The arrays a :class:`~poro2d.dem.simulation.Simulation` holds beside its bodies, as public records.

Every module that reads the engine's lists, masses or kernel settings (measurements,
checkpoints, the reference step, the kernel's records) reads them here, by name:

- :class:`ContactStore`: one contact list in CSR form (row ``i``: the slots of disk ``i``)
  with its contact history, its rebuild scratch, its capacity and an overflow flag. A
  simulation holds two, ``pairs`` (disk-disk) and ``wall_pairs`` (disk-wall).
- :class:`DiskMasses`: the true masses and the inverse inertial masses and inertias.
- :class:`KernelParams`: the scalar settings handed to the kernel and what it hands back.
- :class:`KernelWork`: what the kernel carries between calls (build positions, wall
  statistics) and what it derives itself (partitions, cross pairs, barrier words, grid).

The records are mutable holders of arrays: growing a list or adding disks replaces the
arrays behind a field, and :func:`poro2d.dem.records.kernel_records` reads the current
ones before every kernel call.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from poro2d.dem.neighbors import GridScratch, LevelScratch, grid_scratch, level_scratch
from poro2d.dem.sync import fresh_sync

# the arrays of a list that hold contacts (kept when it grows) and their types
_KEPT = (("other", np.int64), ("fs", float), ("fn", float), ("ov", float), ("nx", float), ("ny", float),
         ("mr", float))  # fmt: skip
# the rebuild's scratch, as long as the list (its contents die with each build)
_SCRATCH = (("new_other", np.int64), ("new_fs", float), ("new_mr", float))


@dataclass(eq=False)
class ContactStore:
    """A contact list in CSR form: row ``i`` holds the slots ``start[i]:start[i + 1]`` of disk ``i``.

    A disk-disk list holds each pair once, in the row of its smaller disk (``other`` the
    larger); a disk-wall list holds the walls near each disk (``other`` a wall number).
    Slots up to ``used`` are filled; the arrays are ``capacity`` long. After a kernel call,
    ``fs``, ``fn``, ``ov``, ``nx``, ``ny`` and ``mr`` are those of its last step for every
    filled slot (the normal also for a pair apart), and ``fn``, ``ov``, ``nx``, ``ny`` are 0
    in the slots a shorter list left behind: the kernel writes them only on the steps that
    someone reads them after (:mod:`poro2d.dem.kernels`). When a list build
    needs more slots the kernel stops before changing the list and reports how many: the
    driver notes it (:meth:`note_demand`, which sets ``overflow`` and ``needed``), grows
    the store and calls again.
    """

    start: np.ndarray  # (n + 1) int64: first slot of each row
    other: np.ndarray  # int64: the other body of each slot (a disk or a wall)
    fs: np.ndarray  # shear force along the tangent (N): the contact's history
    fn: np.ndarray  # normal force (N), 0 when apart
    ov: np.ndarray  # overlap (m), negative when apart
    nx: np.ndarray  # unit normal from the row's disk towards the other body
    ny: np.ndarray
    mr: np.ndarray  # rolling moment on the row's disk (N m): history too, 0 without rolling
    new_start: np.ndarray  # (n + 1) the list being built, copied over start/other/fs/mr when complete
    new_other: np.ndarray
    new_fs: np.ndarray
    new_mr: np.ndarray
    cross: np.ndarray  # disk-disk list only (empty otherwise): slots of pairs across two partitions
    with_cross: bool = False
    overflow: bool = False  # the last kernel call stopped because this list was full
    needed: int = 0  # slots that build asked for (0 without an overflow)

    @classmethod
    def empty(cls, n: int, capacity: int, with_cross: bool = False) -> ContactStore:
        """An empty list of ``n`` rows and ``capacity`` slots (``with_cross``: the disk-disk list)."""
        i8 = np.int64
        store = cls(
            np.zeros(n + 1, i8), *(np.zeros(0, dt) for _, dt in _KEPT), np.zeros(n + 1, i8),
            *(np.zeros(0, dt) for _, dt in _SCRATCH), np.zeros(0, i8), with_cross=with_cross,
        )  # fmt: skip
        store.grow(capacity)
        return store

    @property
    def capacity(self) -> int:
        """Slots the arrays hold."""
        return int(self.other.shape[0])

    @property
    def used(self) -> int:
        """Slots filled by the last list build."""
        return int(self.start[-1])

    def grow(self, capacity: int, keep: int = 0) -> None:
        """(Re)allocate the slots with ``capacity``, keeping the first ``keep`` (history included)."""
        for name, dtype in _KEPT:
            a = np.zeros(capacity, dtype=dtype)
            if keep:
                a[:keep] = getattr(self, name)[:keep]
            setattr(self, name, a)
        self.renew_scratch()

    def renew_scratch(self) -> None:
        """Fresh rebuild scratch as long as the list (after its arrays were replaced whole)."""
        capacity = self.capacity
        for name, dtype in _SCRATCH:
            setattr(self, name, np.zeros(capacity, dtype=dtype))
        self.cross = np.zeros(capacity if self.with_cross else 0, dtype=np.int64)

    def renew_row_scratch(self, n: int) -> None:
        """Fresh ``new_start`` for ``n`` rows."""
        self.new_start = np.zeros(n + 1, dtype=np.int64)

    def add_rows(self, count: int) -> None:
        """Append ``count`` empty rows (disks added after the existing ones)."""
        self.start = np.concatenate([self.start, np.full(count, self.start[-1], dtype=np.int64)])

    def note_demand(self, needed: int) -> None:
        """Record what the last kernel call asked of this list (0: it fitted)."""
        self.needed = int(needed)
        self.overflow = self.needed > 0

    def rows(self) -> np.ndarray:
        """The row (disk) of every filled slot."""
        n = self.start.shape[0] - 1
        return np.repeat(np.arange(n), np.diff(self.start))

    def touching(self) -> np.ndarray:
        """The filled slots whose bodies touch (overlap > 0), in list order."""
        return np.nonzero(self.ov[: self.used] > 0.0)[0]


@dataclass(eq=False)
class DiskMasses:
    """Per-disk masses: the true mass (weight, dashpot) and the inverse inertial ones (density scaling)."""

    mass: np.ndarray
    inv_mass: np.ndarray
    inv_inertia: np.ndarray


@dataclass(eq=False)
class KernelParams:
    """The kernel's scalar settings and results, indexed by the names of :mod:`poro2d.dem.kernels`."""

    prm: np.ndarray  # float64 settings (DT, GX, ..., TIME)
    iprm: np.ndarray  # int64 settings (NSTEPS, ..., NEED_BUILD, THREADS): NEED_BUILD persists
    out: np.ndarray  # float64 results of the last call (STATUS, STEPS_DONE, NEED_PP, ...)


@dataclass(eq=False)
class KernelWork:
    """Arrays of the kernel's own: carried between calls, or derived again in each.

    ``pos_build``, ``wall_build`` and ``wall_stat`` are state (a continued run reads them,
    checkpoints store them); the rest is rebuilt by the kernel from the lists and is
    reallocated by :meth:`renew` whenever the disks, walls or partitions change.
    """

    pos_build: np.ndarray  # (n, 2) positions at the last list build
    wall_build: np.ndarray  # (nw, 2) wall p0 at the last list build
    wall_stat: np.ndarray  # (nw, 2): touching disks and their summed kn per wall
    acc: np.ndarray  # (n, 3) fx, fy, mz accumulators
    part: np.ndarray  # (partitions + 1) first disk of each partition
    xstart: np.ndarray  # (n + 1) cross pairs of each disk
    dlist: np.ndarray  # the deferred disks (those with cross pairs)
    dstart: np.ndarray  # (partitions + 1) the deferred disks of each partition
    held: np.ndarray  # (n + 1) the disks not free (prescribed), ascending, then n to the end
    part_sums: np.ndarray  # (partitions, nw + pad, 4) per-partition wall sums
    tmax: np.ndarray  # (partitions) largest squared drift per thread
    tskip: np.ndarray  # (partitions) largest squared speed per thread of the disks whose drift it skipped
    sync: np.ndarray  # barrier and status words (poro2d.dem.sync)
    grid: GridScratch  # the cell grid of a list build
    levels: LevelScratch | None = None  # the grids by size level (wide gradings), else None

    @classmethod
    def empty(cls, n: int, nw: int, partitions: int, wall_pad: int) -> KernelWork:
        """Zeroed work arrays for ``n`` disks, ``nw`` walls and ``partitions``."""
        derived = [np.zeros(0)] * 10  # acc .. sync: allocated by renew
        work = cls(np.zeros((n, 2)), np.zeros((nw, 2)), np.zeros((nw, 2)), *derived, grid_scratch(0))
        work.renew(n, nw, partitions, wall_pad)
        return work

    def renew(self, n: int, nw: int, partitions: int, wall_pad: int) -> None:
        """Fresh derived arrays for ``n`` disks, ``nw`` walls and ``partitions``."""
        self.acc = np.zeros((n, 3))
        self.xstart = np.zeros(n + 1, dtype=np.int64)
        self.dlist = np.zeros(n, dtype=np.int64)
        self.part = np.zeros(partitions + 1, dtype=np.int64)
        self.dstart = np.zeros(partitions + 1, dtype=np.int64)
        self.held = np.zeros(n + 1, dtype=np.int64)
        # wall sums per partition, wall_pad rows apart: two threads adding to the same
        # cache line would pass it back and forth at every wall contact
        self.part_sums = np.zeros((partitions, nw + wall_pad, 4))
        self.tmax = np.zeros(partitions)
        self.tskip = np.zeros(partitions)
        self.sync = fresh_sync()
        self.grid = grid_scratch(n)
        if self.levels is not None:
            self.levels = level_scratch(n)

    def use_levels(self, on: bool, n: int) -> None:
        """Build the lists from grids by size level (``on``) or from the one cell grid."""
        if not on:
            self.levels = None
        elif self.levels is None or self.levels.level.shape[0] != n:
            self.levels = level_scratch(n)
