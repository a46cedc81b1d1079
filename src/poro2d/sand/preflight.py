"""What a soil will cost before any DEM work: disks, time step, first trials, run time.

The pre-flight reads only the grading and the box (no disk is simulated): the disk count
is the box's solid area over the grading's mean disk area, the time step is the engine's
critical step for the lightest disk (:func:`poro2d.specimen.compaction.time_step`), and the
grading's frictionless jamming porosity (:mod:`poro2d.oracles.jamming`, an energy
minimisation, not a DEM run) places the first trials. The run time is a model:

    particle-steps of a case = disks x (trials x preparation steps + trials x lid steps(mu_prep))

fitted to the stages of measured runs (:data:`LID_STEPS`, :data:`SETTLE_STEPS`, the trials
per case :func:`trials_per_case`; steps scale with 1 / dt, since the lid travels at a set speed
and layers settle in physical time), ``THROUGHPUT`` particle-steps per second per core (or the
machine's own, given), and the cases laid out on the workers as the sweep runs them, the
longest first (:func:`wall_seconds`): the calibration's ends, then the two frictions around
the state, then the specimens. It is an estimate to choose a box and an up-scaling with,
printed as such; the run prints its own measured pace.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from poro2d.errors import InputError
from poro2d.grading import GradingCurve, paper_grading
from poro2d.porosity import parabolic
from poro2d.sand.case import SandCase
from poro2d.specimen.compaction import (
    SpecimenSpec,
    check_box,
    check_feasible,
    estimate_size,
    grading_increments,
    grading_mass_scaling_step,
    is_wide,
    preparation_note,
    time_step,
)
from poro2d.typed_result import TypedResult

#: particle-steps per second per core assumed by the estimate, fitted on whole runs with both
#: cores running cases: the workers' measured pace was 3.0e7 (Toyoura sand, 4 100 and 10 800
#: disks), 3.1-3.7e7 (the paper's sand), 3.4e7 (CB-Mix-No. 2) after the cheaper list builds,
#: 2.1-2.7e7 (the sandy gravel G1-1) before them; set below those, since the step count of the
#: narrow soils' preparations falls short (the paper's sand: 6.2e9 particle-steps against 3.9e9
#: counted; docs/sand.md). Less on a machine busy with other work (0.6e7-1.2e7 seen):
#: ``throughput`` of :func:`preflight` takes the machine's own
THROUGHPUT = 2.6e7
#: lid steps of one calibration trial at the paper grading's time step, by preparation friction
#: (mu_prep, steps; linear between): the mean per trial of the calibration cases of Toyoura sand
#: with the creeping lid at rest below ``CREEP_RATIO`` (calibration box, 2 seeds, 4 100 disks,
#: docs/sand.md): 32 000, 24 000 (mu 0.05), 37 000 and 73 000 at 0, 0.05, 0.1 and 1.0; a first
#: trial's lid comes from far (9 000-114 000), a refined trial's is short (4 000-11 000)
LID_STEPS = ((0.0, 32_000), (0.1, 37_000), (1.0, 73_000))
#: lid steps of one full-size specimen's trial: its first trial is the calibration's, so its lid
#: finds the packing near: 4 000-7 400 at the paper grading's step (Toyoura sand, 3 seeds;
#: the sandy gravel G1-1, 3 seeds)
SPECIMEN_LID_STEPS = 6_000
#: settling steps of one layer after its growth (the layer's and the working friction's stages),
#: at the paper grading's time step: 13 900 (calibration) and 14 600 (specimens) per layer for
#: Toyoura sand. A wide grading's layers end once settled (``WIDE_PREPARATION``) and its
#: frictional working-friction stage creeps long (up to 900 000 steps at mu_prep 1): the sandy
#: gravel G1-1 took 58 000 per calibration layer and 27 000 per specimen layer, hence 50 000
#: (its whole run then within 3 %, the calibration under and the specimens over)
SETTLE_STEPS = 14_000
WIDE_SETTLE_STEPS = 50_000
#: criterion trials per case, measured on the same runs: the dense end accepts its first trial
#: (6 of 6), the loose end needs 1.5 (its lid pushes the first trial over: 1 and 2), the
#: frictions around the state 1.5 (refined to 0.002 from a first trial just looser than the
#: measured ends place them: 19 trials over 14 cases of the four soils of examples/soils, 1 to 4;
#: 2.5 from the table's first trials), the full-size specimens 1.2 (7 of 9 seeds at their first
#: trial)
TRIALS_DENSE_END = 1.0
TRIALS_LOOSE_END = 1.5
TRIALS_BRACKET = 1.5
TRIALS_SPECIMEN = 1.2
#: what a case's rate is on t engine threads, as a share of one thread's gain: the sweep gives a
#: case the spare cores when fewer cases than workers remain (its progress says "threads per case
#: 1 -> 2"); two threads run the engine 1.75-1.94x as fast as one (docs/engine.md), a stage's
#: checks and list builds less so
THREAD_EFFICIENCY = 0.7
#: the jamming reference's disks: enough for phi_J within its seed spread (docs/jamming.md);
#: a wide grading whose largest disks need a bigger cell gets up to ``JAMMING_MAX_DISKS``
JAMMING_DISKS = 1500
JAMMING_MAX_DISKS = 8000


@dataclass(eq=False)
class BoxPlan(TypedResult):
    """A box the run prepares specimens in, and what one specimen holds (m, disks)."""

    width: float
    height: float
    layers: int
    disks: float

    @property
    def band_height(self) -> float:
        return self.height / self.layers


@dataclass(eq=False)
class Jamming(TypedResult):
    """The grading's frictionless jamming porosity (n_J = 1 - phi_J) over seeds, or why not."""

    porosity: float | None
    sd: float | None
    disks: int
    seeds: int
    seconds: float
    note: str = ""


