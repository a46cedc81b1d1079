"""How stiff the disks are against the stress: the stiffness number and the mean overlap.

With linear contacts the typical contact strain is the inverse of the stiffness number

    kappa = kn / (sigma t)

with kn the normal stiffness of a disk-disk contact (N/m; under the ``per_body`` convention two
disks' stiffnesses in series, kA kB / (kA + kB), averaged over the touching contacts; under
``per_pair_type`` the one disk-disk kn), t the disks' thickness and sigma the test's stress (a
biaxial test's sigma_3, a direct shear test's normal stress). At kappa of a few hundred the
packing's elastic strain is of the order of its dilatancy; kappa >= 1000 is the rigid-grain
limit (Roux & Combe; Agnolin & Roux 2007). The overlap is read from the touching contacts: mean
overlap / mean d, d the mean diameter of a contact's two disks, over the disk-disk contacts.
Read through the engine's public surface (``Simulation.contacts()``, the disks' arrays).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class ContactStiffness:
    """The fields of a record that say how stiff a packing's contacts were: kappa = kn / (sigma t)
    and the mean overlap over d of the touching contacts (each record says when: after a test's
    consolidation, at its peak), None in a record of an earlier poro2d (put into each record by
    :func:`poro2d.typed_result.with_fields`)."""

    stiffness_number: float | None = None
    mean_overlap_ratio: float | None = None


@dataclass
class StiffnessAtPeak:
    """The fields of a test's result (and of its line in a study) that say how stiff its contacts
    were: kappa = kn / (sigma t) at the test's stress and the mean overlap over d at the peak,
    None in a test of an earlier poro2d (put into each result by
    :func:`poro2d.typed_result.with_fields`)."""

    stiffness_number: float | None = None
    mean_overlap_ratio_at_peak: float | None = None


@dataclass(frozen=True)
class DiskContacts:
    """The touching disk-disk contacts: their disks ``i``, ``j``, unit normals, the sum of the two
    radii (m) and the overlap (m), read from the contact set's branch vectors."""

    i: np.ndarray
    j: np.ndarray
    normal: np.ndarray
    reach: np.ndarray
    overlap: np.ndarray


def disk_contacts(sim) -> DiskContacts:
    """The touching disk-disk contacts of ``sim`` (:meth:`poro2d.dem.Simulation.contacts`)."""
    return contacts_of(sim.contacts(), sim.particles.radius)


def contacts_of(contacts, radius: np.ndarray) -> DiskContacts:
    """The disk-disk rows of a contact set (``kind`` 0) with the disks' ``radius``: a live
    simulation's or a stored frame's (the peak frame of a direct shear test)."""
    pp = contacts.kind == 0
    i, j = contacts.i[pp], contacts.j[pp]
    reach = radius[i] + radius[j]
    overlap = reach - np.hypot(contacts.branch[pp, 0], contacts.branch[pp, 1])
    return DiskContacts(i, j, contacts.normal[pp], reach, overlap)


def contact_kn(sim) -> float:
    """The mean normal stiffness (N/m) of ``sim``'s disk-disk contacts, as the engine forms it.

    ``per_pair_type``: the one disk-disk kn. ``per_body``: kA kB / (kA + kB) over the touching
    pairs (two equal disks of kn each when none touch: kn / 2).
    """
    if sim.contact.convention == "per_pair_type":
        assert sim.contact.pp is not None
        return float(sim.contact.pp[0])
    kn = sim.particles.kn
    c = disk_contacts(sim)
    if c.i.size == 0:
        return 0.5 * float(np.mean(kn))
    return float(np.mean(kn[c.i] * kn[c.j] / (kn[c.i] + kn[c.j])))


def stiffness_number(kn: float, sigma_pa: float, thickness: float) -> float:
    """kappa = kn / (sigma t): the inverse of a contact's typical strain under ``sigma_pa``."""
    return kn / (sigma_pa * thickness)


def overlap_ratio(sim) -> float:
    """mean(overlap) / mean(d) over the touching disk-disk contacts (d: the two disks' mean diameter)."""
    return mean_overlap_ratio(disk_contacts(sim))


def mean_overlap_ratio(c: DiskContacts) -> float:
    """mean(overlap) / mean(d) of ``c`` (nan without a contact)."""
    if c.i.size == 0:
        return float("nan")
    return float(np.mean(c.overlap) / np.mean(c.reach))


__all__ = [
    "DiskContacts",
    "contact_kn",
    "contacts_of",
    "disk_contacts",
    "mean_overlap_ratio",
    "overlap_ratio",
    "stiffness_number",
]
