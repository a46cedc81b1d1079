"""The paper's case study on built-in defaults, in one call (:func:`run_paper`; ``poro2d paper``).

Stages: the conversion table for the paper's sand (nLab = 0.3434, n_max = 0.4571,
n_min = 0.3253) with Figs. 1-2, the criterion of Fig. 3 with Figs. 5-7, replicate
specimens, direct shear (Fig. 8) and the report. Each stage keeps its files in its own
sub-store; a rerun skips the stages already finished (see :func:`paper_stage`).
``quick`` (``--quick``) runs a reduced specimen (a smaller box, two layers) for a first look.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar, NamedTuple

from poro2d.calibration.specimens import paper_criterion
from poro2d.console import OutputConsole
from poro2d.criterion.replicates import accepted_and_replicates
from poro2d.criterion.result import CriterionResult, ReplicateRow
from poro2d.execute.options import RunOptions
from poro2d.io_utils import Provenance
from poro2d.paper_data import PAPER, QUICK_SHEAR
from poro2d.shear.lab import LabData, read_lab_csv
from poro2d.shear.parts import LabRecord, QuasiStatic, ShearTestSummary
from poro2d.shear.results import ReplicateShearResult, ShearSeriesResult
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store, claims
from poro2d.store.stage import Fingerprint, ResumableStage
from poro2d.sweep.records import SeedReplaced
from poro2d.sweep.sensitivity_records import PaperNumbers
from poro2d.typed_result import TypedResult

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "paper"

if TYPE_CHECKING:
    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.criterion.result import CriterionOutputs

console = OutputConsole()

NORMAL_STRESSES_KPA = (50.0, 100.0, 200.0)
#: what the summary keeps of the criterion's result (the whole result is ``criterion/result.json``)
CRITERION_KEYS = ("final_porosity", "converged", "message", "iterations")


@dataclass(eq=False)
class ConversionRow(TypedResult):
    """One conversion method's row of ``conversions.csv``: its id, name, equation, n2D and flags."""

    method: str
    name: str
    equation: str
    n2d: float
    flags: str


@dataclass(eq=False)
class ConversionsRecord(TypedResult):
    """The conversions stage (``conversions/conversions.json``): the paper's sand, each method's
    row of ``conversions.csv`` and the figures written (Figs. 1-2)."""

    n_lab: float
    n_max: float
    n_min: float
    methods: list[ConversionRow]
    figures: list[str]
    provenance: Provenance

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"methods": ConversionRow, "provenance": Provenance}


@dataclass(eq=False)
class PaperShear(TypedResult):
    """The direct shear stage's summary: the pooled fit over every specimen's peaks; ``tests``
    and ``quasi_static`` of the first specimen; ``replicates``: the replicate specimens' summary."""

    tests: list[ShearTestSummary]
    friction_angle_deg: float | None
    cohesion_kpa: float | None
    r2: float | None
    quasi_static: QuasiStatic
    replicates: ReplicateShearResult

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {
        "replicates": ReplicateShearResult,
        "tests": ShearTestSummary,
        "quasi_static": QuasiStatic,
    }


@dataclass(eq=False)
class PaperFacts(TypedResult):
    """What the paper states (:data:`poro2d.paper_data.PAPER`), kept in the summary for the comparison."""

    n_lab: float
    n_max: float
    n_min: float
    dry_density_kg_m3: float
    solid_density_kg_m3: float
    criterion: PaperNumbers

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"criterion": PaperNumbers}


@dataclass(eq=False)
class PaperTimings(TypedResult):
    """Where the case study's time went (s); the last two only when the criterion converged."""

    conversions_s: float
    criterion_s: float
    replicates_s: float | None = None
    shear_s: float | None = None


