"""The linear contact law (Cundall and Strack 1979), as in PFC's linear model.

One contact between a disk ``i`` and a body ``j`` (another disk or a wall):

* unit normal ``n`` from ``i`` towards ``j``, tangent ``t = (-n_y, n_x)``;
* normal force ``Fn = kn * overlap`` (+ an optional normal dashpot), never tensile;
* shear force ``Fs`` updated incrementally, ``Fs += ks * vt * dt`` with ``vt`` the
  tangential velocity of ``j`` relative to ``i`` at the contact point, then capped at
  ``mu * Fn`` (Coulomb slip).

In 2D the shear force is kept as its component along the current tangent, so it
turns with the contact frame by construction; that scalar is the contact's history.
The force on ``i`` is ``-Fn n + Fs t`` and its moment ``a_i * Fs`` with the lever arm
``a_i = r_i - overlap / 2`` (contact point in the middle of the overlap).

Property combination (PFC 4.0): springs in series, the smaller friction.

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

# contact-model modes
PER_BODY = 0  # PFC 4.0: kn = kA kB / (kA + kB), mu = min(muA, muB)
PER_PAIR_TYPE = 1  # PFC 5 style: one (kn, ks, mu) for disk-disk, one for disk-wall

#: rolling frictions beyond 1 hold a disk against any tilt it meets in a shear band (a disk
#: rolls when the moment arm of its contact force exceeds mu_r R: at 1 the force would have to
#: lean past 45 degrees); larger ones are typos. Every input of a rolling friction (a specimen,
#: a shear test, a strength grid) is held to [0, MAX_ROLLING_FRICTION].
MAX_ROLLING_FRICTION = 1.0


@njit(inline="always", cache=True)
def series(ka, kb):
    """Two springs in series; 0 if either is 0 (equal springs: half, without a division)."""
    if ka == kb:
        return 0.5 * ka
    s = ka + kb
    if s <= 0.0:
        return 0.0
    return ka * kb / s


@njit(inline="always", cache=True)
def linear_force(overlap, vn, vt, fs_old, kn, ks, mu, cn, dt):
    """Normal and shear force magnitudes of one touching contact.

    overlap > 0; vn is the normal approach speed (positive when closing);
    cn the normal dashpot coefficient (0 for none). Returns (fn, fs, sliding).
    """
    fn = kn * overlap + cn * vn
    if fn < 0.0:  # the dashpot may not pull the bodies together
        fn = 0.0
    fs = fs_old + ks * vt * dt
    cap = mu * fn
    sliding = False
    if fs > cap:
        fs = cap
        sliding = True
    elif fs < -cap:
        fs = -cap
        sliding = True
    return fn, fs, sliding


@njit(inline="always", cache=True)
def rolling_moment(m_old, kr, dtheta, cap):
    """Rolling moment on disk ``i`` after a relative rotation ``dtheta`` of ``i`` against ``j``.

    The elastic spring ``kr`` resists the rotation; beyond ``cap`` (>= 0) it slips.
    """
    # min / max rather than branches: a packing holds contacts on and below the limit in
    # no order, and a mispredicted branch per contact costs more than both comparisons
    return min(max(m_old - kr * dtheta, -cap), cap)


@njit(inline="always", cache=True)
def dashpot(beta, kn, m_eff):
    """Critical-damping fraction ``beta`` to a normal dashpot coefficient."""
    if beta <= 0.0:
        return 0.0
    return 2.0 * beta * math.sqrt(kn * m_eff)


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
