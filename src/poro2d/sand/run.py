"""``poro2d sand``: the density-aware 2D porosity of a user's soil at one laboratory state.

Stages (each resumable: rerun the same command to go on):

1. **Pre-flight** (:mod:`poro2d.sand.preflight`): disks, time step, the grading's jamming
   porosity, the first trials and an estimate of the run time, before any DEM work.
2. **Calibration in a small box** of the full box's shape (``[sand] calibration_disks``):
   first the densest and loosest preparations (mu_prep at both ends of ``[sand] mu_prep``),
   which fix the 2D extremes and so the state's 2D target; then only the two frictions around
   the target (predicted from the ends), which fix its preparation friction. Each case starts
   from the grading's own first trial (:func:`poro2d.sweep.density.first_trial` moved to its
   jamming porosity). Cases are cached per grading and box, as the relation's are.
3. **Specimens at full size**, one per seed, at that friction, from the target moved by the
   walls' share of the two boxes (:func:`full_box_trial`); a seed not accepted is replaced by
   the next unused one (``[sand] replacements`` at most).
4. **The answer**: the interior porosity (the number for other codes) and the box
   porosity n' over seeds, the accepted specimens in named folders, a grading figure and
   one summary (``summary.md``, ``summary.csv``, ``sand.json``).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from poro2d.criterion.density import Calibration, StateTarget, state_target
from poro2d.errors import InputError
from poro2d.execute.cluster_options import check_cluster_options
from poro2d.execute.core_share import WorkerUse, use_text
from poro2d.execute.options import RunOptions
from poro2d.interop.origin import SOIL_FILE
from poro2d.io_utils import Provenance, check_output_dir
from poro2d.sand.case import ConfigLike, SandCase, load_sand_case
from poro2d.sand.preflight import Preflight, StageEstimate, bracket, friction_at_share, preflight
from poro2d.sand.profile import case_runs, stage_profile
from poro2d.sand.result import (
    SandCalibration,
    SandResult,
    SeedSpecimen,
    write_summary,
)
from poro2d.store import Store, walk
from poro2d.sweep import density as D
from poro2d.sweep.criterion_base import CriterionBase
from poro2d.sweep.output import held
from poro2d.sweep.records import CalibrationRun, CaseRow, LostCaseRow
from poro2d.sweep.relation import case_seed, seed_accepted

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "sand"

Announce = Callable[[str], None]

#: the calibration's first trials are started looser by this times mu_prep: a frictional
#: preparation made denser than it packs by itself is over-compressed under the lid (F_top of
#: thousands of N/m). On a uniform fine sand at mu_prep 1.0 its lid did not settle within 1.13
#: million steps from 0.216 (the natural n' is about 0.219), while from 0.222 two seeds were
#: accepted, at n' 0.2200 and 0.2179
LOOSE_BIAS = 0.006


def _quiet(_: str) -> None:
    pass


class StageClock:
    """Elapsed time and an overall ETA across the stages, from the pre-flight's estimate
    corrected by the pace measured so far."""

    def __init__(self, estimate: StageEstimate, say: Announce) -> None:
        self.t0 = time.perf_counter()
        self.estimate = {"calibration": estimate.calibration, "specimens": estimate.specimens}
        self.say = say
        self.pace = 1.0  # measured / estimated, from finished stages

    def begin(self, what: str) -> float:
        left = sum(self.estimate.values()) * self.pace
        self.say(f"{what}; elapsed {_clock(self.elapsed())}, about {_clock(left)} left (estimate)")
        return time.perf_counter()

    def end(self, stage: str, started: float) -> None:
        took = time.perf_counter() - started
        est = self.estimate.pop(stage, 0.0)
        if est > 0.0 and took > 1.0:
            self.pace = took / est

    def elapsed(self) -> float:
        return time.perf_counter() - self.t0


def say_use(uses: dict[str, WorkerUse], announce: Announce) -> None:
    """One line per sweep of a stage: how its workers were used."""
    for stage, use in uses.items():
        announce(f"{stage}: {use_text(use)}")


def _clock(seconds: float) -> str:
    s = int(round(max(seconds, 0.0)))
    return f"{s // 3600:d}:{s % 3600 // 60:02d}:{s % 60:02d}"


def calibration_config(case: SandCase, pf: Preflight) -> CriterionBase:
    """The criterion config of the calibration's cases: the sand's, in the calibration box."""
    box = pf.calibration_box
    specimen = dict(case.config.table("specimen"), width=box.width, height=box.height, layers=box.layers)
    return case.config.with_tables(specimen=specimen)


def predicted_mu(cal_ends: Calibration, n2d_target: float) -> float:
    """The preparation friction that the two ends predict for ``n2d_target``: its share between
    the measured ends, through the one shape of n2D against friction (:func:`friction_at_share`)."""
    mus = cal_ends.usable().mus
    lo, hi = cal_ends.n2d_min, cal_ends.n2d_max
    u = 0.0 if hi <= lo else (n2d_target - lo) / (hi - lo)
    return friction_at_share(u, tuple(mus))


def full_box_trial(target: float, dense_end: float | None, cal_dense: float, pf: Preflight) -> float:
    """The full box's first trial: the target less the walls' share it loses in the larger box.

    The dense end of the calibration box lies above the grading's jamming porosity by the loose
    layer along its walls (bottom, sides, lid), a share that falls with the perimeter over the
    area; the full box keeps that share times the ratio of the two boxes' perimeter / area.
    """
    if dense_end is None:
        return target
    small, big = pf.calibration_box, pf.box
    ratio = ((2 * big.width + 2 * big.height) / (big.width * big.height)) / (
        (2 * small.width + 2 * small.height) / (small.width * small.height)
    )
    excess = max(cal_dense - dense_end, 0.0)
    return target - excess * (1.0 - ratio)


def calibration_case(
    case: SandCase, pf: Preflight, mus: list[float], ends: D.MeasuredEnds | None = None
) -> D.CalibrationCase:
    """The calibration at ``mus``, the loosest cases first (its case ids name their folders in the
    cache). Its first trials move with the grading's jamming porosity (the dense end), the
    calibration box's walls' share and the loose bias (:func:`poro2d.sweep.density.calibrate`);
    with the ``ends`` measured, the frictions between them start just looser than the ends
    place them (:func:`poro2d.sweep.density.bracket_first_trial`)."""
    box = pf.calibration_box
    walls = D.wall_share(box.width, box.height, pf.d50_m)
    return D.CalibrationCase(calibration_config(case, pf), tuple(mus), case.calibration_seeds,
                             pf.jamming.porosity, walls, LOOSE_BIAS, loosest_first=True,
                             ends=ends, first_seed=first_seed(case))  # fmt: skip


def first_seed(case: SandCase) -> int:
    """The config's ``seed`` (0 when not given): the first seed of the calibration's cases at every
    friction and of the specimens at full size, so that another seed repeats the whole answer
    from independent packings."""
    return int(case.config.config.get("seed", 0))  # checked when the case was loaded


def measured_ends(cal_ends: Calibration) -> D.MeasuredEnds:
    """The two ends' frictions and accepted n' (the fit of their seeds)."""
    usable = cal_ends.usable()
    return (usable.mus[0], cal_ends.n2d_min), (usable.mus[-1], cal_ends.n2d_max)


def _calibrate(case, pf, store: Store, mus, record, cal_kw, ends=None) -> tuple[Calibration, CalibrationRun]:
    return D.calibrate(calibration_case(case, pf, mus, ends), store, record=record, **cal_kw)


def note_use(uses: dict[str, WorkerUse] | None, stage: str, summary) -> None:
    """Keep in ``uses`` how the workers of a stage's sweep were used (when its cases ran there)."""
    use = None if summary is None else summary.worker_use
    if uses is None or use is None:
        return
    name, k = stage, 1
    while name in uses:  # a stage run again (an end given up, seeds replaced)
        k += 1
        name = f"{stage} {k}"
    uses[name] = use


