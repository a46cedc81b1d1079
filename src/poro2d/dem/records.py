"""The named records of arrays that the compiled kernels work on.

The step loop (:mod:`poro2d.dem.kernels`) reads some sixty arrays. They travel in five
records, one per kind of thing, and the kernels read every array by its name
(``disks.pos``, ``walls.servo``, ``nb.fs``, ``work.dstart``): two arrays of the same
type can no longer be swapped by counting positions wrong.

The records are named tuples. numba compiles them as heterogeneous named tuples: a
field access is resolved at compile time and costs nothing in the loop, and the types
pickle by reference, so ``cache=True`` works. Their fields are the arrays held by the
:class:`~poro2d.dem.simulation.Simulation` and its ``Particles`` and ``Walls``, never
copies: the kernels advance the state in place. A record of records is not used: numba's
parallel loop cannot take one as an argument.

:func:`kernel_records` is the one place that fills them. It is called before every
kernel call, since growing the pair storage, adding disks or walls and renumbering
replace the arrays behind the fields.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from poro2d.dem.simulation import Simulation


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
    tmax: np.ndarray  # (partitions) largest squared drift seen by each thread in a step
    sync: np.ndarray  # int64 barrier and status words (poro2d.dem.sync)
    # the cell grid of a list build (GridScratch's fields: numba's parallel loop takes a
    # record of arrays as an argument, not a record of records)
    cell: np.ndarray
    members: np.ndarray
    cstart: np.ndarray
    cfill: np.ndarray
    ginfo: np.ndarray


class KernelRecords(NamedTuple):
    disks: DiskArrays
    walls: WallArrays
    nb: PairList
    wb: WallPairList
    work: WorkArrays


def kernel_records(sim: Simulation) -> KernelRecords:
    """The records of ``sim``'s current arrays (views, nothing is copied)."""
    p, w = sim.particles, sim.walls
    disks = DiskArrays(
        pos=p.pos, vel=p.vel, theta=p.theta, omega=p.omega, force=sim.force, moment=sim.moment,
        acc=sim._acc, radius=p.radius, mass=sim._mass, inv_mass=sim._inv_mass,
        inv_inertia=sim._inv_inertia, mode=p.mode, kn=p.kn, ks=p.ks, mu=p.mu, mu_r=p.mu_r,
    )  # fmt: skip
    walls = WallArrays(
        p0=w.p0, p1=w.p1, vel=w.vel, kn=w.kn, ks=w.ks, mu=w.mu, mu_r=w.rolling_friction(), mode=w.mode,
        servo_dir=w.servo_dir, servo=w.servo, force=sim.wall_force_vec, stat=sim._wstat,
        p0_build=sim._wall_build, part_sums=sim._wpart,
    )  # fmt: skip
    nb = PairList(
        start=sim._nb_start, j=sim._nb_j, fs=sim._nb_fs, fn=sim._nb_fn, ov=sim._nb_ov, nx=sim._nb_nx,
        ny=sim._nb_ny, new_start=sim._new_start, new_j=sim._new_j, new_fs=sim._new_fs, mr=sim._nb_mr,
        new_mr=sim._new_mr,
    )  # fmt: skip
    wb = WallPairList(
        start=sim._wb_start, w=sim._wb_w, fs=sim._wb_fs, fn=sim._wb_fn, ov=sim._wb_ov, nx=sim._wb_nx,
        ny=sim._wb_ny, new_start=sim._wnew_start, new_w=sim._wnew_w, new_fs=sim._wnew_fs, mr=sim._wb_mr,
        new_mr=sim._wnew_mr,
    )  # fmt: skip
    g = sim._grid
    work = WorkArrays(
        pos_build=sim._pos_build, part=sim._part, xstart=sim._xstart, xpair=sim._xpair, dlist=sim._dlist,
        dstart=sim._dstart, tmax=sim._tmax, sync=sim._sync, cell=g.cell, members=g.members,
        cstart=g.cstart, cfill=g.cfill, ginfo=g.ginfo,
    )  # fmt: skip
    return KernelRecords(disks, walls, nb, wb, work)