@dataclass(eq=False)
class StageEstimate(TypedResult):
    """The pre-flight's estimate for the calibration and the specimens (particle steps or s)."""

    calibration: float
    specimens: float
    total: float | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = ("total",)


@dataclass(eq=False)
class Preflight(TypedResult):
    """The pre-flight of one soil: printed before any DEM work, kept as ``preflight.json`` and in
    ``sand.json``."""

    soil: str
    d_min_m: float
    d50_m: float
    d_max_m: float
    cu: float
    size_ratio: float
    upscale: float
    box: BoxPlan
    calibration_box: BoxPlan
    band_over_d_max: float
    time_step_s: float
    time_step_paper_s: float
    jamming: Jamming
    first_trial: float
    eq12_trial: float
    cases_calibration: int
    cases_specimens: int
    particle_steps: StageEstimate
    seconds: StageEstimate
    workers: int
    budget_minutes: float | None
    suggestion: str
    notes: list[str] = field(default_factory=list)
    #: the finest disk's own step, only when the light disks' inertial masses are raised in the
    #: quasi-static stages (``time_step_s`` is then the step they share; docs/density-scaling.md)
    time_step_unscaled_s: float | None = None
    #: particle-steps per second per core the run time was estimated at (files before it: not said)
    throughput: float | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = ("time_step_unscaled_s", "throughput")
    #: the typed parts, as their classes read them
    PARTS: ClassVar[dict[str, type[TypedResult]]] = {
        "box": BoxPlan,
        "calibration_box": BoxPlan,
        "jamming": Jamming,
        "particle_steps": StageEstimate,
        "seconds": StageEstimate,
    }


#: a lid must rest in the calibration box: its force window at least this many times the
#: grain weights its segments need (:data:`poro2d.criterion.lid.GRAINS_PER_SEGMENT` per segment).
#: Measured on a uniform fine sand (d50 2 mm) prepared at mu_prep 1.0: a box whose window holds
#: 0.49 grain weights per segment (0.114 x 0.046 m, 1400 disks) never let its lid settle in
#: 1.13 million steps (3 seeds of 3), one holding 0.86 (0.2 x 0.081 m, 4300 disks) accepted
#: its first trial; the paper grading's relation runs at 0.73
LID_MARGIN = 3.5


