"""Measurements on a simulation: contacts, porosity, coordination, energy, stress."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from poro2d.errors import InputError


@dataclass
class ContactSet:
    """Touching contacts with their force vectors (the force on body ``i``).

    ``kind`` is 0 for disk-disk (``j`` a disk index) and 1 for disk-wall (``j`` a wall
    index). ``point`` is the contact point, ``branch`` the vector from centre i to
    centre j (or to the contact point, twice the lever, for walls), ``fn``/``fs`` the
    normal and shear force magnitudes (N), ``force`` the vector on ``i`` (N).
    """

    i: np.ndarray
    j: np.ndarray
    kind: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    fn: np.ndarray
    fs: np.ndarray
    force: np.ndarray
    branch: np.ndarray

    def __len__(self) -> int:
        return int(self.i.shape[0])

    @property
    def magnitude(self) -> np.ndarray:
        return np.hypot(self.fn, self.fs)


def contact_set(sim) -> ContactSet:
    p = sim.particles
    pos, r = p.pos, p.radius
    nb, wb = sim.pairs, sim.wall_pairs
    sel = nb.touching()
    i1 = nb.rows()[sel]
    j1 = nb.other[sel]
    nrm1 = np.column_stack([nb.nx[sel], nb.ny[sel]])
    ov1 = nb.ov[sel]
    pt1 = pos[i1] + nrm1 * (r[i1] - 0.5 * ov1)[:, None]
    br1 = pos[j1] - pos[i1]
    fn1, fs1 = nb.fn[sel], nb.fs[sel]

    wsel = wb.touching()
    i2 = wb.rows()[wsel]
    j2 = wb.other[wsel]
    nrm2 = np.column_stack([wb.nx[wsel], wb.ny[wsel]])
    ov2 = wb.ov[wsel]
    pt2 = pos[i2] + nrm2 * (r[i2] - 0.5 * ov2)[:, None]  # the kernel's lever arm, as for disks
    br2 = pt2 - pos[i2]
    fn2, fs2 = wb.fn[wsel], wb.fs[wsel]

    i = np.concatenate([i1, i2])
    nrm = np.vstack([nrm1, nrm2])
    fn = np.concatenate([fn1, fn2])
    fs = np.concatenate([fs1, fs2])
    tang = np.column_stack([-nrm[:, 1], nrm[:, 0]])
    force = -fn[:, None] * nrm + fs[:, None] * tang
    return ContactSet(
        i=i,
        j=np.concatenate([j1, j2]),
        kind=np.concatenate([np.zeros(len(i1), np.int64), np.ones(len(i2), np.int64)]),
        point=np.vstack([pt1, pt2]),
        normal=nrm,
        fn=fn,
        fs=fs,
        force=force,
        branch=np.vstack([br1, br2]),
    )


def coordination_number(sim, exclude_rattlers: bool = False) -> float:
    """Mean number of contacts per disk (disk-wall contacts count once, for the disk).

    With ``exclude_rattlers`` disks with fewer than two contacts are left out
    (the mechanical coordination number), repeatedly until none remains.
    """
    c = sim.contacts()
    n = sim.particles.n
    if n == 0:
        return 0.0
    pp = c.kind == 0
    ii, jj = c.i[pp], c.j[pp]
    wi = c.i[~pp]
    if not exclude_rattlers:
        return float((2 * len(ii) + len(wi)) / n)
    alive = np.ones(n, bool)
    while True:
        keep = alive[ii] & alive[jj]
        z = np.bincount(ii[keep], minlength=n) + np.bincount(jj[keep], minlength=n)
        z += np.bincount(wi[alive[wi]], minlength=n)
        drop = alive & (z < 2)
        if not drop.any():
            break
        alive &= ~drop
    m = alive.sum()
    return float(z[alive].sum() / m) if m else 0.0


def kinetic_energy(sim) -> tuple[float, float]:
    """(translational, rotational) kinetic energy with the true masses (J)."""
    p = sim.particles
    m = p.mass
    et = 0.5 * float(np.sum(m * np.sum(p.vel**2, axis=1)))
    er = 0.5 * float(np.sum(p.inertia * p.omega**2))
    return et, er


@njit(cache=True)
def _quadrant_area(r, a, b):
    """Area of the disk of radius r at the origin with X <= a and Y <= b."""
    if a <= -r or b <= -r:
        return 0.0
    a = min(a, r)
    # integrate h(x) = vertical extent of {Y <= b} within the disk, x in [-r, a]
    if b >= r:
        return _half_area_left(r, a) * 2.0
    c = math.sqrt(r * r - b * b)
    # |x| < c: h = b + s(x); |x| >= c: h = 2 s(x) when b >= 0, else 0
    lo = -r
    total = 0.0
    x1 = min(a, -c)
    if x1 > lo and b >= 0.0:
        total += 2.0 * (_s_int(r, x1) - _s_int(r, lo))
    x0 = max(lo, -c)
    x2 = min(a, c)
    if x2 > x0:
        total += b * (x2 - x0) + _s_int(r, x2) - _s_int(r, x0)
    if a > c and b >= 0.0:
        total += 2.0 * (_s_int(r, a) - _s_int(r, c))
    return total


@njit(inline="always", cache=True)
def _s_int(r, x):
    """Antiderivative of sqrt(r^2 - x^2)."""
    x = max(-r, min(r, x))
    return 0.5 * (x * math.sqrt(max(r * r - x * x, 0.0)) + r * r * math.asin(x / r))


@njit(inline="always", cache=True)
def _half_area_left(r, a):
    """Integral of sqrt(r^2 - x^2) from -r to a."""
    return _s_int(r, a) - _s_int(r, -r)


@njit(cache=True)
def disk_rect_areas(pos, radius, x0, y0, x1, y1):
    """Exact area of each disk clipped by the rectangle [x0, x1] x [y0, y1]."""
    n = pos.shape[0]
    out = np.empty(n)
    for i in range(n):
        cx = pos[i, 0]
        cy = pos[i, 1]
        r = radius[i]
        if cx + r <= x0 or cx - r >= x1 or cy + r <= y0 or cy - r >= y1:
            out[i] = 0.0
            continue
        ax0 = x0 - cx
        ax1 = x1 - cx
        ay0 = y0 - cy
        ay1 = y1 - cy
        out[i] = (
            _quadrant_area(r, ax1, ay1)
            - _quadrant_area(r, ax0, ay1)
            - _quadrant_area(r, ax1, ay0)
            + _quadrant_area(r, ax0, ay0)
        )
    return out


def _lens_area(d, r1, r2):
    """Area of the intersection of two circles at centre distance d (vectorised in d, r1)."""
    d = np.asarray(d, float)
    r1 = np.asarray(r1, float)
    out = np.zeros(np.broadcast(d, r1).shape)
    full = d <= np.abs(r2 - r1)
    out[full] = np.pi * np.minimum(r1, r2)[full] ** 2
    part = (~full) & (d < r1 + r2)
    dd, a = d[part], r1[part]
    c1 = np.clip((dd**2 + a**2 - r2**2) / (2 * dd * a), -1, 1)
    c2 = np.clip((dd**2 + r2**2 - a**2) / (2 * dd * r2), -1, 1)
    out[part] = (
        a**2 * np.arccos(c1)
        + r2**2 * np.arccos(c2)
        - 0.5 * np.sqrt(np.maximum((-dd + a + r2) * (dd + a - r2) * (dd - a + r2) * (dd + a + r2), 0))
    )
    return out


def porosity_rect(pos: np.ndarray, radius: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> float:
    """Porosity of a rectangle: 1 - (disk area inside it) / (its area). Disks are clipped exactly."""
    if not (x1 > x0 and y1 > y0):
        raise InputError("rectangle", (x0, y0, x1, y1), "x1 > x0 and y1 > y0")
    solid = float(np.sum(disk_rect_areas(np.ascontiguousarray(pos), radius, x0, y0, x1, y1)))
    return 1.0 - solid / ((x1 - x0) * (y1 - y0))


def porosity_circle(pos: np.ndarray, radius: np.ndarray, cx: float, cy: float, R: float) -> float:
    """Porosity of a circular region of radius R; disks clipped exactly (lens areas)."""
    if not R > 0:
        raise InputError("circle radius", R, "(0, inf) m")
    d = np.hypot(pos[:, 0] - cx, pos[:, 1] - cy)
    solid = float(np.sum(_lens_area(d, radius, R)))
    return 1.0 - solid / (np.pi * R * R)


def average_stress(sim, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """Average stress tensor (Pa, tension positive) of the disks centred in a rectangle.

    sigma_ab = (1/V) sum over those disks and their contacts of f_a (x_c - x_p)_b,
    with f the force on the disk at contact point x_c and V = rectangle area x
    thickness (Love-Weber). Compression is negative, as in continuum mechanics.
    """
    c = sim.contacts()
    p = sim.particles
    pos = p.pos
    inside = (pos[:, 0] >= x0) & (pos[:, 0] <= x1) & (pos[:, 1] >= y0) & (pos[:, 1] <= y1)
    s = np.zeros((2, 2))
    # side i of every contact
    m = inside[c.i]
    arm = c.point[m] - pos[c.i[m]]
    s += arm.T @ c.force[m]
    # side j of disk-disk contacts (force -f)
    pp = c.kind == 0
    mj = pp & inside[np.where(pp, c.j, 0)]
    armj = c.point[mj] - pos[c.j[mj]]
    s += armj.T @ (-c.force[mj])
    vol = (x1 - x0) * (y1 - y0) * p.thickness
    return s.T / vol
