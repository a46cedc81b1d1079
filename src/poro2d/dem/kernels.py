"""The compiled step loop: every step between two Python-side events in one call.

One step, in order (the PFC cycle):

1. rebuild the neighbour lists if flagged (a disk or wall moved more than skin / 2);
2. disk-disk contact forces (contact law, history update) per pair;
3. disk-wall contact forces per pair;
4. gather: each disk sums gravity and its contact forces (the unbalanced force);
5. local (Cundall) damping and leapfrog integration of the disks;
6. wall resultants, servo walls set their speed from the force error; walls move;
7. flag a rebuild when needed; every ``check_every`` steps test the stop condition.

On several threads, 2-3 form one ``prange`` loop and 4-5 another (two thread wake-ups
per step); each iteration writes only its own slots. On one thread, 2-5 are fused: each
pair adds its force to both disks as it is computed, summed in the same order as the
gather (partners j < i, own row, walls). Results do not depend on the number of threads,
bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from poro2d.dem.contact_law import PER_BODY, dashpot, linear_force, segment_closest, series
from poro2d.dem.neighbors import build_pairs, build_reverse, build_wall_pairs
from poro2d.dem.state import FREE, WALL_SERVO

# float parameters (prm)
DT, GX, GY, DAMP, SKIN, BETA, KN_PP, KS_PP, MU_PP, KN_PW, KS_PW, MU_PW, RATIO_TARGET, TIME = range(14)
N_PRM = 14
# integer parameters (iprm)
MODE, NSTEPS, CHECK_EVERY, NEED_BUILD, SERIAL = range(5)
N_IPRM = 5
# outputs (out)
STATUS, STEPS_DONE, MAX_RATIO, MEAN_RATIO, NEED_PP, NEED_PW, REBUILDS = range(7)
N_OUT = 7
# status codes
RUNNING, CONVERGED, OVERFLOW, UNSTABLE = 0, 1, 2, 3


@njit(cache=True)
def unbalanced_ratios(force, pmode, nb_start, nb_fn, nb_fs, nb_ov, wb_start, wb_fn, wb_fs, wb_ov):
    """(max, mean) unbalanced-force ratios.

    max: largest unbalanced force on a free disk / largest contact force (PFC's
    maximum ratio); mean: mean unbalanced force / mean contact force. ``inf`` when
    nothing touches.
    """
    n = force.shape[0]
    fmax = 0.0
    fsum = 0.0
    nfree = 0
    for i in range(n):
        if pmode[i] == FREE:
            f = math.sqrt(force[i, 0] ** 2 + force[i, 1] ** 2)
            fsum += f
            nfree += 1
            if f > fmax:
                fmax = f
    cmax = 0.0
    csum = 0.0
    nc = 0
    for p in range(nb_start[n]):
        if nb_ov[p] > 0.0:
            f = math.sqrt(nb_fn[p] ** 2 + nb_fs[p] ** 2)
            csum += f
            nc += 1
            if f > cmax:
                cmax = f
    for p in range(wb_start[n]):
        if wb_ov[p] > 0.0:
            f = math.sqrt(wb_fn[p] ** 2 + wb_fs[p] ** 2)
            csum += f
            nc += 1
            if f > cmax:
                cmax = f
    if nc == 0 or cmax <= 0.0 or nfree == 0:
        if nfree == 0:
            return 0.0, 0.0
        return np.inf, np.inf
    return fmax / cmax, (fsum / nfree) / (csum / nc)


@njit(inline="always", cache=True)
def _pair_force(
    i, j, p, pos, vel, omega, radius, mass, pkn, pks, pmu, per_body, prm, beta, dt,
    nb_fs, nb_fn, nb_ov, nb_nx, nb_ny,
):  # fmt: skip
    """Contact law of disk pair slot p (i < j); stores its state, returns True if touching."""
    dx = pos[j, 0] - pos[i, 0]
    dy = pos[j, 1] - pos[i, 1]
    d = math.sqrt(dx * dx + dy * dy)
    ov = radius[i] + radius[j] - d
    nb_ov[p] = ov
    if ov <= 0.0:
        nb_fn[p] = 0.0
        nb_fs[p] = 0.0  # contact lost: history ends
        return False
    if d > 0.0:
        inv = 1.0 / d
        nx = dx * inv
        ny = dy * inv
    else:
        nx = 1.0
        ny = 0.0
    tx = -ny
    ty = nx
    dvx = vel[j, 0] - vel[i, 0]
    dvy = vel[j, 1] - vel[i, 1]
    vn = -(dvx * nx + dvy * ny)
    vt = dvx * tx + dvy * ty - (radius[i] - 0.5 * ov) * omega[i] - (radius[j] - 0.5 * ov) * omega[j]
    if per_body:
        kn = series(pkn[i], pkn[j])
        ks = series(pks[i], pks[j])
        mu = min(pmu[i], pmu[j])
    else:
        kn = prm[KN_PP]
        ks = prm[KS_PP]
        mu = prm[MU_PP]
    cn = dashpot(beta, kn, mass[i] * mass[j] / (mass[i] + mass[j])) if beta > 0.0 else 0.0
    fn, fs, _sl = linear_force(ov, vn, vt, nb_fs[p], kn, ks, mu, cn, dt)
    nb_fn[p] = fn
    nb_fs[p] = fs
    nb_nx[p] = nx
    nb_ny[p] = ny
    return True


@njit(inline="always", cache=True)
def _wall_force(
    i, w, p, pos, vel, omega, radius, mass, pkn, pks, pmu, wp0, wp1, wvel, wkn, wks, wmu, per_body,
    prm, beta, dt, wb_fs, wb_fn, wb_ov, wb_nx, wb_ny,
):  # fmt: skip
    """Contact law of disk-wall slot p; stores its state, returns True if touching."""
    cx, cy = segment_closest(pos[i, 0], pos[i, 1], wp0[w, 0], wp0[w, 1], wp1[w, 0], wp1[w, 1])
    dx = cx - pos[i, 0]
    dy = cy - pos[i, 1]
    d = math.sqrt(dx * dx + dy * dy)
    ov = radius[i] - d
    wb_ov[p] = ov
    if ov <= 0.0:
        wb_fn[p] = 0.0
        wb_fs[p] = 0.0
        return False
    if d > 0.0:
        nx = dx / d
        ny = dy / d
    else:  # centre on the wall line: push along the wall's normal
        sx = wp1[w, 0] - wp0[w, 0]
        sy = wp1[w, 1] - wp0[w, 1]
        sl = math.sqrt(sx * sx + sy * sy)
        nx = sy / sl
        ny = -sx / sl
    tx = -ny
    ty = nx
    dvx = wvel[w, 0] - vel[i, 0]
    dvy = wvel[w, 1] - vel[i, 1]
    vn = -(dvx * nx + dvy * ny)
    vt = dvx * tx + dvy * ty - (radius[i] - 0.5 * ov) * omega[i]
    if per_body:
        kn = series(pkn[i], wkn[w])
        ks = series(pks[i], wks[w])
        mu = min(pmu[i], wmu[w])
    else:
        kn = prm[KN_PW]
        ks = prm[KS_PW]
        mu = prm[MU_PW]
    cn = dashpot(beta, kn, mass[i]) if beta > 0.0 else 0.0
    fn, fs, _sl = linear_force(ov, vn, vt, wb_fs[p], kn, ks, mu, cn, dt)
    wb_fn[p] = fn
    wb_fs[p] = fs
    wb_nx[p] = nx
    wb_ny[p] = ny
    return True


@njit(inline="always", cache=True)
def _advance(i, pos, vel, theta, omega, force, moment, inv_mass, inv_inertia, pmode, damp, dt, pos_build):
    """Local damping and leapfrog update of disk i; returns its squared drift since the last build."""
    if pmode[i] == FREE:
        fx = force[i, 0]
        fy = force[i, 1]
        mz = moment[i]
        if damp > 0.0:
            fx -= damp * abs(fx) * np.sign(vel[i, 0])
            fy -= damp * abs(fy) * np.sign(vel[i, 1])
            mz -= damp * abs(mz) * np.sign(omega[i])
        vel[i, 0] += fx * inv_mass[i] * dt
        vel[i, 1] += fy * inv_mass[i] * dt
        omega[i] += mz * inv_inertia[i] * dt
    pos[i, 0] += vel[i, 0] * dt
    pos[i, 1] += vel[i, 1] * dt
    theta[i] += omega[i] * dt
    ddx = pos[i, 0] - pos_build[i, 0]
    ddy = pos[i, 1] - pos_build[i, 1]
    return ddx * ddx + ddy * ddy


@njit(parallel=True, cache=True)
def run_steps(
    pos, vel, theta, omega, force, moment, radius, mass, inv_mass, inv_inertia, pmode, pkn, pks, pmu,
    wp0, wp1, wvel, wkn, wks, wmu, wmode, wdir, wservo, wforce, wstat,
    nb_start, nb_j, nb_fs, nb_fn, nb_ov, nb_nx, nb_ny, rev_start, rev_p, new_start, new_j, new_fs,
    wb_start, wb_w, wb_fs, wb_fn, wb_ov, wb_nx, wb_ny, wnew_start, wnew_w, wnew_fs,
    pos_build, wall_build, prm, iprm, out,
):  # fmt: skip
    n = pos.shape[0]
    nw = wp0.shape[0]
    dt = prm[DT]
    gx = prm[GX]
    gy = prm[GY]
    damp = prm[DAMP]
    skin = prm[SKIN]
    beta = prm[BETA]
    per_body = iprm[MODE] == PER_BODY
    nsteps = iprm[NSTEPS]
    check_every = iprm[CHECK_EVERY]
    target = prm[RATIO_TARGET]
    lim2 = (0.5 * skin) ** 2
    out[STATUS] = RUNNING
    drift = np.empty(n)  # squared drift of each disk since the last build (parallel path)
    steps = 0
    rebuilds = 0
    for _step in range(nsteps):
        # 1. neighbour lists
        if iprm[NEED_BUILD] != 0:
            got = build_pairs(pos, radius, skin, nb_start, nb_j, nb_fs, new_start, new_j, new_fs)
            if got < 0:
                out[NEED_PP] = -got
                out[STATUS] = OVERFLOW
                break
            got = build_wall_pairs(
                pos, radius, skin, wp0, wp1, wb_start, wb_w, wb_fs, wnew_start, wnew_w, wnew_fs
            )
            if got < 0:
                out[NEED_PW] = -got
                out[STATUS] = OVERFLOW
                break
            build_reverse(n, nb_start, nb_j, rev_start, rev_p)
            pos_build[:, :] = pos
            wall_build[:, :] = wp0
            iprm[NEED_BUILD] = 0
            rebuilds += 1

        if iprm[SERIAL] != 0:
            # 2-4 fused for one thread: each pair adds its force to both disks as it is
            # computed, in the same order as the gather below (partners j < i, own row,
            # walls), so one and two threads give the same numbers bit for bit.
            for i in range(n):
                force[i, 0] = mass[i] * gx
                force[i, 1] = mass[i] * gy
                moment[i] = 0.0
            for i in range(n):
                for p in range(nb_start[i], nb_start[i + 1]):
                    j = nb_j[p]
                    if _pair_force(
                        i, j, p, pos, vel, omega, radius, mass, pkn, pks, pmu, per_body, prm, beta, dt,
                        nb_fs, nb_fn, nb_ov, nb_nx, nb_ny,
                    ):  # fmt: skip
                        fn = nb_fn[p]
                        fs = nb_fs[p]
                        fxp = -fn * nb_nx[p] - fs * nb_ny[p]
                        fyp = -fn * nb_ny[p] + fs * nb_nx[p]
                        force[i, 0] += fxp
                        force[i, 1] += fyp
                        moment[i] += (radius[i] - 0.5 * nb_ov[p]) * fs
                        force[j, 0] -= fxp
                        force[j, 1] -= fyp
                        moment[j] += (radius[j] - 0.5 * nb_ov[p]) * fs
            for i in range(n):
                for p in range(wb_start[i], wb_start[i + 1]):
                    if _wall_force(
                        i, wb_w[p], p, pos, vel, omega, radius, mass, pkn, pks, pmu, wp0, wp1, wvel, wkn,
                        wks, wmu, per_body, prm, beta, dt, wb_fs, wb_fn, wb_ov, wb_nx, wb_ny,
                    ):  # fmt: skip
                        fn = wb_fn[p]
                        fs = wb_fs[p]
                        force[i, 0] += -fn * wb_nx[p] - fs * wb_ny[p]
                        force[i, 1] += -fn * wb_ny[p] + fs * wb_nx[p]
                        moment[i] += (radius[i] - 0.5 * wb_ov[p]) * fs
            # 5. damping and leapfrog integration, with the drift since the last build
            dmax = 0.0
            for i in range(n):
                d2 = _advance(
                    i,
                    pos,
                    vel,
                    theta,
                    omega,
                    force,
                    moment,
                    inv_mass,
                    inv_inertia,
                    pmode,
                    damp,
                    dt,
                    pos_build,
                )
                if d2 > dmax:
                    dmax = d2
        else:
            # 2-3. contact forces per pair, disk-disk then disk-wall rows of each disk
            for i in prange(n):
                for p in range(nb_start[i], nb_start[i + 1]):
                    _pair_force(
                        i, nb_j[p], p, pos, vel, omega, radius, mass, pkn, pks, pmu, per_body, prm, beta, dt,
                        nb_fs, nb_fn, nb_ov, nb_nx, nb_ny,
                    )  # fmt: skip
                for p in range(wb_start[i], wb_start[i + 1]):
                    _wall_force(
                        i, wb_w[p], p, pos, vel, omega, radius, mass, pkn, pks, pmu, wp0, wp1, wvel, wkn,
                        wks, wmu, per_body, prm, beta, dt, wb_fs, wb_fn, wb_ov, wb_nx, wb_ny,
                    )  # fmt: skip
            # 4-5. gather (partners j < i, own row, walls), then damping and leapfrog of disk i:
            # the gather reads only pair data, so moving disk i cannot disturb another's sum
            for i in prange(n):
                fx = mass[i] * gx
                fy = mass[i] * gy
                mz = 0.0
                for q in range(rev_start[i], rev_start[i + 1]):
                    p = rev_p[q]
                    if nb_ov[p] > 0.0:
                        fn = nb_fn[p]
                        fs = nb_fs[p]
                        fx -= -fn * nb_nx[p] - fs * nb_ny[p]
                        fy -= -fn * nb_ny[p] + fs * nb_nx[p]
                        mz += (radius[i] - 0.5 * nb_ov[p]) * fs
                for p in range(nb_start[i], nb_start[i + 1]):
                    if nb_ov[p] > 0.0:
                        fn = nb_fn[p]
                        fs = nb_fs[p]
                        fx += -fn * nb_nx[p] - fs * nb_ny[p]
                        fy += -fn * nb_ny[p] + fs * nb_nx[p]
                        mz += (radius[i] - 0.5 * nb_ov[p]) * fs
                for p in range(wb_start[i], wb_start[i + 1]):
                    if wb_ov[p] > 0.0:
                        fn = wb_fn[p]
                        fs = wb_fs[p]
                        fx += -fn * wb_nx[p] - fs * wb_ny[p]
                        fy += -fn * wb_ny[p] + fs * wb_nx[p]
                        mz += (radius[i] - 0.5 * wb_ov[p]) * fs
                force[i, 0] = fx
                force[i, 1] = fy
                moment[i] = mz
                drift[i] = _advance(
                    i,
                    pos,
                    vel,
                    theta,
                    omega,
                    force,
                    moment,
                    inv_mass,
                    inv_inertia,
                    pmode,
                    damp,
                    dt,
                    pos_build,
                )
            dmax = 0.0
            for i in range(n):
                if drift[i] > dmax:
                    dmax = drift[i]

        # 6. wall resultants (fixed order) and servo speeds; walls move
        for w in range(nw):
            wforce[w, 0] = 0.0
            wforce[w, 1] = 0.0
            wstat[w, 0] = 0.0
            wstat[w, 1] = 0.0
        for i in range(n):
            for p in range(wb_start[i], wb_start[i + 1]):
                if wb_ov[p] > 0.0:
                    w = wb_w[p]
                    fn = wb_fn[p]
                    fs = wb_fs[p]
                    wforce[w, 0] -= -fn * wb_nx[p] - fs * wb_ny[p]
                    wforce[w, 1] -= -fn * wb_ny[p] + fs * wb_nx[p]
                    wstat[w, 0] += 1.0
                    wstat[w, 1] += series(pkn[i], wkn[w]) if per_body else prm[KN_PW]
        for w in range(nw):
            if wmode[w] == WALL_SERVO:
                # compressive force along the servo direction; v = gain * error / (k dt)
                fc = -(wforce[w, 0] * wdir[w, 0] + wforce[w, 1] * wdir[w, 1])
                err = wservo[w, 0] - fc
                vmax = wservo[w, 2]
                if wstat[w, 0] > 0.0:
                    v = wservo[w, 1] * err / (wstat[w, 1] * dt)
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
        prm[TIME] += dt
        steps += 1

        # 7. rebuild flag and stop check
        for w in range(nw):
            ddx = wp0[w, 0] - wall_build[w, 0]
            ddy = wp0[w, 1] - wall_build[w, 1]
            d2 = ddx * ddx + ddy * ddy
            if d2 > dmax:
                dmax = d2
        if dmax > lim2:
            iprm[NEED_BUILD] = 1
        if check_every > 0 and steps % check_every == 0:
            if not math.isfinite(dmax):
                out[STATUS] = UNSTABLE
                break
            if target > 0.0:
                rmax, rmean = unbalanced_ratios(
                    force, pmode, nb_start, nb_fn, nb_fs, nb_ov, wb_start, wb_fn, wb_fs, wb_ov
                )
                out[MAX_RATIO] = rmax
                out[MEAN_RATIO] = rmean
                if rmax < target:
                    out[STATUS] = CONVERGED
                    break
    out[STEPS_DONE] = steps
    out[REBUILDS] = rebuilds
    if out[STATUS] == RUNNING and not math.isfinite(pos.sum()):
        out[STATUS] = UNSTABLE
