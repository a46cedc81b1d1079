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
    return mechanical_coordination(n, ii, jj, wi)[0]


def mechanical_coordination(n: int, ii: np.ndarray, jj: np.ndarray, wi: np.ndarray) -> tuple[float, float]:
    """Contacts per disk among the disks left once the rattlers are out, and the rattlers' share of
    the ``n`` disks.

    ``ii``, ``jj``: the disks of each disk-disk contact; ``wi``: the disk of each disk-wall
    contact (it counts once, for the disk). A rattler has fewer than two contacts; removing
    one may leave a neighbour with fewer, so they are removed until none remains.
    """
    if n == 0:
        return 0.0, 0.0
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
    return (float(z[alive].sum() / m) if m else 0.0), float(1.0 - m / n)


__all__ = ["coordination_number", "mechanical_coordination"]
