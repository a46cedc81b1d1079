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
from poro2d.sweep.records import CalibrationRun, SweepSummary, ending_with
from poro2d.typed_result import TypedResult


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


#: the per-seed quantities a grading point averages: its key prefix, the seed record's field
AVERAGED = (
    ("measured", "accepted_measured_n2d"),
    ("interior", "accepted_interior_porosity"),
    ("first_f_top", "first_f_top_n_per_m"),
    ("first_g", "first_self_weight_n_per_m"),
    ("first_f_top_over_g", "first_f_top_over_g"),
    ("first_n_prime", "first_new_porosity"),
    ("accepted_f_top", "accepted_f_top_n_per_m"),
)


#: the keys a point of either axis goes on with: its n2D over the seeds and what that n2D is
AXIS_POINT_KEYS = dict(
    n2d_mean="float", n2d_sd="float", n="int", seeds="int", unconverged="int", quantity="str"
)
#: the keys a grading point ends with: the mean and sd of each of :data:`AVERAGED`, then its first trial
GRADING_POINT_ENDS = [
    *(f"{name}_{stat}" for name, _ in AVERAGED for stat in ("mean", "sd")),
    "first_trial_porosity",
]


@dataclass(eq=False)
@ending_with(dict.fromkeys(GRADING_POINT_ENDS, "float | None"))
@ending_with(AXIS_POINT_KEYS)
class GradingPoint(TypedResult):
    """One grading over its seeds: its widths, the accepted n2D (:data:`AXIS_POINT_KEYS`), then the
    mean and sd of each of :data:`AVERAGED` (the accepted trial's porosities, the first trial's forces
    beside it), then the first trial."""

    axis: str
    label: str
    cu: float
    cu_nominal: float | None
    d50_mm: float
    d_max_mm: float


@dataclass(eq=False)
@ending_with(AXIS_POINT_KEYS)
class MuPoint(TypedResult):
    """One preparation friction of the calibration: n' of the accepted trial over its seeds."""

    axis: str
    label: str
    mu_prep: float


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

    PARTS = dict.fromkeys(("grading", "mu_prep"), Match)

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
@ending_with({name: kind for name, kind in CalibrationRun.__annotations__.items() if name != "failed"})
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


@dataclass(eq=False)
class StudyTimings(TypedResult):
    """Where a sensitivity study's time went (s): the grading sweep, the friction calibration, all."""

    grading_s: float
    mu_prep_s: float
    total_s: float | None = None


__all__ = [
    "AVERAGED",
    "AXIS_POINT_KEYS",
    "GRADING_POINT_ENDS",
    "StudyCalibration",
    "StudyTimings",
    "Answer",
    "GradingDescription",
    "GradingPoint",
    "GradingSweeps",
    "Match",
    "MuPoint",
    "PaperNumbers",
    "SeedRecord",
    "SensitivityPoints",
    "SensitivitySettings",
    "StudySettings",
]
