"""The typed parts of the sweeps' result files: summaries, fits, points, answers.

A result file of the sweeps (``sweep.json``, ``relation.json``, ``density.json``,
``sensitivity.json``) nests records of a known shape: a sweep's summary, the parabola
fitted to a relation, one point per laboratory state, the answer of the sensitivity study.
Each is a :class:`~poro2d.typed_result.TypedResult` here, its fields the record's keys in
the file's order, so it is written and read back with exactly the keys it had, and still
reads as the dict it was (``fit["a"]``). A result holding parts names them in ``PARTS``
(field -> record class), which the base class reads and writes.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Self

from poro2d.execute.core_share import WorkerUse
from poro2d.labtest.records import ByName
from poro2d.typed_result import TypedResult

if TYPE_CHECKING:
    from poro2d.criterion.result import CriterionResult

#: the conversion methods a relation point is compared with (the table; the figure draws the same)
COMPARE = ("parabolic", "lim_3d", "lim_lab", "densest_state")


def ending_with(annotations: Mapping[str, str]):
    """Class decorator, under ``@dataclass``: the fields ``annotations`` (name -> type) appended to
    the class's own, so that keys several records end with are declared once, in one table."""

    def add(cls: type) -> type:
        cls.__annotations__.update(annotations)
        return cls

    return add


@dataclass(eq=False)
class CaseRow(TypedResult):
    """A case's row (its ``result.json``, or its ``error.json`` when it raised on a worker).

    Where and when it ran, ``status`` (done or failed), the error, and ``results``: the
    case kind's scalars, the cells of the sweep's table. A row in memory may carry labels
    that are not in the file (``reused``: read back, not run), kept as ``extra``.
    """

    case_id: str
    kind: str
    params: dict[str, Any]
    host: str | None
    pid: int | None
    worker: str | None
    started_utc: str | None
    status: str | None
    error: str | None
    time_s: float | None
    finished_utc: str | None
    results: dict[str, Any] | None


#: a trial's porosities a criterion case keeps, of its last (``last_<name>``) and first trial
PROBED = ("trial_porosity", "new_porosity")
#: a trial's disks and walls a criterion case keeps, of its last trial as they are, of its first
#: as ``first_<name>``
WALLS = ("particle_count", "plate_moved", "f_top_n_per_m", "f_bottom_n_per_m", "self_weight_n_per_m")


@dataclass(eq=False)
class CriterionCaseResults(ByName, TypedResult):
    """The table cells of a criterion case (``results`` of its row): the run's answer, then the
    accepted trial (else the last), then the first trial (the paper reports its forces too, its
    Fig. 5), then the accepted specimen's own porosity beside the paper's box porosity n'."""

    n_lab: float
    final_porosity: float
    converged: bool
    iterations: int
    message: str
    initial_trial_porosity: float | None
    last_trial_porosity: float | None
    last_new_porosity: float | None
    particle_count: int | None
    plate_moved: bool | None
    f_top_n_per_m: float | None
    f_bottom_n_per_m: float | None
    f_top_after_n_per_m: float | None
    f_bottom_after_n_per_m: float | None
    self_weight_n_per_m: float | None
    first_trial_porosity: float | None
    first_particle_count: int | None
    first_f_top_n_per_m: float | None
    first_f_bottom_n_per_m: float | None
    first_self_weight_n_per_m: float | None
    first_plate_moved: bool | None
    first_new_porosity: float | None
    criterion_time_s: float | None
    box_porosity: float | None
    interior_porosity: float | None
    interior_porosity_std: float | None
    surface_gap_mean_d50: float | None
    plate_contact_fraction: float | None

    @classmethod
    def of(cls, res: CriterionResult) -> CriterionCaseResults:
        """The cells of a criterion result (its trials as the dicts of its file).

        The accepted trial is not always the last (see ``poro2d.criterion.protocol.closed_bracket``).
        """
        its = [trial.to_dict() for trial in res.iterations]  # each trial's cells as its row holds them
        first = its[0] if its else {}
        last = next((r for r in its if r.get("accepted")), its[-1] if its else {})
        # the run's answer and the accepted specimen's porosities are read off it by name
        return super().of(
            res,
            converged=bool(res.converged),
            iterations=len(its),
            **{f"last_{key}": last.get(key) for key in PROBED},
            **{key: last.get(key) for key in (*WALLS, "f_top_after_n_per_m", "f_bottom_after_n_per_m")},
            **{f"first_{key}": first.get(key) for key in (*PROBED, *WALLS)},
            criterion_time_s=res.time_total_s,
        )


