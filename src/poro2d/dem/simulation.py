"""The Python-side driver of the DEM engine.

A :class:`Simulation` owns the particle and wall state, the contact lists and
the time step. :meth:`Simulation.run` hands whole blocks of steps to the
compiled kernel and only comes back to Python for events: progress updates,
reporters (:mod:`poro2d.dem.reporters`: rows, checkpoints, stop tests) and growing the
contact storage.

Beside ``particles`` and ``walls`` it holds its arrays in public stores
(:mod:`poro2d.dem.stores`): ``pairs`` and ``wall_pairs`` (the contact lists), ``masses``,
``kernel_params`` and ``work``. Other modules read those, never its private names.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from poro2d.dem import kernels as K
from poro2d.dem.contact_law import PER_BODY, PER_PAIR_TYPE
from poro2d.dem.cores import DEFAULT_PARTITIONS, cores_lent, note_block
from poro2d.dem.layout import check_layout
from poro2d.dem.model import (
    ContactModel,
    critical_time_step,
    inertial_masses,
    mass_for_time_step,
    raised_inertia,
    restitution_to_beta,
    single_contact_limit,
)
from poro2d.dem.records import KernelRecords, kernel_records
from poro2d.dem.reporters import Reporter, drive_blocks
from poro2d.dem.state import (
    FREE,
    PARTICLE_FIELDS,
    PRESCRIBED,
    WALL_VELOCITY,
    Particles,
    Walls,
)
from poro2d.dem.stores import ContactStore, DiskMasses, KernelParams, KernelWork
from poro2d.dem.summary import ContactRecord, EngineSummary, MassScalingRecord, RollingFrictionRecord
from poro2d.errors import InputError, is_number

_THREADING_SET = False
# With rolling resistance a contact's rolling spring kr = ks R^2 adds at most 2 ks / m to the
# stiffness over inertial mass a disk feels through that contact (R <= its radius, I = m r^2 / 2),
# beside the 3 ks / m of the shear spring: the bound of the time step grows by 5 / 3.
ROLLING_STIFFNESS_FACTOR = 5.0 / 3.0
WALL_PAD = 4  # rows of 4 doubles: 128 bytes between the wall sums of two partitions


def _prefer_openmp() -> None:
    """numba's OpenMP layer measured fastest here; TBB/workqueue were slower than serial."""
    global _THREADING_SET
    if not _THREADING_SET:
        import numba

        os.environ.setdefault("NUMBA_THREADING_LAYER_PRIORITY", "omp tbb workqueue")
        try:
            numba.config.THREADING_LAYER_PRIORITY = ["omp", "tbb", "workqueue"]
        except Exception:  # pragma: no cover - older numba
            pass
        _THREADING_SET = True


#: the equilibrium measures of :meth:`Simulation.run`, by name: the kernel's code for each
MEASURES = {"max": K.MEASURE_MAX, "mean": K.MEASURE_MEAN, "loaded_max": K.MEASURE_LOADED}
_MEASURE_OUT = {K.MEASURE_MAX: K.MAX_RATIO, K.MEASURE_MEAN: K.MEAN_RATIO, K.MEASURE_LOADED: K.LOADED_RATIO}


def measure_code(measure: str) -> int:
    """The kernel's code of an equilibrium measure; refuses an unknown name."""
    if measure not in MEASURES:
        raise InputError("equilibrium measure", measure, "one of " + ", ".join(repr(m) for m in MEASURES))
    return MEASURES[measure]


