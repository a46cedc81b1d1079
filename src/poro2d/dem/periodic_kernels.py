"""Numba kernels of the periodic shear cell (:mod:`poro2d.dem.periodic`).

The cell is ``L`` wide and ``H`` tall, periodic in x; across y its images are offset by
``delta`` along x (Lees-Edwards): the image of a disk at ``(x, y)`` above the cell sits at
``(x + delta, y + H)``. The cell deforms homogeneously at the rates ``gamma_dot`` (simple
shear, ``delta`` grows at ``gamma_dot H``) and ``e_xx``, ``e_yy`` (its width and height).

Disks carry velocities *relative to that affine flow* (the peculiar velocities ``v'``); the
flow adds ``gamma_dot y`` to ``x`` and the cell's stretching rescales positions. With the
SLLOD term ``-gamma_dot v'_y`` in the x equation, ``v' + gamma_dot y e_x`` obeys Newton's law
exactly as an absolute velocity would, so the choice is a bookkeeping one; it lets the cell
start from the affine profile and makes the Lees-Edwards rule (a disk leaving at the top
re-enters at the bottom with the same peculiar velocity) need no velocity jump.

One contact uses the engine's contact law (:mod:`poro2d.dem.contact_law`): the same
``contact_force``, ``rolling_moment``, ``dashpot``, with the relative velocity at the contact
made of the peculiar velocities plus the affine velocity difference across the branch vector.
A contact's branch vector goes to the partner's image: ``x_j - x_i + sx L + sy delta``,
``y_j - y_i + sy H`` with the integer shifts ``sx, sy`` chosen when the pair list is built.

The pair list is a Verlet list with a skin, built from a cell grid whose rows wrap with the
Lees-Edwards offset. It is rebuilt when the largest non-affine displacement since the last
build (twice it, for two disks) plus the affine change of a branch vector of the largest
reach could have closed the skin; positions are wrapped into the cell then, and the contact
history (shear force, rolling moment) carried over by pair.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from poro2d.dem.contact_law import contact_force, dashpot, reduced_mass, rolling_moment, rolling_radius

# the cell's state, ``cell``
L_, H_, DELTA, GAMMA, TIME, EXX, EYY, L_BUILD, H_BUILD, GAMMA_BUILD = range(10)
CELL_SIZE = 10
# the parameters, ``prm``
DT, KN, KS, MU, MU_R, BETA, GAMMA_DOT, PRESSURE, THICKNESS, GAIN, GAS_RATE, MAX_RATE, SKIN, MODE = range(14)
PRM_SIZE = 14
# what a block sums, ``out``: stresses (tension positive, Pa) summed over its steps
SXX, SXY, SYX, SYY, KXX, KXY, KYY, STEPS, CONTACTS, REBUILDS, SOLID, PRESSURE_ERR = range(12)
OUT_SIZE = 12
# the cell's modes
FIXED = 0  # no barostat (the cell's rates as set)
COMPRESS = 1  # width and height servoed to the pressure, no shear
SHEAR = 2  # height servoed to the pressure, width fixed, sheared at gamma_dot
#: the pressure below which a compressing cell counts as a gas (no force network yet), as a
#: fraction of the target: it then shrinks at the gas rate rather than by the barostat's law
GAS_FRACTION = 0.1


@njit(cache=True)
def wrap_into_cell(pos, cell):
    """Positions into ``[0, L) x [0, H)``; a disk crossing y takes the offset in x with it."""
    L = cell[L_]
    H = cell[H_]
    delta = cell[DELTA]
    for i in range(pos.shape[0]):
        ky = math.floor(pos[i, 1] / H)
        pos[i, 1] -= ky * H
        pos[i, 0] -= ky * delta
        pos[i, 0] -= math.floor(pos[i, 0] / L) * L
        # rounding may leave a coordinate exactly on the far edge
        if pos[i, 0] >= L:
            pos[i, 0] -= L
        if pos[i, 1] >= H:
            pos[i, 1] -= H


@njit(inline="always", cache=True)
def nearest_image(dx, dy, L, H, delta):
    """The shifts (sx, sy) and the branch vector to the image of j nearest to i."""
    sy = -math.floor(dy / H + 0.5)
    dy += sy * H
    dx += sy * delta
    sx = -math.floor(dx / L + 0.5)
    dx += sx * L
    return sx, sy, dx, dy


@njit(cache=True)
def _scan_disk(i, pos, radius, cell, skin, grid, head, nxt, fill, pj, psx, psy, k):
    """The partners j > i within reach of disk i, from the 3 x 3 cells around it (rows wrap
    with the offset); written from row k when ``fill``. Returns the next free row."""
    L = cell[L_]
    H = cell[H_]
    delta = cell[DELTA]
    nx, ny = grid[0], grid[1]
    cw = L / nx
    ch = H / ny
    xi = pos[i, 0]
    yi = pos[i, 1]
    row = min(int(yi / ch), ny - 1)
    for dr in range(-1, 2):
        r = row + dr
        xs = xi  # where the partners of this row sit, in the row's own x
        if r >= ny:
            r -= ny
            xs = xi - delta
        elif r < 0:
            r += ny
            xs = xi + delta
        xs -= math.floor(xs / L) * L
        col = min(int(xs / cw), nx - 1)
        for dc in range(-1, 2):
            c = (col + dc) % nx
            j = head[r * nx + c]
            while j >= 0:
                if j > i:
                    k = _keep_pair(
                        i, j, pos[j, 0] - xi, pos[j, 1] - yi, radius, skin, L, H, delta, fill, pj, psx, psy, k
                    )
                j = nxt[j]
    return k


@njit(cache=True)
def _scan_all(i, pos, radius, cell, skin, fill, pj, psx, psy, k):
    """The partners j > i within reach of disk i by trying every disk (cells under 3 x 3 bins)."""
    L, H, delta = cell[L_], cell[H_], cell[DELTA]
    for j in range(i + 1, pos.shape[0]):
        dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
        k = _keep_pair(i, j, dx, dy, radius, skin, L, H, delta, fill, pj, psx, psy, k)
    return k


@njit(inline="always", cache=True)
def _keep_pair(i, j, dx, dy, radius, skin, L, H, delta, fill, pj, psx, psy, k):
    """Count (and write at row k when ``fill``) the pair i, j when j's nearest image lies within
    reach of i (``dx, dy``: j's centre minus i's); returns the next free row."""
    sx, sy, dx, dy = nearest_image(dx, dy, L, H, delta)
    reach = radius[i] + radius[j] + skin
    if dx * dx + dy * dy < reach * reach:
        if fill:
            pj[k] = j
            psx[k] = sx
            psy[k] = sy
        return k + 1
    return k


@njit(cache=True)
def _list_pairs(pos, radius, cell, skin, fill, start, pj, psx, psy):
    """One pass over the disks: counts the pairs, or writes them (rows ordered by i)."""
    n = pos.shape[0]
    reach = 2.0 * radius.max() + skin if n else 1.0
    nx = int(cell[L_] / reach)
    ny = int(cell[H_] / reach)
    grid = np.array([max(nx, 1), max(ny, 1)])
    binned = nx >= 3 and ny >= 3
    head = np.full(grid[0] * grid[1], -1, dtype=np.int64)
    nxt = np.full(n, -1, dtype=np.int64)
    if binned:
        cw = cell[L_] / nx
        ch = cell[H_] / ny
        for i in range(n):
            b = min(int(pos[i, 1] / ch), ny - 1) * nx + min(int(pos[i, 0] / cw), nx - 1)
            nxt[i] = head[b]
            head[b] = i
    k = 0
    for i in range(n):
        if fill:
            start[i] = k
        if binned:
            k = _scan_disk(i, pos, radius, cell, skin, grid, head, nxt, fill, pj, psx, psy, k)
        else:
            k = _scan_all(i, pos, radius, cell, skin, fill, pj, psx, psy, k)
    if fill:
        start[n] = k
    return k


@njit(cache=True)
def build_pairs(pos, radius, cell, skin, old_start, old_j, old_fs, old_mr):
    """The pair list of the wrapped positions, with the history of pairs that were listed before.

    Returns (start, pj, sx, sy, fs, mr): rows of disk i are ``start[i]:start[i + 1]``. A cell
    at least two reaches wide and tall holds one image of a pair within reach, so a pair is
    named by (i, j) alone and its history follows it whatever shift it gets.
    """
    n = pos.shape[0]
    none_i = np.zeros(0, dtype=np.int64)
    none_f = np.zeros(0)
    count = _list_pairs(pos, radius, cell, skin, False, none_i, none_i, none_f, none_f)
    start = np.zeros(n + 1, dtype=np.int64)
    pj = np.empty(count, dtype=np.int64)
    psx = np.empty(count)
    psy = np.empty(count)
    _list_pairs(pos, radius, cell, skin, True, start, pj, psx, psy)
    fs = np.zeros(count)
    mr = np.zeros(count)
    for i in range(n):
        for p in range(start[i], start[i + 1]):
            for q in range(old_start[i], old_start[i + 1]):
                if old_j[q] == pj[p]:
                    fs[p] = old_fs[q]
                    mr[p] = old_mr[q]
                    break
    return start, pj, psx, psy, fs, mr


@njit(cache=True)
def pair_owners(start):
    """The disk i of every row of a pair list."""
    n = start.shape[0] - 1
    pi = np.empty(start[n], dtype=np.int64)
    for i in range(n):
        for p in range(start[i], start[i + 1]):
            pi[p] = i
    return pi


@njit(cache=True)
def contact_forces(
    pos, vel, omega, radius, mass, pi, pj, psx, psy, pfs, pmr, pfn, force, moment, cell, prm, out
):
    """Forces and moments of every pair for one step; their stress (tension positive) into ``out``.

    ``out[SXX..SYY]`` gain ``-(1/V) sum f_a l_b`` with ``f`` the force on j and ``l`` the branch
    vector from i to j's image (Love-Weber; V = L H t). Returns the touching contacts and this
    step's sigma_xx and sigma_yy.
    """
    L, H, delta, exx, eyy = cell[L_], cell[H_], cell[DELTA], cell[EXX], cell[EYY]
    dt, gdot = prm[DT], prm[GAMMA_DOT]
    kn, ks, mu, mu_r, beta = prm[KN], prm[KS], prm[MU], prm[MU_R], prm[BETA]  # the cell's one law
    force[:] = 0.0
    moment[:] = 0.0
    wxx = wxy = wyx = wyy = 0.0  # the contacts' sum of f l, before the volume
    touching = 0
    for p in range(pj.shape[0]):
        i = pi[p]
        j = pj[p]
        dx = pos[j, 0] - pos[i, 0] + psx[p] * L + psy[p] * delta
        dy = pos[j, 1] - pos[i, 1] + psy[p] * H
        d = math.sqrt(dx * dx + dy * dy)
        ov = radius[i] + radius[j] - d
        if ov <= 0.0:
            pfn[p] = 0.0
            pfs[p] = 0.0  # contact lost: its history ends
            pmr[p] = 0.0
            continue
        nx = dx / d
        ny = dy / d
        # j's image moves with the affine flow at its own place: the flow's difference over l
        dvx = vel[j, 0] - vel[i, 0] + gdot * dy + exx * dx
        dvy = vel[j, 1] - vel[i, 1] + eyy * dy
        ai = radius[i] - 0.5 * ov
        aj = radius[j] - 0.5 * ov
        cn = dashpot(beta, kn, reduced_mass(mass[i], mass[j]))
        fn, fs, fx, fy = contact_force(
            ov, nx, ny, dvx, dvy, ai, aj, omega[i], omega[j], pfs[p], kn, ks, mu, cn, dt
        )
        pfn[p] = fn
        pfs[p] = fs
        force[i, 0] += fx  # (fx, fy) on i
        force[i, 1] += fy
        force[j, 0] -= fx
        force[j, 1] -= fy
        mi = ai * fs
        mj = aj * fs
        if mu_r > 0.0:
            reff = rolling_radius(radius[i], radius[j])
            mr = rolling_moment(pmr[p], ks, reff, omega[i] - omega[j], dt, mu_r, fn)
            pmr[p] = mr
            mi += mr
            mj -= mr
        moment[i] += mi
        moment[j] += mj
        # the force on j is (-fx, -fy): sigma = -(1/V) sum f_j l  =  (1/V) sum f_i l
        wxx += fx * dx
        wxy += fx * dy
        wyx += fy * dx
        wyy += fy * dy
        touching += 1
    v = L * H * prm[THICKNESS]
    out[SXX] += wxx / v
    out[SXY] += wxy / v
    out[SYX] += wyx / v
    out[SYY] += wyy / v
    return touching, wxx / v, wyy / v


@njit(cache=True)
def kinetic_stress(vel, mass, cell, prm, out):
    """The kinetic stress ``-(1/V) sum m v'_a v'_b`` of the peculiar velocities into ``out``;
    returns its yy and xx components."""
    kxx = 0.0
    kxy = 0.0
    kyy = 0.0
    for i in range(vel.shape[0]):
        kxx -= mass[i] * vel[i, 0] * vel[i, 0]
        kxy -= mass[i] * vel[i, 0] * vel[i, 1]
        kyy -= mass[i] * vel[i, 1] * vel[i, 1]
    v = cell[L_] * cell[H_] * prm[THICKNESS]
    out[KXX] += kxx / v
    out[KXY] += kxy / v
    out[KYY] += kyy / v
    return kxx / v, kyy / v


@njit(cache=True)
def integrate(pos, vel, omega, theta, inv_mass, inv_inertia, force, moment, drift, cell, prm):
    """Symplectic Euler with the affine flow: returns the largest squared non-affine drift."""
    dt = prm[DT]
    gdot = prm[GAMMA_DOT]
    worst = 0.0
    for i in range(pos.shape[0]):
        vy = vel[i, 1]
        vel[i, 0] += (force[i, 0] * inv_mass[i] - gdot * vy) * dt  # SLLOD: Newton for v' + gdot y e_x
        vel[i, 1] += force[i, 1] * inv_mass[i] * dt
        omega[i] += moment[i] * inv_inertia[i] * dt
        pos[i, 0] += (vel[i, 0] + gdot * pos[i, 1]) * dt
        pos[i, 1] += vel[i, 1] * dt
        theta[i] += omega[i] * dt
        drift[i, 0] += vel[i, 0] * dt
        drift[i, 1] += vel[i, 1] * dt
        worst = max(worst, drift[i, 0] * drift[i, 0] + drift[i, 1] * drift[i, 1])
    return worst


@njit(inline="always", cache=True)
def _clip(x, lim):
    return min(max(x, -lim), lim)


@njit(cache=True)
def barostat(pos, cell, prm, syy, sxx):
    """The cell's stretching rates from this step's stress, and the affine rescaling they make.

    SHEAR: ``e_yy = gain (p_yy - P)`` with ``p_yy = -sigma_yy``; COMPRESS: both directions at
    ``gain (p - P)`` with p the mean pressure, or at the gas rate while p < GAS_FRACTION P.
    Rates are capped at MAX_RATE. Returns |p - P| / P of the servoed stress (0 in FIXED).
    """
    mode = int(prm[MODE])
    if mode == FIXED:
        exx = cell[EXX]
        eyy = cell[EYY]
        err = 0.0
    else:
        target = prm[PRESSURE]
        p = -syy if mode == SHEAR else -0.5 * (sxx + syy)
        rate = prm[GAIN] * (p - target)
        if mode == COMPRESS and p < GAS_FRACTION * target:
            rate = -prm[GAS_RATE]
        rate = _clip(rate, prm[MAX_RATE])
        eyy = rate
        exx = rate if mode == COMPRESS else 0.0
        cell[EXX] = exx
        cell[EYY] = eyy
        err = abs(p - target) / target
    dt = prm[DT]
    fx = 1.0 + exx * dt
    fy = 1.0 + eyy * dt
    if fx != 1.0 or fy != 1.0:
        for i in range(pos.shape[0]):
            pos[i, 0] *= fx
            pos[i, 1] *= fy
        cell[L_] *= fx
        cell[H_] *= fy
        cell[DELTA] *= fx
    return err


@njit(cache=True)
def _needs_build(worst_drift2, cell, prm, reach):
    """Whether any pair could have come within contact since the list was built."""
    affine = abs(cell[GAMMA] - cell[GAMMA_BUILD])
    affine += abs(math.log(cell[L_] / cell[L_BUILD])) + abs(math.log(cell[H_] / cell[H_BUILD]))
    return 2.0 * math.sqrt(worst_drift2) + affine * reach > prm[SKIN]


@njit(cache=True)
def _mark_build(drift, cell):
    drift[:] = 0.0
    cell[L_BUILD] = cell[L_]
    cell[H_BUILD] = cell[H_]
    cell[GAMMA_BUILD] = cell[GAMMA]


@njit(cache=True)
def rebuild(pos, radius, drift, cell, prm, start, pj, pfs, pmr):
    """Wrap the positions and the offset into the cell, and list the pairs anew (history kept)."""
    cell[DELTA] -= math.floor(cell[DELTA] / cell[L_]) * cell[L_]
    wrap_into_cell(pos, cell)
    _mark_build(drift, cell)
    return build_pairs(pos, radius, cell, prm[SKIN], start, pj, pfs, pmr)


@njit(nogil=True, cache=True)
def advance(
    nsteps, pos, vel, omega, theta, radius, mass, inv_mass, inv_inertia, drift, pairs, cell, prm, out
):
    """``nsteps`` steps of the cell in one call; the block's sums go to ``out``.

    ``pairs`` is (start, pj, sx, sy, fs, mr); returns it, rebuilt when the skin was used up.
    """
    start, pj, psx, psy, pfs, pmr = pairs
    pi = pair_owners(start)
    pfn = np.zeros(pj.shape[0])
    n = pos.shape[0]
    force = np.zeros((n, 2))
    moment = np.zeros(n)
    reach = 2.0 * radius.max() + prm[SKIN] if n else 0.0
    solid = 0.0
    for i in range(n):
        solid += math.pi * radius[i] * radius[i]
    dt = prm[DT]
    for _ in range(nsteps):
        touching, sxx, syy = contact_forces(
            pos, vel, omega, radius, mass, pi, pj, psx, psy, pfs, pmr, pfn, force, moment, cell, prm, out
        )
        kxx, kyy = kinetic_stress(vel, mass, cell, prm, out)
        worst = integrate(pos, vel, omega, theta, inv_mass, inv_inertia, force, moment, drift, cell, prm)
        cell[DELTA] += prm[GAMMA_DOT] * cell[H_] * dt
        cell[GAMMA] += prm[GAMMA_DOT] * dt
        cell[TIME] += dt
        out[CONTACTS] += touching
        out[STEPS] += 1.0
        out[SOLID] += solid / (cell[L_] * cell[H_])
        out[PRESSURE_ERR] += barostat(pos, cell, prm, syy + kyy, sxx + kxx)
        if _needs_build(worst, cell, prm, reach):
            start, pj, psx, psy, pfs, pmr = rebuild(pos, radius, drift, cell, prm, start, pj, pfs, pmr)
            pi = pair_owners(start)
            pfn = np.zeros(pj.shape[0])
            out[REBUILDS] += 1.0
    return start, pj, psx, psy, pfs, pmr