@dataclass(eq=False)
class PaperSummary(TypedResult):
    """The case study's summary (``results.json``), as :func:`run_paper` returns it.

    ``criterion``: the criterion's result with only the accepted porosity, ``converged``,
    ``message`` and the trials (:data:`CRITERION_KEYS`; the whole result is
    ``criterion/result.json``); ``replicate_specimens``: one row per extra
    seed (None with one specimen); ``shear``: the pooled fit over the specimens, the first
    specimen's ``tests`` and ``quasi_static``, and ``replicates`` (None when the criterion
    did not converge); ``paper``: what the paper states, for the comparison; ``lab``: the
    laboratory data given with ``--lab`` (source, kind, peaks), written only then;
    ``specimens_asked`` (``--replicates``), ``specimen_seeds`` (the seeds of the specimens sheared,
    the first seed first) and ``seeds_replaced`` (each replicate seed not accepted, why, and the
    seed tried in its place: None once the replacements were spent), written once the criterion
    converged (absent in a summary of an earlier poro2d).
    """

    OPTIONAL = ("lab", "specimens_asked", "specimen_seeds", "seeds_replaced")

    quick: bool
    seed: int
    conversions: ConversionsRecord
    criterion: CriterionResult
    replicate_specimens: list[ReplicateRow] | None
    shear: PaperShear | None
    paper: PaperFacts
    timings: PaperTimings
    provenance: Provenance
    lab: LabRecord | None = None
    specimens_asked: int | None = None
    specimen_seeds: list[int] | None = None
    seeds_replaced: list[SeedReplaced] | None = None

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {
        "conversions": ConversionsRecord,
        "criterion": CriterionResult,
        "replicate_specimens": ReplicateRow,
        "shear": PaperShear,
        "paper": PaperFacts,
        "timings": PaperTimings,
        "provenance": Provenance,
        "lab": LabRecord,
        "seeds_replaced": SeedReplaced,
    }

    @property
    def specimens_short(self) -> int:
        """How many of the specimens asked for were not sheared (0 when not recorded)."""
        if self.specimens_asked is None or self.specimen_seeds is None:
            return 0
        return self.specimens_asked - len(self.specimen_seeds)


def replaced_replicates(rows: list[ReplicateRow], asked: int) -> list[SeedReplaced]:
    """The replicate seeds not accepted among ``rows`` (in seed order), each with the seed tried in
    its place: the seeds after the ``asked`` first ones take the refused ones' places in turn, as
    :func:`poro2d.criterion.replicates.run_replicates` tries them; None once they are spent."""
    refused = [r for r in rows if not r.converged]
    extra = [r.seed for r in rows[asked:]]
    by = (extra + [None] * len(refused))[: len(refused)]
    return [SeedReplaced(r.seed, r.message, b) for r, b in zip(refused, by, strict=True)]


def count_specimens(summary: PaperSummary, asked: int) -> None:
    """Record in ``summary`` the ``asked`` specimens (``--replicates``), the seeds of those sheared
    and the replicate seeds not accepted; nothing when the criterion did not converge (no specimen)."""
    if not summary.criterion.converged:
        return
    rows = summary.replicate_specimens or []
    summary.specimens_asked = asked
    summary.specimen_seeds = [summary.seed, *(r.seed for r in rows if r.converged)]
    summary.seeds_replaced = replaced_replicates(rows, asked - 1)


def specimen_lines(summary: PaperSummary) -> list[str]:
    """What the answer is over, in words: each replicate seed not accepted with why and what took its
    place, then how many of the specimens asked for were sheared (nothing when not recorded)."""
    if summary.specimens_asked is None or summary.specimen_seeds is None:
        return []
    lines = [
        f"replicate seed {r.seed} not accepted ({r.reason}): "
        + ("no seed left to replace it" if r.replaced_by is None else f"replaced by seed {r.replaced_by}")
        for r in summary.seeds_replaced or []
    ]
    seeds = ", ".join(map(str, summary.specimen_seeds))
    lines.append(f"{len(summary.specimen_seeds)} of {summary.specimens_asked} specimens asked for were "
                 f"accepted and sheared (seeds {seeds})")  # fmt: skip
    return lines


