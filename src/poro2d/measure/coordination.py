"""The coordination number: contacts per disk, with or without the rattlers."""

from __future__ import annotations

import numpy as np


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


__all__ = ["coordination_number"]
