"""The typed parts of ``sensitivity.json``: settings, gradings, seeds, points and the answer.

Each record lists its keys in the file's order (see :mod:`poro2d.sweep.records`), so the
study writes the file it wrote before and reads it back typed; each still reads as the dict
it was (``point["n2d_mean"]``), which the report's tables and figure use.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

from poro2d.record import Record, Spliced
from poro2d.sweep.records import SweepSummary
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class MeanSd(TypedResult):
    """Mean, sample sd (0 for one value) and count of the finite values (NaN mean for none)."""

    mean: float
    sd: float
    n: int


@dataclass(eq=False)
class PaperNumbers(TypedResult):
    """The numbers the paper reports for its criterion run (``paper`` of the file): n_lab, the
    trials and their particle counts, the wall forces and self weights of the first and the
    accepted trial, the accepted porosity. The case study keeps them without n_lab, which it
    states beside them (``paper.criterion`` of its summary): n_lab is written only when given.
    """

    OPTIONAL: ClassVar[tuple[str, ...]] = ("n_lab",)

    n_lab: float | None = field(default=None, kw_only=True)  # kw_only: first key, yet optional
    trials: list[float]
    particle_counts: list[int]
    porosity_change_first_trial: float
    f_top_first_trial_kn_per_m: float
    f_bottom_first_trial_kn_per_m: float
    self_weight_first_trial_n_per_m: float
    f_top_accepted_n_per_m: float
    f_bottom_accepted_n_per_m: float
    self_weight_accepted_n_per_m: float
    accepted_porosity: float


@dataclass(eq=False)
class StudySettings(TypedResult):
    """What the study varies: the grading widths, the frictions, seeds per point, quick or full."""

    cus: list[float]
    mus: list[float]
    seeds: int
    quick: bool


@dataclass(eq=False)
class SensitivitySettings(StudySettings):
    """The study's settings as its file records them: beside what it varies, the seeds run, the
    preparation friction of the grading axis and the first trial of its protocol."""

    seed_list: list[int] | None = None
    mu_prep: float | None = None
    n_lab: float | None = None
    first_trial: float | None = None
    first_trial_from: str | None = None


@dataclass(eq=False)
class GradingDescription(TypedResult):
    """One grading of the study: its label (the reference, or ``Cu x``), widths and sizes."""

    label: str
    cu_nominal: float | None
    cu: float
    d10_mm: float
    d50_mm: float
    d_min_mm: float
    d_max_mm: float
    mean_disk_area_m2: float
    sizes_m: list[float]
    percent_passing: list[float]
    source: str


@dataclass(eq=False)
class SeedRecord(TypedResult):
    """One criterion run of the grading axis, flattened: accepted n2D, first and accepted trial."""

    grading: str
    cu: float
    seed: int
    status: str | None
    converged: bool
    accepted_n2d: float | None
    accepted_measured_n2d: float | None
    accepted_interior_porosity: float | None
    last_estimate_n2d: float | None
    iterations: int | None
    first_trial_porosity: float | None
    first_f_top_n_per_m: float | None
    first_self_weight_n_per_m: float | None
    first_f_top_over_g: float | None
    first_plate_moved: float | None
    first_new_porosity: float | None
    accepted_f_top_n_per_m: float | None
    accepted_f_bottom_n_per_m: float | None
    accepted_self_weight_n_per_m: float | None
    message: str | None
    time_s: float | None


@dataclass(eq=False)
class GradingPoint(TypedResult):
    """One grading over its seeds: the accepted n2D, and the first trial's forces beside it."""

    axis: str
    label: str
    cu: float
    cu_nominal: float | None
    d50_mm: float
    d_max_mm: float
    n2d_mean: float
    n2d_sd: float
    n: int
    seeds: int
    unconverged: int
    quantity: str
    measured_mean: float
    measured_sd: float
    interior_mean: float | None = None
    interior_sd: float | None = None
    first_f_top_mean: float | None = None
    first_f_top_sd: float | None = None
    first_g_mean: float | None = None
    first_g_sd: float | None = None
    first_f_top_over_g_mean: float | None = None
    first_f_top_over_g_sd: float | None = None
    first_n_prime_mean: float | None = None
    first_n_prime_sd: float | None = None
    accepted_f_top_mean: float | None = None
    accepted_f_top_sd: float | None = None
    first_trial_porosity: float | None = None