def calibration_stage(
    case: SandCase, pf: Preflight, store: Store, cal_kw: dict, uses: dict[str, WorkerUse] | None = None
) -> tuple[StateTarget, SandCalibration]:
    """The ends, then the two frictions around the state: its target and friction.

    ``cal_kw``: ``options`` and ``use_cache`` (:func:`poro2d.sweep.density.calibrate`); ``uses``:
    where each sweep's worker use is kept (:func:`note_use`).
    """
    cal_ends, usable, ends_info = calibrate_ends(case, pf, store, cal_kw, uses)
    ends = [usable[0], usable[-1]]
    first = state_target(case.lab.n_lab, case.n_max, case.n_min, cal_ends)
    mus = bracket(usable, predicted_mu(cal_ends, first.n2d_target))
    placed = measured_ends(cal_ends)
    cal, info = (
        (cal_ends, ends_info)
        if mus == ends
        else _calibrate(case, pf, store, mus, "calibration.json", cal_kw, placed)
    )
    if mus != ends:
        note_use(uses, "calibration", info.summary)
    if mus == ends:
        store.write_json(
            "calibration.json", {"calibration": cal.to_dict(), "mus": mus, "note": "the ends only"}
        )
    target = state_target(case.lab.n_lab, case.n_max, case.n_min, cal)
    dropped = [mu for mu in case.mus if mu < ends[0] or mu > ends[1]]
    dense = [v for v in info.interior[0] if v is not None]
    return target, SandCalibration(
        mus=mus,
        calibration=cal,
        n2d_min=cal.n2d_min,
        n2d_max=cal.n2d_max,
        dropped_ends=dropped,
        cases=info.cases,
        interior_by_friction=info.interior,
        # the densest preparation's own porosity: to hold against the jamming porosity
        dense_end_interior=float(np.mean(dense)) if dense else None,
        dense_end_interior_sd=float(np.std(dense, ddof=1)) if len(dense) > 1 else None,
        bracket_ends=[list(end) for end in placed],
    )


