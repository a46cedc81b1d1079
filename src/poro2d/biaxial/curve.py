"""A biaxial test's curve: one row per ``record_strain`` of axial strain, held as arrays.

Strains are logarithmic (true) strains from the walls' positions, compression positive:
eps_1 = ln(H0 / H), eps_3 = ln(W0 / W), so that the area change is exactly
eps_v = ln(A0 / A) = eps_1 + eps_3 (positive: the specimen contracts; negative: it dilates),
and eps_s = eps_1 - eps_3 is the 2D shear strain. H0 and W0 are the box's after
consolidation. sigma_1 (the plate) and sigma_3 (the side walls) as
:class:`poro2d.biaxial.box.BiaxialBox` measures them; q = sigma_1 - sigma_3,
p = (sigma_1 + sigma_3) / 2 and the mobilized friction sin(phi) = q / (sigma_1 + sigma_3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from poro2d.biaxial.box import BiaxialBox, BoxSize
from poro2d.biaxial.stiffness import contact_strain, overlap_ratio
from poro2d.dem import Simulation
from poro2d.labtest.curve import CurveRow, curve_of
from poro2d.measure.fabric import FABRIC_COLUMNS, Fabric, measure_fabric
from poro2d.store import Store
from poro2d.typed_result import with_fields

#: columns written since the elastic strain was told apart from the plastic (absent from a curve of
#: before): the mean overlap over the mean diameter of the disk-disk contacts and the elastic strain
#: they hold (:mod:`poro2d.biaxial.stiffness`), the plastic strains (:mod:`poro2d.biaxial.elastic`);
#: and since the fabric was recorded, the disks' (:class:`~poro2d.measure.fabric.Fabric`)
OPTIONAL_COLUMNS = (
    "mean_overlap_ratio", "elastic_axial_strain", "elastic_lateral_strain", "plastic_volumetric_strain",
    "plastic_shear_strain", *FABRIC_COLUMNS,
)  # fmt: skip


@dataclass(eq=False)
@with_fields(Fabric, after="elastic_lateral_strain", optional=True)
class BiaxialRow(CurveRow):
    """One row of ``curve.csv``, its fields the columns in order (see the module's conventions)."""

    step: int
    axial_strain: float
    lateral_strain: float
    volumetric_strain: float
    shear_strain: float
    sigma_1_kpa: float
    sigma_3_kpa: float
    sigma_3_left_kpa: float
    sigma_3_right_kpa: float
    deviator_kpa: float
    mean_stress_kpa: float
    sin_phi: float
    max_unbalanced_ratio: float
    inertial_number: float
    mean_overlap_ratio: float | None = None
    elastic_axial_strain: float | None = None
    elastic_lateral_strain: float | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = (*OPTIONAL_COLUMNS[:3], *FABRIC_COLUMNS)


class BiaxialCurve(curve_of(BiaxialRow, "BiaxialColumns", __name__, optional=OPTIONAL_COLUMNS)):
    """A test's recorded curve: one float array per column of :data:`CURVE_COLUMNS`, and of
    :data:`OPTIONAL_COLUMNS` where it has them (None where not); a mapping of the names it has
    to the arrays, in the file's order."""

    def with_plastic(self, volumetric: np.ndarray, shear: np.ndarray) -> BiaxialCurve:
        """This curve with its plastic strains (:func:`poro2d.biaxial.elastic.plastic_strains`)."""
        return replace(self, plastic_volumetric_strain=volumetric, plastic_shear_strain=shear)


#: the columns of ``curve.csv``, in order (those every curve has)
CURVE_COLUMNS = BiaxialCurve.COLUMNS


def read_curve(store: Store, name: str = "curve.csv") -> BiaxialCurve | None:
    """The curve kept in ``store`` (None without it)."""
    rows = store.read_rows(name)
    return None if rows is None else BiaxialCurve.of_rows(rows)


def curve_row(
    sim: Simulation, start: BoxSize, step: int, d50: float, rho: float, strain_rate: float, contacts=None
) -> BiaxialRow:
    """One row of the curve: the box's strains and stresses now (see the module's conventions);
    ``contacts``: the simulation's contacts now (read here when None)."""
    now = BiaxialBox.size(sim)
    s1, s3, left, right = BiaxialBox.stresses(sim)
    e1 = math.log(start.height / now.height)
    e3 = math.log(start.width / now.width)
    p = 0.5 * (s1 + s3)
    ratio, _ = sim.unbalanced_ratios()
    elastic_1, elastic_3 = contact_strain(sim)
    return BiaxialRow(
        step=step,
        axial_strain=e1,
        lateral_strain=e3,
        volumetric_strain=e1 + e3,
        shear_strain=e1 - e3,
        sigma_1_kpa=s1 / 1e3,
        sigma_3_kpa=s3 / 1e3,
        sigma_3_left_kpa=left / 1e3,
        sigma_3_right_kpa=right / 1e3,
        deviator_kpa=(s1 - s3) / 1e3,
        mean_stress_kpa=p / 1e3,
        sin_phi=(s1 - s3) / (s1 + s3) if s1 + s3 > 0 else math.nan,
        max_unbalanced_ratio=ratio,
        inertial_number=strain_rate * d50 * math.sqrt(rho / p) if p > 0 else math.inf,
        mean_overlap_ratio=overlap_ratio(sim),
        elastic_axial_strain=elastic_1,
        elastic_lateral_strain=elastic_3,
        **measure_fabric(sim.contacts() if contacts is None else contacts, sim.particles.n).row(),
    )


__all__ = ["CURVE_COLUMNS", "OPTIONAL_COLUMNS", "BiaxialCurve", "BiaxialRow", "curve_row", "read_curve"]
