"""The typed parts of the direct shear results: what the nested objects of their files hold.

Each part is a :class:`~poro2d.typed_result.TypedResult` (so a read-only mapping that
equals the dict of its file, and is written as that dict) with one field per key, in the
file's order: a test's force balance, end values and consolidation; a series' summary of
each test, its quasi-static check, its rate check and laboratory comparison; a
Mohr-Coulomb fit as kept in a file, with or without its confidence intervals; a
replicate study's peaks at one normal stress.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import ClassVar

import numpy as np

from poro2d.labtest.records import TestSummary, typed_parts
from poro2d.measure.stiffness import StiffnessAtPeak
from poro2d.typed_result import TypedResult, with_fields


@dataclass(eq=False)
class ForceBalance(TypedResult):
    """How far the upper half, the shear plane and the lower half agree over a test (kPa, relative)."""

    mean_abs_upper_minus_plane_rel: float
    mean_abs_upper_minus_lower_rel: float
    mean_upper_kpa: float
    mean_plane_kpa: float
    mean_lower_kpa: float
    note: str


@dataclass(eq=False)
class EndValues(TypedResult):
    """The end of a test's curve, smoothed over one peak window."""

    shear_stress_kpa: float
    normal_stress_kpa: float
    plate_displacement_mm: float
    coordination_number: float


@dataclass(eq=False)
class MohrCoulombFit(TypedResult):
    """tau = c + sigma tan(phi), least squares over the points (stresses in kPa), as a file keeps it
    (:func:`poro2d.shear.fit.mohr_coulomb` makes it).

    ``through_origin`` fits are tau = sigma tan(phi) (c = 0). ``r2`` is the coefficient of
    determination of the fitted line against the points (for the fit through the origin it is
    taken about the mean as well, so it can be negative when the line is poor).
    """

    friction_angle_deg: float
    cohesion_kpa: float
    r2: float
    n_points: int
    through_origin: bool
    tan_phi: float

    def predict(self, sigma_kpa) -> np.ndarray:
        return self.cohesion_kpa + self.tan_phi * np.asarray(sigma_kpa, float)


@dataclass(eq=False)
class FitInterval(MohrCoulombFit):
    """A Mohr-Coulomb line with ``level`` Student-t intervals of phi and c (None without dof)."""

    level: float | None = None
    dof: int | None = None
    friction_angle_ci_deg: list[float] | None = None
    cohesion_ci_kpa: list[float] | None = None


@dataclass(eq=False)
class ResidualAtRest(TypedResult):
    """A test's residual read where the plate has stopped rising (a test's ``residual_dilation_stopped``).

    ``reached``: whether the curve ends in a stretch at least ``min_stretch_m`` long whose
    plate slope, and its halves' slopes, stay within ``rate_limit``; ``status`` says so in
    words. The stretch runs from ``start_mm`` to ``end_mm`` of shear displacement; over it, the
    means of the shear stress, the plate's and the plane's normal stress and the upper walls'
    upward friction (kPa), the shear stress over each normal stress (``stress_ratio``: the
    plate's, ``plane_stress_ratio``: the plane's), the plane's share of the plate's stress, and
    the plate's slope (``dilation_rate``) and the larger of its halves' (``max_part_rate``,
    absolute). ``end_rate``: the slope over the last ``min_stretch_m`` of the curve, reached or
    not. The numbers are None when it was not reached (the plane's when the curve has no plane
    record, an earlier poro2d's).
    """

    reached: bool
    status: str
    rate_limit: float
    min_stretch_m: float
    start_mm: float | None
    end_mm: float
    shear_stress_kpa: float | None
    normal_stress_kpa: float | None
    plane_normal_stress_kpa: float | None
    upper_wall_friction_kpa: float | None
    stress_ratio: float | None
    plane_stress_ratio: float | None
    plane_share: float | None
    dilation_rate: float | None
    max_part_rate: float | None
    end_rate: float | None


@dataclass
@with_fields(StiffnessAtPeak, after="box_note")
class LaterParts:
    """The fields a test's ``result.json`` and its line in a series have had since a later poro2d (a
    test of before lacks them): the part of the plate's load the shear plane carries at the peak
    (:func:`poro2d.shear.curve.plane_load_fraction`), the residual read where the plate has stopped
    rising (:mod:`poro2d.shear.residual`), whether the test read its box rather than its material
    (:mod:`poro2d.shear.box_dominated`), the stiffness number and the overlap
    (:mod:`poro2d.measure.stiffness`)."""

    plane_load_fraction_at_peak: float | None = None
    residual_dilation_stopped: ResidualAtRest | None = None
    box_dominated: bool | None = None
    box_note: str | None = None


#: the keys of :class:`LaterParts`, written only when known
LATER_KEYS = tuple(f.name for f in fields(LaterParts))


@typed_parts
@dataclass(eq=False)
@with_fields(LaterParts, after="folder")
class ShearTestSummary(TestSummary):
    """One test's line of a series' ``result.json`` (and ``peaks.csv``, without its nested parts)."""

    normal_stress_kpa: float
    peak_shear_stress_kpa: float
    shear_displacement_at_peak_m: float
    peak_stress_ratio: float
    peak_shear_stress_raw_kpa: float
    normal_stress_at_peak_kpa: float
    plate_displacement_at_peak_mm: float
    end: EndValues
    end_shear_displacement_m: float
    ended_by: str | None
    max_inertial_number: float | None
    inertial_number_ok: bool
    normal_stress_max_error_after_consolidation: float
    force_balance: ForceBalance
    wall_time_s: float
    consolidation_normal_stress_error: float
    folder: str

    OPTIONAL: ClassVar[tuple[str, ...]] = LATER_KEYS


