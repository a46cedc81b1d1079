"""The 2D material's critical-state line: the periodic cell's steady state over several pressures.

Each pressure is a critical-state study over seeds (:func:`poro2d.critical_state.run`), all of
them jobs of one executor so that the worker processes stay busy over the whole line. The line
is written as soils are, e_cs = e_Gamma - lambda ln(p' / 1 kPa) (Been & Jefferies 1985; Verdugo
& Ishihara 1996 for Toyoura sand), with p' the window's mean stress (sigma_xx + sigma_yy) / 2 and
e = (1 - phi) / phi the 2D void ratio of the disks. It is fitted by least squares through every
seed's steady state (not the pressures' means), so the fit weighs the seeds' scatter.

With linear contacts the slope lambda is the contacts' softness, not the grains' crushing that
makes a laboratory line bend: at a fixed stiffness the overlaps grow as 1 / kappa with
kappa = kn / (p t), so the solid fraction rises with pressure. A case with ``stiffness_number``
holds kappa fixed (the rigid-grain limit when large): its line shows what the disks' arrangement
alone gives (docs/critical-state.md, "The critical-state line").
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from poro2d.critical_state.case import CriticalStateCase
from poro2d.critical_state.results import CriticalStateResult, CriticalStateTestResult, void_ratio
from poro2d.critical_state.run import KIND, MAX_SEEDS, seed_runs, seed_store, study_of, write_study
from poro2d.errors import InputError, check_int
from poro2d.execute import RunOptions
from poro2d.io_utils import Provenance
from poro2d.labtest.records import StudyRun, typed_parts
from poro2d.measure.spread import Spread
from poro2d.store import Store, claimed
from poro2d.typed_result import NOT_IN_FILE, TypedResult, with_fields

#: the most pressures one line may hold, and the fewest it needs for a slope with a scatter
MAX_PRESSURES = 12
MIN_PRESSURES = 2
#: the reference pressure of e_Gamma (kPa): the line's intercept is its void ratio at 1 kPa
REFERENCE_KPA = 1.0
#: the table of a line: a row per pressure (:meth:`LinePoint.row`)
LINE_CSV = "line.csv"


def window_mean_stress(test: CriticalStateTestResult) -> float:
    """The steady window's mean of p' = (sigma_xx + sigma_yy) / 2 (kPa) of one seed's run."""
    s = test.series
    return float(s.mean_stress_kpa[s.window(test.case.window_start)].mean())


@typed_parts
@dataclass(eq=False)
class LinePoint(TypedResult):
    """One pressure of the line: its study's numbers over the seeds (see the module)."""

    pressure_kpa: float
    mean_stress_kpa: Spread
    void_ratio: Spread
    solid_fraction: Spread
    stress_ratio: Spread
    friction_angle_deg: Spread
    coordination: Spread
    stiffness_number: float
    mean_overlap_ratio: Spread
    steady: bool
    note: str

    @classmethod
    def of(cls, pressure_kpa: float, study: CriticalStateResult) -> LinePoint:
        return cls(
            pressure_kpa=pressure_kpa,
            mean_stress_kpa=Spread.of([window_mean_stress(t) for t in study.tests]),
            void_ratio=Spread.of([void_ratio(t.solid_fraction) for t in study.tests]),
            solid_fraction=study.solid_fraction,
            stress_ratio=study.stress_ratio,
            friction_angle_deg=study.friction_angle_deg,
            coordination=study.coordination,
            stiffness_number=float(study.stiffness_number),
            mean_overlap_ratio=study.mean_overlap_ratio,
            steady=study.steady,
            note=study.note,
        )

    def row(self) -> dict[str, float | bool]:
        """The point as a row of ``line.csv`` (means, and the seeds' sd where it matters)."""
        return {
            "pressure_kpa": self.pressure_kpa,
            "mean_stress_kpa": self.mean_stress_kpa.mean,
            "void_ratio": self.void_ratio.mean,
            "void_ratio_sd": self.void_ratio.sd if self.void_ratio.sd is not None else math.nan,
            "solid_fraction": self.solid_fraction.mean,
            "stress_ratio": self.stress_ratio.mean,
            "stress_ratio_sd": self.stress_ratio.sd if self.stress_ratio.sd is not None else math.nan,
            "friction_angle_deg": self.friction_angle_deg.mean,
            "coordination": self.coordination.mean,
            "stiffness_number": self.stiffness_number,
            "mean_overlap_ratio": self.mean_overlap_ratio.mean,
            "steady": self.steady,
        }