@dataclass(eq=False)
class LostCaseRow(TypedResult):
    """The row of a case whose task failed outside the case (its worker lost): its ``error.json``."""

    case_id: str
    kind: str
    params: dict[str, Any]
    status: str
    error: str
    time_s: float | None
    results: dict[str, Any]
    host: str | None
    pid: int | None
    worker: str | None
    finished_utc: str


def case_row(row: Mapping[str, Any] | CaseRow | LostCaseRow) -> CaseRow | LostCaseRow:
    """A case's row typed: the dict of one (built by hand, or read from a file) as a :class:`CaseRow`."""
    return row if isinstance(row, CaseRow | LostCaseRow) else CaseRow.from_dict(row)


@dataclass(eq=False)
class CaseEntry(TypedResult):
    """A case as ``sweep.json`` lists it: its id (its folder's name) and its parameters."""

    id: str
    params: dict[str, Any]


@dataclass(eq=False)
class SweepSummary(TypedResult):
    """A sweep's counts and times (``summary`` of ``sweep.json``).

    ``parallel_efficiency``: busy case time over wall time and worker threads (when a
    cluster ran cases); ``from_calibration``: the state checks read back from the
    calibration's cases (a relation's ``states_summary``); ``worker_use``: cases per worker,
    threads per case over time and idle core-time (when cases ran).
    """

    OPTIONAL = ("worker_use",)
    PARTS = {"worker_use": WorkerUse}

    cases: int | None = None
    ran: int | None = None
    reused: int | None = None
    done: int | None = None
    failed: int | None = None
    wall_time_s: float | None = None
    case_time_sum_s: float | None = None
    worker_processes: list[str] | None = None
    parallel_efficiency: float | None = None
    from_calibration: int | None = None
    worker_use: WorkerUse | None = None


@dataclass(eq=False)
class CalibrationRun(TypedResult):
    """Where a calibration's cases are and how many ran (``sweeps.calibration`` of a relation).

    ``key``: the digest naming its cache entry; ``cases``: the folder of its sweep;
    ``source``: "computed" when a case ran, else "cache"; ``interior``: the accepted
    specimens' interior porosity per friction and seed (only for calibrations whose first
    trials follow the grading, see :class:`~poro2d.sweep.density.CalibrationCase`);
    ``summary`` and ``failed``: its sweep's summary and failed cases.
    """

    OPTIONAL = ("interior",)
    PARTS = {"summary": SweepSummary}

    key: str
    cases: str
    ran: int
    reused: int
    source: str
    interior: list[list[float | None]] | None = None
    summary: SweepSummary | None = None
    failed: int | None = None


@dataclass(eq=False)
class SeedReplaced(TypedResult):
    """A seed whose specimen was not accepted (``seeds_replaced`` of ``sand.json`` and of a
    density-mode criterion's ``density.json``): why, and the seed tried in its place (None once
    the replacements were spent)."""

    seed: int
    reason: str
    replaced_by: int | None


@dataclass(eq=False)
class DensitySweeps(TypedResult):
    """The two sweeps of density mode: the calibration's, the state checks' and their failures;
    with a seed replaced (one state's checks), the seeds accepted and those replaced."""

    PARTS = {"calibration": CalibrationRun, "states_summary": SweepSummary, "seeds_replaced": SeedReplaced}
    OPTIONAL = ("seeds_used", "seeds_replaced")

    calibration: CalibrationRun
    states_summary: SweepSummary
    failed_cases: int
    seeds_used: list[int] | None = None
    seeds_replaced: list[SeedReplaced] | None = None