def calibrate_ends(
    case: SandCase, pf: Preflight, store: Store, cal_kw: dict, uses: dict[str, WorkerUse] | None = None
) -> tuple[Calibration, tuple, CalibrationRun]:
    """The densest and loosest preparations that at least one seed could prepare.

    An end whose every seed was refused (e.g. a lid that does not settle on a very frictional
    preparation) gives way to the next friction inwards, as the relation drops such a friction;
    the frictions left are returned with the calibration and its record. Fewer than two is an error.
    """
    lo, hi = 0, len(case.mus) - 1
    while True:
        cal, info = _calibrate(case, pf, store, [case.mus[lo], case.mus[hi]], "calibration_ends.json", cal_kw)
        note_use(uses, "calibration ends", info.summary)
        ok_lo, ok_hi = cal.accepted(0).size > 0, cal.accepted(1).size > 0
        if ok_lo and ok_hi:
            return cal, case.mus[lo : hi + 1], info
        lo, hi = lo + (not ok_lo), hi - (not ok_hi)
        if hi <= lo:
            cal.usable()  # raises: the frictions that could be prepared, and where to look
            raise AssertionError("unreachable: usable() refuses fewer than two frictions")


def specimen_stage(
    case: SandCase, trial: StateTarget, store: Store, options: RunOptions, announce: Announce = _quiet,
    uses: dict[str, WorkerUse] | None = None,
) -> list[CaseRow | LostCaseRow]:  # fmt: skip
    """One criterion case per seed at full size, at the state's friction, from ``trial``.

    A seed not accepted is replaced by the next unused seed, at most ``case.replacements`` in
    all, until ``case.seeds`` are accepted: the rows of every seed tried, in seed order. Seeds
    are tried in order from the config's ``seed`` (0 when not given: 0, 1, ...), so a rerun reads
    every finished seed back, replaced ones too.
    """
    from poro2d.criterion.protocol import trial_grid
    from poro2d.sweep.runner import run_sweep

    crit = case.config.table("criterion")
    grid = trial_grid(float(crit.get("resolution", 0.01)), crit.get("refine_tolerance"))
    first = first_seed(case)
    tried = case.seeds
    while True:
        sweep = D.StateChecks(case.config, (trial,), tried, grid, first_seed=first).sweep
        res = run_sweep(sweep, store.child("states"), options=options)
        note_use(uses, "specimens", res.summary)
        rows = sorted(res.rows, key=case_seed)
        more = min(case.seeds - sum(map(seed_accepted, rows)), case.seeds + case.replacements - tried)
        if more <= 0:
            return rows
        refused = [case_seed(r) for r in rows if not seed_accepted(r)]
        announce(
            f"seed(s) {', '.join(map(str, refused))} not accepted: trying seed(s) "
            f"{', '.join(map(str, range(first + tried, first + tried + more)))} in their place"
        )
        tried += more


def keep_specimens(rows: list[CaseRow | LostCaseRow], store: Store, label: str, soil: dict,
                   state: dict) -> list[SeedSpecimen]:  # fmt: skip
    """Each seed's accepted specimen in a named store (``specimens/<label>-seed<k>``), with a
    ``soil.json`` naming the soil and its laboratory state."""
    kept = []
    for r in rows:
        seed = case_seed(r)
        # the criterion's store of the case
        src = store.child("states", "cases", str(r.case_id), "run")
        folder = None
        if seed_accepted(r) and src.has("specimen.npz"):
            name = f"{label}-seed{seed}"
            dest = store.child("specimens", name)
            for f in src.names():
                if src.has(f) and not f.startswith("."):
                    src.copy(f, dest)
            # who the specimen is, for the export headers (poro2d.interop.origin)
            dest.write_json(SOIL_FILE, {"soil": soil, "state": state, "mode": "density", "seed": seed})
            folder = str(Path("specimens", name))
        kept.append(SeedSpecimen.from_row(seed, r, folder))
    return kept


def _state_label(case: SandCase) -> str:
    dr = case.lab.relative_density
    return f"Dr{dr:.3f}" if dr is not None else f"n{case.lab.n_lab:.4f}"


def check_soil(
    config: ConfigLike,
    *,
    seeds: int | None = None,
    workers: int | None = None,
    budget_minutes: float | None = None,
) -> tuple[SandCase, Preflight]:
    """The soil checked and its pre-flight, with no DEM work (``poro2d sand --preflight``)."""
    check_cluster_options(None, workers)
    case = load_sand_case(config, seeds=seeds, budget_minutes=budget_minutes)
    return case, _preflight(case, workers)


