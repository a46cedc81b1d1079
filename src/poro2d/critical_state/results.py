"""Typed results of the periodic reference: one run's ``result.json`` and a study's over seeds."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from poro2d.critical_state.case import CriticalStateCase
from poro2d.critical_state.series import CellSeries
from poro2d.critical_state.steady import SteadyState
from poro2d.io_utils import Provenance
from poro2d.labtest.records import ByName, StudyRun, TestSummary, typed_parts
from poro2d.measure.fabric import FabricRoses
from poro2d.measure.spread import Spread
from poro2d.typed_result import NOT_IN_FILE, TypedResult, with_fields


@typed_parts
@dataclass(eq=False)
class CriticalStateTestResult(ByName, SteadyState):
    """One periodic shear run: its steady state over the window (its first keys, those of
    :class:`~poro2d.critical_state.steady.SteadyState`) and how it was reached.

    stress_ratio = tau / sigma_yy over the window with its standard error over blocks,
    friction_angle_deg = atan of it; solid_fraction likewise; inertial_number the one reached
    (at the measured sigma_yy), coordination 2 N_c / N; the drifts and ``steady`` as
    :mod:`poro2d.critical_state.steady` reads them (``note`` says why not);
    ``stiffness_number`` kappa = kn / (P t) of the contacts at the case's pressure and
    ``mean_overlap_ratio`` the touching contacts' mean overlap over the mean diameter at the
    end (about 1 / kappa: the share of the solid fraction that is the contacts' softness; both
    absent in files of earlier versions). ``series`` (not in the file): the rows as arrays; ``roses``
    (not in the file, kept beside it as ``fabric_rose.json``): the contact orientations at the
    largest stress ratio and at the end.
    """

    disks: int
    mean_diameter_m: float
    cell_width_m: float
    cell_height_m: float
    shear_rate_per_s: float
    dt_s: float
    compression_steps: int
    shear_steps: int
    rebuilds: int
    wall_time_s: float
    particle_steps_per_s: float
    case: CriticalStateCase
    provenance: Provenance
    stiffness_number: float | None = None
    mean_overlap_ratio: float | None = None
    series: CellSeries | None = field(default=None, kw_only=True, repr=False, metadata=NOT_IN_FILE)
    roses: FabricRoses | None = field(default=None, kw_only=True, repr=False, metadata=NOT_IN_FILE)

    OPTIONAL: ClassVar[tuple[str, ...]] = ("stiffness_number", "mean_overlap_ratio")

    @property
    def void_ratio(self) -> float:
        """The 2D void ratio (1 - solid fraction) / solid fraction of the steady state."""
        return void_ratio(self.solid_fraction)


def void_ratio(solid_fraction: float) -> float:
    """The 2D void ratio e = (1 - phi) / phi of a solid (area) fraction phi."""
    return (1.0 - solid_fraction) / solid_fraction


@dataclass(eq=False)
class SeedSummary(TestSummary):
    """One seed's row of a study's ``result.json`` (``note``: steady, or which drift was too large)."""

    seed: int
    disks: int
    stress_ratio: float
    stress_ratio_se: float
    friction_angle_deg: float
    solid_fraction: float
    inertial_number: float
    coordination: float
    normal_stress_kpa: float
    stress_ratio_drift: float
    solid_fraction_drift: float
    steady: bool
    note: str
    wall_time_s: float
    stiffness_number: float | None = None
    mean_overlap_ratio: float | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = ("stiffness_number", "mean_overlap_ratio")


@typed_parts
@dataclass(eq=False)
@with_fields(StudyRun, after="case")
class CriticalStateResult(TypedResult):
    """Periodic shear runs of one case on several seeds (the study's ``result.json``).

    Each number's spread over the seeds (:class:`Spread`), the void ratio (1 - phi) / phi with
    them; ``steady`` only if every seed's window was steady (``note`` says which was not);
    ``stiffness_number`` kappa at the pressure and the mean overlap over d (absent in files of
    earlier versions); ``contact_anisotropy``: each seed's mean a_c over the steady window
    (:mod:`poro2d.measure.fabric`; absent in files of earlier versions). ``tests`` (not in the
    file): each seed's full result with its series.
    """

    seeds: list[int]
    stress_ratio: Spread
    friction_angle_deg: Spread
    solid_fraction: Spread
    inertial_number: Spread
    coordination: Spread
    steady: bool
    note: str
    summaries: list[SeedSummary]
    case: CriticalStateCase
    void_ratio: Spread | None = None
    stiffness_number: float | None = None
    mean_overlap_ratio: Spread | None = None
    contact_anisotropy: Spread | None = None
    tests: list[CriticalStateTestResult] = field(
        default_factory=list, kw_only=True, repr=False, metadata=NOT_IN_FILE
    )

    OPTIONAL: ClassVar[tuple[str, ...]] = (
        "void_ratio", "stiffness_number", "mean_overlap_ratio", "contact_anisotropy",
    )  # fmt: skip

    def headline(self) -> str:
        """The steady-state friction (tau/sigma and angle) and solid fraction with their spread."""
        n = len(self.seeds)
        state = "critical state" if self.steady else "end state (NOT STEADY)"
        return (
            f"{state}: tau/sigma = {self.stress_ratio.text()}, phi = {self.friction_angle_deg.text(1)} deg, "
            f"solid fraction = {self.solid_fraction.text()}"
            + (f", e = {self.void_ratio.text(4)}" if self.void_ratio is not None else "")
            + f" ({n} seed{'s' if n > 1 else ''})"
        )


__all__ = ["CriticalStateResult", "CriticalStateTestResult", "SeedSummary", "Spread", "void_ratio"]
