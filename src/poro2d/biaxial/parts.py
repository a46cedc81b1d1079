"""The typed parts of a biaxial test's files: its consolidation, its checks, the spread of an angle."""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, ClassVar

from poro2d.biaxial.stiffness import STIFFNESS_DEFINITION
from poro2d.labtest.records import ByName, TestSummary, typed_parts
from poro2d.measure.spread import Spread
from poro2d.measure.stiffness import StiffnessAtPeak
from poro2d.typed_result import TypedResult, with_fields


@dataclass(eq=False)
class ElasticProbe(TypedResult):
    """The specimen's elastic compliance along the test's stress path, read after shearing
    (:mod:`poro2d.biaxial.elastic`): the plate held, then unloaded by ``unload`` of the deviator at
    constant sigma_3.

    ``before`` and ``after``: (sigma_1 in kPa, eps_1, eps_3) at the two equilibria;
    ``axial_compliance`` and ``lateral_compliance`` (1/MPa): d eps_1 / d sigma_1 and
    d eps_3 / d sigma_1 over the unloading; ``bulk_modulus_mpa`` K = 1 / (2 (C1 + C3)) and
    ``shear_modulus_mpa`` G = 1 / (2 (C1 - C3)) (2D: p and t = (sigma_1 - sigma_3) / 2 against
    eps_v and eps_s); ``contact_axial_compliance`` and ``contact_lateral_compliance``: the same
    secants of the contacts' elastic strain (:func:`poro2d.biaxial.stiffness.contact_strain`), what
    the plastic strains take out; ``reached``: both equilibria reached (otherwise no compliance).
    """

    definition: str
    unload: float
    before: list[float]
    after: list[float]
    sigma_3_kpa: list[float]
    steps: int
    reached: bool
    axial_compliance: float | None
    lateral_compliance: float | None
    bulk_modulus_mpa: float | None
    shear_modulus_mpa: float | None
    contact_axial_compliance: float | None
    contact_lateral_compliance: float | None


@dataclass(eq=False)
class StiffnessScale(TypedResult):
    """What ``stiffness_number`` did to a test (:mod:`poro2d.biaxial.stiffness`): the asked kappa,
    the disks' new kn and ks (N/m) and the factor on the specimen's contact stiffness."""

    stiffness_number: float
    disk_kn: float
    disk_ks: float
    factor: float


@dataclass(eq=False)
class ShearChecks(TypedResult):
    """What the shearing stage kept: sigma_3 on target, equilibrium, the inertial number.

    ``sigma_3_max_error`` and ``sigma_3_mean_error``: |sigma_3 / target - 1| over the rows
    after the first 1 % of axial strain (the side walls start moving then);
    ``inertial_number_at_confining``: I = rate d50 sqrt(rho / sigma_3), the largest of the test
    (p only grows in shear), against ``inertial_limit``.
    """

    sigma_3_max_error: float
    sigma_3_mean_error: float
    stress_tolerance: float
    sigma_3_held: bool
    mean_unbalanced_ratio: float
    max_unbalanced_ratio: float
    inertial_number_at_confining: float
    max_inertial_number: float
    inertial_limit: float
    quasi_static: bool


@dataclass(eq=False)
class AngleSpread(Spread):
    """One angle over the replicates (degrees): mean, sd (None for one), min, max and each value."""

    def text(self, digits: int = 1, unit: str = " deg") -> str:
        """``31.2 +- 1.4 deg (29.9-32.8)``, or ``31.2 deg`` for one value."""
        return super().text(digits, unit)


@dataclass
class StudySpreads:
    """A study's numbers over its replicates, the same in its ``result.json`` and in its line in a
    series: each angle's spread (and the axial strain at the peak's); ``critical_state_reached``
    only if every replicate reached it (``critical_state_note`` says which did not)."""

    peak_friction_angle: AngleSpread
    critical_state_friction_angle: AngleSpread
    max_dilatancy_angle: AngleSpread
    axial_strain_at_peak: AngleSpread
    critical_state_reached: bool
    critical_state_note: str


@dataclass
class ElasticSpreads:
    """The spreads over replicates a study adds once tests carry their elastic numbers (None for a
    study holding a test read back from before: see ``of_all``), the last fields of a study's
    ``result.json`` and of its line in a series."""

    plastic_max_dilatancy_angle: AngleSpread | None = None
    stiffness_number: Spread | None = None
    mean_overlap_ratio_at_peak: Spread | None = None


#: the keys of :class:`ElasticSpreads`, written only when known
ELASTIC_SPREADS = tuple(f.name for f in fields(ElasticSpreads))