def paper_stage(store: Store, quick: bool, seed: int) -> ResumableStage:
    """The case study's store, bound by ``paper.json`` to ``--quick`` and ``--seed``.

    Its parts bind their own folders too (the criterion's ``config.json``, each test's
    ``test.json``) and are read back when finished; the summary and the report are made
    again on every run, so ``--replicates`` and ``--lab`` may change between runs (the
    specimens and tests already done are reused). A folder written before ``paper.json``
    existed is adopted.
    """
    return store.stage(
        Fingerprint({"quick": quick, "seed": seed}),
        record="paper.json",
        extra={"provenance": Provenance.now().to_dict()},
        allowed="an empty folder or one holding a paper run of the same --quick and --seed",
        explain=lambda keys, _: (
            f"it holds a paper run with other {', '.join(f'--{k}' for k in keys or [])}; choose another --out"
        ),
        unrecorded="adopt",
    )


def conversion_files(store: Store) -> ConversionsRecord:
    """The conversion table (``conversions.csv``) and Figs. 1-2 in ``store``; the summary of both.

    The summary is the stage's ``conversions.json``, written after the files by the stage.
    """
    from poro2d.porosity import convert_all
    from poro2d.report.conversion_figures import write_relation_figures

    res = convert_all(PAPER["n_lab"], n_max=PAPER["n_max"], n_min=PAPER["n_min"])
    rows = [
        {"method": r.id, "name": r.name, "equation": r.equation, "n2d": r.value, "flags": ";".join(r.flags)}
        for r in res.results.values()
    ]
    store.write_csv("conversions.csv", rows)
    figs = write_relation_figures(store.root, n_max=PAPER["n_max"], n_min=PAPER["n_min"],
                                  mark_n_lab=PAPER["n_lab"])  # fmt: skip
    return ConversionsRecord(n_lab=PAPER["n_lab"], n_max=PAPER["n_max"], n_min=PAPER["n_min"],
                             methods=[ConversionRow.from_dict(r) for r in rows],
                             figures=[str(f.name) for f in figs], provenance=Provenance.now())  # fmt: skip


@dataclass(frozen=True, eq=False)
class PaperCase:
    """The case study's choices, checked when made: ``quick`` (the reduced specimen), the first
    specimen's ``seed``, ``replicates`` specimens (1-20) for direct shear, a laboratory CSV ``lab``
    (a path, read here: a bad file fails before any simulation) overlaid on Fig. 8, and ``threads``
    of the DEM kernels (None: at most two)."""

    quick: bool = False
    seed: int = 0
    replicates: int = 3
    lab: LabData | str | Path | None = None
    threads: int | None = None

    def __post_init__(self) -> None:
        from poro2d.errors import check_int

        object.__setattr__(self, "seed", check_int("--seed", self.seed, 0))
        object.__setattr__(self, "replicates", check_int("--replicates", self.replicates, 1, 20))
        if self.lab is not None and not isinstance(self.lab, LabData):
            object.__setattr__(self, "lab", read_lab_csv(self.lab))


@claims(KIND)
def run_paper(case: PaperCase, store: Store, *, options: RunOptions = RunOptions()) -> PaperSummary:
    """The paper's case study of ``case``: conversions, the criterion (Fig. 3), direct shear on
    replicate specimens (Fig. 8), the report, kept in ``store``. Resumable: finished stages are read
    back. ``options``: whether bars show (:class:`~poro2d.execute.options.RunOptions`).

    Returns the summary kept as the store's ``results.json``; ``summary.criterion.converged``
    says whether the criterion found its porosity (no shear tests otherwise).
    """
    from poro2d.io_utils import check_output_dir

    out = store.root
    check_output_dir(store.parameter, out)
    quick, seed = case.quick, case.seed
    crit = paper_criterion(store, quick, seed, case.threads, options.progress)
    stage = paper_stage(store, quick, seed)
    stage.check()  # and the folder: one of another paper run is refused before anything is written
    summary, criterion, shear_figures, shear_series = _run_stages(
        store, stage, crit, case, progress=options.progress
    )
    count_specimens(summary, case.replicates)
    store.write_result("results.json", summary)
    from poro2d.calibration.run import CalibrationResult
    from poro2d.report.paper_report import CALIBRATION_FOLDER, write_paper_report

    # the report takes objects and opens no file: a calibration kept beside the run is read here
    calibration = CalibrationResult.read(store.child(CALIBRATION_FOLDER))
    md, html = write_paper_report(
        out,
        summary,
        criterion,
        shear_figures=shear_figures,
        calibration=calibration,
        shear_series=shear_series,
    )
    console.print(f"results in {out}/results.json; report: {html} and {md}")
    return summary


