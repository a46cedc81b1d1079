"""Typed results of the sweeps: ``sweep.json``, ``density.json``, ``relation.json`` and ``sensitivity.json``.

Each class lists its file's keys as fields, in the file's order (see
:mod:`poro2d.typed_result`); the runs build the dict they wrote before and return it as
``Class.from_dict(...)``, so the files stay what they were and a key a mode does not write
stays out of the file. Their nested records (a sweep's summary, a relation's fit and
points) are typed parts (:mod:`poro2d.sweep.records`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from poro2d.criterion.density import Calibration
from poro2d.critical_state.state_table import StateMapRecord
from poro2d.execute.dask_cluster import ClusterInfo
from poro2d.io_utils import Provenance
from poro2d.store import Store
from poro2d.sweep.records import (
    CalibrationRun,
    CaseEntry,
    CaseRow,
    DensityPoint,
    DensitySweeps,
    Eq12Coefficients,
    LostCaseRow,
    PaperPoint,
    QuadraticFit,
    RelationPoint,
    Spread,
    SweepSummary,
)
from poro2d.sweep.sensitivity_records import (
    Answer,
    GradingDescription,
    GradingSweeps,
    PaperNumbers,
    SeedRecord,
    SensitivityPoints,
    SensitivitySettings,
    StudyCalibration,
    StudyTimings,
)
from poro2d.typed_result import NOT_IN_FILE, TypedResult

if TYPE_CHECKING:  # pandas is imported where a table is made, not with the results
    import pandas as pd


@dataclass(eq=False)
class SweepResult(TypedResult):
    """A finished sweep (its ``sweep.json``), with every case's row and the table of them.

    ``cases``: id and parameters of each case; ``config``: the sweep's config as given;
    ``cluster``: where the cases ran (empty when every case was reused); ``summary``: cases
    run, reused and failed, their times. ``rows`` (not in the file): one row per case in
    the sweep's order (``status``, ``results``, ``reused``, where and when it ran);
    ``table``: the same as a pandas DataFrame (``results.csv``); ``store`` (not in the file):
    the sweep's store, which hands out each case's (:meth:`case_store`).
    """

    PARTS = {"cases": CaseEntry, "summary": SweepSummary, "cluster": ClusterInfo, "provenance": Provenance}

    status: str
    title: str
    kind: str
    axes: list[str]
    cases: list[CaseEntry]
    config: dict[str, Any]
    base_dir: str | None
    retries: int
    provenance: Provenance
    cluster: ClusterInfo
    summary: SweepSummary
    finished_utc: str
    rows: list[CaseRow | LostCaseRow] = field(
        default_factory=list, kw_only=True, repr=False, metadata=NOT_IN_FILE
    )
    table: pd.DataFrame | None = field(default=None, kw_only=True, repr=False, metadata=NOT_IN_FILE)
    store: Store | None = field(default=None, kw_only=True, repr=False, metadata=NOT_IN_FILE)

    @property
    def failed(self) -> list[CaseRow | LostCaseRow]:
        """The rows of the cases that failed."""
        return [r for r in self.rows if r.status == "failed"]

    def case_store(self, case_id: str) -> Store:
        """What case ``case_id`` wrote (``cases/<id>/run``: its kind's files, a criterion run's)."""
        assert self.store is not None, "a sweep read from its file alone knows no store"
        return self.store.child("cases", case_id, "run")


@dataclass(eq=False)
class DensityStateResult(TypedResult):
    """The density-controlled criterion for one laboratory state (``density.json``).

    The state (``n_lab``, ``relative_density``), its 2D target and preparation friction
    from the calibration, and the accepted n2D over seeds (mean, sd, per seed; NaN mean
    when no seed converged), the measured n' and the interior porosity beside it.
    ``converged``: every seed accepted. ``sweeps``: where the calibration came from and
    the state sweep's summary.
    """

    PARTS = {"sweeps": DensitySweeps, "calibration": Calibration, "provenance": Provenance}

    mode: str
    n_lab: float
    relative_density: float
    n2d_target: float
    mu_prep: float
    final_porosity_mean: float
    final_porosity_sd: float
    final_porosity_per_seed: list[float]
    measured_porosity_mean: float
    interior_porosity_mean: float | None
    interior_porosity_sd: float | None
    interior_porosity_per_seed: list[float] | None
    seeds: int
    seeds_converged: int
    converged: bool
    n2d_min: float
    n2d_max: float
    calibration: Calibration
    sweeps: DensitySweeps
    config: dict[str, Any]
    provenance: Provenance


@dataclass(eq=False)
class RelationResult(TypedResult):
    """The relation n2D(nLab) of one grading (``relation.json``).

    ``points``: one dict per laboratory state, loose to dense; ``fit``: the Eq. 12-form
    parabola through the converged points (None with fewer than two). Density mode adds
    the calibration, the calibrated 2D extremes, the loose-dense ``spread`` and ``sweeps``
    (calibration and state sweeps); paper mode the one sweep's ``sweep_summary``.
    """

    PARTS = {"points": RelationPoint, "fit": QuadraticFit, "spread": Spread,
             "sweep_summary": SweepSummary, "sweeps": DensitySweeps, "eq12": Eq12Coefficients,
             "calibration": Calibration, "provenance": Provenance,
             "state_maps": StateMapRecord}  # fmt: skip
    #: with a ``[state]`` table, both maps of every state (:mod:`poro2d.critical_state.state_table`)
    OPTIONAL = ("state_maps",)

    n_max: float
    n_min: float
    points: list[PaperPoint | DensityPoint]
    fit: QuadraticFit | None
    fit_note: str
    eq12: Eq12Coefficients
    converged_points: int
    flagged_points: int
    mode: str
    calibration: Calibration | None = None
    n2d_max: float | None = None
    n2d_min: float | None = None
    spread: Spread | None = None
    quick: bool | None = None
    sweep_summary: SweepSummary | None = None
    config: dict[str, Any] | None = None
    sweeps: DensitySweeps | None = None
    provenance: Provenance | None = None
    state_maps: list[StateMapRecord] | None = None

    @property
    def failed_cases(self) -> int:
        """Cases that raised (their tracebacks are in the output folder), over every sweep."""
        if self.sweeps is not None:
            return int(self.sweeps.failed_cases)
        return int(self.sweep_summary.failed or 0) if self.sweep_summary is not None else 0


@dataclass(eq=False)
class SensitivityResult(TypedResult):
    """The accepted n2D against grading width and preparation friction (``sensitivity.json``).

    ``points``: ``grading`` (one per Cu, the reference first) and ``mu_prep`` (one per
    friction, from the density calibration); ``seeds``: one record per grading and seed;
    ``answer``: which width or friction reproduces the paper's 0.15, in lines of text;
    ``figure``: the figure's path (a study read back points it into its folder).
    """

    PARTS = {"settings": SensitivitySettings, "gradings": GradingDescription,
             "seeds": SeedRecord, "points": SensitivityPoints, "sweeps": GradingSweeps,
             "answer": Answer, "paper": PaperNumbers, "calibration": StudyCalibration,
             "timings": StudyTimings, "provenance": Provenance}  # fmt: skip

    title: str
    settings: SensitivitySettings
    gradings: list[GradingDescription]
    seeds: list[SeedRecord]
    points: SensitivityPoints
    calibration: StudyCalibration
    paper: PaperNumbers
    config: dict[str, Any]
    sweeps: GradingSweeps
    timings: StudyTimings
    answer: Answer
    figure: str | None = None
    provenance: Provenance | None = None


__all__ = ["CalibrationRun", "DensityStateResult", "RelationResult", "SensitivityResult", "SweepResult"]
