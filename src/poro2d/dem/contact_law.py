"""The linear contact law (Cundall and Strack 1979), as in PFC's linear model: written once here.

As YADE splits it (Ip2 / Law2), in two parts that the walled kernels (:mod:`poro2d.dem.kernels`)
and the periodic cell's (:mod:`poro2d.dem.periodic_kernels`) both call:

* **mixing** (:func:`mix`, :func:`mix_rolling`, :func:`rolling_radius`, :func:`reduced_mass`):
  two bodies' own properties to the parameters of their contact. PFC 4.0's rule: springs in
  series, the smaller friction, the smaller rolling friction. The description the driver and
  the exporters read (:class:`poro2d.dem.model.ContactModel`) names the same rule.
* **the law** (:func:`contact_force`, :func:`rolling_moment`): one touching contact of a disk
  ``i`` and a body ``j`` (another disk or a wall), from its parameters and its history.

One contact:

* unit normal ``n`` from ``i`` towards ``j``, tangent ``t = (-n_y, n_x)``;
* normal force ``Fn = kn * overlap`` (+ an optional normal dashpot), never tensile;
* shear force ``Fs`` updated incrementally, ``Fs += ks * vt * dt`` with ``vt`` the
  tangential velocity of ``j`` relative to ``i`` at the contact point, then capped at
  ``mu * Fn`` (Coulomb slip).

In 2D the shear force is kept as its component along the current tangent, so it
turns with the contact frame by construction; that scalar is the contact's history.
The force on ``i`` is ``-Fn n + Fs t`` and its moment ``a_i * Fs`` with the lever arm
``a_i = r_i - overlap / 2`` (contact point in the middle of the overlap). A wall is a body
that does not turn, with no lever arm.

Rolling resistance (optional; the elastic-plastic spring of Iwashita and Oda 1998, type
A of Ai et al. 2011, PFC's rolling-resistance linear model): a contact also carries a
rolling moment ``Mr``, its second piece of history, updated incrementally from the
relative rotation, ``Mr -= kr (omega_i - omega_j) dt`` (a wall does not turn), with the
rolling stiffness ``kr = ks R^2`` and capped at ``mu_r R Fn``; ``R = ri rj / (ri + rj)``
for two disks, the disk's radius against a wall, ``mu_r`` the smaller of the two bodies'
rolling frictions. ``Mr`` acts on ``i`` and ``-Mr`` on ``j``: a pure couple, so it
changes no force.
"""

from __future__ import annotations

import math

from numba import njit

from poro2d.dem.fma import fma

# contact-model modes
PER_BODY = 0  # PFC 4.0: kn = kA kB / (kA + kB), mu = min(muA, muB)
PER_PAIR_TYPE = 1  # PFC 5 style: one (kn, ks, mu) for disk-disk, one for disk-wall

#: rolling frictions beyond 1 hold a disk against any tilt it meets in a shear band (a disk
#: rolls when the moment arm of its contact force exceeds mu_r R: at 1 the force would have to
#: lean past 45 degrees); larger ones are typos. Every input of a rolling friction (a specimen,
#: a shear test, a strength grid) is held to [0, MAX_ROLLING_FRICTION].
MAX_ROLLING_FRICTION = 1.0


# ------------------------------------------------------------------ mixing (YADE's Ip2)
# Two bodies' own properties to the parameters of their contact. The kernels of the walled
# engine and of the periodic cell, and the driver's constants for bodies all alike, mix here.


@njit(inline="always", cache=True)
def in_series(ka, kb):
    """Two springs in series as one quotient, ``ka kb / (ka + kb)`` (0 when both are 0).

    The time-step bound and the exported files compute it so; the kernels take :func:`series`.
    """
    s = ka + kb
    if s <= 0.0:
        return 0.0
    return ka * kb / s


@njit(inline="always", cache=True)
def series(ka, kb):
    """Two springs in series as the kernels take them: equal springs halved, without a division.

    Half of a spring is exact; the quotient of :func:`in_series` may round it a bit off.
    """
    if ka == kb:
        return 0.5 * ka
    return in_series(ka, kb)