def _run_stages(store: Store, stage: ResumableStage, crit: PorosityCriterion, case: PaperCase, *,
                progress: bool) -> tuple[PaperSummary, CriterionOutputs, dict, dict]:  # fmt: skip
    """Conversions, criterion, replicate specimens and direct shear (each read back when done).

    Returns the summary, the criterion's results (its side files read through their classes),
    the shear figures written (by the names of the report's ``SHEAR_FIGURES`` and its fabric
    section's) and each specimen's shear series with its curves, by label.
    """
    from poro2d.criterion.result import CriterionOutputs
    from poro2d.criterion.table import print_result
    from poro2d.report.criterion_figures import draw_criterion, draw_stored_criterion

    quick, replicates, lab_data = case.quick, case.replicates, case.lab
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    conv = _conversions_stage(store, stage)
    timings["conversions_s"] = time.perf_counter() - t0
    console.print(f"[bold]2/3 criterion[/] (Fig. 3) for nLab = {crit.settings.n_lab}"
                  f"{' [quick specimen]' if quick else ''}")  # fmt: skip
    t1 = time.perf_counter()
    result = crit.run()
    timings["criterion_s"] = time.perf_counter() - t1
    draw_criterion(result, store.child("criterion"))
    print_result(result, store.child("criterion"))
    shear = reps = None
    shear_figures: dict[str, Path] = {}
    shear_series: dict[str, ShearSeriesResult] = {}
    if result.converged:
        t2 = time.perf_counter()
        n2d = result.final_porosity
        specimens, reps = accepted_and_replicates(crit.spec, crit.grading, crit.settings, n2d, crit.seed,
                                                  replicates, store, progress=progress)  # fmt: skip
        timings["replicates_s"] = time.perf_counter() - t2
        for row in reps or []:
            draw_stored_criterion(store.child("replicates", row.folder))
        shear, shear_figures, shear_series = _shear_stage(
            specimens, store.child("shear"), quick, lab_data, progress
        )
        timings["shear_s"] = time.perf_counter() - t2 - timings["replicates_s"]
    else:
        console.print("[yellow]criterion not converged: direct shear skipped[/]")
    summary = PaperSummary(
        quick=quick,
        seed=crit.seed,
        conversions=conv,
        criterion=CriterionResult.from_dict({k: getattr(result, k) for k in CRITERION_KEYS}),
        replicate_specimens=reps,
        shear=shear,
        paper=PaperFacts.from_dict(PAPER),
        timings=PaperTimings.from_dict(timings),
        provenance=Provenance.now(),
        lab=lab_data.record() if lab_data is not None else None,
    )
    return summary, CriterionOutputs.read(store.child("criterion"), result), shear_figures, shear_series


def _conversions_stage(store: Store, stage: ResumableStage) -> ConversionsRecord:
    """Stage 1: every conversion of the paper's sand, printed as a table and written with Figs. 1-2."""
    console.print("[bold]1/3 conversions[/] (Eqs. 1-12, Figs. 1-2)")
    conv = stage.run(lambda: conversion_files(store.child("conversions")), "conversions/conversions.json",
                     decode=ConversionsRecord.from_dict)  # fmt: skip
    for m in conv.methods:
        v = "skipped" if m.n2d is None else f"{m.n2d:.4f}"
        console.print(f"  {m.method:<24} {m.equation:<10} {v:>8} {m.flags}")
    return conv