#: the angles (and the strain at the peak) a study spreads over its tests: a test's number is the
#: name with ``_deg`` (the strain: the name)
ANGLES = ("peak_friction_angle", "critical_state_friction_angle", "max_dilatancy_angle")


def angle_spreads(tests: list, names: tuple[str, ...] = ANGLES) -> dict[str, AngleSpread]:
    """Each of the angles ``names`` spread over ``tests``, by name."""
    return {k: AngleSpread.of([getattr(t, f"{k}_deg") for t in tests]) for k in names}


def spread_of(kind: type[Spread], values: list[float | None]) -> Spread | None:
    """The spread of ``values``, or None when a test lacks the number (one read back from before it
    was recorded, or without its probe): a spread over some replicates would pass for all of them."""
    if not values or any(v is None for v in values):
        return None
    return kind.of(values)


@dataclass(eq=False)
@with_fields(StiffnessAtPeak, after="wall_time_s")
class BiaxialTestSummary(TestSummary):
    """One replicate's row of a study's ``result.json``."""

    replicate: int
    specimen: str
    peak_friction_angle_deg: float
    axial_strain_at_peak: float
    critical_state_friction_angle_deg: float
    critical_state_reached: bool
    max_dilatancy_angle_deg: float
    end_volumetric_strain: float
    sigma_3_max_error: float
    wall_time_s: float
    plastic_max_dilatancy_angle_deg: float | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = (
        "stiffness_number", "mean_overlap_ratio_at_peak", "plastic_max_dilatancy_angle_deg",
    )  # fmt: skip


@typed_parts
@dataclass(eq=False)
@with_fields(ElasticSpreads, after="critical_state_note")
@with_fields(StudySpreads, after="folder")
class StressSummary(ByName, TypedResult):
    """One confining stress of a series: its replicates' spread and where its files are (read off
    the stress's study by name)."""

    confining_stress_kpa: float
    folder: str

    OPTIONAL: ClassVar[tuple[str, ...]] = ELASTIC_SPREADS


@dataclass(eq=False)
class Definitions(TypedResult):
    """How each number is read (the text of docs/biaxial.md, kept with the numbers)."""

    strains: str
    stresses: str
    peak: str
    critical_state: str
    dilatancy: str
    plastic: str | None = None
    stiffness_number: str | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = ("plastic", "stiffness_number")


DEFINITIONS: dict[str, Any] = {
    "strains": "logarithmic from the wall positions after consolidation, compression positive: "
    "eps_1 = ln(H0/H), eps_3 = ln(W0/W), eps_v = eps_1 + eps_3 (negative: dilation), eps_s = eps_1 - eps_3",
    "stresses": "sigma_1 = plate force / (W t), sigma_3 = mean side wall force / (H t), "
    "t the disks' thickness; sin(phi) = (sigma_1 - sigma_3) / (sigma_1 + sigma_3)",
    "peak": "largest sin(phi) smoothed over smoothing_strain of axial strain",
    "critical_state": "mean sin(phi) over the last critical_window of the axial strain, critical only if "
    "|d eps_v / d eps_1| there is at most critical_rate_limit",
    "dilatancy": "sin(psi) = -d eps_v / d eps_s over secants of smoothing_strain; psi_max its largest value",
    "plastic": "eps_1^p = eps_1 - (eps_1^e - eps_1,0^e), eps_3^p = eps_3 - (eps_3^e - eps_3,0^e), eps^e the "
    "uniform strain whose contact overlaps best fit the measured ones (least squares over the disk-disk "
    "contacts, each row); plastic psi_max from eps_v^p and eps_s^p as psi_max from eps_v, eps_s",
    "stiffness_number": STIFFNESS_DEFINITION,
}
#: how a series' envelope is read (:mod:`poro2d.biaxial.envelope`)
ENVELOPE_DEFINITION = (
    "least-squares line through the tops (s, t) = ((sigma_1 + sigma_3) / 2, (sigma_1 - sigma_3) / 2) "
    "of every test's peak circle, sigma_1 = sigma_3 (1 + sin phi_peak) / (1 - sin phi_peak): "
    "slope sin(phi), intercept c cos(phi); the line is tangent to the circles"
)


__all__ = [
    "DEFINITIONS", "ELASTIC_SPREADS", "ENVELOPE_DEFINITION", "AngleSpread", "BiaxialTestSummary",
    "Definitions", "ElasticProbe", "ElasticSpreads", "ShearChecks",
    "StiffnessScale", "StressSummary", "StudySpreads", "spread_of",
]  # fmt: skip