@dataclass(eq=False)
class MuPoint(TypedResult):
    """One preparation friction of the calibration: n' of the accepted trial over its seeds."""

    axis: str
    label: str
    mu_prep: float
    n2d_mean: float
    n2d_sd: float
    n: int
    seeds: int
    unconverged: int
    quantity: str


@dataclass(eq=False)
class SensitivityPoints(TypedResult):
    """The study's two axes: one point per grading (the reference first), one per friction."""

    PARTS = {"grading": GradingPoint, "mu_prep": MuPoint}

    grading: list[GradingPoint]
    mu_prep: list[MuPoint]


@dataclass(frozen=True)
class PointRow(Record):
    """A row of ``sensitivity.csv``: the point's own columns (a grading's or a friction's, which
    differ), then whether it reproduces the paper's n2D, the seeds and the version."""

    ROW = (Spliced("point"), "reproduces_paper", "seed_list", "poro2d_version")

    point: GradingPoint | MuPoint
    reproduces_paper: bool
    seed_list: str
    poro2d_version: str

    @classmethod
    def of(
        cls, point: GradingPoint | MuPoint, target: float, tolerance: float, seeds: list[int], version: str
    ):
        """The row of ``point``: it reproduces the paper when its mean lies within ``tolerance``
        of ``target``."""
        mean = point.n2d_mean
        close = mean is not None and math.isfinite(mean) and abs(mean - target) <= tolerance + 1e-12
        return cls(point, close, " ".join(map(str, seeds)), version)


@dataclass(eq=False)
class Match(TypedResult):
    """Where an axis meets a target n2D: the points within the tolerance, the closest one, and
    where the means cross it (linear interpolation). Only the first four when no point counts."""

    matches: list[float]
    closest: float | None
    closest_mean: float | None = None
    closest_sd: float | None = None
    closest_n: int | None = None
    distance: float | None = None
    crossing: float | None = None
    ends: list[list[float]] | None = None


@dataclass(eq=False)
class Answer(TypedResult):
    """Which grading width and which friction accept the paper's n2D, and the lines saying so."""

    PARTS = {"grading": Match, "mu_prep": Match}

    target: float
    tolerance: float
    grading: Match
    mu_prep: Match
    lines: list[str]


@dataclass(eq=False)
class GradingSweeps(TypedResult):
    """The grading axis's sweep: its summary and the cases that failed."""

    PARTS = {"grading": SweepSummary}

    grading: SweepSummary
    failed_cases: int


@dataclass(eq=False)
class StudyCalibration(TypedResult):
    """The density calibration of a sensitivity study (its ``calibration``): the row of its
    :class:`~poro2d.criterion.density.Calibration` (mu_prep -> n2D over seeds) merged with where
    it ran (the fields of :class:`~poro2d.sweep.records.CalibrationRun`); ``failed`` is the run's
    count of failed cases, which takes the place of the per-friction seeds not accepted (the
    field keeps its place in the file).
    """

    PARTS = {"summary": SweepSummary}

    mus: list[float]
    samples: list[list[float | None]]
    seeds: list[int]
    mean: list[float | None]
    sd: list[float | None]
    fitted: list[float | None]
    failed: int | list[int] | None
    dropped: list[float]
    key: str
    cases: str
    ran: int
    reused: int
    source: str
    interior: list[list[float | None]] | None = None
    summary: SweepSummary | None = None


@dataclass(eq=False)
class StudyTimings(TypedResult):
    """Where a sensitivity study's time went (s): the grading sweep, the friction calibration, all."""

    grading_s: float
    mu_prep_s: float
    total_s: float | None = None


__all__ = [
    "StudyCalibration",
    "StudyTimings",
    "Answer",
    "GradingDescription",
    "GradingPoint",
    "GradingSweeps",
    "Match",
    "MeanSd",
    "MuPoint",
    "PaperNumbers",
    "SeedRecord",
    "SensitivityPoints",
    "SensitivitySettings",
    "StudySettings",
]