def calibration_box(
    spec: SpecimenSpec, grading: GradingCurve, disks: int, porosity: float, *, lid_window: float | None = None
) -> BoxPlan:
    """A box of the full box's shape holding about ``disks`` disks (the full box if that is smaller).

    Its layers keep about the full box's band height in grain sizes, and every band holds at
    least three of the largest disks, the box at least ten across. ``lid_window``: the
    criterion's force fraction when the fill acceptance's lid must rest in the box; the box is
    then wide enough that the window holds ``LID_MARGIN`` times the grain weights its segments
    need (a small box's window is the weight of a few grains: its lid never settles).
    """
    from poro2d.criterion.lid import GRAINS_PER_SEGMENT, SEGMENT_D50

    full = estimate_size(spec, grading, porosity).disks
    scale = math.sqrt(disks / full)
    if lid_window is not None:
        # window = lid_window x N grains, N = full x scale^2; segments = scale W / (SEGMENT_D50 d50)
        per_width = LID_MARGIN * GRAINS_PER_SEGMENT / (SEGMENT_D50 * grading.size_at(50.0) * lid_window)
        scale = max(scale, per_width * spec.width / full)
    if scale >= 1.0:
        return BoxPlan(spec.width, spec.height, spec.layers, full)
    d_max = grading.d_max_m
    # as many layers as keep the full box's band height (rounded up: thinner bands, not thicker)
    layers = max(1, min(spec.layers, math.ceil(spec.layers * scale - 1e-9)))
    height = max(spec.height * scale, 3.0 * d_max * layers)
    width = max(spec.width * scale, 10.0 * d_max)
    width, height = round(width, 4), round(height, 4)
    if width >= spec.width or height >= spec.height:
        return BoxPlan(spec.width, spec.height, spec.layers, full)
    small = replace(spec, width=width, height=height, layers=layers)
    return BoxPlan(width, height, layers, estimate_size(small, grading, porosity).disks)


def jamming_of(grading: GradingCurve, seeds: int = 3, *, use_cache: bool = True) -> Jamming:
    """The grading's jamming porosity, with disks enough for its largest grains (or a note why not).

    Kept in the cache folder (:func:`poro2d.sweep.density.cache_dir`) by grading, disks and
    seeds: a second pre-flight of the same grading reads it back (checked: finite numbers of
    the right kind, else computed again).
    """
    if not use_cache:
        return _compute_jamming(grading, seeds)
    from poro2d import __version__
    from poro2d.identity import identity_digest
    from poro2d.store import Store
    from poro2d.sweep.density import cache_dir

    key = identity_digest(
        {
            "sizes": grading.sizes_m,
            "percent": grading.percent_passing,
            "seeds": seeds,
            "disks": JAMMING_DISKS,
            "version": __version__,
        },
        length=16,
    )
    store, name = Store(cache_dir() / "jamming"), f"{key}.json"
    data = store.read_json(name)
    try:
        jam = _jamming_from(data) if isinstance(data, dict) else None
    except (ValueError, TypeError, KeyError):
        jam = None
    if jam is not None:
        return jam
    jam = _compute_jamming(grading, seeds)
    try:
        store.write_json(name, jam.to_dict())
    except OSError:  # a read-only cache: the reference is simply computed again next time
        pass
    return jam


def _jamming_from(d: dict) -> Jamming | None:
    """A cached reference, or None when the entry is not one (damaged, edited, of another kind)."""
    por, sd = d["porosity"], d["sd"]
    if por is not None and not (
        isinstance(por, float)
        and 0.0 < por < 1.0
        and isinstance(sd, float)
        and math.isfinite(sd)
        and sd >= 0.0
    ):
        return None
    return Jamming(por, sd, int(d["disks"]), int(d["seeds"]), float(d["seconds"]), str(d["note"]))


def _compute_jamming(grading: GradingCurve, seeds: int) -> Jamming:
    import time

    from poro2d.oracles.jamming import jamming_reference

    # the periodic cell must be wider than four of the largest radii: N mean disks at phi 0.85
    need = (4.0 * grading.d_max_m / 2.0) ** 2 * 4.0 * 0.85 / grading.mean_disk_area()
    n = int(max(JAMMING_DISKS, math.ceil(need * 1.2)))
    t0 = time.perf_counter()
    if n > JAMMING_MAX_DISKS:
        note = (
            f"not computed: the largest grains need a periodic cell of about {n} disks "
            f"(at most {JAMMING_MAX_DISKS} here)"
        )
        return Jamming(None, None, n, 0, 0.0, note)
    try:
        ref = jamming_reference(grading, n_disks=n, seeds=tuple(range(seeds)))
    except InputError as exc:
        return Jamming(None, None, n, 0, time.perf_counter() - t0, f"not computed: {exc}")
    note = "" if ref.converged else "a minimisation stalled (docs/jamming.md)"
    return Jamming(ref.porosity_mean, ref.porosity_std, n, seeds, ref.seconds, note)


