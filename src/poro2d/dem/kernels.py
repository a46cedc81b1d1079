"""The compiled step loop: every step between two Python-side events in one call.

One step, in order (the PFC cycle):

1. rebuild the neighbour lists if flagged (a disk or wall moved more than skin / 2), from
   one cell grid or, for wide size ratios, from grids by size level (:mod:`poro2d.dem.neighbors`);
2. contact forces of every disk-disk and disk-wall pair (contact law, history update);
3. the unbalanced force of each disk: gravity plus its contact forces;
4. local (Cundall) damping and leapfrog integration of the disks;
5. wall resultants, servo walls set their speed from the force error; walls move;
6. flag a rebuild when needed; every ``check_every`` steps test the stop condition.

The stop test falls on the steps that are multiples of ``check_every`` counted from
the start of the driver's run (``iprm[CHECK_OFFSET]`` steps of it came before this
call), not from the start of the call: the driver cuts a run into calls wherever a
progress update, a callback or a storage overflow needs Python, and those cuts must
not move the test (a run would stop on another step and give other numbers).

How the work is laid out (see :mod:`poro2d.dem.partition`): the disks form ``P``
contiguous partitions. Within a partition 2-4 are one pass over the disks in index
order: each pair adds its force to both disks as it is computed (partners ``j > i``
only, so when disk ``i``'s row is done its force is complete and it is advanced at
once; no later row reads it). A pair whose partner lies in a later partition only
stores its force; that partner is *deferred* and collects such forces after all
partitions are done (phase 2). The order of every sum is therefore fixed by the
partitions: for a disk, gravity, then the pairs of earlier rows of its partition,
its own row, its walls, then its cross pairs; for a wall, partition by partition.
With rolling resistance a contact adds its rolling moment to the first disk's sum (and takes
it from the second's), then its shear moment a Fs, each lever arm's product fused into that
sum (:mod:`poro2d.dem.fma`).

What the steps write: a pair's history (``fs``, ``mr``) at every step; its geometry and
normal force (``ov``, ``fn``, ``nx``, ``ny``) and the disks' unbalanced forces and moments
only where they are read: for the cross pairs and deferred disks at every step (phase 2
reads them), for everything on a stop-check step and on the call's last step (the stop
test and Python read them). The other steps move less memory; no number depends on it.

Threads: one worker per thread runs all steps of the call, each on its own
partitions; workers meet at two barriers per step (after phase 1, after phase 2;
one more on stop-check steps, and a few between the phases of a list rebuild), not at
a thread start-up per loop. With
one thread the same worker runs alone, without barriers. Results do not depend on
the number of threads, bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from poro2d.dem.contact_law import (
    PER_BODY,
    contact_components,
    contact_force,
    dashpot,
    mix,
    mix_rolling,
    reduced_mass,
    rolling_moment,
    rolling_radius,
    segment_closest,
)
from poro2d.dem.fma import fma
from poro2d.dem.neighbors import (
    cell_grid,
    copy_rows,
    count_level_rows,
    count_pair_rows,
    count_wall_rows,
    fill_level_rows,
    fill_pair_rows,
    fill_wall_rows,
    level_grid,
    prefix_rows,
)
from poro2d.dem.partition import partition
from poro2d.dem.records import BodyProps, KernelRecords, RollingProps
from poro2d.dem.state import (
    FREE,
    SERVO_ERROR_SUM,
    SERVO_GAIN,
    SERVO_INTEGRAL,
    SERVO_MAX_SPEED,
    SERVO_TARGET,
    WALL_SERVO,
)
from poro2d.dem.sync import STATUS_WORD, atomic_load, atomic_store, barrier, start_handshake

# float parameters (prm)
DT, GX, GY, DAMP, SKIN, BETA, KN_PP, KS_PP, MU_PP, KN_PW, KS_PW, MU_PW, RATIO_TARGET, TIME = range(14)
N_PRM = 14
# integer parameters (iprm): MODE / MODE_PW say whether disk-disk / disk-wall contacts combine
# the bodies' properties (PER_BODY) or use the constants in prm; CHECK_OFFSET is the number
# of steps of the driver's run done before this call (the stop test counts from the run's start)
# MEASURE: which equilibrium measure the stop test compares with RATIO_TARGET (below)
MODE, NSTEPS, CHECK_EVERY, NEED_BUILD, THREADS, MODE_PW, CHECK_OFFSET, MEASURE = range(8)
N_IPRM = 8
# outputs (out)
STATUS, STEPS_DONE, MAX_RATIO, MEAN_RATIO, NEED_PP, NEED_PW, REBUILDS, THREADS_USED = range(8)
LOADED_RATIO, RATTLERS = 8, 9
N_OUT = 10
# equilibrium measures of the stop test: the maximum ratio over every free disk (PFC's maximum
# ratio, the paper's), the mean ratio (mean unbalanced / mean contact force, PFC's average
# ratio), the maximum ratio over the load-bearing disks (two contacts or more: rattlers, which
# never carry a balanced load, left out)
MEASURE_MAX, MEASURE_MEAN, MEASURE_LOADED = 0, 1, 2
# status codes
RUNNING, CONVERGED, OVERFLOW, UNSTABLE = 0, 1, 2, 3
# per-partition wall sums (walls.part_sums[k, w, :])
WFX, WFY, WCOUNT, WKSUM = range(4)
# columns of walls.stat: disks touching the wall, their summed contact kn (the servo's stiffness)
STAT_COUNT, STAT_KSUM = range(2)


@njit(cache=True)
def equilibrium_measures(force, pmode, nb_start, nb_j, nb_fn, nb_fs, nb_ov, wb_start, wb_fn, wb_fs, wb_ov):
    """(max, mean, loaded max, rattlers): the unbalanced-force ratios of a step.

    max: largest unbalanced force on a free disk / largest contact force (PFC's maximum
    ratio); mean: mean unbalanced force / mean contact force (PFC's average ratio); loaded
    max: the maximum ratio over the free disks touching two bodies or more; rattlers: the
    number of free disks touching fewer than two. Ratios are ``inf`` when nothing touches.
    """
    n = force.shape[0]
    touches = np.zeros(n, dtype=np.int64)
    cmax = 0.0
    csum = 0.0
    nc = 0
    for i in range(n):
        for p in range(nb_start[i], nb_start[i + 1]):
            if nb_ov[p] > 0.0:
                touches[i] += 1
                touches[nb_j[p]] += 1
                f = math.sqrt(nb_fn[p] ** 2 + nb_fs[p] ** 2)
                csum += f
                nc += 1
                cmax = max(cmax, f)
    for i in range(n):  # walls after every pair: the sums in the order of the ratios before
        for p in range(wb_start[i], wb_start[i + 1]):
            if wb_ov[p] > 0.0:
                touches[i] += 1
                f = math.sqrt(wb_fn[p] ** 2 + wb_fs[p] ** 2)
                csum += f
                nc += 1
                cmax = max(cmax, f)
    fmax = 0.0
    floaded = 0.0
    fsum = 0.0
    nfree = 0
    rattlers = 0
    for i in range(n):
        if pmode[i] == FREE:
            f = math.sqrt(force[i, 0] ** 2 + force[i, 1] ** 2)
            fsum += f
            nfree += 1
            fmax = max(fmax, f)
            if touches[i] >= 2:
                floaded = max(floaded, f)
            else:
                rattlers += 1
    if nfree == 0:
        return 0.0, 0.0, 0.0, 0
    if nc == 0 or cmax <= 0.0:
        return np.inf, np.inf, np.inf, rattlers
    return fmax / cmax, (fsum / nfree) / (csum / nc), floaded / cmax, rattlers


@njit(inline="always", cache=True)
def _wall_normal(dx, dy, d, sx, sy):
    """Unit normal from a disk to a wall: along dx, dy (closest wall point minus centre, length
    d), or, with the centre on the wall line, the normal of the wall's direction sx, sy."""
    if d > 0.0:
        return dx / d, dy / d
    sl = math.sqrt(sx * sx + sy * sy)
    return sy / sl, -sx / sl


@njit(inline="always", cache=True)
def _damped(f, v, damp):
    """Cundall's local damping of one force or moment component."""
    return f - damp * abs(f) * np.sign(v)


@njit(inline="always", cache=True)
def _leap(v, f, damp, inv_m, dt):
    """Leapfrog: a speed (or spin) ``v`` after a step under the damped force (or moment) ``f``."""
    return fma(_damped(f, v, damp) * inv_m, dt, v)


@njit(inline="always", cache=True, error_model="numpy")
def _pair_ahead(q, q_end, rq, nb_start, nb_j, posf, dx, dy, d, inv):
    """The geometry of listed pair ``q`` (its row found from ``rq`` on): (row, dx, dy, d, 1 / d).

    Beyond the partition's pairs (``q >= q_end``) the row and geometry given are returned.
    """
    if q >= q_end:
        return rq, dx, dy, d, inv
    while nb_start[rq + 1] <= q:
        rq += 1
    j = np.uint64(nb_j[q])
    r = np.uint64(rq)
    U1 = np.uint64(1)
    U2 = np.uint64(2)
    dx = posf[U2 * j] - posf[U2 * r]
    dy = posf[U2 * j + U1] - posf[U2 * r + U1]
    d = math.sqrt(fma(dx, dx, dy * dy))
    return rq, dx, dy, d, 1.0 / d


@njit(cache=True, error_model="numpy")
def _phase_forces(
    k, disks, walls, nb, wb, work, prm, props, dash, roll, pw_body, dt, gx, gy, damp, stored, skip2
):
    """Phase 1 on partition k: forces of its rows, advance of its non-deferred disks.

    ``props`` holds the disks' (kn, ks, mu) (:class:`~poro2d.dem.records.BodyProps`) when
    disk-disk contacts combine them per pair, else None (the constants in prm); ``dash``
    the critical-damping fraction of the contact dashpot, None without one. Being None is
    a type, so numba compiles a variant without that code: those branches and the arrays
    they need cost registers in the pair loop (5-7 % of its speed), even when never taken.
    ``roll`` likewise: the bodies' rolling frictions (:class:`~poro2d.dem.records.RollingProps`),
    None when no disk has one, and then no rolling moment is computed or stored.

    ``stored`` (True, or None) says whether this step keeps what only readers after it
    need: every pair's geometry and normal force (``ov``, ``fn``, ``nx``, ``ny`` of both
    lists) and every disk's unbalanced force and moment. They drive no later step; they
    are read by the stop test, by Python after a call, and, for the cross pairs and the
    deferred disks, by phase 2 of the same step, which therefore get them at every step.
    The driver asks for them on a check step and on the last step of a call
    (:func:`_stores_all`). Skipping them elsewhere spares the force pass most of its
    writes: the pair loop then writes only the history (``fs``, ``mr``). A step that
    stores writes the normal of every listed pair, touching or not, so what a call leaves
    does not depend on where earlier calls ended.

    ``skip2``: a disk that moved at a squared speed below it this step cannot have drifted
    half the skin since the lists were built (:func:`_drift_bound`), so its drift is not
    computed (its build position not read); -1 computes every disk's.

    Returns the largest squared drift of the disks whose drift was computed, and the largest
    squared speed of those whose was not (-1 if none).
    """
    # local names for the arrays of the loop (the records' fields, read once)
    pos, vel, theta, omega = disks.pos, disks.vel, disks.theta, disks.omega
    force, moment, acc, radius = disks.force, disks.moment, disks.acc, disks.radius
    mass, inv_mass, inv_inertia = disks.mass, disks.inv_mass, disks.inv_inertia
    pkn, pks, pmu = disks.kn, disks.ks, disks.mu
    wp0, wp1, wvel, wkn, wks, wmu = walls.p0, walls.p1, walls.vel, walls.kn, walls.ks, walls.mu
    wpart = walls.part_sums
    nb_start, nb_j, nb_fs, nb_fn, nb_ov, nb_nx, nb_ny = nb.start, nb.j, nb.fs, nb.fn, nb.ov, nb.nx, nb.ny
    wb_start, wb_w, wb_fs, wb_fn, wb_ov, wb_nx, wb_ny = wb.start, wb.w, wb.fs, wb.fn, wb.ov, wb.nx, wb.ny
    nb_mr, wb_mr = nb.mr, wb.mr
    pos_build, part, dlist, dstart, held = work.pos_build, work.part, work.dlist, work.dstart, work.held
    # flat views: an (n, 2) index costs a multiplication by a run-time row length
    posf = pos.reshape(pos.size)
    velf = vel.reshape(vel.size)
    accf = acc.reshape(acc.size)
    U1 = np.uint64(1)
    U2 = np.uint64(2)
    U3 = np.uint64(3)
    nw = wp0.shape[0]
    for w in range(nw):
        wpart[k, w, WFX] = 0.0
        wpart[k, w, WFY] = 0.0
        wpart[k, w, WCOUNT] = 0.0
        wpart[k, w, WKSUM] = 0.0
    kn = prm[KN_PP]
    ks = prm[KS_PP]
    mu = prm[MU_PP]
    i0 = part[k]
    i1 = part[k + 1]
    # the partition's deferred disks, in ascending order: a cursor on them, not a per-disk
    # look at the cross-pair rows (8 bytes less to read per disk)
    m = dstart[k]
    m1 = dstart[k + 1]
    deferred = dlist[m] if m < m1 else i1
    # and one on the disks not free (``held``, ascending, n after the last): no per-disk mode
    h = np.searchsorted(held, i0)
    hold = held[h]
    dmax = 0.0
    vskip = -1.0
    # the pair loop works one pair ahead: the next listed pair's geometry (its square root
    # and inverse) is computed before this pair's contact law, so the two long-latency
    # operations no longer wait at the head of each pair's chain (nor after a row's end,
    # whose loop exit is mispredicted). The next pair is of this row or a later one, whose
    # disks no earlier row moves: the same numbers as computed in place, bit for bit.
    q_end = nb_start[i1]
    rq, ldx, ldy, ld, linv = _pair_ahead(nb_start[i0], q_end, i0, nb_start, nb_j, posf, 0.0, 0.0, 0.0, 0.0)
    for i_ in range(i0, i1):
        i = np.uint64(i_)  # unsigned indices: no negative-index wrap-around code
        fx = accf[U3 * i]
        fy = accf[U3 * i + U1]
        mz = accf[U3 * i + U2]
        xi = posf[U2 * i]
        yi = posf[U2 * i + U1]
        ri = radius[i]
        mur_i = 0.0
        if roll is not None:
            mur_i = roll.disk_mu_r[i]
        for p_ in range(nb_start[i_], nb_start[i_ + 1]):
            p = np.uint64(p_)
            js = nb_j[p]
            j = np.uint64(js)
            dx = ldx
            dy = ldy
            d = ld
            inv = linv  # 1 / d (inf for d = 0, then not used)
            rq, ldx, ldy, ld, linv = _pair_ahead(p_ + 1, q_end, rq, nb_start, nb_j, posf, ldx, ldy, ld, linv)
            ov = ri + radius[j] - d
            if ov <= 0.0:
                nb_fs[p] = 0.0  # contact lost: history ends
                if roll is not None:
                    nb_mr[p] = 0.0
                if stored is not None:  # apart: d >= ri + rj > 0
                    nb_ov[p] = ov
                    nb_fn[p] = 0.0
                    nb_nx[p] = dx * inv
                    nb_ny[p] = dy * inv
                elif js >= i1:  # a cross pair: phase 2 reads that it is apart
                    nb_ov[p] = ov
                continue
            if props is not None:
                kn, ks, mu = mix(props.kn[i], props.ks[i], props.mu[i], props.kn[j], props.ks[j], props.mu[j])
            cn = 0.0
            if dash is not None:
                cn = dashpot(dash, kn, reduced_mass(mass[i], mass[j]))
            if d > 0.0:  # a product by the inverse: one division for both components
                nx = dx * inv
                ny = dy * inv
            else:
                nx = 1.0
                ny = 0.0
            ai = fma(-0.5, ov, ri)
            aj = fma(-0.5, ov, radius[j])
            dvx = velf[U2 * j] - velf[U2 * i]
            dvy = velf[U2 * j + U1] - velf[U2 * i + U1]
            wi = omega[i]
            wj = omega[j]
            fn, fs, fxp, fyp = contact_force(
                ov, nx, ny, dvx, dvy, ai, aj, wi, wj, nb_fs[p], kn, ks, mu, cn, dt
            )
            nb_fs[p] = fs
            fx += fxp
            fy += fyp
            # the contact's moments: a_i Fs (+ Mr) on i, a_j Fs (- Mr) on j, each lever arm's
            # product fused into its disk's sum
            mr = 0.0
            if roll is not None:
                reff = rolling_radius(ri, radius[j])
                mur = mix_rolling(mur_i, roll.disk_mu_r[j])
                mr = rolling_moment(nb_mr[p], ks, reff, wi - wj, dt, mur, fn)
                nb_mr[p] = mr
                mz += mr
            mz = fma(ai, fs, mz)
            if js < i1:  # a partner in a later partition collects this in phase 2
                accf[U3 * j] -= fxp
                accf[U3 * j + U1] -= fyp
                mj = accf[U3 * j + U2]
                if roll is not None:
                    mj -= mr
                accf[U3 * j + U2] = fma(aj, fs, mj)
                if stored is None:
                    continue
            nb_ov[p] = ov  # a cross pair's, or on a step that stores them all
            nb_fn[p] = fn
            nb_nx[p] = nx
            nb_ny[p] = ny
        for p_ in range(wb_start[i_], wb_start[i_ + 1]):
            p = np.uint64(p_)
            w = np.uint64(wb_w[p])
            cx, cy = segment_closest(xi, yi, wp0[w, 0], wp0[w, 1], wp1[w, 0], wp1[w, 1])
            dx = cx - xi
            dy = cy - yi
            d = math.sqrt(dx * dx + dy * dy)
            ov = ri - d
            if ov <= 0.0:
                wb_fs[p] = 0.0
                if roll is not None:
                    wb_mr[p] = 0.0
                if stored is not None:
                    wb_ov[p] = ov
                    wb_fn[p] = 0.0
                    wb_nx[p], wb_ny[p] = _wall_normal(dx, dy, d, wp1[w, 0] - wp0[w, 0], wp1[w, 1] - wp0[w, 1])
                continue
            if pw_body:
                wkn_, wks_, wmu_ = mix(pkn[i], pks[i], pmu[i], wkn[w], wks[w], wmu[w])
            else:
                wkn_ = prm[KN_PW]
                wks_ = prm[KS_PW]
                wmu_ = prm[MU_PW]
            cn = 0.0
            if dash is not None:
                cn = dashpot(dash, wkn_, mass[i])
            ai = fma(-0.5, ov, ri)
            nx, ny = _wall_normal(dx, dy, d, wp1[w, 0] - wp0[w, 0], wp1[w, 1] - wp0[w, 1])
            fn, fs, fxp, fyp = contact_force(
                ov, nx, ny, wvel[w, 0] - velf[U2 * i], wvel[w, 1] - velf[U2 * i + U1], ai, 0.0, omega[i], 0.0,
                wb_fs[p], wkn_, wks_, wmu_, cn, dt,
            )  # fmt: skip
            wb_fs[p] = fs
            if stored is not None:
                wb_ov[p] = ov
                wb_fn[p] = fn
                wb_nx[p] = nx
                wb_ny[p] = ny
            fx += fxp
            fy += fyp
            if roll is not None:  # a wall does not turn: the disk's spin is the relative one
                mur = mix_rolling(mur_i, roll.wall_mu_r[w])
                mr = rolling_moment(wb_mr[p], wks_, ri, omega[i], dt, mur, fn)
                wb_mr[p] = mr
                mz += mr
            mz = fma(ai, fs, mz)
            wpart[k, w, WFX] -= fxp
            wpart[k, w, WFY] -= fyp
            wpart[k, w, WCOUNT] += 1.0
            wpart[k, w, WKSUM] += wkn_
        if stored is not None or i_ == deferred:
            force[i, 0] = fx
            force[i, 1] = fy
            moment[i] = mz
        free = i_ != hold
        if not free:
            h += 1
            hold = held[h]
        if i_ == deferred:  # the partial sums wait in force and moment for phase 2
            m += 1
            deferred = dlist[m] if m < m1 else i1
            continue
        # ready for the next step: the earlier rows of its partition add to this
        accf[U3 * i] = mass[i] * gx
        accf[U3 * i + U1] = mass[i] * gy
        accf[U3 * i + U2] = 0.0
        if free:
            velf[U2 * i] = _leap(velf[U2 * i], fx, damp, inv_mass[i], dt)
            velf[U2 * i + U1] = _leap(velf[U2 * i + U1], fy, damp, inv_mass[i], dt)
            omega[i] = _leap(omega[i], mz, damp, inv_inertia[i], dt)
        vx = velf[U2 * i]
        vy = velf[U2 * i + U1]
        posf[U2 * i] = fma(vx, dt, posf[U2 * i])
        posf[U2 * i + U1] = fma(vy, dt, posf[U2 * i + U1])
        theta[i] = fma(omega[i], dt, theta[i])
        v2 = fma(vx, vx, vy * vy)
        if v2 < skip2:  # never for a speed not finite
            vskip = max(vskip, v2)
        else:
            ddx = posf[U2 * i] - pos_build[i, 0]
            ddy = posf[U2 * i + U1] - pos_build[i, 1]
            dmax = max(dmax, fma(ddx, ddx, ddy * ddy))
    return dmax, vskip


@njit(cache=True, error_model="numpy")
def _phase_deferred(m0, m1, disks, nb, work, roll, gx, gy, damp, dt):
    """Phase 2: deferred disks ``dlist[m0:m1]`` add their cross pairs and advance.

    Each deferred disk only reads its own cross pairs, so the list is shared out
    evenly among the threads, whatever partition a disk belongs to.
    """
    pos, vel, theta, omega = disks.pos, disks.vel, disks.theta, disks.omega
    force, moment, acc, radius = disks.force, disks.moment, disks.acc, disks.radius
    mass, inv_mass, inv_inertia, pmode = disks.mass, disks.inv_mass, disks.inv_inertia, disks.mode
    nb_fs, nb_fn, nb_ov, nb_nx, nb_ny, nb_mr = nb.fs, nb.fn, nb.ov, nb.nx, nb.ny, nb.mr
    pos_build, xstart, xpair, dlist = work.pos_build, work.xstart, work.xpair, work.dlist
    dmax = 0.0
    for m in range(m0, m1):
        i = dlist[m]
        fx = force[i, 0]
        fy = force[i, 1]
        mz = moment[i]
        for q in range(xstart[i], xstart[i + 1]):
            p = xpair[q]
            if nb_ov[p] > 0.0:  # the same numbers as phase 1 gives a partner in its partition
                fs = nb_fs[p]
                fxp, fyp = contact_components(nb_fn[p], fs, nb_nx[p], nb_ny[p])
                fx -= fxp
                fy -= fyp
                if roll is not None:
                    mz -= nb_mr[p]
                mz = fma(fma(-0.5, nb_ov[p], radius[i]), fs, mz)
        force[i, 0] = fx
        force[i, 1] = fy
        moment[i] = mz
        acc[i, 0] = mass[i] * gx
        acc[i, 1] = mass[i] * gy
        acc[i, 2] = 0.0
        if pmode[i] == FREE:
            vel[i, 0] = _leap(vel[i, 0], fx, damp, inv_mass[i], dt)
            vel[i, 1] = _leap(vel[i, 1], fy, damp, inv_mass[i], dt)
            omega[i] = _leap(omega[i], mz, damp, inv_inertia[i], dt)
        pos[i, 0] = fma(vel[i, 0], dt, pos[i, 0])
        pos[i, 1] = fma(vel[i, 1], dt, pos[i, 1])
        theta[i] = fma(omega[i], dt, theta[i])
        ddx = pos[i, 0] - pos_build[i, 0]
        ddy = pos[i, 1] - pos_build[i, 1]
        dmax = max(dmax, fma(ddx, ddx, ddy * ddy))
    return dmax


@njit(cache=True)
def _move_walls(walls, dt):
    """Wall resultants (partition by partition), servo speeds, wall motion."""
    wp0, wp1, wvel, wmode = walls.p0, walls.p1, walls.vel, walls.mode
    wdir, wservo = walls.servo_dir, walls.servo
    wforce, wstat, wpart = walls.force, walls.stat, walls.part_sums
    nw = wp0.shape[0]
    for w in range(nw):
        wforce[w, 0] = 0.0
        wforce[w, 1] = 0.0
        wstat[w, STAT_COUNT] = 0.0
        wstat[w, STAT_KSUM] = 0.0
        for k in range(wpart.shape[0]):
            wforce[w, 0] += wpart[k, w, WFX]
            wforce[w, 1] += wpart[k, w, WFY]
            wstat[w, STAT_COUNT] += wpart[k, w, WCOUNT]
            wstat[w, STAT_KSUM] += wpart[k, w, WKSUM]
        if wmode[w] == WALL_SERVO:
            # compressive force along the servo direction; v = gain * error / (k dt)
            fc = -(wforce[w, 0] * wdir[w, 0] + wforce[w, 1] * wdir[w, 1])
            err = wservo[w, SERVO_TARGET] - fc
            vmax = wservo[w, SERVO_MAX_SPEED]
            if wstat[w, STAT_COUNT] > 0.0:
                summed = wservo[w, SERVO_ERROR_SUM] + err
                gain = wservo[w, SERVO_GAIN]
                integral = wservo[w, SERVO_INTEGRAL]
                v = gain * (err + integral * summed) / (wstat[w, STAT_KSUM] * dt)
                if -vmax <= v <= vmax:  # no wind-up while the speed is bounded
                    wservo[w, SERVO_ERROR_SUM] = summed
            else:  # nothing touches: approach (or retreat) at full speed
                v = vmax if err > 0.0 else -vmax
            if v > vmax:
                v = vmax
            elif v < -vmax:
                v = -vmax
            wvel[w, 0] = v * wdir[w, 0]
            wvel[w, 1] = v * wdir[w, 1]
    for w in range(nw):
        wp0[w, 0] += wvel[w, 0] * dt
        wp0[w, 1] += wvel[w, 1] * dt
        wp1[w, 0] += wvel[w, 0] * dt
        wp1[w, 1] += wvel[w, 1] * dt


@njit(cache=True)
def _clear_tail(ov, fn, nx, ny, used, old_used):
    """Zero the geometry of the slots a shorter list leaves behind (``used`` to ``old_used``).

    They would hold what the last step that stored (see :func:`_phase_forces`) wrote, and
    which step that was depends on where calls ended; zeros do not.
    """
    for p in range(used, old_used):
        ov[p] = 0.0
        fn[p] = 0.0
        nx[p] = 0.0
        ny[p] = 0.0


@njit(cache=True)
def _rebuild(t, nthr, disks, walls, nb, wb, work, prm, out, levels):
    """All workers rebuild the lists together; thread 0 does the serial parts.

    ``levels`` is None for the one cell grid, else the grids by size level
    (:class:`~poro2d.dem.neighbors.LevelScratch`): a type, so each search compiles
    into its own variant and the one grid's code is the same as without the other.
    Returns False (on every worker) when the pair storage is too small.
    """
    pos, radius = disks.pos, disks.radius
    wp0, wp1, wall_build = walls.p0, walls.p1, walls.p0_build
    nb_start, nb_j, nb_fs, nb_mr = nb.start, nb.j, nb.fs, nb.mr
    new_start, new_j, new_fs, new_mr = nb.new_start, nb.new_j, nb.new_fs, nb.new_mr
    wb_start, wb_w, wb_fs, wb_mr = wb.start, wb.w, wb.fs, wb.mr
    wnew_start, wnew_w, wnew_fs, wnew_mr = wb.new_start, wb.new_w, wb.new_fs, wb.new_mr
    pos_build, sync = work.pos_build, work.sync
    part, xstart, xpair, dlist, dstart = work.part, work.xstart, work.xpair, work.dlist, work.dstart
    cell, members, cstart, cfill, ginfo = work.cell, work.members, work.cstart, work.cfill, work.ginfo
    cand = work.cand
    skin = prm[SKIN]
    n = pos.shape[0]
    lo = t * n // nthr
    hi = (t + 1) * n // nthr
    if t == 0:
        if levels is None:
            cell_grid(pos, radius, skin, cell, members, cstart, cfill, ginfo)
        else:
            level_grid(pos, radius, skin, levels)
    barrier(sync, nthr)
    if levels is None:
        count_pair_rows(lo, hi, pos, radius, skin, cell, members, cstart, ginfo, new_start, cand)
    else:
        count_level_rows(lo, hi, pos, radius, skin, levels, new_start)
    count_wall_rows(lo, hi, pos, radius, skin, wp0, wp1, wnew_start)
    barrier(sync, nthr)
    if t == 0:
        total = prefix_rows(n, new_start)
        wtotal = prefix_rows(n, wnew_start)
        status = RUNNING
        if total > nb_j.shape[0]:
            out[NEED_PP] = total
            status = OVERFLOW
        if wtotal > wb_w.shape[0]:
            out[NEED_PW] = wtotal
            status = OVERFLOW
        atomic_store(sync, STATUS_WORD, status)
    barrier(sync, nthr)
    if atomic_load(sync, STATUS_WORD) != RUNNING:
        return False
    if levels is None:
        fill_pair_rows(lo, hi, pos, radius, skin, cell, members, cstart, ginfo, nb_start, nb_j, nb_fs,
                       new_start, new_j, new_fs, nb_mr, new_mr, cand)  # fmt: skip
    else:
        fill_level_rows(lo, hi, pos, radius, skin, levels, nb_start, nb_j, nb_fs, nb_mr, new_start,
                        new_j, new_fs, new_mr)  # fmt: skip
    fill_wall_rows(lo, hi, pos, radius, skin, wp0, wp1, wb_start, wb_w, wb_fs, wnew_start, wnew_w, wnew_fs,
                   wb_mr, wnew_mr)  # fmt: skip
    barrier(sync, nthr)  # the old rows are read by every filler: overwrite them only now
    copy_rows(lo, hi, new_start, new_j, new_fs, nb_start, nb_j, nb_fs, new_mr, nb_mr)
    copy_rows(lo, hi, wnew_start, wnew_w, wnew_fs, wb_start, wb_w, wb_fs, wnew_mr, wb_mr)
    for i in range(lo, hi):
        pos_build[i, 0] = pos[i, 0]
        pos_build[i, 1] = pos[i, 1]
    if t == 0:
        for w in range(wp0.shape[0]):
            wall_build[w, 0] = wp0[w, 0]
            wall_build[w, 1] = wp0[w, 1]
    barrier(sync, nthr)
    if t == 0:
        partition(n, nb_start, nb_j, wb_start, part, xstart, xpair, dlist, dstart)
    barrier(sync, nthr)
    return True


# relative and absolute (per step, x half the skin) slack of the drift bound: far above the
# round-off of a position update, of a squared distance and of a square root
BOUND_REL = 1e-9
BOUND_ABS = 1e-6


@njit(inline="always", cache=True)
def _skip_below(bound, half_skin, dt):
    """The squared speed below which a disk cannot drift past ``half_skin`` in one step.

    ``bound`` holds every disk's drift since the lists were built, as of the last step; a
    disk that then moves at speed v drifts at most ``bound + v dt`` (and a position's
    round-off, the absolute slack). So the rebuild test needs its drift only above this.
    -1 when the bound leaves no room (or is not finite): every drift is computed.
    """
    room = half_skin * (1.0 - BOUND_REL) - bound - BOUND_ABS * half_skin
    if not room > 0.0:
        return -1.0
    v = room / (dt * (1.0 + BOUND_REL))
    return v * v * (1.0 - BOUND_REL)


@njit(cache=True)
def _drift_bound(bound, tmax, tskip, nthr, dt, half_skin):
    """A bound on every disk's drift after this step, from the threads' shared numbers.

    A disk whose drift was computed drifted at most the square root of the largest of those
    (``tmax``); one whose was not, at most the last bound plus its step (``tskip``, the
    largest squared speed among them). When every drift was computed, the bound comes
    down to the largest of them. A disk whose speed is not finite is always computed and
    left out here (``>`` is false for NaN): the rebuild test takes it as before.
    """
    dexact = 0.0
    vs = -1.0
    for u in range(nthr):
        if tmax[u] > dexact:
            dexact = tmax[u]
        if tskip[u] > vs:
            vs = tskip[u]
    b = math.sqrt(dexact)
    if vs >= 0.0:
        b = max(b, bound + math.sqrt(vs) * dt)
    return b * (1.0 + BOUND_REL) + BOUND_ABS * half_skin


@njit(cache=True)
def _largest_drift(tmax, nthr, wp0, wall_build):
    """Largest squared drift of a disk or wall since the lists were built.

    Every worker computes it from the same shared numbers, so all take the same rebuild
    and stop decisions without another barrier. Arrays, not records: a record passed to a
    helper costs a reference count per array at every step.
    """
    dmax = 0.0
    for u in range(nthr):
        if tmax[u] > dmax:
            dmax = tmax[u]
    for w in range(wp0.shape[0]):
        ddx = wp0[w, 0] - wall_build[w, 0]
        ddy = wp0[w, 1] - wall_build[w, 1]
        d2 = ddx * ddx + ddy * ddy
        if d2 > dmax:
            dmax = d2
    return dmax


@njit(cache=True)
def _converged(t, nthr, disks, nb, wb, sync, out, target, measure):
    """The stop test: thread 0 computes the ratios once, and every worker reads its verdict.

    ``measure`` (``MEASURE_MAX``, ``MEASURE_MEAN`` or ``MEASURE_LOADED``) is the ratio
    compared with ``target``. It takes whole records (a reference count per array) since it
    runs on check steps only.
    """
    if t == 0:
        rmax, rmean, rloaded, rattlers = equilibrium_measures(
            disks.force, disks.mode, nb.start, nb.j, nb.fn, nb.fs, nb.ov, wb.start, wb.fn, wb.fs, wb.ov
        )
        out[MAX_RATIO] = rmax
        out[MEAN_RATIO] = rmean
        out[LOADED_RATIO] = rloaded
        out[RATTLERS] = rattlers
        r = rmean if measure == MEASURE_MEAN else (rloaded if measure == MEASURE_LOADED else rmax)
        atomic_store(sync, STATUS_WORD, CONVERGED if r < target else RUNNING)
    barrier(sync, nthr)  # nobody may change the forces before they are read
    return atomic_load(sync, STATUS_WORD) == CONVERGED


@njit(inline="always", cache=True)
def _stores_all(step, nsteps, since_check, check_every):
    """Whether step ``step`` of a call stores every pair's geometry and every disk's force.

    The stop test reads them right after a check step, and Python after the call's last
    step (contacts, checkpoints, measurements). A call that stops early stops on a check
    step; one that stops at a full list reports the overflow, and the driver calls again
    for the steps left, which end on a step that stores.
    """
    return step == nsteps - 1 or (check_every > 0 and since_check + 1 == check_every)


@njit(cache=True)
def _report(status, steps, rebuilds, need_build, pos, iprm, out):
    """The call's outcome for the driver, written once by thread 0 after the last step."""
    out[STATUS] = status
    out[STEPS_DONE] = steps
    out[REBUILDS] = rebuilds
    iprm[NEED_BUILD] = 1 if need_build else 0
    if status == RUNNING and not math.isfinite(pos.sum()):
        out[STATUS] = UNSTABLE


@njit(cache=True)
def _worker(t, nthr, disks, walls, nb, wb, work, prm, iprm, out, props, dash, roll, levels):
    """Run the steps of this call on thread t of nthr: partitions t P / nthr to (t + 1) P / nthr - 1."""
    wp0, wall_build = walls.p0, walls.p0_build
    part, dstart, tmax, tskip, sync = work.part, work.dstart, work.tmax, work.tskip, work.sync
    dt, gx, gy, damp, target = prm[DT], prm[GX], prm[GY], prm[DAMP], prm[RATIO_TARGET]
    measure, nsteps, check_every = iprm[MEASURE], iprm[NSTEPS], iprm[CHECK_EVERY]
    half_skin = 0.5 * prm[SKIN]
    lim2 = half_skin**2
    # every disk's drift since the last build is at most this: the first step computes all
    bound = np.inf
    pw_body = iprm[MODE_PW] == PER_BODY
    # steps of the run since its last stop test: the test schedule ignores where calls begin
    since_check = iprm[CHECK_OFFSET] % check_every if check_every > 0 else 0
    need_build = iprm[NEED_BUILD] != 0
    npart = part.shape[0] - 1
    n = disks.pos.shape[0]
    k0 = t * npart // nthr
    k1 = (t + 1) * npart // nthr
    steps = 0
    rebuilds = 0
    status = RUNNING
    for step in range(nsteps):
        if need_build:
            used, wused = nb.start[n], wb.start[n]
            if not _rebuild(t, nthr, disks, walls, nb, wb, work, prm, out, levels):
                status = OVERFLOW
                break
            if t == 0:  # slots nobody else touches now: the lists end before them
                _clear_tail(nb.ov, nb.fn, nb.nx, nb.ny, nb.start[n], used)
                _clear_tail(wb.ov, wb.fn, wb.nx, wb.ny, wb.start[n], wused)
            need_build = False
            rebuilds += 1
            bound = 0.0  # every disk at its build position
        # phase 1: forces; disks without cross pairs advance at once. Both phases stay here:
        # a helper taking the records would add a reference count per array at every step
        dmax = 0.0
        vskip = -1.0
        stores = _stores_all(step, nsteps, since_check, check_every)
        check = check_every > 0 and since_check + 1 == check_every
        # a check step computes every drift: its finiteness test sees them all, as ever
        skip2 = -1.0 if check else _skip_below(bound, half_skin, dt)
        for k in range(k0, k1):
            if stores:
                d2, v2 = _phase_forces(k, disks, walls, nb, wb, work, prm, props, dash, roll, pw_body, dt, gx,
                                       gy, damp, True, skip2)  # fmt: skip
            else:
                d2, v2 = _phase_forces(k, disks, walls, nb, wb, work, prm, props, dash, roll, pw_body, dt, gx,
                                       gy, damp, None, skip2)  # fmt: skip
            if d2 > dmax:
                dmax = d2
            if v2 > vskip:
                vskip = v2
        barrier(sync, nthr)
        # phase 2: the deferred disks, shared out evenly; thread 0 also moves the walls
        ndef = dstart[npart]
        m0, m1 = t * ndef // nthr, (t + 1) * ndef // nthr
        d2 = _phase_deferred(m0, m1, disks, nb, work, roll, gx, gy, damp, dt)
        if d2 > dmax:
            dmax = d2
        tmax[t] = dmax  # after the first barrier: the others read both until then
        tskip[t] = vskip
        if t == 0:
            _move_walls(walls, dt)
            prm[TIME] += dt
        barrier(sync, nthr)
        steps += 1
        since_check += 1
        dmax = _largest_drift(tmax, nthr, wp0, wall_build)
        bound = _drift_bound(bound, tmax, tskip, nthr, dt, half_skin)
        if dmax > lim2:
            need_build = True
        if check_every > 0 and since_check == check_every:
            since_check = 0
            if not math.isfinite(dmax):
                status = UNSTABLE
                break
            if target > 0.0 and _converged(t, nthr, disks, nb, wb, sync, out, target, measure):
                status = CONVERGED
                break
    if t == 0:
        _report(status, steps, rebuilds, need_build, disks.pos, iprm, out)


@njit(cache=True)
def prepare(disks, nb, wb, work, prm):
    """Before a call: gravity in every accumulator, the disks not free, partitions of the current lists."""
    acc, mass, mode, held = disks.acc, disks.mass, disks.mode, work.held
    n = disks.pos.shape[0]
    h = 0
    for i in range(n):
        acc[i, 0] = mass[i] * prm[GX]
        acc[i, 1] = mass[i] * prm[GY]
        acc[i, 2] = 0.0
        if mode[i] != FREE:  # modes change between calls only
            held[h] = i
            h += 1
    held[h:] = n
    partition(n, nb.start, nb.j, wb.start, work.part, work.xstart, work.xpair, work.dlist, work.dstart)


# A block runs without Python's lock (nogil): a block can last minutes on a loaded machine, and
# the worker process's other threads (a Dask worker's heartbeat) must go on meanwhile, or the
# scheduler takes the silent worker for dead and restarts it, losing its work.
@njit(parallel=True, nogil=True, cache=True)
def _run_threads(nthr, disks, walls, nb, wb, work, prm, iprm, out, props, dash, roll, levels):
    # prepare here, not in a call of its own: each call costs the dispatch of every array
    prepare(disks, nb, wb, work, prm)
    ok = np.zeros(nthr, dtype=np.int64)
    for t in prange(nthr):
        if start_handshake(work.sync, nthr):
            ok[t] = 1
            _worker(t, nthr, disks, walls, nb, wb, work, prm, iprm, out, props, dash, roll, levels)
    return ok.sum() == nthr


@njit(nogil=True, cache=True)
def step_block_serial(disks, walls, nb, wb, work, prm, iprm, out, props, dash, roll, levels):
    prepare(disks, nb, wb, work, prm)
    _worker(0, 1, disks, walls, nb, wb, work, prm, iprm, out, props, dash, roll, levels)
    out[THREADS_USED] = 1


def rolling_active(disk_mu_r: np.ndarray) -> bool:
    """Whether any contact can carry a rolling moment: a contact takes the smaller ``mu_r``
    of its bodies, so without a disk above 0 there is none (and the kernel skips the law)."""
    return bool(disk_mu_r.size and disk_mu_r.max() > 0.0)


def step_block(rec: KernelRecords, prm, iprm, out) -> None:
    """Advance up to ``iprm[NSTEPS]`` steps on ``iprm[THREADS]`` threads (see module doc).

    ``rec`` holds the arrays (:func:`poro2d.dem.records.kernel_records`).
    """
    disks, walls, nb, wb, work = rec.disks, rec.walls, rec.nb, rec.wb, rec.work
    nthr = int(min(iprm[THREADS], work.part.shape[0] - 1))
    props = BodyProps(disks.kn, disks.ks, disks.mu) if iprm[MODE] == PER_BODY else None
    dash = float(prm[BETA]) if prm[BETA] > 0.0 else None
    roll = RollingProps(disks.mu_r, walls.mu_r) if rolling_active(disks.mu_r) else None
    levels = rec.levels  # None: the one cell grid
    if nthr <= 1:
        step_block_serial(disks, walls, nb, wb, work, prm, iprm, out, props, dash, roll, levels)
        return
    work.sync[:] = 0
    if _run_threads(nthr, disks, walls, nb, wb, work, prm, iprm, out, props, dash, roll, levels):
        out[THREADS_USED] = nthr
    else:  # the threading layer ran the workers one after the other: go on alone
        work.sync[:] = 0
        _worker(0, 1, disks, walls, nb, wb, work, prm, iprm, out, props, dash, roll, levels)
        out[THREADS_USED] = 1
