"""The cell of a case: its disks drawn, placed loosely, and compressed to the pressure.

Radii come from the case's grading (:func:`poro2d.grading.draw_disks`, the seed's), shuffled
with the same seed and set on a square lattice one largest diameter apart, each jittered
inside its site: no two overlap, so no force is invented at the start. That gas (solid
fraction about 0.25 for the paper's grading) is compressed isotropically, fast while no
force network carries the pressure, then by the barostat's law until the mean pressure holds
within 1 % over a block: the state the shear starts from. The critical state forgets it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from poro2d.critical_state.case import THICKNESS, CriticalStateCase
from poro2d.dem.periodic import CellLaw, PeriodicCell
from poro2d.grading import draw_disks

#: the most a barostat or the gas stage may shrink the cell in one step (a fraction of its size):
#: a disk then never meets a neighbour at more than a small fraction of its overlap per step
MAX_STRAIN_PER_STEP = 2.5e-5
#: compression ends when the mean |p - P| / P of a block is below this
PRESSURE_TOLERANCE = 0.01
COMPRESS_BLOCK = 1000
MAX_COMPRESS_BLOCKS = 1000


def contact_law(case: CriticalStateCase) -> CellLaw:
    """The case's contact values (:meth:`CriticalStateCase.contact_stiffness`), one friction for all."""
    kn, ks = case.contact_stiffness()
    return CellLaw(
        kn=kn,
        ks=ks,
        friction=case.particle_friction,
        rolling_friction=case.rolling_friction,
        restitution=case.restitution,
    )


def loose_cell(case: CriticalStateCase) -> PeriodicCell:
    """The seed's disks on a jittered square lattice (the gas the compression starts from)."""
    rng = np.random.default_rng(case.seed)
    area = case.disks * case.grading.mean_disk_area()
    radius = rng.permutation(draw_disks(case.grading, area, rng))
    n = radius.size
    spacing = 2.0 * float(radius.max()) * 1.001
    cols = math.ceil(math.sqrt(n))
    rows = math.ceil(n / cols)
    site = np.arange(n)
    room = 0.5 * spacing - radius  # how far a disk may move inside its site
    jitter = rng.uniform(-1.0, 1.0, (n, 2)) * room[:, None]
    pos = (np.stack([site % cols, site // cols], axis=1) + 0.5) * spacing + jitter
    return PeriodicCell(
        radius,
        pos,
        cols * spacing,
        rows * spacing,
        contact_law(case),
        density=case.solid_density,
        thickness=THICKNESS,
        dt_safety=case.dt_safety,
    )


def barostat_gain(cell: PeriodicCell, case: CriticalStateCase) -> float:
    """Strain rate per pascal of pressure error (1/(Pa s)): the error relaxes in ``barostat_time``
    sound-crossing times of the cell, with the contact modulus E = kn / t as its stiffness."""
    modulus = cell.law.kn / THICKNESS
    crossing = cell.height * math.sqrt(case.solid_density / modulus)
    return 1.0 / (modulus * case.barostat_time * crossing)


def compress(
    cell: PeriodicCell, case: CriticalStateCase, report: Callable[[float], None] | None = None
) -> int:
    """Compress ``cell`` isotropically to the case's pressure; returns the steps it took.

    Raises RuntimeError when the pressure does not hold within PRESSURE_TOLERANCE in
    MAX_COMPRESS_BLOCKS blocks (a contact too soft or a pressure too high for the disks).
    """
    pressure = case.pressure_kpa * 1e3
    max_rate = MAX_STRAIN_PER_STEP / cell.dt
    for k in range(MAX_COMPRESS_BLOCKS):
        cell.compress(pressure, barostat_gain(cell, case), max_rate, max_rate)
        block = cell.run(COMPRESS_BLOCK)
        if report is not None:
            report(min(1.0, (1.0 - block.pressure_error) ** 4))
        if block.pressure_error < PRESSURE_TOLERANCE:
            return (k + 1) * COMPRESS_BLOCK
    raise RuntimeError(
        f"the cell did not hold {case.pressure_kpa:g} kPa within {100 * PRESSURE_TOLERANCE:g} % in "
        f"{MAX_COMPRESS_BLOCKS * COMPRESS_BLOCK} steps of compression"
    )


def mean_overlap_ratio(cell: PeriodicCell) -> float:
    """The touching contacts' mean overlap over the disks' mean diameter now (0 without contacts):
    the typical contact strain, about 1 / kappa."""
    c = cell.contacts()
    if c["i"].size == 0:
        return 0.0
    overlap = cell.radius[c["i"]] + cell.radius[c["j"]] - np.hypot(c["lx"], c["ly"])
    return float(overlap.mean()) / mean_diameter(cell)


def mean_diameter(cell: PeriodicCell) -> float:
    """The disks' number-mean diameter (m): the d of the inertial number."""
    return 2.0 * float(cell.radius.mean())


def shear_rate(cell: PeriodicCell, case: CriticalStateCase) -> float:
    """gamma_dot (1/s) of the case's inertial number at its pressure: I / (d sqrt(rho / P))."""
    return case.inertial_number / (
        mean_diameter(cell) * math.sqrt(case.solid_density / (case.pressure_kpa * 1e3))
    )


__all__ = [
    "barostat_gain",
    "compress",
    "contact_law",
    "loose_cell",
    "mean_diameter",
    "mean_overlap_ratio",
    "shear_rate",
]
