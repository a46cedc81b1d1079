"""The kinetic energy of the disks, translational and rotational."""

from __future__ import annotations

import numpy as np


def kinetic_energy(sim) -> tuple[float, float]:
    """(translational, rotational) kinetic energy with the true masses (J)."""
    p = sim.particles
    m = p.mass
    et = 0.5 * float(np.sum(m * np.sum(p.vel**2, axis=1)))
    er = 0.5 * float(np.sum(p.inertia * p.omega**2))
    return et, er


__all__ = ["kinetic_energy"]