@dataclass(eq=False)
class LineFit(TypedResult):
    """e_cs = e_gamma - lambda_ln ln(p' / reference_kpa), least squares through ``points`` values.

    lambda_log10 = lambda_ln ln 10 (the slope per decade, as lines are often published);
    r2 the share of the void ratio's variance the line explains (None when the void ratios do
    not vary); residual_sd the scatter about the line.
    """

    e_gamma: float
    lambda_ln: float
    lambda_log10: float
    reference_kpa: float
    r2: float | None
    residual_sd: float
    points: int
    definition: str

    @classmethod
    def through(cls, p_kpa: np.ndarray, e: np.ndarray) -> LineFit:
        """The least-squares line of ``e`` against ln(``p_kpa`` / reference)."""
        x = np.log(np.asarray(p_kpa, float) / REFERENCE_KPA)
        y = np.asarray(e, float)
        if x.size < 2 or np.ptp(x) == 0.0:
            raise InputError("pressures", sorted(set(np.round(np.exp(x), 6))), "at least two pressures")
        slope, intercept = np.polyfit(x, y, 1)
        resid = y - (intercept + slope * x)
        total = float(np.sum((y - y.mean()) ** 2))
        dof = max(x.size - 2, 1)
        return cls(
            e_gamma=float(intercept),
            lambda_ln=float(-slope),
            lambda_log10=float(-slope * math.log(10.0)),
            reference_kpa=REFERENCE_KPA,
            r2=1.0 - float(np.sum(resid**2)) / total if total > 0.0 else None,
            residual_sd=math.sqrt(float(np.sum(resid**2)) / dof),
            points=int(x.size),
            definition="e_cs = e_gamma - lambda_ln ln(p' / reference_kpa); e = (1 - phi) / phi, "
            "p' = (sigma_xx + sigma_yy) / 2 over the steady window, every seed a point",
        )

    def void_ratio_at(self, p_kpa: float) -> float:
        """e_cs of the line at the mean stress ``p_kpa``."""
        return self.e_gamma - self.lambda_ln * math.log(p_kpa / self.reference_kpa)

    def text(self) -> str:
        return f"e_cs = {self.e_gamma:.4f} - {self.lambda_ln:.4f} ln(p'/kPa)"


#: how far beyond its outermost points a measured line is read (a share of p'): the nominal
#: pressures sit within about 2 % of the measured mean stresses
READ_BEYOND = 0.1


@dataclass(frozen=True)
class MeasuredLine:
    """The line through a study's points themselves: e_cs(p') read linearly in ln p' between the
    pressures' mean (p', e) points. With linear contacts the line bends (its slope grows as
    1 / kappa), so the points, not the fitted straight line, say e_cs at a given stress."""

    p_kpa: tuple[float, ...]
    e: tuple[float, ...]

    def void_ratio_at(self, p_kpa: float) -> float:
        """e_cs at ``p_kpa``, refused beyond the points by more than :data:`READ_BEYOND`."""
        lo, hi = self.p_kpa[0], self.p_kpa[-1]
        if not lo * (1.0 - READ_BEYOND) <= p_kpa <= hi * (1.0 + READ_BEYOND):
            raise InputError("p'", p_kpa, f"[{lo:.3g}, {hi:.3g}] kPa, the 2D line's pressures")
        x = np.log(self.p_kpa)
        k = int(np.clip(np.searchsorted(x, math.log(p_kpa)), 1, x.size - 1))
        w = (math.log(p_kpa) - x[k - 1]) / (x[k] - x[k - 1])
        return float(self.e[k - 1] + w * (self.e[k] - self.e[k - 1]))