def _preflight(case: SandCase, workers: int | None) -> Preflight:
    """The pre-flight on ``workers`` cores (None: every core of this machine)."""
    cores = workers if workers is not None else os.cpu_count() or 1
    return preflight(case, workers=cores, budget_minutes=case.budget_minutes)


def run_sand(
    case: SandCase,
    store: Store | None = None,
    *,
    options: RunOptions = RunOptions(),
    use_cache: bool = True,
    announce: Announce = _quiet,
    on_preflight: Callable[[SandCase, Preflight], None] | None = None,
) -> SandResult:
    """The density-aware 2D porosity of a soil at its laboratory state, over seeds.

    ``case``: a sand config read and checked (:func:`~poro2d.sand.case.load_sand_case` of a TOML
    file or a dict, with ``seeds`` and ``budget_minutes``). Keeps in ``store``
    ``preflight.json`` before any DEM work, then the calibration, the specimens
    (``specimens/<state>-seed<k>``), ``summary.md``, ``summary.csv`` and ``sand.json`` (returned
    as a :class:`~poro2d.sand.result.SandResult`). ``on_preflight`` is called with the case and
    its pre-flight before any DEM work (the command prints it there, and draws ``fig_grading.png``
    with it afterwards: ``draw_grading`` of ``report/grading_figure.py``), ``announce`` with one
    line per stage, with the elapsed time and an overall ETA.
    ``options``: where the jobs run and whether bars show (:class:`~poro2d.execute.options.RunOptions`;
    the pre-flight's estimate counts ``workers``). ``use_cache``: the calibration's cases live in the
    shared cache, where another run finds them (else in the store's ``calibration``). Rerun to
    resume: finished cases are read back.
    ``store=None``: nothing is kept (the run works in a scratch folder, removed at the end; the
    specimens' folders then name nothing).
    """
    if not isinstance(case, SandCase):
        raise InputError("case", type(case).__name__, "a SandCase: load_sand_case(config)")
    from poro2d.execute.dask_cluster import check_reachable

    if store is not None:
        check_output_dir(store.parameter, store.root)
    # the soil's own refusals (a box, a time step) and a scheduler that does not answer come
    # before the folder is claimed: a refused run leaves no mark in it
    pf = _preflight(case, options.workers)
    check_reachable(options.scheduler)
    with held(store, KIND) as kept:
        return _run_sand(case, pf, kept, options, use_cache, announce, on_preflight)


def _run_sand(case, pf, store, options, use_cache, announce, on_preflight) -> SandResult:
    store.write_json(
        "preflight.json",
        {
            "preflight": pf.to_dict(),
            "soil": case.soil_record(),
            "provenance": Provenance.now().to_dict(),
        },
    )
    if on_preflight is not None:
        on_preflight(case, pf)
    clock = StageClock(pf.seconds, announce)
    t = clock.begin(
        f"calibration: {pf.cases_calibration} cases at most, {pf.calibration_box.disks:.0f} disks each",
    )
    uses: dict[str, WorkerUse] = {}
    target, cal_record = calibration_stage(
        case, pf, store, {"options": options, "use_cache": use_cache}, uses
    )
    clock.end("calibration", t)
    say_use(uses, announce)
    trial = full_box_trial(target.n2d_target, pf.jamming.porosity, cal_record.n2d_min, pf)
    t = clock.begin(
        f"specimens: {case.seeds} at full size ({pf.box.disks:.0f} disks), "
        f"mu_prep {target.mu_prep:.3f}, first trial {trial:.4f}",
    )
    rows = specimen_stage(case, replace(target, n2d_target=trial), store, options, announce, uses)
    clock.end("specimens", t)
    say_use({k: v for k, v in uses.items() if k.startswith("specimens")}, announce)
    kept = keep_specimens(rows, store, _state_label(case), case.soil_record(), case.lab.to_dict())
    ends = cal_record.bracket_ends
    placed = None if ends is None else tuple(tuple(end) for end in ends)
    final = calibration_case(case, pf, [float(m) for m in cal_record.mus], placed)
    cal_ids = [c.id for c in final.sweep.cases]
    runs = [c.child("run") for c in walk(store.child("states", "cases"), "*")]
    cal_record = replace(
        cal_record,
        time_profile=stage_profile(case_runs(Store(cal_record.cases), cal_ids)),
        specimens_time_profile=stage_profile(runs),
    )
    result = SandResult.build(case, pf, target, trial, cal_record, kept, clock.elapsed(), uses or None)
    write_summary(result, store)
    return result


__all__ = ["bracket", "full_box_trial", "predicted_mu", "check_soil", "run_sand"]