def _regroup(start: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Rewrite ``start`` for slots that now belong to ``rows``; returns the slot order.

    Slots of one row keep their relative order (a stable sort).
    """
    n = start.shape[0] - 1
    start[0] = 0
    start[1:] = np.cumsum(np.bincount(rows, minlength=n))
    return np.argsort(rows, kind="stable")


@dataclass(frozen=True)
class MassScaling:
    """How far a simulation's inertial masses are raised (:meth:`Simulation.set_mass_scaling`).

    ``dt_s``: the time step they are raised for (``None``: true masses); ``disks``: how many
    disks are heavier than they are; ``largest_ratio``: the largest inertial over true mass;
    ``added_fraction``: the inertial mass added over the total true mass.
    """

    dt_s: float | None = None
    disks: int = 0
    largest_ratio: float = 1.0
    added_fraction: float = 0.0

    @classmethod
    def of(cls, true_mass: np.ndarray, inertial: np.ndarray, dt: float) -> MassScaling:
        ratio = inertial / true_mass
        added = float(np.sum(inertial - true_mass) / np.sum(true_mass))
        return cls(dt, int(np.count_nonzero(ratio > 1.0)), float(ratio.max()), added)


class SimulationError(RuntimeError):
    """The run cannot go on (numerical instability, bad state)."""


@dataclass
class RunResult:
    """What one call of :meth:`Simulation.run` did."""

    steps: int
    converged: bool
    max_ratio: float
    mean_ratio: float
    wall_time_s: float
    rebuilds: int
    particle_steps: int  # steps x disks
    loaded_ratio: float = math.nan  # max ratio over disks touching two bodies or more
    rattler_fraction: float = math.nan  # free disks touching fewer than two bodies
    measure: str = "max"  # the ratio the stop test compared with its target

    @property
    def measured_ratio(self) -> float:
        """The ratio of the measure the stop test compared (``max``, ``mean`` or ``loaded_max``)."""
        return {"max": self.max_ratio, "mean": self.mean_ratio, "loaded_max": self.loaded_ratio}[self.measure]

    @property
    def particle_steps_per_s(self) -> float:
        return self.particle_steps / self.wall_time_s if self.wall_time_s > 0 else math.nan


class Simulation:
    """2D DEM of disks and wall segments with the linear contact law.

    Parameters
    ----------
    particles, walls
        The bodies (state is held by reference and advanced in place).
    contact
        Property convention (:class:`ContactModel`), PFC 4.0 per-body by default.
    gravity
        (gx, gy) in m/s^2.
    local_damping
        Cundall's local non-viscous damping coefficient alpha in [0, 1):
        each force and moment component is reduced by ``alpha |F| sign(v)``.
    restitution
        Optional normal restitution coefficient in (0, 1] for a viscous normal
        dashpot (impact problems); ``None`` for no dashpot.
    dt
        Fixed time step (s); ``None`` for ``dt_safety`` times the critical step
        ``sqrt(m_min / k_sum)`` (see :func:`poro2d.dem.model.critical_time_step`).
    dt_safety
        Safety factor of the automatic time step, in (0, 1].
    density_scale
        Inertial mass multiplier >= 1 (density scaling for quasi-static runs);
        gravity still acts on the true mass. Reported in every output.
    mass_scaling_dt
        Time step (s) that every disk's inertial mass is raised for (per-disk density
        scaling, :meth:`set_mass_scaling`): a disk lighter than the mass whose critical step
        times ``dt_safety`` is this one takes that mass, and its moment of inertia grows by
        the same ratio. ``None`` (default): every disk keeps its mass. Gravity acts on the
        true mass; for quasi-static stages only.
    skin
        Verlet skin (m); default 0.2 x the mean radius.
    threads
        Threads for the compiled loop, at most ``partitions`` of them (results do not
        depend on it). Below ``parallel_min_particles`` disks (1000 by default) the
        loop runs on one thread anyway: two thread meetings per step cost more than
        a step of a few hundred disks.
    partitions
        Contiguous ranges of disks that fix the order of every force sum
        (:mod:`poro2d.dem.partition`); each is worked on by one thread. Results are
        identical, bit for bit, for any number of threads up to ``partitions``;
        another ``partitions`` changes the round-off. Default 2.
    """

    parallel_min_particles = 1000
    #: r_max / r_min above which the lists are built from grids by size level
    #: (:mod:`poro2d.dem.neighbors`): one grid of cells 2 r_max + skin wide crowds its cells
    #: with fines. Narrower gradings (the paper's 3.5, the built-in wide gradings' 25 and
    #: less) keep the one grid, and so every number they gave before.
    level_ratio = 40.0
    #: disks below which :meth:`set_sorting` leaves the numbering alone (a small packing's
    #: arrays stay in cache whatever their order: renumbering there costs and gains nothing)
    sort_min_particles = 20_000

    def __init__(
        self,
        particles: Particles,
        walls: Walls | None = None,
        contact: ContactModel | None = None,
        gravity: tuple[float, float] = (0.0, -9.81),
        local_damping: float = 0.7,
        restitution: float | None = None,
        dt: float | None = None,
        dt_safety: float = 0.8,
        density_scale: float = 1.0,
        mass_scaling_dt: float | None = None,
        skin: float | None = None,
        threads: int = 1,
        partitions: int = DEFAULT_PARTITIONS,
    ) -> None:
        _prefer_openmp()
        self.particles = particles
        self.walls = walls if walls is not None else Walls()
        self.contact = contact if contact is not None else ContactModel()
        g = np.asarray(gravity, dtype=float)
        if g.shape != (2,) or not np.all(np.isfinite(g)):
            raise InputError("gravity", gravity, "two finite numbers (gx, gy) in m/s^2")
        self.gravity = (float(g[0]), float(g[1]))
        self.set_local_damping(local_damping)
        self.restitution = None if restitution is None else float(restitution)
        self._beta = 0.0 if restitution is None else restitution_to_beta(restitution)
        if not density_scale >= 1.0:
            raise InputError("density_scale", density_scale, "[1, inf)")
        self.density_scale = float(density_scale)
        self._mass_scaling_dt = self._checked_scaling_dt(mass_scaling_dt)
        if not 0.0 < dt_safety <= 1.0:
            raise InputError("dt_safety", dt_safety, "(0, 1]")
        self.dt_safety = float(dt_safety)
        self._fixed_dt = dt
        if skin is not None and not skin > 0.0:
            raise InputError("skin", skin, "(0, inf) m")
        self._skin = skin
        if not (isinstance(partitions, (int, np.integer)) and 1 <= partitions <= 256):
            raise InputError("partitions", partitions, "an integer in [1, 256]")
        self.partitions = int(partitions)
        self.threads = self.check_threads(threads)
        self.threads_used = 0  # threads the kernel ran on in its last call (0: not called yet)
        self._block_threads = 1  # threads asked of the kernel in the current block
        self.step_count = 0
        self.time = 0.0
        # the forces (and so the unbalanced ratios) are those of a step; false before the
        # first one unless the state came from a run (a checkpoint's step_count > 0)
        self._stepped = False
        self._checked_ratio: float | None = None  # max ratio at the last stop test of a run
        self._n_alloc = -1
        self.sort_every: int | None = None  # renumbering along the curve: off (set_sorting)
        self._sorted_at: int | None = None  # the clock's step of the last renumbering
        check_layout(self.particles.pos, self.particles.radius, self.walls)
        self._refresh()

    @property
    def beta(self) -> float:
        """Damping ratio of the normal dashpot, from ``restitution`` (0 without a dashpot)."""
        return self._beta

    @property
    def fixed_dt(self) -> float | None:
        """The time step given at construction (``None``: chosen from the critical step)."""
        return self._fixed_dt

    @property
    def mass_scaling_dt(self) -> float | None:
        """The time step the inertial masses are raised for (``None``: true masses)."""
        return self._mass_scaling_dt

    @staticmethod
    def _checked_scaling_dt(dt: float | None) -> float | None:
        if dt is None:
            return None
        if not (is_number(dt) and 0.0 < dt < math.inf):
            raise InputError("mass_scaling_dt", dt, "(0, inf) s, or None for the true masses")
        return float(dt)

    def set_mass_scaling(self, dt: float | None) -> None:
        """Raise the disks' inertial masses for the time step ``dt`` from the next step on.

        A quasi-static stage (settling, a servo plate) may run with the masses and inertias
        of light disks raised so that all share the step ``dt``: its static equilibria do not
        move (gravity acts on the true mass, local damping is a fraction of the force), the
        approach to them does. ``None`` gives every disk its true mass back, for stages whose
        dynamics matter (shearing at a rate, the inertial number). The time step is chosen
        again either way (a fixed ``dt`` stays fixed).
        """
        self._mass_scaling_dt = self._checked_scaling_dt(dt)
        self._refresh()

    @property
    def local_damping(self) -> float:
        """Cundall's local damping coefficient alpha (:meth:`set_local_damping` changes it)."""
        return self._local_damping

    def set_local_damping(self, alpha: float) -> None:
        """Set the local damping coefficient alpha in [0, 1); it acts from the next step on."""
        if not (is_number(alpha) and 0.0 <= alpha < 1.0):
            raise InputError("local_damping", alpha, "[0, 1)")
        self._local_damping = float(alpha)

    def reset_clock(self) -> None:
        """Count steps and time from zero from here on (a protocol stage's own clock).

        Nothing else changes: the state, the lists, the servo's summed error and the
        unbalanced ratios of the last step stay as they are.
        """
        self._stepped = self._stepped or self.step_count > 0
        self.step_count = 0
        self.time = 0.0
        self._sorted_at = None

    @property
    def effective_threads(self) -> int:
        """Threads asked of the kernel: 1 for small systems, else ``threads`` or the cores lent to
        this process (:mod:`poro2d.dem.cores`), whichever is more, at most ``partitions`` and
        numba's thread pool: the same numbers on any of these counts."""
        if self.particles.n < self.parallel_min_particles:
            return 1
        import numba

        lent = min(cores_lent(), numba.config.NUMBA_NUM_THREADS)
        return min(max(self.threads, lent), self.partitions)

    # ----------------------------------------------------------------- setup
    @staticmethod
    def check_threads(threads: int) -> int:
        """``threads`` as an int, refused unless in [1, the threads numba may use]."""
        import numba

        top = numba.config.NUMBA_NUM_THREADS
        if not (isinstance(threads, (int, np.integer)) and 1 <= threads <= top):
            raise InputError("threads", threads, f"an integer in [1, {top}]")
        return int(threads)

    def _refresh(self) -> None:
        """Recompute masses, time step and (re)allocate storage after a state change."""
        p = self.particles
        n = p.n
        m_in, i_in = inertial_masses(p, self.density_scale)
        k_sum = self.contact.stiffness_sum_bound(p, self.walls)
        if K.rolling_active(p.mu_r):
            k_sum *= ROLLING_STIFFNESS_FACTOR
        self.mass_scaling = MassScaling()
        if self._mass_scaling_dt is not None and n:
            floor = mass_for_time_step(self._mass_scaling_dt, k_sum, self.dt_safety)
            true_m = m_in
            m_in, i_in = raised_inertia(m_in, i_in, floor)
            self.mass_scaling = MassScaling.of(true_m, m_in, self._mass_scaling_dt)
        self.masses = DiskMasses(
            mass=np.ascontiguousarray(p.mass),
            inv_mass=np.ascontiguousarray(1.0 / m_in) if n else np.zeros(0),
            inv_inertia=np.ascontiguousarray(1.0 / i_in) if n else np.zeros(0),
        )
        m_min = float(m_in.min()) if n else 1.0
        self.dt_critical = critical_time_step(m_min, k_sum)
        if self._fixed_dt is None:
            self.dt = self.dt_safety * self.dt_critical if math.isfinite(self.dt_critical) else 1e-4
        else:
            dt = float(self._fixed_dt)
            limit = single_contact_limit(m_min, self.contact.max_stiffness(p, self.walls))
            if not (dt > 0.0 and dt < limit):
                raise InputError(
                    "dt", dt, f"(0, {limit:.3g}) s",
                    f"unstable: the lightest disk spinning on one contact diverges above {limit:.3g} s;"
                    f" the automatic step would be {self.dt_safety * self.dt_critical:.3g} s",
                )  # fmt: skip
            if dt > self.dt_critical:
                warnings.warn(
                    f"dt = {dt:.3g} s exceeds the critical step {self.dt_critical:.3g} s of a disk "
                    "with a full set of contacts; dense packings may become unstable",
                    stacklevel=3,
                )
            self.dt = dt
        if self._skin is None:
            self.skin = 0.2 * float(p.radius.mean()) if n else 1e-3
        else:
            self.skin = float(self._skin)
        if n != self._n_alloc:
            self._allocate(n)
        self.work.use_levels(n > 0 and float(p.radius.max()) > self.level_ratio * float(p.radius.min()), n)
        self.kernel_params.iprm[K.NEED_BUILD] = 1

    @property
    def neighbor_search(self) -> str:
        """How the lists are built: ``"cells"`` (one cell grid) or ``"levels"`` (grids by size
        level, chosen when r_max / r_min exceeds ``level_ratio``)."""
        return "cells" if self.work.levels is None else "levels"

    def _allocate(self, n: int) -> None:
        """Fresh stores for ``n`` disks: empty contact lists (no history), zeroed sums."""
        self._n_alloc = n
        nw = self.walls.n
        self.force = np.zeros((n, 2))
        self.moment = np.zeros(n)
        self.wall_force_vec = np.zeros((nw, 2))
        #: the disk-disk and disk-wall contact lists (:class:`~poro2d.dem.stores.ContactStore`)
        self.pairs = ContactStore.empty(n, max(16, 4 * n), with_cross=True)
        self.wall_pairs = ContactStore.empty(n, max(16, n // 4))
        self.work = KernelWork.empty(n, nw, self.partitions, WALL_PAD)
        self.kernel_params = KernelParams(
            prm=np.zeros(K.N_PRM), iprm=np.zeros(K.N_IPRM, dtype=np.int64), out=np.zeros(K.N_OUT)
        )

    def _renew_work(self, n: int) -> None:
        """Per-disk and per-partition work arrays that the kernel derives itself."""
        self.work.renew(n, self.walls.n, self.partitions, WALL_PAD)
        self.pairs.renew_row_scratch(n)
        self.wall_pairs.renew_row_scratch(n)

    def grow_pairs(self, capacity: int, keep: int = 0) -> None:
        """Give the disk-disk list ``capacity`` slots, keeping the first ``keep`` (their history)."""
        self.pairs.grow(capacity, keep)

    def grow_wall_pairs(self, capacity: int, keep: int = 0) -> None:
        """Give the disk-wall list ``capacity`` slots, keeping the first ``keep`` (their history)."""
        self.wall_pairs.grow(capacity, keep)

    def sync_walls(self) -> None:
        """Take in walls added to ``self.walls`` (``Walls.add``) since the arrays were sized.

        Called before every run and measurement of a wall; a comparison of two counts
        when nothing was added. The new walls are checked against the disks as at
        construction, get their rows in the per-wall arrays, and take part from the next
        step: the time step follows their stiffness and the lists are rebuilt. Walls
        cannot be taken away: the disk-wall lists hold wall numbers.
        """
        nw_old, nw = self.wall_force_vec.shape[0], self.walls.n
        if nw == nw_old:
            return
        if nw < nw_old:
            raise InputError(
                "walls", f"{nw} walls", f"at least the {nw_old} this simulation was run with",
                "walls can be added (Walls.add), not removed",
            )  # fmt: skip
        check_layout(self.particles.pos, self.particles.radius, self.walls)
        new = nw - nw_old
        self.wall_force_vec = np.concatenate([self.wall_force_vec, np.zeros((new, 2))])
        work = self.work
        work.wall_stat = np.concatenate([work.wall_stat, np.zeros((new, 2))])
        work.wall_build = np.ascontiguousarray(np.concatenate([work.wall_build, self.walls.p0[nw_old:]]))
        self._renew_work(self.particles.n)  # the per-partition wall sums
        self._refresh()  # time step and a list rebuild before the next step

    # --------------------------------------------------------------- mutation
    def particles_changed(self) -> None:
        """Call after editing radii, densities, positions or adding/removing disks."""
        n_old = self._n_alloc
        if self.particles.n != n_old:
            self._n_alloc = -1  # fresh lists: indices changed, old history is void
        self._refresh()

    def add_particles(self, new: Particles) -> np.ndarray:
        """Append disks; existing contacts keep their history. Returns the new indices."""
        p = self.particles
        if new.thickness != p.thickness:
            raise InputError("thickness", new.thickness, f"{p.thickness} (that of the disks present)")
        n0 = p.n
        # checked on the whole packing before anything changes; disk numbers as after the append
        check_layout(np.concatenate([p.pos, new.pos]), np.concatenate([p.radius, new.radius]), self.walls)
        for f in PARTICLE_FIELDS:
            setattr(p, f, np.ascontiguousarray(np.concatenate([getattr(p, f), getattr(new, f)])))
        n = p.n
        # Old rows keep their place; the new disks start with empty rows.
        self.pairs.add_rows(n - n0)
        self.wall_pairs.add_rows(n - n0)
        self._renew_work(n)
        self.force = np.concatenate([self.force, np.zeros((n - n0, 2))])
        self.moment = np.concatenate([self.moment, np.zeros(n - n0)])
        self.work.pos_build = np.concatenate([self.work.pos_build, new.pos])
        self._n_alloc = n
        self._refresh()
        return np.arange(n0, n)

    # per-disk arrays beside the Particles' fields, by holder and name (all are permuted)
    _PER_DISK = ((None, "force"), (None, "moment"), ("work", "pos_build"), ("masses", "mass"),
                 ("masses", "inv_mass"), ("masses", "inv_inertia"))  # fmt: skip

    def reorder(self, order) -> None:
        """Renumber the disks: new disk ``k`` is old disk ``order[k]``; contacts keep their history.

        The motion does not depend on the numbering (up to round-off: sums are added in
        another order), its speed does (see :mod:`poro2d.dem.ordering`; e.g.
        ``sim.reorder(strip_order(sim.particles.pos, sim.particles.radius))``). Index
        arrays held elsewhere must be mapped with ``order`` too.
        """
        from poro2d.dem.ordering import is_permutation

        p = self.particles
        n = p.n
        order = np.asarray(order)
        if not is_permutation(order, n):
            raise InputError("order", f"array of shape {order.shape}", f"a permutation of 0 .. {n - 1}")
        order = order.astype(np.int64)
        new_of_old = np.empty(n, dtype=np.int64)
        new_of_old[order] = np.arange(n)
        for f in PARTICLE_FIELDS:
            setattr(p, f, np.ascontiguousarray(getattr(p, f)[order]))
        for holder_name, f in self._PER_DISK:
            holder = self if holder_name is None else getattr(self, holder_name)
            setattr(holder, f, np.ascontiguousarray(getattr(holder, f)[order]))
        self._renumber_pairs(new_of_old)
        self._renumber_wall_pairs(new_of_old)
        self.kernel_params.iprm[K.NEED_BUILD] = 1  # rows in the kernel's own order before the next step

    def set_sorting(self, every: int | None) -> None:
        """Renumber the disks along :func:`~poro2d.dem.ordering.curve_order` every ``every`` steps.

        As disks move, partners drift apart in memory; renumbering them again keeps a
        large packing's force pass reading from cache (LAMMPS's ``atom_modify sort`` does
        the same). The renumbering falls before the steps whose clock (``step_count``) is a
        multiple of ``every``, whatever blocks, reporters or threads a run has, so a run's
        numbers depend on its state alone; they differ from an unsorted run's by round-off
        (sums in another order). Packings of fewer than ``sort_min_particles`` disks are
        never renumbered. ``None`` (the default) turns it off. Disk numbers change at each
        renumbering: a caller keeping disk indices across a run must not turn it on.
        """
        if every is not None and not (isinstance(every, (int, np.integer)) and every >= 1):
            raise InputError("sort_every", every, "an integer >= 1 (steps), or None for no renumbering")
        self.sort_every = None if every is None else int(every)
        self._sorted_at = None

    def _sorting(self) -> bool:
        return self.sort_every is not None and self.particles.n >= self.sort_min_particles

    def _sort_if_due(self) -> None:
        """Renumber along the curve when the clock stands on a multiple of ``sort_every``."""
        if not self._sorting() or self.step_count % self.sort_every or self._sorted_at == self.step_count:
            return
        from poro2d.dem.ordering import curve_order

        self.reorder(curve_order(self.particles.pos, self.particles.radius))
        self._sorted_at = self.step_count

    def _steps_before_sort(self, steps: int) -> int:
        """``steps``, cut so that a kernel call ends where the next renumbering falls."""
        if not self._sorting():
            return steps
        k = self.sort_every
        return min(steps, k - self.step_count % k)

    def _renumber_pairs(self, new_of_old: np.ndarray) -> None:
        """Disk-disk list in new numbers: rows by the smaller new index, history unchanged.

        Swapping the two disks of a pair turns its normal and tangent round; the shear
        force on the (new) first disk, ``fs`` along its tangent, is the same number.
        """
        nb = self.pairs
        m = nb.used
        a = new_of_old[nb.rows()]
        b = new_of_old[nb.other[:m]]
        swap = a > b
        first = np.where(swap, b, a)
        sort = _regroup(nb.start, first)
        nb.other[:m] = np.where(swap, a, b)[sort]
        sign = np.where(swap, -1.0, 1.0)
        # the rolling moment is the one on the first disk: the other disk's is its opposite
        for arr, flip in ((nb.fs, False), (nb.fn, False), (nb.ov, False),
                          (nb.nx, True), (nb.ny, True), (nb.mr, True)):  # fmt: skip
            arr[:m] = (arr[:m] * sign if flip else arr[:m])[sort]

    def _renumber_wall_pairs(self, new_of_old: np.ndarray) -> None:
        """Disk-wall rows follow their disks."""
        wb = self.wall_pairs
        m = wb.used
        sort = _regroup(wb.start, new_of_old[wb.rows()])
        for arr in (wb.other, wb.fs, wb.fn, wb.ov, wb.nx, wb.ny, wb.mr):
            arr[:m] = arr[:m][sort]

    def set_particle_friction(self, mu: float) -> None:
        """Change every disk's friction coefficient (e.g. 0.05 -> 3 after preparation)."""
        if not (mu >= 0.0 and math.isfinite(mu)):
            raise InputError("particle friction", mu, "[0, inf)")
        self.particles.mu[:] = mu
        if self.contact.convention == "per_pair_type":
            pp = self.contact.pp
            assert pp is not None
            self.contact = ContactModel("per_pair_type", (pp[0], pp[1], float(mu)), self.contact.pw)

    def set_rolling_friction(self, mu_r: float, walls: float | None = None) -> None:
        """Give every disk (and, with ``walls``, every wall) the rolling friction ``mu_r``.

        A contact takes the smaller of its two bodies' values. The time step is chosen again
        (rolling springs stiffen the packing, see ``ROLLING_STIFFNESS_FACTOR``); going to 0
        everywhere ends every contact's rolling history.
        """
        for name, value in (("rolling friction", mu_r), ("wall rolling friction", walls)):
            if value is not None and not (is_number(value) and 0.0 <= value < math.inf):
                raise InputError(name, value, "[0, inf)")
        self.particles.mu_r[:] = mu_r
        if walls is not None:
            self.walls.rolling_friction()[:] = walls
        if not K.rolling_active(self.particles.mu_r):
            self.pairs.mr[:] = 0.0
            self.wall_pairs.mr[:] = 0.0
        self._refresh()

    def rolling_moments(self) -> tuple[np.ndarray, np.ndarray]:
        """The rolling moments of the touching contacts (N m): (disk-disk, disk-wall) in list order.

        A disk-disk entry is the moment on the row's disk (its partner gets the opposite).
        """
        return self.pairs.mr[self.pairs.touching()], self.wall_pairs.mr[self.wall_pairs.touching()]

    def set_wall_velocity(self, wall: str | int, velocity: tuple[float, float]) -> None:
        w = self.walls.index(wall)
        v = np.asarray(velocity, dtype=float)
        if v.shape != (2,) or not np.all(np.isfinite(v)):
            raise InputError(f"wall {self.walls.names[w]} velocity", velocity, "two finite numbers (m/s)")
        self.walls.mode[w] = WALL_VELOCITY
        self.walls.vel[w] = v

    def extend_wall_up(self, wall: str | int, height: float) -> None:
        """Move the upper end of a vertical wall up to ``height`` (m) when it ends below it.

        A box's side walls reach past its top by the box size; a lid or plate raised above
        that (an over-full specimen) needs them longer, or disks could leave over them.
        """
        w = self.walls.index(wall)
        p0, p1 = self.walls.p0, self.walls.p1
        if p0[w, 0] != p1[w, 0]:
            raise InputError(f"wall {self.walls.names[w]}", "not vertical", "a vertical wall (a box's side)")
        end = p0 if p0[w, 1] >= p1[w, 1] else p1
        if end[w, 1] < height:
            end[w, 1] = float(height)
            self.kernel_params.iprm[K.NEED_BUILD] = 1

    def translate_wall(self, wall: str | int, dx: float, dy: float) -> None:
        """Move a wall rigidly by (dx, dy) at once (a teleport, e.g. a temporary lid)."""
        w = self.walls.index(wall)
        self.walls.p0[w] += (dx, dy)
        self.walls.p1[w] += (dx, dy)
        self.kernel_params.iprm[K.NEED_BUILD] = 1

    def set_wall_servo(
        self,
        wall: str | int,
        target_force: float,
        direction: tuple[float, float],
        max_speed: float,
        gain: float = 0.5,
        integral: float = 0.0,
    ) -> None:
        """Servo a wall along ``direction`` (the way it moves to compress) to a force.

        Every step: v = gain * (e + integral * E) / (sum of contact kn on the wall * dt),
        bounded by ``max_speed``, with e = target - F the force error, F the compressive
        force along ``direction`` (N) and E the sum of e over the steps so far (not
        summed while the speed is at its bound). ``integral = 0`` is PFC's proportional
        servo; it lags behind a specimen that keeps dilating or contracting by
        e = v k dt / gain, which a small integral gain (e.g. 1e-3 per step) removes.
        A wall that touches nothing moves at ``max_speed`` towards the target.
        """
        w = self.walls.index(wall)
        d = np.asarray(direction, dtype=float)
        nd = float(np.hypot(*d)) if d.shape == (2,) else 0.0
        if nd == 0.0 or not math.isfinite(nd):
            raise InputError("servo direction", direction, "a non-zero (x, y) vector")
        if not (target_force >= 0.0 and math.isfinite(target_force)):
            raise InputError("servo target force", target_force, "[0, inf) N")
        if not max_speed > 0.0:
            raise InputError("servo max_speed", max_speed, "(0, inf) m/s")
        if not 0.0 < gain <= 1.0:
            raise InputError("servo gain", gain, "(0, 1]")
        if not 0.0 <= integral <= 0.1:
            raise InputError("servo integral gain", integral, "[0, 0.1] per step")
        self.walls.set_servo(w, d / nd, target_force, gain, max_speed, integral)

    def fix_particles(self, mask: np.ndarray, velocity=(0.0, 0.0), omega: float = 0.0) -> None:
        """Prescribe velocity and spin of the disks in ``mask`` (zero = fixed)."""
        self.particles.mode[mask] = PRESCRIBED
        self.particles.vel[mask] = velocity
        self.particles.omega[mask] = omega

    # -------------------------------------------------------------------- run
    def _load_params(
        self, nsteps: int, check_every: int, ratio_target: float, offset: int, measure: int = 0
    ) -> None:
        prm, iprm = self.kernel_params.prm, self.kernel_params.iprm
        prm[K.DT] = self.dt
        prm[K.GX], prm[K.GY] = self.gravity
        prm[K.DAMP] = self.local_damping
        prm[K.SKIN] = self.skin
        prm[K.BETA] = self._beta
        # the kernel mixes the bodies' values per contact where no constant stands for them
        pp, pw = self.contact.kernel_constants(self.particles, self.walls)
        iprm[K.MODE] = PER_BODY if pp is None else PER_PAIR_TYPE
        iprm[K.MODE_PW] = PER_BODY if pw is None else PER_PAIR_TYPE
        if pp is not None:
            prm[K.KN_PP], prm[K.KS_PP], prm[K.MU_PP] = pp.kn, pp.ks, pp.mu
        if pw is not None:
            prm[K.KN_PW], prm[K.KS_PW], prm[K.MU_PW] = pw.kn, pw.ks, pw.mu
        prm[K.RATIO_TARGET] = ratio_target
        prm[K.TIME] = self.time
        iprm[K.NSTEPS] = nsteps
        iprm[K.CHECK_EVERY] = check_every
        iprm[K.CHECK_OFFSET] = offset
        iprm[K.MEASURE] = measure
        iprm[K.THREADS] = self._block_threads

    def kernel_records(self) -> KernelRecords:
        """The kernel's records of the current arrays (views: the kernel advances them in place)."""
        return kernel_records(
            self.particles, self.walls, self.force, self.moment, self.wall_force_vec,
            self.masses, self.pairs, self.wall_pairs, self.work,
        )  # fmt: skip

    def _kernel_block(
        self, nsteps: int, check_every: int, ratio_target: float, offset: int, measure: int = 0
    ) -> tuple[int, int, int]:
        """Run up to ``nsteps`` in compiled code; returns (steps done, status, list rebuilds).

        ``offset`` is the number of steps of the current :meth:`run` before this block:
        the kernel tests the stop condition on the run's own multiples of ``check_every``,
        so neither the block length nor a restart after growing the storage moves a test.
        """
        import numba

        # one count for the whole block (a lender may change its answer meanwhile)
        self._block_threads = max(1, self.effective_threads)
        numba.set_num_threads(self._block_threads)
        started = time.perf_counter()
        if self.work.part.shape[0] != self.partitions + 1:
            self._renew_work(self.particles.n)  # partitions changed since allocation
        done = 0
        status = K.RUNNING
        rebuilds = 0
        params = self.kernel_params
        out = params.out
        while done < nsteps:
            self._sort_if_due()
            chunk = self._steps_before_sort(nsteps - done)
            self._load_params(chunk, check_every, ratio_target, offset + done, measure)
            out[:] = 0.0
            K.step_block(self.kernel_records(), params.prm, params.iprm, out)
            self.threads_used = int(out[K.THREADS_USED])
            steps = int(out[K.STEPS_DONE])
            if ratio_target and (offset + done + steps) // check_every > (offset + done) // check_every:
                # the last stop test's value of the measure it compared
                self._checked_ratio = float(out[_MEASURE_OUT[measure]])
            done += steps
            rebuilds += int(out[K.REBUILDS])
            self.step_count += steps
            self.time = float(params.prm[K.TIME])
            self._stepped = self._stepped or steps > 0
            status = int(out[K.STATUS])
            self.pairs.note_demand(int(out[K.NEED_PP]))
            self.wall_pairs.note_demand(int(out[K.NEED_PW]))
            if status == K.OVERFLOW:
                if self.pairs.overflow:
                    self.grow_pairs(int(self.pairs.needed * 1.5) + 16, keep=self.pairs.used)
                if self.wall_pairs.overflow:
                    self.grow_wall_pairs(int(self.wall_pairs.needed * 1.5) + 16, keep=self.wall_pairs.used)
                continue
            if status == K.UNSTABLE:
                raise SimulationError(
                    f"the simulation became unstable (non-finite positions) near step "
                    f"{self.step_count}, t = {self.time:.6g} s, dt = {self.dt:.3g} s; "
                    "use a smaller dt or dt_safety"
                )
            if status == K.CONVERGED:
                break
        note_block(self.threads_used, time.perf_counter() - started)  # what lent cores did (dem.cores)
        return done, status, rebuilds

    def run(
        self,
        steps: int,
        *,
        until_ratio: float | None = None,
        check_every: int = 100,
        reporters: Sequence[Reporter] = (),
        progress: bool | str = False,
        measure: str = "max",
    ) -> RunResult:
        """Advance up to ``steps`` steps.

        until_ratio
            stop as soon as the unbalanced-force ratio named by ``measure`` drops below
            this value (tested inside the kernel on steps ``check_every``, ``2
            check_every``, ... of this call).
        measure
            ``"max"`` (largest unbalanced force / largest contact force, PFC's maximum
            ratio, the paper's), ``"mean"`` (mean unbalanced / mean contact force, PFC's
            average ratio) or ``"loaded_max"`` (the maximum over the disks touching two
            bodies or more: rattlers, which never carry a balanced load, left out); see
            :func:`poro2d.dem.kernels.equilibrium_measures`.
        reporters
            each called every ``period`` steps of this run (:mod:`poro2d.dem.reporters`):
            ``report(sim, step)``, True stops the run. Blocks end where one is due.
        progress
            show a rich progress bar (steps/s, particle-steps/s, ETA) on a terminal,
            plain lines now and then elsewhere (:mod:`poro2d.progress`); a string is
            used as its label.

        Neither ``progress`` nor the reporters' periods change a number: reporters that only read
        the state leave the run bit for bit as it is without them, and the stop tests
        fall on the same steps.
        """
        if not (isinstance(steps, (int, np.integer)) and steps >= 0):
            raise InputError("steps", steps, "an integer >= 0")
        if until_ratio is not None and not until_ratio > 0.0:
            raise InputError("until_ratio", until_ratio, "(0, inf)")
        if not (isinstance(check_every, (int, np.integer)) and check_every >= 1):
            raise InputError("check_every", check_every, "an integer >= 1")
        code = measure_code(measure)
        reporters = tuple(reporters)
        self.sync_walls()
        target = 0.0 if until_ratio is None else float(until_ratio)
        n = self.particles.n
        t0 = time.perf_counter()
        ran = {"steps": 0, "converged": False, "rebuilds": 0}  # the blocks' sums, as they end
        self._checked_ratio = None
        # Blocks end where a reporter is due, or every 2000 steps or so for a bar alone. It
        # changes no number: the kernel counts its stop tests from the start of this run.
        block = steps
        bar = None
        if progress:
            from poro2d.progress import StepProgress

            bar = StepProgress(str(progress) if isinstance(progress, str) else "DEM", steps, n)
            bar.start()
            if not reporters:
                block = max(check_every, min(steps, 2000))

        def advance(nb: int) -> tuple[int, bool]:
            k, status, block_rebuilds = self._kernel_block(nb, check_every, target, ran["steps"], code)
            ran["steps"] += k
            ran["rebuilds"] += block_rebuilds
            if bar is not None:
                bar.update(ran["steps"], self._checked_ratio)
            ran["converged"] = status == K.CONVERGED
            return k, ran["converged"]

        try:
            done = drive_blocks(advance, steps, reporters, self, block)
        finally:
            if bar is not None:
                bar.stop()
        wall = time.perf_counter() - t0
        m = self.equilibrium_measures()
        return RunResult(
            done, ran["converged"], m["max"], m["mean"], wall, ran["rebuilds"], particle_steps=done * n,
            loaded_ratio=m["loaded_max"], rattler_fraction=m["rattler_fraction"], measure=measure,
        )  # fmt: skip

    def solve(
        self,
        ratio: float = 1e-3,
        max_steps: int = 1_000_000,
        check_every: int = 100,
        progress: bool | str = False,
        measure: str = "max",
    ) -> RunResult:
        """Cycle until the unbalanced-force ratio ``measure`` (see :meth:`run`) is below ``ratio``."""
        return self.run(
            max_steps, until_ratio=ratio, check_every=check_every, progress=progress, measure=measure
        )

    # ------------------------------------------------------------ measurement
    def unbalanced_ratios(self) -> tuple[float, float]:
        """(max, mean) unbalanced-force ratio of the last step (inf before the first)."""
        m = self.equilibrium_measures()
        return m["max"], m["mean"]

    def equilibrium_measures(self) -> dict:
        """The ratios of the last step (inf before the first) by measure name, and the rattlers.

        ``max``, ``mean``, ``loaded_max`` (see :meth:`run`) and ``rattler_fraction``: the
        share of free disks touching fewer than two bodies.
        """
        n = self.particles.n
        if not (self._stepped or self.step_count > 0) or self.force.shape[0] != n:
            return {"max": math.inf, "mean": math.inf, "loaded_max": math.inf, "rattler_fraction": math.nan}
        nb, wb = self.pairs, self.wall_pairs
        r = K.equilibrium_measures(
            self.force, self.particles.mode, nb.start, nb.other, nb.fn, nb.fs, nb.ov,
            wb.start, wb.fn, wb.fs, wb.ov,
        )  # fmt: skip
        free = int(np.count_nonzero(self.particles.mode == FREE))
        return {
            "max": float(r[0]),
            "mean": float(r[1]),
            "loaded_max": float(r[2]),
            "rattler_fraction": float(r[3]) / free if free else 0.0,
        }

    def ratio_of(self, measure: str) -> float:
        """The last step's unbalanced-force ratio by ``measure`` (``max``, ``mean``, ``loaded_max``)."""
        measure_code(measure)
        return self.equilibrium_measures()[measure]

    def wall_force(self, wall: str | int) -> np.ndarray:
        """Resultant contact force that the disks exert on a wall (N), as (fx, fy)."""
        self.sync_walls()
        return self.wall_force_vec[self.walls.index(wall)].copy()

    def wall_force_per_thickness(self, wall: str | int) -> np.ndarray:
        """Wall force per metre of disk thickness (N/m, the paper's unit)."""
        return self.wall_force(wall) / self.particles.thickness

    def contacts(self):
        """Touching contacts as a :class:`poro2d.dem.contacts.ContactSet`."""
        from poro2d.dem.contacts import contact_set

        return contact_set(self)

    def _rolling_summary(self) -> RollingFrictionRecord | None:
        """The rolling frictions, only when some disk has one (outputs without it stay as they were)."""
        if not K.rolling_active(self.particles.mu_r):
            return None
        p, w = self.particles, self.walls
        return RollingFrictionRecord(
            disks=[float(p.mu_r.min()), float(p.mu_r.max())],
            walls=[float(v) for v in w.rolling_friction()],
            combination="min",
            stiffness="ks R^2",
        )

    def _mass_scaling_summary(self) -> MassScalingRecord | None:
        """The per-disk scaling, only when set (outputs without it stay as they were)."""
        ms = self.mass_scaling
        if self._mass_scaling_dt is None:
            return None
        return MassScalingRecord(
            time_step_s=self._mass_scaling_dt, disks_scaled=ms.disks, largest_ratio=ms.largest_ratio,
            added_mass_fraction=ms.added_fraction, gravity_on="true mass",
        )  # fmt: skip

    def summary(self) -> EngineSummary:
        """Settings that every output file should record (a file's ``engine``)."""
        c = self.contact
        return EngineSummary(
            n_particles=self.particles.n,
            n_walls=self.walls.n,
            wall_names=list(self.walls.names),
            thickness_m=self.particles.thickness,
            contact=ContactRecord(convention=c.convention, pp=c.pp, pw=c.pw),
            gravity=list(self.gravity),
            local_damping=self.local_damping,
            restitution=self.restitution,
            rolling_friction=self._rolling_summary(),
            dt_s=self.dt,
            dt_critical_s=self.dt_critical,
            dt_mode="fixed" if self._fixed_dt is not None else f"auto (safety {self.dt_safety})",
            density_scale=self.density_scale,
            density_scaling=self.density_scale != 1.0,
            mass_scaling=self._mass_scaling_summary(),
            skin_m=self.skin,
            threads=self.threads,
            threads_intended=self.effective_threads,
            threads_used=self.threads_used,  # by the kernel's last call (0: none yet)
            partitions=self.partitions,
            step=self.step_count,
            time_s=self.time,
            sort_every_steps=self.sort_every if self._sorting() else None,
        )