def lid_steps(mu: float, stage: str = "calibration") -> float:
    """Lid steps of one trial at the paper grading's time step for preparation friction ``mu``
    (:data:`LID_STEPS`, linear between its points, flat beyond them); a full-size specimen's
    (``stage`` "specimens"): :data:`SPECIMEN_LID_STEPS`."""
    if stage == "specimens":
        return float(SPECIMEN_LID_STEPS)
    mus, steps = zip(*LID_STEPS, strict=True)
    return float(np.interp(mu, mus, steps))


def preparation_steps(spec: SpecimenSpec, slow: float, wide: bool = False) -> float:
    """Steps of one trial's preparation: each layer's growth, then its settling (``SETTLE_STEPS``,
    or ``WIDE_SETTLE_STEPS`` for a ``wide`` grading, x ``slow``, the paper grading's time step over
    this one's)."""
    settle = WIDE_SETTLE_STEPS if wide else SETTLE_STEPS
    return spec.layers * (spec.growth_increments * spec.growth_steps + settle * slow)


def trials_per_case(mu: float, mus: tuple[float, ...], stage: str) -> float:
    """Criterion trials a case needs, as measured: the calibration's dense end, loose end or a
    friction between them (``mus``: the calibration's frictions), or a full-size specimen."""
    if stage == "specimens":
        return TRIALS_SPECIMEN
    if mu <= mus[0]:
        return TRIALS_DENSE_END
    return TRIALS_LOOSE_END if mu >= mus[-1] else TRIALS_BRACKET


def friction_at_share(u: float, mus: tuple[float, ...]) -> float:
    """The preparation friction whose n2D lies at the share ``u`` (0 dense, 1 loose) between the
    two ends: the rise of n2D with friction has one shape across gradings (steep at low friction,
    flat towards 1; ``FILL_FIRST_TRIALS``), inverted here and bounded by the ends ``mus``."""
    from poro2d.sweep.density import FILL_FIRST_TRIALS

    mu_ref, n_ref = (np.array(v) for v in zip(*FILL_FIRST_TRIALS, strict=True))
    shape = (n_ref - n_ref[0]) / (n_ref[-1] - n_ref[0])
    mu = float(np.interp(min(max(u, 0.0), 1.0), shape, mu_ref))
    return min(max(mu, mus[0]), mus[-1])


def bracket(mus: tuple[float, ...], mu: float) -> list[float]:
    """The calibration frictions that enclose ``mu``: the ends and its two neighbours."""
    inner = [m for m in mus if m <= mu][-1:] + [m for m in mus if m > mu][:1]
    return sorted({mus[0], mus[-1], *inner})


def expected_friction(case: SandCase) -> float:
    """The preparation friction the state will need, before any calibration: its share between
    the 2D extremes taken as 1 - Dr (:func:`friction_at_share`)."""
    from poro2d.criterion.density import lab_relative_density

    dr = lab_relative_density(case.lab.n_lab, case.n_max, case.n_min)
    return friction_at_share(1.0 - dr, case.mus)


@dataclass(frozen=True)
class CasePlan:
    """The cases of one stage as the estimate counts them: a friction and a seed count each."""

    frictions: tuple[float, ...]
    seeds: int
    stage: str

    @property
    def count(self) -> int:
        return len(self.frictions) * self.seeds


def case_plans(case: SandCase) -> tuple[CasePlan, CasePlan, CasePlan]:
    """The calibration's ends, the frictions around the state (those that are not ends), the specimens."""
    mus = case.mus
    mu = expected_friction(case)
    inner = tuple(m for m in bracket(mus, mu) if m not in (mus[0], mus[-1]))
    return (
        CasePlan((mus[-1], mus[0]), case.calibration_seeds, "calibration"),
        CasePlan(inner, case.calibration_seeds, "calibration"),
        CasePlan((mu,), case.seeds, "specimens"),
    )


def case_steps(
    spec: SpecimenSpec, mu: float, trials: float, slow: float, stage: str = "calibration", wide: bool = False
) -> float:
    """Steps of one case of ``stage``: ``trials`` preparations and lid stages at friction ``mu``."""
    return trials * (preparation_steps(spec, slow, wide) + lid_steps(mu, stage) * slow)


def thread_gain(threads: int) -> float:
    """How much faster a case runs on ``threads`` engine threads than on one (``THREAD_EFFICIENCY``)."""
    return 1.0 + THREAD_EFFICIENCY * (threads - 1)