@dataclass(eq=False)
class QuadraticFit(TypedResult):
    """n2D = a nLab^2 + b nLab fitted by least squares (no constant: through the origin).

    ``residuals``: data minus fit per point; ``r2``: about the mean (None for equal values).
    """

    a: float
    b: float
    points: int
    residuals: list[float]
    rms_residual: float
    max_abs_residual: float
    r2: float | None
    form: str


@dataclass(eq=False)
class Spread(TypedResult):
    """The loosest minus the densest converged state of a relation, measured (not a fit).

    The same for the interior porosity (the packing's own, no gap under the plate);
    ``monotone``: n2D never rises from loose to dense.
    """

    loose_n_lab: float
    dense_n_lab: float
    n2d_loose_minus_dense: float
    sd: float
    monotone: bool
    interior_loose_minus_dense: float | None = None
    interior_sd: float | None = None
    interior_monotone: bool | None = None


@dataclass(eq=False)
class RelationPoint(TypedResult):
    """One laboratory state of a relation: a paper-mode point (it names its case) or a density-mode one.

    A relation's file holds either kind in its ``points``; reading a point as a
    ``RelationPoint`` gives the kind its keys say.
    """

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Self:
        if cls is RelationPoint:
            return (PaperPoint if "case_id" in data else DensityPoint).from_dict(data)
        return super().from_dict(data)


#: the keys every relation point ends with: the conversions compared, then the fitted parabola
#: there, the point's distance from it and from Eq. 12 (None without a fit)
POINT_ENDS = dict.fromkeys(
    [*(f"n2d_{m}" for m in COMPARE), "n2d_fit", "residual", "dem_minus_parabola"], "float | None"
)


@dataclass(eq=False)
@ending_with(POINT_ENDS)
class PaperPoint(RelationPoint):
    """One laboratory state of a paper-mode relation: its case, the criterion's n2D, the methods.

    ``n2d_dem``: the accepted n2D, else the last estimate n' (``flag`` says which) or NaN for
    a failed case.
    """

    case_id: str
    n_lab: float
    relative_density: float
    degree_of_density: float
    n2d_dem: float
    converged: bool
    flag: str
    iterations: int | None
    initial_trial_porosity: float | None
    particle_count: int | None
    message: str | None


@dataclass(eq=False)
@ending_with(POINT_ENDS)
class DensityPoint(RelationPoint):
    """One laboratory state of a density-mode relation: its target, friction and n2D over seeds.

    ``n2d_dem``: the mean accepted n2D of the converged seeds (``n2d_seeds`` each);
    ``n2d_measured``: the mean measured n' of those trials; ``n2d_interior``: the mean
    interior porosity of their specimens.
    """

    n_lab: float
    relative_density: float
    degree_of_density: float
    n2d_target: float
    mu_prep: float
    n2d_dem: float
    n2d_sd: float
    n2d_seeds: list[float]
    n2d_measured: float
    n2d_measured_sd: float
    n2d_interior: float | None
    n2d_interior_sd: float | None
    n2d_interior_seeds: list[float] | None
    seeds: int
    seeds_converged: int
    converged: bool
    flag: str
    message: str


@dataclass(eq=False)
class Eq12Coefficients(TypedResult):
    """The coefficients of the paper's Eq. 12, n2D = a nLab^2 + b nLab, a relation is set beside."""

    a: float
    b: float


__all__ = [
    "COMPARE",
    "CalibrationRun",
    "CaseEntry",
    "CaseRow",
    "CriterionCaseResults",
    "DensityPoint",
    "DensitySweeps",
    "Eq12Coefficients",
    "LostCaseRow",
    "PaperPoint",
    "QuadraticFit",
    "RelationPoint",
    "SeedReplaced",
    "Spread",
    "SweepSummary",
    "case_row",
    "ending_with",
]
