"""The average stress of the disks in a region, from their contact forces (Love-Weber)."""

from __future__ import annotations

import numpy as np


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


__all__ = ["average_stress"]
