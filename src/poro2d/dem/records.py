"""The named records of arrays that the compiled kernels work on.

The step loop (:mod:`poro2d.dem.kernels`) reads some sixty arrays. They travel in five
records, one per kind of thing, and the kernels read every array by its name
(``disks.pos``, ``walls.servo``, ``nb.fs``, ``work.dstart``): two arrays of the same
type can no longer be swapped by counting positions wrong.

The records are named tuples. numba compiles them as heterogeneous named tuples: a
field access is resolved at compile time and costs nothing in the loop, and the types
pickle by reference, so ``cache=True`` works. Their fields are the arrays of the
simulation's ``Particles`` and ``Walls`` and of its public stores (:mod:`poro2d.dem.stores`:
the two contact lists, the masses, the kernel's work arrays), never copies: the kernels
advance the state in place. A record of records is not used: numba's parallel loop
cannot take one as an argument.

:func:`kernel_records` is the one place that fills them. It is called before every
kernel call, since growing the pair storage, adding disks or walls and renumbering
replace the arrays behind the fields.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from poro2d.dem.neighbors import LevelScratch
    from poro2d.dem.state import Particles, Walls
    from poro2d.dem.stores import ContactStore, DiskMasses, KernelWork


class DiskArrays(NamedTuple):
    """The disks: state, per-step sums and constant properties (one row per disk)."""

    pos: np.ndarray  # (n, 2) centres (m)
    vel: np.ndarray  # (n, 2) velocities (m/s), half a step behind pos
    theta: np.ndarray  # rotations (rad)
    omega: np.ndarray  # spins (rad/s)
    force: np.ndarray  # (n, 2) unbalanced force of the last step (N)
    moment: np.ndarray  # unbalanced moment of the last step (N m)
    acc: np.ndarray  # (n, 3) fx, fy, mz accumulators: weight, then pairs of earlier rows
    radius: np.ndarray
    mass: np.ndarray  # true mass (weight and dashpot)
    inv_mass: np.ndarray  # inverse inertial mass (density scaling included)
    inv_inertia: np.ndarray
    mode: np.ndarray  # int64: FREE or PRESCRIBED
    kn: np.ndarray  # per-body properties, combined per contact under PER_BODY
    ks: np.ndarray
    mu: np.ndarray
    mu_r: np.ndarray  # rolling friction


class BodyProps(NamedTuple):
    """The disks' per-body (kn, ks, mu), handed over when disk-disk contacts combine them."""

    kn: np.ndarray
    ks: np.ndarray
    mu: np.ndarray


class RollingProps(NamedTuple):
    """The bodies' rolling frictions, handed over only when some disk has one above 0."""

    disk_mu_r: np.ndarray
    wall_mu_r: np.ndarray


class WallArrays(NamedTuple):
    """The wall segments, their servo settings and their per-step sums (one row per wall)."""

    p0: np.ndarray  # (nw, 2) end points (m)
    p1: np.ndarray
    vel: np.ndarray  # (nw, 2) velocities (m/s)
    kn: np.ndarray
    ks: np.ndarray
    mu: np.ndarray
    mu_r: np.ndarray
    mode: np.ndarray  # int64: WALL_VELOCITY or WALL_SERVO
    servo_dir: np.ndarray  # (nw, 2) unit direction a servo wall moves to compress
    servo: np.ndarray  # (nw, SERVO_COLUMNS): columns named in poro2d.dem.state (SERVO_TARGET, ...)
    force: np.ndarray  # (nw, 2) resultant contact force on the wall (N)
    stat: np.ndarray  # (nw, 2): columns STAT_COUNT (touching disks) and STAT_KSUM (their summed kn)
    p0_build: np.ndarray  # (nw, 2) p0 at the last list build (a wall's drift triggers a rebuild)
    part_sums: np.ndarray  # (partitions, nw + pad, 4) per-partition sums: WFX, WFY, WCOUNT, WKSUM


class PairList(NamedTuple):
    """Disk-disk Verlet half list in CSR form (row i: partners j > i) and its rebuild scratch."""

    start: np.ndarray  # (n + 1) first slot of each row
    j: np.ndarray  # partner of each slot
    fs: np.ndarray  # shear force along the tangent (N): the contact's history
    fn: np.ndarray  # normal force (N), 0 when apart
    ov: np.ndarray  # overlap (m), negative when apart
    nx: np.ndarray  # unit normal from i towards j
    ny: np.ndarray
    new_start: np.ndarray  # the list being built, copied over start/j/fs/mr when complete
    new_j: np.ndarray
    new_fs: np.ndarray
    mr: np.ndarray  # rolling moment on i (N m; -mr on j): history too, 0 without rolling
    new_mr: np.ndarray


