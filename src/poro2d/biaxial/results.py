"""Typed results of the biaxial test: one test's ``result.json`` and a study's ``result.json``."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from poro2d.biaxial.angles import Angles, PlasticAngles
from poro2d.biaxial.curve import BiaxialCurve, read_curve
from poro2d.biaxial.envelope import EnvelopeRecord
from poro2d.biaxial.lab import LabCurve
from poro2d.biaxial.parts import (
    ELASTIC_SPREADS,
    AngleSpread,
    BiaxialTestSummary,
    Definitions,
    ElasticProbe,
    ElasticSpreads,
    ShearChecks,
    StiffnessScale,
    StressSummary,
    StudySpreads,
)
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.io_utils import Provenance
from poro2d.labtest.records import ByName, ConsolidationRecord, StudyRun, typed_parts
from poro2d.measure.stiffness import StiffnessAtPeak
from poro2d.store import Store
from poro2d.typed_result import NOT_IN_FILE, TypedResult, with_fields


@typed_parts
@dataclass(eq=False)
@with_fields(PlasticAngles, after="elastic_probe", optional=True)
@with_fields(StiffnessAtPeak, after="provenance")
class BiaxialTestResult(ByName, Angles):
    """One biaxial test (a replicate folder's ``result.json``): its angles (its first keys, those of
    :class:`~poro2d.biaxial.angles.Angles`) and how they were obtained.

    Angles in degrees, strains as fractions (compression positive), stresses in kPa; the
    definitions are :mod:`poro2d.biaxial.angles`'. ``stiffness_number``: kappa = kn / (sigma_3 t)
    of the test (:mod:`poro2d.biaxial.stiffness`; the consolidation record has it too, with the
    overlap then), ``mean_overlap_ratio_at_peak`` the mean overlap / mean diameter at the peak;
    ``elastic_probe`` the compliance measured after shearing and ``plastic_*`` the dilatancy of
    the plastic strains (:class:`~poro2d.biaxial.angles.PlasticAngles`, absent without them;
    :mod:`poro2d.biaxial.elastic`). ``curve`` (not in the file): the recorded curve
    (:class:`~poro2d.biaxial.curve.BiaxialCurve`).
    """

    checks: ShearChecks
    consolidation: ConsolidationRecord
    strain_rate_per_s: float
    plate_velocity_m_per_s: float
    d50_m: float
    dt_s: float
    local_damping: float
    density_scale: float
    shear_steps: int
    records: int
    wall_time_s: float
    settings: BiaxialSettings
    specimen: str
    specimen_digest: str
    provenance: Provenance
    stiffness_scale: StiffnessScale | None = None
    elastic_probe: ElasticProbe | None = None
    curve: BiaxialCurve | None = field(default=None, kw_only=True, repr=False, metadata=NOT_IN_FILE)

    #: written since the elastic strain was told apart (a test of before has none of them; a test
    #: without its probe no plastic ones; ``stiffness_scale`` only with ``stiffness_number``)
    OPTIONAL: ClassVar[tuple[str, ...]] = (
        "stiffness_number", "mean_overlap_ratio_at_peak", "stiffness_scale", "elastic_probe",
        "plastic_max_dilatancy_angle_deg", "plastic_axial_strain_at_max_dilatancy",
        "plastic_end_dilatancy_angle_deg", "plastic_end_volumetric_strain",
    )  # fmt: skip

    @classmethod
    def read(cls, store: Store) -> BiaxialTestResult | None:
        """A finished test read back from ``store`` with its curve (None if it holds none)."""
        data = store.read_json("result.json")
        if not isinstance(data, dict):
            return None
        result = cls.from_dict(data)
        result.curve = read_curve(store)
        return result


@dataclass
@with_fields(StudyRun, after="specimens")
class BiaxialStudy:
    """The fields of a biaxial study's ``result.json`` after its own numbers, the same in a series':
    how each number is read, the settings and specimens of its tests, how it ran
    (:class:`~poro2d.labtest.records.StudyRun`) and the laboratory curve (only with one)."""

    definitions: Definitions
    settings: BiaxialSettings
    specimens: list[str]
    lab: LabCurve | None = None


@typed_parts
@dataclass(eq=False)
@with_fields(ElasticSpreads, after="lab")
@with_fields(BiaxialStudy, after="summaries")
@with_fields(StudySpreads, after="replicates")
class BiaxialResult(TypedResult):
    """Biaxial tests at one confining stress on replicate specimens (the study's ``result.json``).

    ``peak_friction_angle``, ``critical_state_friction_angle`` and ``max_dilatancy_angle``:
    each angle's spread over the replicates; ``critical_state_reached`` only if every
    replicate reached it (``critical_state_note`` says which did not); ``lab`` only with
    laboratory curves. ``tests`` (not in the file): each replicate's full result.
    """

    OPTIONAL: ClassVar[tuple[str, ...]] = ("lab", *ELASTIC_SPREADS)

    confining_stress_kpa: float
    replicates: int
    summaries: list[BiaxialTestSummary]
    tests: list[BiaxialTestResult] = field(
        default_factory=list, kw_only=True, repr=False, metadata=NOT_IN_FILE
    )

    def headline(self) -> str:
        """The number to take away, one line: peak and critical-state angles with their spread."""
        n = self.replicates
        cs = "phi_cs" if self.critical_state_reached else "phi_end (not yet at critical state)"
        return (
            f"biaxial at sigma_3 = {self.confining_stress_kpa:g} kPa, {n} replicate{'s' if n > 1 else ''}: "
            f"phi_peak = {self.peak_friction_angle.text()}, "
            f"{cs} = {self.critical_state_friction_angle.text()}"
        )


@typed_parts
@dataclass(eq=False)
@with_fields(BiaxialStudy, after="sigma_3_note")
class BiaxialSeriesResult(TypedResult):
    """Biaxial tests at several confining stresses on replicate specimens (the series' ``result.json``).

    ``stresses``: per confining stress the replicates' spread (each stress's own study is in its
    folder); ``peak_friction_angle``, ``critical_state_friction_angle`` and
    ``max_dilatancy_angle``: pooled over every test of every stress; ``envelope`` (and
    ``envelope_through_origin``): the Mohr-Coulomb line of the peak circles
    (:mod:`poro2d.biaxial.envelope`), each circle on the side walls' sigma_3 at its peak;
    ``sigma_3_held`` only if every test kept sigma_3 on target (``sigma_3_note`` says how far
    off it went otherwise). ``studies`` (not in the file): each stress's
    :class:`BiaxialResult`, its tests with their curves.
    """

    OPTIONAL: ClassVar[tuple[str, ...]] = ("lab", "plastic_max_dilatancy_angle")

    confining_stresses_kpa: list[float]
    replicates: int
    stresses: list[StressSummary]
    peak_friction_angle: AngleSpread
    critical_state_friction_angle: AngleSpread
    max_dilatancy_angle: AngleSpread
    envelope: EnvelopeRecord
    envelope_through_origin: EnvelopeRecord
    envelope_definition: str
    critical_state_reached: bool
    critical_state_note: str
    sigma_3_held: bool
    sigma_3_note: str
    plastic_max_dilatancy_angle: AngleSpread | None = None
    studies: list[BiaxialResult] = field(default_factory=list, kw_only=True, repr=False, metadata=NOT_IN_FILE)

    def headline(self) -> str:
        """The number to take away, one line: the angles pooled over every test, then the envelope."""
        n = sum(len(s.peak_friction_angle.values) for s in self.stresses)
        cs = "phi_cs" if self.critical_state_reached else "phi_end (not yet at critical state)"
        stresses = ", ".join(f"{v:g}" for v in self.confining_stresses_kpa)
        env = self.envelope
        fit = (
            f"peak envelope phi = {env.friction_angle_deg:.1f} deg, c = {env.cohesion_kpa:.1f} kPa"
            if env.friction_angle_deg is not None
            else "no peak envelope"
        )
        return (
            f"biaxial at sigma_3 = {stresses} kPa, {self.replicates} replicate(s) each, "
            f"pooled over {n} tests: phi_peak = {self.peak_friction_angle.text()}, "
            f"{cs} = {self.critical_state_friction_angle.text()}; {fit}"
        )


__all__ = ["BiaxialResult", "BiaxialSeriesResult", "BiaxialStudy", "BiaxialTestResult"]