def wall_seconds(cases: list[float], workers: int) -> float:
    """Wall time of cases of ``cases`` seconds (on one thread) each on ``workers`` cores.

    As a sweep runs them: the longest first, each to the worker that frees first; once no case
    waits, the running ones share the cores as engine threads (``workers // running`` each).
    """
    cores = max(workers, 1)
    waiting = sorted(cases, reverse=True)
    running: list[float] = []  # the one-thread seconds each running case has left
    wall = 0.0
    while waiting or running:
        while waiting and len(running) < cores:
            running.append(waiting.pop(0))
        rate = 1.0 if waiting else thread_gain(cores // len(running))
        first = min(running)
        wall += first / rate
        running = [r - first for r in running]
        running.remove(0.0)
    return wall


def _cases(case: SandCase) -> tuple[int, int]:
    """Calibration cases (the ends and the frictions around the state, per calibration seed) and
    specimens."""
    ends, inner, specimens = case_plans(case)
    return ends.count + inner.count, specimens.count


def _stage(
    plan: CasePlan, mus: tuple[float, ...], spec: SpecimenSpec, disks: float, slow: float, wide: bool
) -> list:
    """Particle-steps of each case of ``plan`` (``mus``: the calibration's frictions)."""
    out = []
    for mu in plan.frictions:
        steps = case_steps(spec, mu, trials_per_case(mu, mus, plan.stage), slow, plan.stage, wide)
        out += [disks * steps] * plan.seeds
    return out


def budget_suggestion(
    case: SandCase, seconds: float, budget_min: float | None, first: float = 0.2, workers: int = 2
) -> str:
    """A box, up-scaling or cut of fines that fits ``budget_min``, with what each costs the answer.

    Disks grow with 1 / upscale^2 and steps with 1 / dt ~ 1 / upscale, so the time goes with
    upscale^-3; an up-scaling is offered only while the largest grain still fits half a layer.
    A cut of fines is offered at the smallest d_min that fits, with the mass it removes.
    """
    if budget_min is None:
        return ""
    budget = budget_min * 60.0
    if seconds <= budget:
        return f"fits the budget of {budget_min:g} min (estimate {seconds / 60:.0f} min)"
    ratio = seconds / budget
    g, spec = case.grading, case.spec
    options = []
    up = g.upscale * ratio ** (1.0 / 3.0)
    if g.d_max_m * up / g.upscale <= 0.5 * spec.height / spec.layers:
        options.append(
            f"up-scale by {up:.3g} instead of {g.upscale:g} (fewer, larger disks: fewer grains across "
            "the box and a coarser surface)"
        )
    else:
        options.append(
            f"no up-scaling fits: by {up:.3g} the largest grain would exceed half a layer "
            f"({0.5 * spec.height / spec.layers * 1e3:.3g} mm)"
        )
    cut = _fines_cut_for(case, budget, first, workers)
    if cut is not None:
        options.append(
            f"cut the fines with [grading] d_min_mm = {cut[0]:.3g} (removes {cut[1]:.1f} % of the mass; "
            "the specimens are then the coarser soil, see the note on cuts)"
        )
    side = math.sqrt(1.0 / ratio)
    if side * spec.height / spec.layers >= 2.0 * g.d_max_m and side * spec.width >= 10.0 * g.d_max_m:
        options.append(
            f"a box of {1.0 / ratio:.2f} times the area at this up-scaling (the walls' loose layer then "
            "weighs more in n'; the interior porosity is less affected)"
        )
    options.append("fewer seeds (a wider confidence interval)")
    return f"estimate {seconds / 60:.0f} min exceeds the budget of {budget_min:g} min: " + "; or ".join(
        options
    )


def _fines_cut_for(case: SandCase, budget: float, first: float, workers: int) -> tuple[float, float] | None:
    """(d_min_mm, % of the mass removed) of the smallest cut of fines whose estimate fits ``budget``."""
    g = case.grading
    table = case.config.table("grading")
    for d in np.geomspace(g.d_min_m, g.size_at(50.0), 25)[1:]:
        d_mm = float(f"{d * 1e3:.3g}")
        try:
            cut = GradingCurve.from_config(dict(table, d_min_mm=d_mm), base_dir=case.base_dir)
            secs = workload(case, case.spec, cut, first, workers).seconds.total
        except InputError:
            continue
        if secs <= budget:
            removed = float(np.interp(np.log(d_mm / 1e3), np.log(g.sizes), g.percent))
            return d_mm, removed
    return None


@dataclass(frozen=True)
class Workload:
    """The boxes, time steps and estimated work of a run (:func:`workload`)."""

    full: BoxPlan
    calibration: BoxPlan
    dt: float
    dt_paper: float
    particle_steps: StageEstimate
    seconds: StageEstimate
    #: the finest disk's own step when the masses are raised (``dt`` the shared one), else None
    dt_unscaled: float | None = None


def workload(
    case: SandCase, spec: SpecimenSpec, g: GradingCurve, first: float, workers: int,
    throughput: float = THROUGHPUT,
) -> Workload:  # fmt: skip
    """What ``case`` costs with ``spec`` and grading ``g`` from first trial ``first`` (the model above),
    at ``throughput`` particle-steps per second per core."""
    crit = case.config.table("criterion")
    # a very wide grading's layers grow in more increments than the spec's (growth_increments)
    spec = replace(spec, growth_increments=grading_increments(spec, g))
    full = BoxPlan(spec.width, spec.height, spec.layers, estimate_size(spec, g, first).disks)
    fill = crit.get("acceptance", "plate") == "fill"
    window = float(crit.get("force_fraction", 0.01)) if fill else None
    cal = calibration_box(spec, g, case.calibration_disks, first, lid_window=window)
    # the quasi-static stages step at the density-scaled step when the specimen's disks get one
    dt_true = time_step(spec, g.d_min_m)
    scaled = grading_mass_scaling_step(spec, g, first)
    dt = dt_true if scaled is None else scaled
    dt_paper = time_step(spec, paper_grading().d_min_m)
    slow = dt_paper / dt
    ends, inner, specimens = case_plans(case)
    cal_spec = replace(spec, width=cal.width, height=cal.height, layers=cal.layers)
    wide = is_wide(g)
    work = [_stage(p, case.mus, cal_spec, cal.disks, slow, wide) for p in (ends, inner)]
    work.append(_stage(specimens, case.mus, spec, full.disks, slow, wide))
    psteps = StageEstimate(calibration=sum(work[0]) + sum(work[1]), specimens=sum(work[2]))
    # the ends run before the frictions around the state (which they choose), the specimens last
    walls = [wall_seconds([w / throughput for w in stage], workers) for stage in work]
    secs = StageEstimate(calibration=walls[0] + walls[1], specimens=walls[2], total=sum(walls))
    return Workload(full, cal, dt, dt_paper, psteps, secs, None if scaled is None else dt_true)


def preflight(
    case: SandCase, *, workers: int = 2, budget_minutes: float | None = None, throughput: float = THROUGHPUT
) -> Preflight:
    """The pre-flight of ``case``: every number from the grading and the box, no DEM run.

    ``throughput``: particle-steps per second per core of the machine (``THROUGHPUT`` unless given).

    Refuses (InputError) a box whose layers cannot hold the largest disk, before the jamming
    porosity is computed (the first trial's wall share in such a box is no porosity: 1.88 in a
    1 mm box of Toyoura sand).
    """
    spec, g = case.spec, case.grading
    check_box(spec, g)
    jam = jamming_of(g)
    from poro2d.sweep.density import first_trial, wall_share

    crit = case.config.table("criterion")
    first = first_trial(crit, case.mus[0], jam.porosity, wall_share(spec.width, spec.height, g.size_at(50.0)))
    check_feasible(spec, g, first)
    work = workload(case, spec, g, first, workers, throughput)
    full, cal, dt, dt_paper = work.full, work.calibration, work.dt, work.dt_paper
    psteps, secs = work.particle_steps, work.seconds
    n_cal, n_spec = _cases(case)
    eq12 = float(parabolic(case.lab.n_lab))
    notes = _notes(case, jam, eq12, dt, dt_paper, full)
    return Preflight(
        soil=case.name,
        d_min_m=g.d_min_m,
        d50_m=g.size_at(50.0),
        d_max_m=g.d_max_m,
        cu=g.uniformity,
        size_ratio=g.d_max_m / g.d_min_m,
        upscale=g.upscale,
        box=full,
        calibration_box=cal,
        band_over_d_max=full.band_height / g.d_max_m,
        time_step_s=dt,
        time_step_paper_s=dt_paper,
        jamming=jam,
        first_trial=first,
        eq12_trial=eq12,
        cases_calibration=n_cal,
        cases_specimens=n_spec,
        particle_steps=psteps,
        seconds=secs,
        workers=workers,
        budget_minutes=budget_minutes,
        suggestion=budget_suggestion(case, secs.total, budget_minutes, first, workers),
        notes=notes,
        time_step_unscaled_s=work.dt_unscaled,
        throughput=throughput,
    )


def _notes(case: SandCase, jam: Jamming, eq12: float, dt: float, dt_paper: float, full: BoxPlan) -> list[str]:
    notes = []
    if jam.porosity is not None and eq12 < jam.porosity:
        notes.append(
            f"Eq. 12's trial {eq12:.3f} is denser than this grading can pack (jamming porosity "
            f"{jam.porosity:.3f}): paper mode would start from an over-full box"
        )
    if jam.porosity is None:
        notes.append(f"jamming porosity {jam.note}; first trials from the paper grading's table")
    if dt < 0.25 * dt_paper:
        notes.append(
            f"the finest disks set a time step {dt_paper / dt:.1f} times smaller than the paper grading's: "
            "cutting fines (d_min_mm) or up-scaling more shortens every stage"
        )
    if case.spec.mass_scaling != "off" and dt > time_step(case.spec, case.grading.d_min_m):
        notes.append(
            f"density scaling: the light disks' inertial masses are raised so that every disk steps at "
            f"{dt:.3g} s in settling and under the lid ({time_step(case.spec, case.grading.d_min_m):.3g} s "
            'without); [specimen] mass_scaling = "off" keeps the true masses'
        )
    notes += _cut_notes(case)
    prep = preparation_note(case.spec, case.grading)
    if prep:  # said once here: the cases on the workers keep it in their results
        notes.append(f"preparation: {prep}")
    crit = case.config.table("criterion")
    if crit.get("acceptance", "plate") == "fill":
        from poro2d.criterion.lid import GRAINS_PER_SEGMENT, SEGMENT_D50

        per_segment = (
            float(crit.get("force_fraction", 0.01))
            * full.disks
            * SEGMENT_D50
            * (case.grading.size_at(50.0) / case.spec.width)
        )
        if per_segment < LID_MARGIN * GRAINS_PER_SEGMENT:
            notes.append(
                f"the full box's force window holds {per_segment:.2f} grain weights per lid segment "
                f"(below {LID_MARGIN * GRAINS_PER_SEGMENT:.2f}): a frictional (loose) preparation's lid "
                "may not settle; a larger box or a wider [criterion] force_fraction helps"
            )
    band = full.band_height / case.grading.d_max_m
    if band < 4.0:
        notes.append(f"each layer is only {band:.1f} largest grains tall: fewer layers pack more evenly")
    return notes


def _cut_notes(case: SandCase) -> list[str]:
    """What a d_min_mm / d_max_mm cut does to the soil, and how the laboratory state is read then."""
    table = case.config.table("grading")
    cuts = {k: table[k] for k in ("d_min_mm", "d_max_mm") if k in table}
    if not cuts:
        return []
    whole = GradingCurve.from_config(
        {k: v for k, v in table.items() if k not in cuts}, base_dir=case.base_dir
    )
    log_d, pct = np.log(whole.sizes), whole.percent
    notes = []
    for key, value in cuts.items():
        p = float(np.interp(np.log(float(value) / 1000.0), log_d, pct))
        share = p if key == "d_min_mm" else 100.0 - p
        what = "finer" if key == "d_min_mm" else "coarser"
        notes.append(
            f"{key} = {value:g} removes {share:.1f} % of the mass (everything {what}): the specimens are "
            "made of the rest; e_max/e_min and the state are the laboratory's for the whole soil, and "
            "poro2d maps the state's Dr onto the cut grading's own 2D extremes (its calibration), so "
            "the answer is the cut soil's at the same relative density, not at the same void ratio"
        )
    return notes


__all__ = [
    "THROUGHPUT",
    "CasePlan",
    "bracket",
    "case_plans",
    "case_steps",
    "expected_friction",
    "friction_at_share",
    "lid_steps",
    "preparation_steps",
    "trials_per_case",
    "wall_seconds",
    "Workload",
    "workload",
    "BoxPlan",
    "Jamming",
    "Preflight",
    "budget_suggestion",
    "calibration_box",
    "jamming_of",
    "preflight",
]
