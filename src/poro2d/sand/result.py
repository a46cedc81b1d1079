"""The answer of ``poro2d sand``: ``sand.json`` and the paste-ready summary beside it.

The first number is the specimen's own (interior) porosity, mean +- sd over seeds: the
porosity to give another code that fills a closed box (docs/porosity.md). The box porosity
n' (the criterion's, under the lid) follows it.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from poro2d.criterion.density import Calibration
from poro2d.critical_state.state_table import StateMapRecord, state_map_lines, state_map_record
from poro2d.execute.core_share import WorkerUse, use_text
from poro2d.io_utils import Provenance, float_or_nan
from poro2d.lab_state import LabState
from poro2d.labtest.records import ByName
from poro2d.sand.case import SoilRecord
from poro2d.sand.preflight import Preflight
from poro2d.sand.profile import StageProfile
from poro2d.sand.reached import StateReached
from poro2d.sand.spread import AnswerError
from poro2d.specimen.compaction import is_wide
from poro2d.store import Store
from poro2d.sweep.records import CaseRow, LostCaseRow, SeedReplaced
from poro2d.typed_result import NOT_IN_FILE, Keyed, TypedResult


def _stats(values: list[float | None]) -> tuple[float, float]:
    v = np.array([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    if v.size == 0:
        return math.nan, math.nan
    return float(v.mean()), float(v.std(ddof=1)) if v.size > 1 else 0.0


@dataclass(eq=False)
class SeedSpecimen(TypedResult):
    """One seed's specimen at full size: accepted or why not, its porosities, its folder.

    It is also the record ``sand.json`` keeps of each seed (``seed_results``).
    """

    seed: int
    accepted: bool
    box_porosity: float | None
    interior_porosity: float | None
    particle_count: int | None
    trials: int | None
    folder: str | None
    message: str = ""

    @classmethod
    def from_row(cls, seed: int, row: CaseRow | LostCaseRow, folder: str | None) -> SeedSpecimen:
        res = row.results or {}
        ok = row.status == "done" and bool(res.get("converged")) and folder is not None

        def num(key):
            v = res.get(key)
            return float(v) if v is not None and math.isfinite(float(v)) else None

        why = res.get("message") or row.error or ""
        return cls(
            seed,
            ok,
            num("last_new_porosity"),
            num("interior_porosity"),
            res.get("particle_count"),
            res.get("iterations"),
            folder,
            "" if ok else str(why),
        )


def replaced_seeds(kept: list[SeedSpecimen], requested: int) -> list[SeedReplaced]:
    """The seeds not accepted, in order, each with the seed tried after the requested ones in its place
    (the seeds run from the config's first seed, so the requested ones are the first ``requested``)."""
    extra = sorted(k.seed for k in kept)[requested:]
    refused = [k for k in kept if not k.accepted]
    by = extra + [None] * (len(refused) - len(extra))
    return [SeedReplaced(k.seed, k.message, b) for k, b in zip(refused, by, strict=True)]


@dataclass(eq=False)
class SandCalibration(TypedResult):
    """The calibration in the small box (``calibration`` in ``sand.json``).

    ``mus``: the preparation frictions of the final calibration; ``calibration``: its record
    (:meth:`poro2d.criterion.density.Calibration.to_dict`); ``n2d_min``/``n2d_max``: the 2D
    extremes; ``dropped_ends``: frictions no seed could prepare; ``cases``: the sweep's folder;
    ``interior_by_friction``: interior porosities per friction and seed; the densest
    preparation's own porosity (to hold against the jamming porosity); where the time went
    in the calibration and in the specimens at full size; ``bracket_ends``: the ends' frictions and
    accepted n', [[mu, n'], [mu, n']], the frictions between them started from
    (:func:`poro2d.sweep.density.bracket_first_trial`).
    """

    OPTIONAL: ClassVar[tuple[str, ...]] = ("time_profile", "specimens_time_profile", "bracket_ends")

    mus: list[float]
    calibration: Calibration
    n2d_min: float
    n2d_max: float
    dropped_ends: list[float]
    cases: str
    interior_by_friction: list[list[float | None]]
    dense_end_interior: float | None
    dense_end_interior_sd: float | None
    time_profile: StageProfile | None = None
    specimens_time_profile: StageProfile | None = None
    bracket_ends: list[list[float]] | None = None

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {
        "calibration": Calibration,
        "time_profile": StageProfile,
        "specimens_time_profile": StageProfile,
    }


@dataclass(eq=False)
class AcceptedState(ByName, TypedResult):
    """One accepted specimen of ``sand.json``'s ``states``: its state, seed, folder and porosities (the
    seed and porosities read off its :class:`SeedSpecimen` by name)."""

    n_lab: float
    relative_density: float | None
    seed: int
    specimen: str | None
    box_porosity: float | None
    interior_porosity: float | None


@dataclass(eq=False)
class SandResult(TypedResult):
    """``sand.json``: the soil, its state, the answer over seeds and where every part is."""

    mode: str
    soil: SoilRecord
    state: LabState
    interior_porosity_mean: float
    interior_porosity_sd: float
    box_porosity_mean: float
    box_porosity_sd: float
    solid_fraction_mean: float
    seeds: int
    seeds_accepted: int
    #: the seeds whose specimens make the answer, and those not accepted (why, and their replacements)
    seeds_used: list[int]
    seeds_replaced: list[SeedReplaced]
    converged: bool
    mu_prep: float
    n2d_target: float
    first_trial_full_box: float
    n2d_min: float
    n2d_max: float
    jamming_porosity: float | None
    jamming_porosity_sd: float | None
    calibration: SandCalibration
    states: list[AcceptedState]
    seed_results: list[SeedSpecimen]
    preflight: Preflight
    wall_seconds: float
    config: dict[str, Any]
    provenance: Provenance
    #: both maps at the test stress, with a ``[state]`` table (:mod:`poro2d.critical_state.state_table`)
    state_map: StateMapRecord | None = None
    #: how each stage's workers were used, by stage (:class:`~poro2d.execute.core_share.WorkerUse`)
    worker_use: dict[str, WorkerUse] | None = None
    #: the answer's standard error: the specimens' and the calibration's seeds (:mod:`poro2d.sand.spread`)
    answer_error: AnswerError | None = None
    #: where the specimens landed against the target: the Dr they reached (:mod:`poro2d.sand.reached`)
    state_reached: StateReached | None = None
    specimens: list[SeedSpecimen] = field(default_factory=list, metadata=NOT_IN_FILE)

    #: the typed parts, as their classes read them
    PARTS: ClassVar[dict[str, type[TypedResult]]] = {
        "soil": SoilRecord,
        "calibration": SandCalibration,
        "state": LabState,
        "states": AcceptedState,
        "seed_results": SeedSpecimen,
        "seeds_replaced": SeedReplaced,
        "preflight": Preflight,
        "provenance": Provenance,
        "state_map": StateMapRecord,
        "worker_use": Keyed(WorkerUse),
        "answer_error": AnswerError,
        "state_reached": StateReached,
    }
    OPTIONAL: ClassVar[tuple[str, ...]] = ("state_map", "worker_use", "answer_error", "state_reached")

    @classmethod
    def build(
        cls,
        case,
        pf,
        target,
        trial: float,
        cal_record: SandCalibration,
        kept: list[SeedSpecimen],
        seconds: float,
        worker_use: dict[str, WorkerUse] | None = None,
    ) -> SandResult:
        accepted = [k for k in kept if k.accepted]
        interiors, boxes = [k.interior_porosity for k in accepted], [k.box_porosity for k in accepted]
        inner_m, inner_sd = _stats(interiors)
        box_m, box_sd = _stats(boxes)
        lab = case.lab
        states = [
            AcceptedState.of(k, n_lab=lab.n_lab, relative_density=lab.relative_density, specimen=k.folder)
            for k in accepted
        ]
        n_ok = len(accepted)
        error = AnswerError.of(
            target.relative_density, cal_record.calibration, cal_record.mus, cal_record.interior_by_friction,
            target.mu_prep, interiors,
        )  # fmt: skip
        reached = StateReached.of(
            target.relative_density, target.n2d_target, trial, cal_record.calibration, boxes, interiors,
            wide=is_wide(case.grading),
        )  # fmt: skip
        state_map = (
            None
            if case.state is None
            else state_map_record(case.state, lab, cal_record.n2d_max, cal_record.n2d_min, target.n2d_target,
                                  case.grading.source)
        )  # fmt: skip
        return cls(
            mode="density",
            soil=case.soil_record(),
            state=lab,
            interior_porosity_mean=inner_m,
            interior_porosity_sd=inner_sd,
            box_porosity_mean=box_m,
            box_porosity_sd=box_sd,
            solid_fraction_mean=1.0 - inner_m if math.isfinite(inner_m) else math.nan,
            seeds=case.seeds,
            seeds_accepted=n_ok,
            seeds_used=[k.seed for k in accepted],
            seeds_replaced=replaced_seeds(kept, case.seeds),
            converged=n_ok == case.seeds,
            mu_prep=target.mu_prep,
            n2d_target=target.n2d_target,
            first_trial_full_box=trial,
            n2d_min=cal_record.n2d_min,
            n2d_max=cal_record.n2d_max,
            jamming_porosity=pf.jamming.porosity,
            jamming_porosity_sd=pf.jamming.sd,
            calibration=cal_record,
            states=states,
            seed_results=list(kept),
            preflight=pf,
            wall_seconds=seconds,
            config=case.config.as_config(),
            provenance=Provenance.now(),
            state_map=state_map,
            worker_use=worker_use,
            answer_error=error,
            state_reached=reached,
            specimens=list(kept),
        )


def state_text(st: LabState) -> str:
    """The laboratory state in a title: ``nLab = 0.4023 (Dr = 0.800)``."""
    dr = st.relative_density
    return f"nLab = {st.n_lab:.4f}" + (f" (Dr = {dr:.3f})" if dr is not None else "")


def lab_text(st: LabState) -> str:
    """The laboratory state in full: n, e, Dr when known, and how it was given."""
    dr = "" if st.relative_density is None else f", Dr = {st.relative_density:.3f}"
    return f"n = {st.n_lab:.4f}, e = {st.e:.4f}{dr} (given as {st.given})"


def mean_sd_text(mean: float | None, sd: float | None) -> str:
    """``mean +- sd``, or n/a without a number (None, as a file keeps NaN)."""
    return "n/a" if mean is None or not math.isfinite(mean) else f"{mean:.4f} +- {sd or 0.0:.4f}"


@dataclass(eq=False)
class SummaryRow(TypedResult):
    """The row of ``summary.csv``: the soil, its state, the answer over seeds (fields in column order)."""

    JSON_VALUES: ClassVar[bool] = False  # a row of a CSV table: NaN stays NaN ("nan")

    soil: str | None
    upscale: float | None
    disks: int
    n_lab: float
    e: float
    Dr: float | None
    mu_prep: float
    interior_porosity: float
    interior_sd: float
    box_porosity: float
    box_sd: float
    solid_fraction: float
    jamming_porosity: float
    seeds: int
    seeds_accepted: int
    Dr_reached: float
    interior_at_target: float
    interior_at_target_se: float

    @classmethod
    def of(cls, res: SandResult) -> SummaryRow:
        """The row of a finished run."""
        st, pf, at = res.state, res.preflight, res.state_reached
        return cls(
            res.soil.name,
            res.soil.upscale,
            round(pf.box.disks),
            st.n_lab,
            st.e,
            st.relative_density,
            res.mu_prep,
            # a mean over no specimen is NaN in the table (None in sand.json)
            float_or_nan(res.interior_porosity_mean),
            float_or_nan(res.interior_porosity_sd),
            float_or_nan(res.box_porosity_mean),
            float_or_nan(res.box_porosity_sd),
            float_or_nan(res.solid_fraction_mean),
            res.jamming_porosity,
            res.seeds,
            res.seeds_accepted,
            # where the specimens landed (NaN without an accepted one, or from an older poro2d)
            float_or_nan(None if at is None else at.relative_density_reached),
            float_or_nan(None if at is None else at.interior_at_target),
            float_or_nan(None if at is None else at.interior_at_target_se),
        )


def summary_markdown(res: SandResult, store: Store) -> str:
    """The paste-ready summary: the answer first, then the soil, the run and the specimens
    (the export commands name the store's folder)."""
    out = store.root
    st, soil = res.state, res.soil
    jam = res.jamming_porosity
    lines = [
        f"# {soil.name}: 2D porosity at {state_text(st)}",
        "",
        "**Interior porosity (use this in other codes): "
        f"{mean_sd_text(res.interior_porosity_mean, res.interior_porosity_sd)}**"
        f" over {res.seeds_accepted} of {res.seeds} seeds{used_seeds(res)}",
        "",
        *_error_lines(res),
        "| quantity | value |",
        "| --- | --- |",
        f"| soil | {soil.name} ({soil.reference or 'no reference given'}) |",
        f"| grading | {soil.grading_source}, up-scaled x{soil.upscale:g} |",
        f"| disks (full box) | {res.preflight.box.disks:.0f} |",
        f"| laboratory state | {lab_text(st)} |",
        f"| preparation friction mu_prep | {res.mu_prep:.3f} |",
        f"| interior porosity | {mean_sd_text(res.interior_porosity_mean, res.interior_porosity_sd)} |",
        f"| box porosity n' (under the lid) | {mean_sd_text(res.box_porosity_mean, res.box_porosity_sd)} |",
        f"| solid fraction (interior) | {_fmt(res.solid_fraction_mean)} |",
        "| jamming porosity of the grading | "
        + ("n/a" if jam is None else f"{jam:.4f} +- {res.jamming_porosity_sd or 0.0:.4f}")
        + " |",
        f"| 2D extremes n' (calibration box) | {res.n2d_min:.4f} dense, {res.n2d_max:.4f} loose |",
        f"| dense end, interior (calibration box) | {_fmt(res.calibration.dense_end_interior)} "
        f"(against the jamming porosity {_fmt(jam)}) |",
        f"| wall time | {res.wall_seconds / 60:.1f} min |",
        *[f"| workers, {stage} | {use_text(use)} |" for stage, use in (res.worker_use or {}).items()],
        *_profile_rows(res),
        "",
        *[line for w in warnings(res) for line in (f"**Note:** {w}", "")],
        "| seed | accepted | interior | box n' | disks | folder |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for k in res.specimens:
        lines.append(
            f"| {k.seed} | {'yes' if k.accepted else 'no: ' + k.message} | {_fmt(k.interior_porosity)} | "
            f"{_fmt(k.box_porosity)} | {k.particle_count or ''} | {k.folder or ''} |"
        )
    first = next((k for k in res.specimens if k.accepted), None)
    if first is not None:
        state = f"--n-lab {st.n_lab:.6g} --seed {first.seed}"
        lines += [
            "",
            "Export, e.g.:",
            "",
            "```bash",
            f"poro2d export {out} {state} --to lammps --out {out / 'lammps'}",
            f"poro2d export {out / first.folder} --to yade --out {out / 'yade'}",
            "```",
        ]
    if res.state_map is not None:
        lines += ["", "## State parameter", "", *state_map_lines(res.state_map)]
    return "\n".join(lines) + "\n"


def _error_lines(res: SandResult) -> list[str]:
    """The answer's standard error and the state the specimens reached, under the answer (none in a
    sand.json of an older poro2d)."""
    lines = []
    if res.answer_error is not None:
        lines += [f"The answer's {res.answer_error.text()}: another run from other seeds lands within 2.8 "
                  "standard errors of this answer 19 times in 20.", ""]  # fmt: skip
    if res.state_reached is not None:
        lines += [f"The {res.state_reached.text()}.", ""]
    return lines


def used_seeds(res: SandResult) -> str:
    """The seeds the answer is over, when one was replaced (": 0, 2, 3"); "" otherwise."""
    return f": {', '.join(map(str, res.seeds_used))}" if res.seeds_replaced else ""


def _profile_rows(res: SandResult) -> list[str]:
    """Where the time went: per stage (calibration, specimens) and phase (preparation, lid)."""
    rows = []
    for label, key in (("calibration", "time_profile"), ("specimens", "specimens_time_profile")):
        prof = getattr(res.calibration, key)
        if prof is None:
            continue
        parts = []
        for phase in ("prepare", "plate"):
            p = getattr(prof, phase)
            rate = p.particle_steps_per_s
            pace = "" if rate is None or not math.isfinite(rate) else f" ({rate:.3g} particle-steps/s)"
            parts.append(f"{phase} {p.steps:,} steps in {p.seconds / 60:.1f} min{pace}")
        rows.append(f"| {label}: {prof.trials} trials | {'; '.join(parts)} |")
    return rows


def warnings(res: SandResult) -> list[str]:
    """What the answer must be read with: preparations that could not be made, seeds refused."""
    out = []
    dropped = res.calibration.dropped_ends or []
    if dropped:
        mus = res.calibration.mus or []
        out.append(
            f"no seed could be prepared at mu_prep {', '.join(f'{m:g}' for m in dropped)}: the 2D extremes "
            f"are those of mu_prep {mus[0]:g} to {mus[-1]:g}, so a state's Dr is mapped onto a narrower "
            "range than the preparation can span (see the calibration's cases for why)"
        )
    replaced = res.seeds_replaced or []  # None in a sand.json of an older poro2d
    for r in replaced:
        if r.replaced_by is not None:
            out.append(f"seed {r.seed} not accepted ({r.reason}): replaced by seed {r.replaced_by}")
    left = [r.seed for r in replaced if r.replaced_by is None]
    if left:
        out.append(f"seed(s) {', '.join(map(str, left))} not accepted: the spread is over fewer specimens")
    return out


def _fmt(v: float | None) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.4f}"


def write_summary(res: SandResult, store: Store) -> None:
    """``summary.md``, ``summary.csv`` and, last (it marks the run done), ``sand.json``."""
    buf = io.StringIO()
    row = SummaryRow.of(res).to_dict()
    w = csv.DictWriter(buf, fieldnames=list(row), lineterminator="\n")
    w.writeheader()
    w.writerow(row)
    for name, text in (("summary.md", summary_markdown(res, store)), ("summary.csv", buf.getvalue())):
        store.write_text(name, text)
    store.write_result("sand.json", res)


__all__ = [
    "SandCalibration",
    "SandResult",
    "SeedReplaced",
    "SeedSpecimen",
    "replaced_seeds",
    "summary_markdown",
    "SummaryRow",
    "lab_text",
    "state_text",
    "used_seeds",
    "warnings",
    "write_summary",
]
