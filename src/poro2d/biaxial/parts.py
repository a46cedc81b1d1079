"""The typed parts of a biaxial test's files: its consolidation, its checks, the spread of an angle."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from poro2d.measure.spread import Spread
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class BoxRecord(TypedResult):
    """The box as built (m): the specimen's width and height, the disks' thickness."""

    width: float
    height: float
    thickness: float


@dataclass(eq=False)
class ConsolidationRecord(TypedResult):
    """How consolidation to sigma_3 ended: steps, the unbalanced-force ratio and each wall's stress."""

    confining_stress_kpa: float
    steps: int
    max_unbalanced_ratio: float
    sigma_1_kpa: float
    sigma_3_left_kpa: float
    sigma_3_right_kpa: float
    max_stress_error: float
    width_m: float
    height_m: float
    porosity: float
    coordination_number: float
    wall_time_s: float
    box: BoxRecord

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"box": BoxRecord}


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


@dataclass(eq=False)
class TestSummary(TypedResult):
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


@dataclass(eq=False)
class StressSummary(TypedResult):
    """One confining stress of a series: its replicates' spread and where its files are."""

    confining_stress_kpa: float
    folder: str
    peak_friction_angle: AngleSpread
    critical_state_friction_angle: AngleSpread
    max_dilatancy_angle: AngleSpread
    axial_strain_at_peak: AngleSpread
    critical_state_reached: bool
    critical_state_note: str

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {
        "peak_friction_angle": AngleSpread,
        "critical_state_friction_angle": AngleSpread,
        "max_dilatancy_angle": AngleSpread,
        "axial_strain_at_peak": AngleSpread,
    }


@dataclass(eq=False)
class LabCurveRecord(TypedResult):
    """Laboratory curves given with the test (the user's own data): where they came from and what they say."""

    source: str
    rows: int
    peak_friction_angle_deg: float | None
    end_friction_angle_deg: float | None


@dataclass(eq=False)
class Definitions(TypedResult):
    """How each number is read (the text of docs/biaxial.md, kept with the numbers)."""

    strains: str
    stresses: str
    peak: str
    critical_state: str
    dilatancy: str


DEFINITIONS: dict[str, Any] = {
    "strains": "logarithmic from the wall positions after consolidation, compression positive: "
    "eps_1 = ln(H0/H), eps_3 = ln(W0/W), eps_v = eps_1 + eps_3 (negative: dilation), eps_s = eps_1 - eps_3",
    "stresses": "sigma_1 = plate force / (W t), sigma_3 = mean side wall force / (H t), "
    "t the disks' thickness; sin(phi) = (sigma_1 - sigma_3) / (sigma_1 + sigma_3)",
    "peak": "largest sin(phi) smoothed over smoothing_strain of axial strain",
    "critical_state": "mean sin(phi) over the last critical_window of the axial strain, critical only if "
    "|d eps_v / d eps_1| there is at most critical_rate_limit",
    "dilatancy": "sin(psi) = -d eps_v / d eps_s over secants of smoothing_strain; psi_max its largest value",
}
#: how a series' envelope is read (:mod:`poro2d.biaxial.envelope`)
ENVELOPE_DEFINITION = (
    "least-squares line through the tops (s, t) = ((sigma_1 + sigma_3) / 2, (sigma_1 - sigma_3) / 2) "
    "of every test's peak circle, sigma_1 = sigma_3 (1 + sin phi_peak) / (1 - sin phi_peak): "
    "slope sin(phi), intercept c cos(phi); the line is tangent to the circles"
)


__all__ = [
    "DEFINITIONS", "ENVELOPE_DEFINITION", "AngleSpread", "BoxRecord", "ConsolidationRecord", "Definitions",
    "LabCurveRecord", "ShearChecks", "StressSummary", "TestSummary",
]  # fmt: skip
