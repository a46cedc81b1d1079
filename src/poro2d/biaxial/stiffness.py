"""How stiff the disks are against the stress: the stiffness number and the mean overlap.

With linear contacts the typical contact strain is the inverse of the stiffness number

    kappa = kn / (sigma_3 t)

with kn the normal stiffness of a disk-disk contact (N/m; under the ``per_body`` convention
two disks' stiffnesses in series, kA kB / (kA + kB), averaged over the touching contacts;
under ``per_pair_type`` the one disk-disk kn), t the disks' thickness and sigma_3 the
confining stress. At kappa of a few hundred the packing's elastic strain is of the order of
its dilatancy (docs/biaxial.md); kappa >= 1000 is the rigid-grain limit (Roux & Combe;
Agnolin & Roux 2007). The overlap is read from the touching contacts
(:meth:`poro2d.dem.Simulation.contacts`): mean(overlap) / mean(d), d the mean diameter of a
contact's two disks, over the disk-disk contacts.

``stiffness_number`` of :class:`~poro2d.biaxial.settings.BiaxialSettings` sets kappa: the disks'
kn and ks are replaced (their ratio kept) so that a contact of two of them has the kn of the
asked kappa at sigma_3 (:func:`scaled_stiffness`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from poro2d.dem import Simulation
from poro2d.measure.stiffness import (
    DiskContacts,
    contact_kn,
    disk_contacts,
    overlap_ratio,
    stiffness_number,
)

#: how the stiffness number is read (kept with the numbers)
STIFFNESS_DEFINITION = (
    "kappa = kn / (sigma_3 t): kn the mean normal stiffness of the touching disk-disk contacts "
    "(per_body: the two disks' kn in series), t the disks' thickness, sigma_3 the confining stress; "
    "overlap ratio = mean overlap / mean diameter of the touching disk-disk contacts"
)


def contact_strain(sim: Simulation) -> tuple[float, float]:
    """(eps_1^e, eps_3^e): the elastic strain the contacts hold, compression positive (nan without
    three contacts).

    A linear contact's overlap is its elastic shortening. Were the strain uniform (affine), a
    contact of normal n between disks whose radii add to d would overlap by d n.eps.n; the strain
    whose overlaps fit the measured ones best (least squares over the disk-disk contacts) is the
    packing's elastic strain in that approximation: eps_1^e along y (the plate's axis), eps_3^e
    along x. The disks' non-affine relaxation makes the true elastic strain somewhat larger.
    """
    c = disk_contacts(sim)
    if c.i.size < 3:
        return float("nan"), float("nan")
    nx, ny = c.normal[:, 0], c.normal[:, 1]
    rows = np.column_stack([nx * nx, ny * ny, 2.0 * nx * ny])
    fit = np.linalg.lstsq(rows, c.overlap / c.reach, rcond=None)[0]
    return float(fit[1]), float(fit[0])


@dataclass(frozen=True)
class DiskStiffness:
    """The disks' stiffness (N/m) that gives a contact the kn of a stiffness number, and by how much
    it changed the specimen's (``factor``: the new contact kn over the old)."""

    kn: float
    ks: float
    factor: float


def scaled_stiffness(sim: Simulation, kappa: float, sigma_pa: float) -> DiskStiffness:
    """The disks' kn and ks (their ratio kept) so that a disk-disk contact of ``sim`` has
    kn = kappa sigma t (``per_body``: each disk 2 kappa sigma t, two equal springs in series)."""
    target = kappa * sigma_pa * sim.particles.thickness
    if sim.contact.convention == "per_pair_type":
        assert sim.contact.pp is not None
        kn, ks = float(sim.contact.pp[0]), float(sim.contact.pp[1])
        return DiskStiffness(target, target * ks / kn, target / kn)
    p = sim.particles
    ratio = float(np.mean(p.ks) / np.mean(p.kn))
    return DiskStiffness(2.0 * target, 2.0 * target * ratio, target / contact_kn(sim))


__all__ = [
    "STIFFNESS_DEFINITION",
    "DiskStiffness",
    "DiskContacts",
    "contact_kn",
    "contact_strain",
    "disk_contacts",
    "overlap_ratio",
    "scaled_stiffness",
    "stiffness_number",
]