@dataclass(eq=False)
class StateMark(TypedResult):
    """A 2D state held against the line: its label, its void ratio, and at each of the line's
    pressures its state parameter psi = e - e_cs(p') (``psi``, in the order of ``pressures_kpa``)
    and psi over ``span`` (the 2D preparation's e_max - e_min; None when not given)."""

    label: str
    void_ratio: float
    psi: list[float]
    span: float | None
    psi_normalised: list[float] | None

    @classmethod
    def of(cls, label: str, e: float, line, pressures: list[float], span: float | None) -> StateMark:
        """``line``: what reads e_cs at a pressure (:class:`MeasuredLine`)."""
        psi = [e - line.void_ratio_at(p) for p in pressures]
        return cls(label, float(e), psi, span, None if not span else [v / span for v in psi])


@typed_parts
@dataclass(eq=False)
@with_fields(StudyRun, after="case")
class CriticalStateLineResult(TypedResult):
    """The line over ``pressures_kpa`` (the study's ``result.json``): a point per pressure, the fit
    through every seed, the stress ratio pooled over every run; ``steady`` only if every run was
    (``note`` names those that were not). ``studies`` (not in the file): each pressure's study."""

    pressures_kpa: list[float]
    seeds: list[int]
    line: LineFit
    points: list[LinePoint]
    stress_ratio: Spread
    friction_angle_deg: Spread
    steady: bool
    note: str
    case: CriticalStateCase
    marks: list[StateMark] | None = None
    studies: list[CriticalStateResult] = field(
        default_factory=list, kw_only=True, repr=False, metadata=NOT_IN_FILE
    )

    OPTIONAL: ClassVar[tuple[str, ...]] = ("marks",)

    def measured(self) -> MeasuredLine:
        """The line through the points (:class:`MeasuredLine`), by rising mean stress."""
        return measured_line(self.points)

    def headline(self) -> str:
        """The line and the pooled friction, with the range of pressures and seeds."""
        lo, hi = min(self.pressures_kpa), max(self.pressures_kpa)
        n = len(self.seeds)
        state = "critical-state line" if self.steady else "end-state line (NOT STEADY)"
        r2 = f", R2 {self.line.r2:.2f}" if self.line.r2 is not None else ""
        return (
            f"{state}: {self.line.text()} over {lo:g}-{hi:g} kPa{r2}; tau/sigma = "
            f"{self.stress_ratio.text()}, phi = {self.friction_angle_deg.text(1)} deg "
            f"({len(self.pressures_kpa)} pressures x {n} seed{'s' if n > 1 else ''})"
        )


def line_result(
    case: CriticalStateCase, pressures: list[float], studies: list[CriticalStateResult], *,
    processes: int, wall_time_s: float, config: dict | None,
    marks: list[tuple[str, float]] | None = None, span: float | None = None,
) -> CriticalStateLineResult:  # fmt: skip
    """The line's result from its pressures' studies (each holding its seeds' tests); ``marks``:
    (label, 2D void ratio) states to hold against the line, ``span`` the 2D e_max - e_min."""
    points = [LinePoint.of(p, s) for p, s in zip(pressures, studies, strict=True)]
    tests = [t for s in studies for t in s.tests]
    fit = LineFit.through(
        np.array([window_mean_stress(t) for t in tests]),
        np.array([void_ratio(t.solid_fraction) for t in tests]),
    )
    missed = [f"{p:g} kPa" for p, s in zip(pressures, studies, strict=True) if not s.steady]
    note = (
        "every run reached a steady state"
        if not missed
        else f"not steady at {', '.join(missed)}: those points are not on the critical-state line"
    )
    result = CriticalStateLineResult(
        pressures_kpa=list(pressures),
        seeds=list(studies[0].seeds),
        line=fit,
        points=points,
        stress_ratio=Spread.of([t.stress_ratio for t in tests]),
        friction_angle_deg=Spread.of([t.friction_angle_deg for t in tests]),
        steady=not missed,
        note=note,
        case=case,
        processes=processes,
        wall_time_s=wall_time_s,
        config=config or {},
        provenance=Provenance.now(),
        marks=[StateMark.of(label, e, measured_line(points), list(pressures), span) for label, e in marks]
        if marks
        else None,
        studies=list(studies),
    )
    return result


