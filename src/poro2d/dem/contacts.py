"""The touching contacts of a simulation as arrays, read from its public contact stores.

:meth:`poro2d.dem.simulation.Simulation.contacts` returns them; the measurements
(:mod:`poro2d.measure`: stress, coordination) and the force-chain figures read them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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


__all__ = ["ContactSet", "contact_set"]