@njit(inline="always", cache=True)
def mix(kn_a, ks_a, mu_a, kn_b, ks_b, mu_b):
    """A contact's (kn, ks, mu) from its two bodies' (PFC 4.0): springs in series, the smaller friction."""
    return series(kn_a, kn_b), series(ks_a, ks_b), min(mu_a, mu_b)


@njit(inline="always", cache=True)
def mix_rolling(mu_r_a, mu_r_b):
    """A contact's rolling friction: the smaller of its bodies'."""
    return min(mu_r_a, mu_r_b)


@njit(inline="always", cache=True)
def rolling_radius(ra, rb):
    """The effective radius ``R = ra rb / (ra + rb)`` of a disk pair (a disk's own against a wall)."""
    return ra * rb / (ra + rb)


@njit(inline="always", cache=True)
def reduced_mass(ma, mb):
    """The mass the normal dashpot of a disk pair damps (a disk's own against a wall)."""
    return ma * mb / (ma + mb)


@njit(inline="always", cache=True)
def dashpot(beta, kn, m_eff):
    """Critical-damping fraction ``beta`` to a normal dashpot coefficient."""
    if beta <= 0.0:
        return 0.0
    return 2.0 * beta * math.sqrt(kn * m_eff)


# ------------------------------------------------------------------ the law (YADE's Law2)


@njit(inline="always", cache=True)
def contact_force(ov, nx, ny, dvx, dvy, ai, aj, wi, wj, fs_old, kn, ks, mu, cn, dt):
    """One touching contact: (fn, fs, fx, fy), (fx, fy) the force on ``i``.

    ov > 0 the overlap; (nx, ny) the unit normal from i towards j; dvx, dvy the velocity of
    j relative to i; ai, aj the lever arms r - ov / 2, wi, wj the spins (a wall: 0 and 0,
    which leaves every number as without them); cn the normal dashpot (0 for none).
    Scalars only: helpers that take arrays cost reference counting in the pair loop.
    """
    vn = -fma(dvx, nx, dvy * ny)  # approach speed, positive when closing
    vt = fma(-aj, wj, fma(-ai, wi, fma(dvy, nx, -(dvx * ny))))
    fn = fma(cn, vn, kn * ov)
    if fn < 0.0:  # the dashpot may not pull the bodies together
        fn = 0.0
    fs = fma(ks * vt, dt, fs_old)
    cap = mu * fn
    # two selects, not a branch: contacts at and below the cap come in no order, and a
    # mispredicted branch per contact costs more. The same numbers as `if fs > cap: cap,
    # elif fs < -cap: -cap`, signed zeros and NaN included, since cap >= 0 (or NaN)
    fs = cap if fs > cap else fs
    fs = -cap if fs < -cap else fs
    fx, fy = contact_components(fn, fs, nx, ny)
    return fn, fs, fx, fy


@njit(inline="always", cache=True)
def contact_components(fn, fs, nx, ny):
    """The force ``-Fn n + Fs t`` on ``i`` of a contact, as (fx, fy); ``t = (-n_y, n_x)``."""
    return fma(-fn, nx, -(fs * ny)), fma(fs, nx, -(fn * ny))


@njit(inline="always", cache=True)
def rolling_moment(m_old, ks, reff, dw, dt, mu_r, fn):
    """Rolling moment on disk ``i`` after it turned at ``dw`` against ``j`` for a step ``dt``.

    The elastic spring ``kr = ks R^2`` resists the rotation; beyond ``mu_r R fn`` it slips.
    """
    kr = ks * reff * reff
    cap = mu_r * reff * fn
    # min / max rather than branches: a packing holds contacts on and below the limit in
    # no order, and a mispredicted branch per contact costs more than both comparisons
    return min(max(m_old - kr * (dw * dt), -cap), cap)


@njit(inline="always", cache=True)
def segment_closest(px, py, ax, ay, bx, by):
    """Closest point to (px, py) on the segment a-b."""
    dx = bx - ax
    dy = by - ay
    L2 = dx * dx + dy * dy
    s = ((px - ax) * dx + (py - ay) * dy) / L2
    if s < 0.0:
        s = 0.0
    elif s > 1.0:
        s = 1.0
    return ax + s * dx, ay + s * dy