def measured_line(points: list[LinePoint]) -> MeasuredLine:
    """The line through ``points`` (:class:`MeasuredLine`), by rising mean stress."""
    pts = sorted(points, key=lambda pt: pt.mean_stress_kpa.mean)
    return MeasuredLine(tuple(pt.mean_stress_kpa.mean for pt in pts), tuple(pt.void_ratio.mean for pt in pts))


def pressure_folder(pressure_kpa: float) -> str:
    """The sub-folder of one pressure's study: ``p100kPa``."""
    return f"p{pressure_kpa:g}kPa"


def check_pressures(pressures) -> list[float]:
    """The line's pressures as floats, each in the case's range, distinct, at least two."""
    from poro2d.critical_state.case import CASE_RANGES

    values = list(pressures) if not isinstance(pressures, str | bytes) else None
    if values is None or not MIN_PRESSURES <= len(values) <= MAX_PRESSURES:
        raise InputError(
            "pressures", pressures, f"a list of {MIN_PRESSURES} to {MAX_PRESSURES} pressures (kPa)"
        )
    for v in values:
        CASE_RANGES["pressure_kpa"].check("pressures", v)
    if len(set(values)) != len(values):
        raise InputError("pressures", values, "distinct pressures")
    return [float(v) for v in values]


def run_critical_state_line(
    case: CriticalStateCase,
    pressures: list[float],
    store: Store | None = None,
    *,
    seeds: int = 3,
    options: RunOptions = RunOptions(),
    config: dict | None = None,
    marks: list[tuple[str, float]] | None = None,
    span: float | None = None,
) -> CriticalStateLineResult:
    """``case`` at every pressure of ``pressures`` (kPa) on ``seeds`` seeds: the line e_cs(p').

    ``marks``: (label, 2D void ratio) states to hold against the line (a specimen's 2D ends, a
    state as mapped): each gets its state parameter at every pressure;
    ``span``: the 2D e_max - e_min that normalises it. Every (pressure, seed) run is one job of
    the executor. ``store``: the line's ``result.json`` and ``line.csv``, and per pressure a
    folder ``p<P>kPa/`` holding what a one-pressure study holds (its seeds' runs kept as they
    finish, read back on a rerun). Call it under ``if __name__ == "__main__":`` in a script
    when it runs on several processes (``options``; worker processes import the calling script).
    """
    if not isinstance(case, CriticalStateCase):
        raise InputError("case", type(case).__name__, "a CriticalStateCase")
    values = check_pressures(pressures)
    n = check_int("seeds", seeds, 1, MAX_SEEDS)
    if store is not None and not isinstance(store, Store):
        raise InputError("store", type(store).__name__, "a poro2d.store.Store or None")
    cases = [[case.at_pressure(p).with_seed(case.seed + k) for k in range(n)] for p in values]

    def work() -> CriticalStateLineResult:
        t0 = time.perf_counter()
        kept = [None if store is None else store.child(pressure_folder(p)) for p in values]
        flat = [(c, at) for row, at in zip(cases, kept, strict=True) for c in row]
        tests, workers = seed_runs([c for c, _ in flat], options, [seed_store(at, c) for c, at in flat])
        studies = []
        for k, row in enumerate(cases):
            studies.append(
                study_of(row, tests[k * n : (k + 1) * n], workers, time.perf_counter() - t0, config)
            )
            if kept[k] is not None:
                write_study(kept[k], row, studies[-1])
        result = line_result(
            case, values, studies, processes=workers, wall_time_s=time.perf_counter() - t0, config=config,
            marks=marks, span=span,
        )  # fmt: skip
        if store is not None:
            write_line(store, result)
        return result

    with claimed(store, KIND):
        return work()


def write_line(store: Store, result: CriticalStateLineResult) -> None:
    """``line.csv``, then ``result.json`` (last: it says the line is done)."""
    rows = [p.row() for p in result.points]
    store.write_csv(LINE_CSV, rows, header=list(rows[0]))
    store.write_result("result.json", result)


__all__ = [
    "CriticalStateLineResult",
    "LineFit",
    "LinePoint",
    "MeasuredLine",
    "StateMark",
    "check_pressures",
    "line_result",
    "pressure_folder",
    "run_critical_state_line",
    "window_mean_stress",
]