class ShearStage(NamedTuple):
    """What the direct shear stage hands the report: its summary, the figures written (by the
    report's names) and each specimen's series with its curves, by label, the first first."""

    summary: PaperShear
    figures: dict[str, Path]
    series: dict[str, ShearSeriesResult]


def _shear_stage(specimens: SpecimenSet, store: Store, quick: bool, lab_data, progress: bool) -> ShearStage:
    """Direct shear at the paper's normal stresses on every specimen: the summary over them, the
    figures written (Fig. 8 over the specimens, the first specimen's curves, fabric and roses) and
    the series."""
    from poro2d.report.fabric_figures import draw_shear_fabric
    from poro2d.report.shear_figures import draw_replicate_shear
    from poro2d.shear.replicates import ReplicateShear
    from poro2d.shear.settings import ShearSettings

    console.print(
        f"[bold]3/3 direct shear[/] (Fig. 8) at {', '.join(f'{v:g}' for v in NORMAL_STRESSES_KPA)} kPa "
        f"on {len(specimens)} specimen(s)"
    )
    sset = ShearSettings(**(QUICK_SHEAR if quick else {}))
    rep = ReplicateShear(specimens, NORMAL_STRESSES_KPA, sset, store=store, lab=lab_data,
                         options=RunOptions(progress=progress)).run()  # fmt: skip
    draw_replicate_shear(rep, store, lab_data)
    first_label, first = next(iter(rep.series.items()))
    draw_shear_fabric(first, store.child(first_label))  # nothing for curves without fabric columns
    fit = rep.fit  # None with one normal stress
    phi, c, r2 = (fit.friction_angle_deg, fit.cohesion_kpa, fit.r2) if fit is not None else (None,) * 3
    ci = fit.friction_angle_ci_deg if fit is not None else None
    console.print(
        f"  friction angle {float('nan') if phi is None else phi:.1f} deg"
        + (f" ({fit.level:.0%} interval {ci[0]:.1f} to {ci[1]:.1f})" if ci else "")
        + f", cohesion {float('nan') if c is None else c:.1f} kPa over {len(specimens)} specimen(s); "
        + "per specimen "
        + ", ".join(f"{v:.1f}" for v in rep.friction_angle_per_specimen_deg)
        + " deg"
    )
    summary = PaperShear(
        # the pooled fit over every specimen's peaks; "tests" and quasi_static of the first specimen
        tests=first.tests,
        friction_angle_deg=phi,
        cohesion_kpa=c,
        r2=r2,
        quasi_static=first.quasi_static,
        replicates=ReplicateShearResult.from_dict(rep.to_dict()),
    )
    figures = {
        "curves_replicates": store.path("fig8a_shear_curves_replicates.png"),
        "peaks_replicates": store.path("fig8b_peak_strength_replicates.png"),
        "curves_first": store.child(first_label).path("fig8a_shear_curves.png"),
        **_fabric_figures(first, store.child(first_label)),
    }
    return ShearStage(summary, figures, rep.series)


def _fabric_figures(series: ShearSeriesResult, store: Store) -> dict[str, Path]:
    """The fabric figures ``series`` has in ``store`` by the report's names (none for curves without
    fabric columns): its ``fabric.png`` and each test's rose."""
    from poro2d.report.fabric_figures import CURVE_FIGURE, ROSE_FIGURE
    from poro2d.report.paper_fabric import FABRIC_CURVES, rose_figure

    found = {FABRIC_CURVES: (store, CURVE_FIGURE)}
    found.update(
        {rose_figure(t.normal_stress_kpa): (store.child(t.folder), ROSE_FIGURE) for t in series.tests}
    )
    return {name: where.path(file) for name, (where, file) in found.items() if where.has(file)}