class WallPairList(NamedTuple):
    """Disk-wall candidate list in CSR form (row i: walls near disk i) and its rebuild scratch."""

    start: np.ndarray
    w: np.ndarray  # wall of each slot
    fs: np.ndarray
    fn: np.ndarray
    ov: np.ndarray
    nx: np.ndarray  # unit normal from the disk towards the wall
    ny: np.ndarray
    new_start: np.ndarray
    new_w: np.ndarray
    new_fs: np.ndarray
    mr: np.ndarray  # rolling moment on the disk (N m)
    new_mr: np.ndarray


class WorkArrays(NamedTuple):
    """What the kernel derives itself: partitions, cross pairs, thread meeting, grid."""

    pos_build: np.ndarray  # (n, 2) positions at the last list build
    part: np.ndarray  # (partitions + 1) first disk of each partition
    xstart: np.ndarray  # (n + 1) cross pairs of each disk, as rows of xpair
    xpair: np.ndarray  # slots of the cross pairs (disk j in a later partition than i)
    dlist: np.ndarray  # the deferred disks (those with cross pairs)
    dstart: np.ndarray  # (partitions + 1) the deferred disks of each partition, as rows of dlist
    held: np.ndarray  # (n + 1) the disks not free, ascending, then n to the end (set by prepare)
    tmax: np.ndarray  # (partitions) largest squared drift seen by each thread in a step
    tskip: np.ndarray  # (partitions) largest squared speed of the disks whose drift a thread skipped
    sync: np.ndarray  # int64 barrier and status words (poro2d.dem.sync)
    # the cell grid of a list build (GridScratch's fields: numba's parallel loop takes a
    # record of arrays as an argument, not a record of records)
    cell: np.ndarray
    members: np.ndarray
    cstart: np.ndarray
    cfill: np.ndarray
    ginfo: np.ndarray
    cand: np.ndarray


class KernelRecords(NamedTuple):
    disks: DiskArrays
    walls: WallArrays
    nb: PairList
    wb: WallPairList
    work: WorkArrays
    # the grids by size level of a wide grading's list builds; None: the one cell grid
    levels: LevelScratch | None = None


def kernel_records(
    particles: Particles,
    walls: Walls,
    force: np.ndarray,
    moment: np.ndarray,
    wall_force: np.ndarray,
    masses: DiskMasses,
    pairs: ContactStore,
    wall_pairs: ContactStore,
    work: KernelWork,
) -> KernelRecords:
    """The records of a simulation's current arrays (views, nothing is copied).

    ``force``, ``moment`` and ``wall_force`` are the unbalanced forces and moments of the
    disks and the walls' resultants, which the kernel writes at every step.
    """
    p, w = particles, walls
    disks = DiskArrays(
        pos=p.pos, vel=p.vel, theta=p.theta, omega=p.omega, force=force, moment=moment,
        acc=work.acc, radius=p.radius, mass=masses.mass, inv_mass=masses.inv_mass,
        inv_inertia=masses.inv_inertia, mode=p.mode, kn=p.kn, ks=p.ks, mu=p.mu, mu_r=p.mu_r,
    )  # fmt: skip
    walls_rec = WallArrays(
        p0=w.p0, p1=w.p1, vel=w.vel, kn=w.kn, ks=w.ks, mu=w.mu, mu_r=w.rolling_friction(), mode=w.mode,
        servo_dir=w.servo_dir, servo=w.servo, force=wall_force, stat=work.wall_stat,
        p0_build=work.wall_build, part_sums=work.part_sums,
    )  # fmt: skip
    nb, wb = pairs, wall_pairs
    nb_rec = PairList(
        start=nb.start, j=nb.other, fs=nb.fs, fn=nb.fn, ov=nb.ov, nx=nb.nx, ny=nb.ny,
        new_start=nb.new_start, new_j=nb.new_other, new_fs=nb.new_fs, mr=nb.mr, new_mr=nb.new_mr,
    )  # fmt: skip
    wb_rec = WallPairList(
        start=wb.start, w=wb.other, fs=wb.fs, fn=wb.fn, ov=wb.ov, nx=wb.nx, ny=wb.ny,
        new_start=wb.new_start, new_w=wb.new_other, new_fs=wb.new_fs, mr=wb.mr, new_mr=wb.new_mr,
    )  # fmt: skip
    g = work.grid
    work_rec = WorkArrays(
        pos_build=work.pos_build, part=work.part, xstart=work.xstart, xpair=nb.cross, dlist=work.dlist,
        dstart=work.dstart, held=work.held, tmax=work.tmax, tskip=work.tskip, sync=work.sync, cell=g.cell,
        members=g.members, cstart=g.cstart, cfill=g.cfill, ginfo=g.ginfo, cand=g.cand,
    )  # fmt: skip
    return KernelRecords(disks, walls_rec, nb_rec, wb_rec, work_rec, work.levels)