@dataclass(eq=False)
class QuasiStatic(TypedResult):
    """A series' check of the inertial number over all its tests."""

    max_inertial_number: float | None
    inertial_limit: float
    inertial_number_ok: bool
    inertial_number_definition: str


@dataclass(eq=False)
class RateCheckRow(TypedResult):
    """One test against its rerun at half the velocity."""

    normal_stress_kpa: float
    peak_kpa: float
    peak_half_velocity_kpa: float
    relative_change: float
    shear_displacement_at_peak_m: float
    shear_displacement_at_peak_half_velocity_m: float
    max_inertial_number_half_velocity: float | None
    mean_abs_change_before_peak: float | None
    wall_time_s: float


@typed_parts
@dataclass(eq=False)
class RateCheck(TypedResult):
    """How the peaks change at half the velocity (a series run with ``rate_check``)."""

    velocity_m_per_s: float
    half_velocity_m_per_s: float
    tests: list[RateCheckRow]
    max_abs_relative_change: float
    tolerance: float
    passed: bool
    friction_angle_half_velocity_deg: float | None
    friction_angle_change_deg: float | None
    max_mean_abs_change_before_peak: float | None
    note: str


@dataclass(eq=False)
class LabPeak(TypedResult):
    """One laboratory peak: the peak shear stress at a normal stress (kPa)."""

    normal_stress_kpa: float
    peak_shear_stress_kpa: float


@typed_parts
@dataclass(eq=False)
class LabRecord(TypedResult):
    """Laboratory data as a file keeps them (:meth:`poro2d.shear.lab.LabData.record`)."""

    source: str
    kind: str
    peaks: list[LabPeak]


@typed_parts
@dataclass(eq=False)
class LabComparison(LabRecord):
    """The laboratory data a series is compared with (its first keys, a :class:`LabRecord`'s), their
    fits and the difference of the angles."""

    fit: MohrCoulombFit | None
    friction_angle_deg: float | None
    cohesion_kpa: float | None
    friction_angle_difference_deg: float | None
    fit_through_origin: MohrCoulombFit


@dataclass(eq=False)
class StressPeaks(TypedResult):
    """The peaks of every specimen at one normal stress: mean, sd (0 with one), count and values."""

    normal_stress_kpa: float
    peak_mean_kpa: float
    peak_sd_kpa: float
    n: int
    peaks_kpa: list[float]


@dataclass(eq=False)
class StrengthDefinitions(TypedResult):
    """How a strength study measures each of its angles, in words (a study's ``definitions``)."""

    peak_friction_angle: str
    residual_friction_angle: str
    max_dilation_angle: str


@dataclass(eq=False)
class StrengthCase(TypedResult):
    """One (mu_r, f_p) case of a strength study (a row of ``strength.csv``, with the pooled intervals).

    Peak and residual friction angles and the dilation angle, mean and sd over the specimens
    (None when no specimen gave one; the sd None with one specimen); the pooled fits over
    every specimen's points with their intervals; the mean residual stress ratio (the last fifth of
    each curve), and the mean tau/sigma where dilation stopped, on the plate and on the plane,
    over the ``tests_dilation_stopped`` tests that reached it.
    """

    mu_r: float
    particle_friction: float
    specimens: int
    peak_friction_angle_mean_deg: float | None
    peak_friction_angle_sd_deg: float | None
    residual_friction_angle_mean_deg: float | None
    residual_friction_angle_sd_deg: float | None
    max_dilation_angle_mean_deg: float | None
    max_dilation_angle_sd_deg: float | None
    peak_friction_angle_pooled_deg: float | None
    peak_friction_angle_pooled_ci_deg: list[float] | None
    cohesion_pooled_kpa: float | None
    residual_friction_angle_pooled_deg: float
    residual_friction_angle_pooled_ci_deg: list[float] | None
    residual_stress_ratio_mean: float
    residual_dilation_stopped_ratio_mean: float | None = None
    residual_dilation_stopped_plane_ratio_mean: float | None = None
    tests_dilation_stopped: int | None = None
    #: kappa = kn / (sigma t) over the case's tests, lowest and highest, and the largest mean overlap
    #: / d at a peak (poro2d.measure.stiffness): how much elastic strain psi max carries
    stiffness_number_min: float | None = None
    stiffness_number_max: float | None = None
    mean_overlap_ratio_at_peak_max: float | None = None

    # the residual read where dilation stopped (poro2d.shear.residual): the means over the tests
    # that reached it (None when none did) and how many did; absent in a study of an earlier poro2d
    OPTIONAL: ClassVar[tuple[str, ...]] = (
        "residual_dilation_stopped_ratio_mean", "residual_dilation_stopped_plane_ratio_mean",
        "tests_dilation_stopped", "stiffness_number_min", "stiffness_number_max",
        "mean_overlap_ratio_at_peak_max",
    )  # fmt: skip


__all__ = [
    "LATER_KEYS", "EndValues", "FitInterval", "MohrCoulombFit", "ForceBalance",
    "LabComparison", "LabPeak", "LabRecord", "LaterParts", "QuasiStatic", "RateCheck", "RateCheckRow",
    "ResidualAtRest", "StrengthCase", "StrengthDefinitions", "StressPeaks",
    "ShearTestSummary",
]  # fmt: skip
