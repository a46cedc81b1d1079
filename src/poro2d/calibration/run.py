"""``run_calibration``: the micro-parameters (f_p, mu_r; optionally the disks' kn and ks) that
reproduce laboratory direct shear.

Every evaluation of a parameter pair is a shear test per replicate specimen and per
laboratory normal stress (the units, :mod:`poro2d.calibration.units`), run on Dask.
Round 1 evaluates a space-filling design; the surrogate and the posterior follow
(:mod:`poro2d.calibration.model`); round 2 (``refine`` > 0) evaluates points drawn from
that posterior, and the surrogate and posterior are fitted again on every point.
Everything is checked before the first test starts.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import partial
from typing import Any, ClassVar

import numpy as np

from poro2d.biaxial.settings import BiaxialSettings
from poro2d.calibration import model
from poro2d.calibration.biaxial import (
    BIAXIAL,
    BiaxialLabRecord,
    check_quasi_static,
)
from poro2d.calibration.box_dominated import (
    BoxDominatedPoints,
    TooFewPoints,
    box_dominated_points,
    quick_box_note,
    with_box_note,
)
from poro2d.calibration.case import CalibrationCase, min_points
from poro2d.calibration.cluster import ClusterRecord, UnitFailure, UnitRunner
from poro2d.calibration.discrepancy import Discrepancy, DiscrepancyRecord, discrepancy_record
from poro2d.calibration.evaluations import PARAMETER_KEYS, DesignPoint, Observed, target_key
from poro2d.calibration.lab_repeats import lab_scatter_ratio, lab_share
from poro2d.calibration.specimens import (
    check_replicates,
    preset_specimens,
    replicate_unit,
)
from poro2d.calibration.units import CACHE, UnitRow, observable_unit
from poro2d.errors import InputError
from poro2d.execute.dask_cluster import check_reachable
from poro2d.execute.options import RunOptions
from poro2d.io_utils import Provenance, check_output_dir
from poro2d.measure.stiffness import StiffnessAtPeak
from poro2d.shear.box_scale import BoxScale, box_scale
from poro2d.shear.parts import LabRecord
from poro2d.shear.settings import (
    ShearSettings,
)
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store, claims
from poro2d.typed_result import NOT_IN_FILE, Keyed, TypedResult, part, with_fields

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "calibrate"


#: the disks' stiffnesses (N/m) beside the frictions of a calibration's records: absent from the
#: file of a calibration that did not calibrate them
STIFFNESS_KEYS = ("particle_kn", "particle_ks")


@dataclass(eq=False)
class ParameterValues(TypedResult):
    """A value per calibrated parameter: a number (the posterior maximum or median; the disks' kn, ks
    in N/m), a [low, high] pair (a range or an interval) or a yes/no (whether an interval is wide);
    None where unknown."""

    particle_friction: Any
    rolling_friction: Any
    particle_kn: Any = None
    particle_ks: Any = None

    OPTIONAL: ClassVar[tuple[str, ...]] = STIFFNESS_KEYS


@dataclass(eq=False)
class ChainRecord(TypedResult):
    """The emcee chain a posterior in more than two parameters was sampled with: walkers, steps of
    each (the burn-in included), the burn-in discarded and the autocorrelation time per parameter
    (steps, in the order of ``ranges``)."""

    sampler: str
    walkers: int
    steps: int
    burn_in: int
    autocorrelation_steps: list[float]


@dataclass(eq=False)
class CalibrationTimings(TypedResult):
    """Where a calibration's time went (s)."""

    wall_time_s: float


@dataclass(eq=False)
@with_fields(StiffnessAtPeak, after="noise_sd")
class FittedObservable(TypedResult):
    """One laboratory value fitted: the observable (``peak``, ``end``, ``dilation``, a reading, a
    biaxial ratio) at a normal (or confining) stress, the laboratory's value, the surrogate's at the
    best parameters and the noise it was given, in the observable's :attr:`unit`, which the file's
    keys name: ``lab_kpa``, ``model_kpa``, ``noise_sd_kpa`` for a shear stress, ``lab_mm``, ...
    for the dilation, ``lab_ratio``, ... for a dimensionless one; then, of the design's tests at this
    stress, the median kappa = kn / (sigma t) and mean overlap / d at the peak (how much elastic
    strain a dilation or volumetric observable carries; None: not recorded)."""

    observable: str
    normal_stress_kpa: float
    lab: float | None
    model: float | None
    noise_sd: float | None

    #: the values whose keys in the file end in the unit
    IN_UNIT: ClassVar[tuple[str, ...]] = ("lab", "model", "noise_sd")
    OPTIONAL: ClassVar[tuple[str, ...]] = (*IN_UNIT, "stiffness_number", "mean_overlap_ratio_at_peak")

    @property
    def unit(self) -> str:
        """The unit of the values (``kPa``, ``mm`` or ``ratio``: dimensionless)."""
        return observable_unit(self.observable)

    def to_dict(self) -> dict[str, Any]:
        u = self.unit.lower()
        return {f"{k}_{u}" if k in self.IN_UNIT else k: v for k, v in super().to_dict().items()}

    @classmethod
    def from_dict(cls, data) -> FittedObservable:
        """The record of its entry in a file, its values read under the keys of its unit."""
        named = {f"{k}_{observable_unit(data['observable']).lower()}": k for k in cls.IN_UNIT}
        return super().from_dict({named.get(k, k): v for k, v in data.items()})


@dataclass(eq=False)
class PosteriorSummary(TypedResult):
    """What ``result.json`` keeps of the posterior (``posterior``).

    ``median``: per parameter (inside its interval, unlike the maximum on a ridge);
    ``correlation``: of the two parameters (near +-1: a ridge); ``wide``: per parameter,
    whether its interval spans more than :data:`~poro2d.calibration.model.WIDE_FRACTION` of
    its range; ``grid``: points per axis; ``prior``: in words; ``observables``: the values
    fitted; ``noise_correlation``: of the observables' noise.
    """

    median: ParameterValues
    correlation: float
    wide: ParameterValues
    grid: int
    prior: str
    observables: list[FittedObservable]
    noise_correlation: list[list[float]]
    #: the covariance's correction for being estimated (model.precision_factor): the noise sd are
    #: divided by its square root; absent from files of earlier versions
    precision_factor: float | None = None
    #: laboratory repeats averaged (:mod:`poro2d.calibration.lab_repeats`) and their pooled variance
    #: over a simulated specimen's; absent from the file of a calibration against one series
    lab_repeats: int | None = None
    lab_scatter_ratio: float | None = None
    #: with kn or ks calibrated (``grid`` None): the chain the posterior was sampled with
    chain: ChainRecord | None = None
    #: the model-discrepancy term (:mod:`poro2d.calibration.discrepancy`); absent without one
    discrepancy: DiscrepancyRecord | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = (
        "precision_factor", "lab_repeats", "lab_scatter_ratio", "chain", "discrepancy"
    )  # fmt: skip

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {
        "median": ParameterValues,
        "wide": ParameterValues,
        "observables": FittedObservable,
        "chain": ChainRecord,
        "discrepancy": DiscrepancyRecord,
    }


@dataclass(eq=False)
class CalibrationResult(TypedResult):
    """A calibration (``result.json``): the best parameters, their intervals, the posterior.

    ``best``: the posterior maximum (``particle_friction``, ``rolling_friction``): the pair
    that reproduces the laboratory best; on a ridge or at a range's end it may lie outside
    the central intervals, which ``posterior["median"]`` never does;
    ``intervals``: central credible intervals at ``level``; ``posterior``: its correlation
    (near +-1: a ridge), whether each interval is wide, the observables fitted;
    ``evaluations``: one :class:`DesignPoint` per design point (each observable's replicate values);
    ``fit``: the surrogate per observable; ``lab``: the laboratory values fitted;
    ``box_scale``: the smallest box of the specimens against ASTM D3080 and the size-insensitive
    2D box: parameters fitted to a box-scale box carry its biases (docs/shear.md).
    """

    best: ParameterValues
    intervals: ParameterValues
    level: float
    posterior: PosteriorSummary
    evaluations: list[DesignPoint]
    fit: dict[str, model.Surrogate]
    lab: LabRecord | BiaxialLabRecord
    specimens: dict[str, str]
    ranges: ParameterValues
    settings: ShearSettings | BiaxialSettings
    cluster: ClusterRecord
    failures: list[UnitFailure]
    timings: CalibrationTimings
    config: dict[str, Any]
    provenance: Provenance
    #: why the intervals are unknown (then ``intervals`` and ``posterior["wide"]`` hold None);
    #: absent from the file of a calibration whose design estimates its own noise
    unidentified: str | None = None
    box_scale: BoxScale | None = None
    #: the laboratory test fitted: "biaxial" (then ``lab`` and ``settings`` are the biaxial ones);
    #: absent from a direct shear calibration's file
    test: str | None = None
    #: the design points left out of the fit because a test of theirs was box-dominated, with the
    #: calibration's sentence on what its box can measure; absent from a biaxial calibration's file
    #: and from files of earlier versions
    box_dominated: BoxDominatedPoints | None = None
    #: what the figures are drawn from (the posterior, the curves nearest the best), with a store
    drawing: Any = field(default=None, kw_only=True, repr=False, metadata=NOT_IN_FILE)

    OPTIONAL: ClassVar[tuple[str, ...]] = ("unidentified", "box_scale", "test", "box_dominated")
    #: the fields read as their records from a file's dict (``fit``: a surrogate per observable)
    PARTS: ClassVar[dict[str, type[TypedResult] | Keyed]] = {
        "best": ParameterValues,
        "intervals": ParameterValues,
        "lab": LabRecord,
        "ranges": ParameterValues,
        "settings": ShearSettings,
        "timings": CalibrationTimings,
        "provenance": Provenance,
        "posterior": PosteriorSummary,
        "cluster": ClusterRecord,
        "failures": UnitFailure,
        "fit": Keyed(model.Surrogate),
        "evaluations": DesignPoint,
        "box_scale": BoxScale,
        "box_dominated": BoxDominatedPoints,
    }

    @classmethod
    def from_dict(cls, data) -> CalibrationResult:
        """A calibration from its file; a biaxial one's ``lab`` and ``settings`` read as theirs."""
        obj = super().from_dict(data)
        if data.get("test") == BIAXIAL:
            obj.lab = part(BiaxialLabRecord, data.get("lab"))
            obj.settings = part(BiaxialSettings, data.get("settings"))
        return obj

    @property
    def biaxial(self) -> bool:
        """Whether the laboratory data were biaxial tests (the stress of each target is sigma_3)."""
        return self.test == BIAXIAL

    @classmethod
    def read(cls, store: Store) -> CalibrationResult | None:
        """The calibration finished in ``store`` (its ``result.json``), or None when there is none."""
        return store.read_result("result.json", cls.from_dict)


@claims(KIND)
def run_calibration(
    case: CalibrationCase, store: Store | None = None, *, options: RunOptions = RunOptions()
) -> CalibrationResult:
    """Calibrate f_p and mu_r (and kn, ks when ranged) of ``case`` (a
    :class:`~poro2d.calibration.case.CalibrationCase`: what each option means) on its replicate
    specimens; keeps ``result.json`` in ``store``. ``options``: where the jobs run and whether bars
    show (:class:`~poro2d.execute.options.RunOptions`, as the sweeps). A rerun reuses every finished
    shear test (cached by content in the store's ``cache``); ``store=None`` keeps nothing (every test
    runs, no figure or report is made; a preset's specimens need a store).
    """
    t0 = time.perf_counter()
    if not isinstance(case, CalibrationCase):
        raise InputError(
            "case", type(case).__name__, "a CalibrationCase: CalibrationCase.of(lab, specimens, ...)"
        )
    if store is not None:
        check_output_dir(store.parameter, store.root)
    if case.preset is not None and store is None:
        raise InputError("store", None, "a store to keep the preset's specimens in")
    check_reachable(options.scheduler)
    found = case.specimens
    if found is None:
        made = preset_specimens(store.child("specimens"), quick=case.quick, seed=case.seed,
                                replicates=case.replicates, progress=options.progress)  # fmt: skip
        found = made.read()
    check_replicates(found)
    if case.biaxial:
        check_quasi_static(found, case.lab.confining_stresses(), case.base)
    runner = UnitRunner(options)
    try:
        post, surrogates, table = _rounds(case, found, runner, None if store is None else store.child(CACHE))
    except TooFewPoints as exc:
        if not case.quick or case.biaxial:
            raise
        note = quick_box_note(smallest_box(found).disks, case.base.max_displacement)
        raise TooFewPoints(f"{note}; {exc}") from None
    finally:
        runner.close()
    result = _result(case, post, surrogates, table, found, runner, t0)
    if store is not None:
        from poro2d.calibration.outputs import write_outputs

        make_unit = partial(case.make, base=case.base)
        result.drawing = write_outputs(store, result, post, case.repeats, found, make_unit, case.stresses)
    return result


def _rounds(case: CalibrationCase, found: SpecimenSet, runner: UnitRunner, cache: Store | None):
    """Round 1 on the space-filling design, round 2 (``refine``) on draws from its posterior; the
    posterior, surrogates and table of the last fit."""
    stresses, axes = case.stresses, case.ranges.axes
    design = model.space_filling(case.ranges, case.points, case.design_seed)
    rows = runner.run(_units(design, found, stresses, case.base, case.make, axes), cache, "round 1")
    infer = partial(_infer, case.ranges, lab_error=case.lab_error, lab_series=case.lab_series,
                    seed=case.design_seed, keep_box_dominated=case.keep_box_dominated,
                    discrepancy=case.discrepancy)  # fmt: skip
    post, surrogates, table = infer(design, found, stresses, rows, case.targets)
    if case.refine:
        extra = [p for p in post.draw(case.refine, case.design_seed + 1) if p not in design]
        design = design + extra
        rows += runner.run(_units(extra, found, stresses, case.base, case.make, axes), cache, "round 2")
        post, surrogates, table = infer(design, found, stresses, rows, case.targets)
    return post, surrogates, table


def smallest_box(found: SpecimenSet) -> BoxScale:
    """The :class:`BoxScale` of the narrowest box (in largest grains) among the read specimens."""
    scales = [box_scale(*s.box(), s.arrays["particles.radius"]) for s in found.contents()]
    return min(scales, key=lambda b: b.width_over_d_max)


def _units(design, specimens: SpecimenSet, stresses, base, make=replicate_unit, axes=("fp", "mu_r")) -> list:
    """The units of ``design``: per design point, per specimen, per normal (or confining) stress (the
    order of the rows :func:`_infer` reads; the units of more points follow those of the first).
    ``make``: the unit of one test (:func:`replicate_unit`, or a biaxial one); ``axes``: the
    parameters of each design point (``kn``, ``ks`` after the two frictions when calibrated)."""
    return [
        make(specimens, label, s, base, fp, mu_r, **dict(zip(axes[2:], stiffness, strict=True)))
        for fp, mu_r, *stiffness in design
        for label in specimens
        for s in stresses
    ]


def _infer(
    ranges,
    design,
    specimens: SpecimenSet,
    stresses,
    rows: list[UnitRow | None],
    targets,
    lab_error,
    lab_series=None,
    seed: int = 0,
    *,
    keep_box_dominated: bool = False,
    discrepancy="none",
):
    """The surrogates (one per target), the posterior and the table of replicate values per design point.

    ``rows``: the units' rows in the order of :func:`_units` (None: the test failed);
    ``lab_series``: every laboratory repeat's values (series x targets; None: one series); ``seed``:
    of the sampler, when kn or ks are calibrated (the grid of two parameters needs none);
    ``discrepancy``: the model-discrepancy mode (:mod:`poro2d.calibration.discrepancy`). A design point
    with a box-dominated test is left out of the fit (:func:`box_dominated_points`) unless
    ``keep_box_dominated``; the posterior's ``box_dominated`` says which."""
    per_point = len(specimens) * len(stresses)
    table = []
    for k, (fp, mu_r, *stiffness) in enumerate(design):
        point = rows[k * per_point : (k + 1) * per_point]
        observed = []
        for obs, s, _ in targets:
            at_s = point[stresses.index(s) :: len(stresses)]  # one row per specimen
            values = [row.observable(obs) if row is not None else float("nan") for row in at_s]
            observed.append(Observed(obs, s, values))
        given = {PARAMETER_KEYS[a]: v for a, v in zip(ranges.axes[2:], stiffness, strict=True)}
        table.append(DesignPoint(fp, mu_r, tuple(observed), **given))
    # a design point any of whose tests read the box, not the material, is left out of the fit
    flagged = [[r for r in rows[k * per_point : (k + 1) * per_point] if r is not None and r.box_dominated]
               for k in range(len(table))]  # fmt: skip
    left_out = box_dominated_points(flagged, table, min_points(ranges.dim), keep_box_dominated)
    kept = np.array([keep_box_dominated or not f for f in flagged], bool)
    unit = ranges.to_unit(*zip(*(e.parameters(ranges.axes) for e in table), strict=True))[kept]
    values = np.array([[o.values for o in e.observed] for e in table], float)[kept]
    surrogates = []
    for k, (obs, s, _) in enumerate(targets):
        ok = np.isfinite(values[:, k]).any(axis=1)
        if ok.sum() < min_points(ranges.dim):
            raise RuntimeError(
                f"only {int(ok.sum())} design points have a {obs} at {s:g} kPa; "
                f"the surrogate needs {min_points(ranges.dim)}"
            )
        surrogates.append(model.fit_surrogate(unit[ok], values[ok, k], observable_unit(obs)))
    lab_values = [y for *_, y in targets]
    try:  # an overflow or a 0/0 here would end in a posterior of NaN read as an answer
        with np.errstate(divide="raise", over="raise", invalid="raise"):
            units = [observable_unit(obs) for obs, *_ in targets]
            seed_cov = model.seed_covariance(values)
            ratio = None if lab_series is None else lab_scatter_ratio(lab_series, seed_cov)
            count = 1 if lab_series is None else lab_series.shape[0]
            share = lab_share(count, ratio)
            cov = model.noise_covariance(surrogates, seed_cov, lab_values, lab_error, units, share)
            factor = _precision_factor(values, len(targets))
            cov = cov / factor
            term = Discrepancy.of(discrepancy)
            if ranges.dim == 2:
                post = model.posterior(ranges, surrogates, lab_values, cov, term)
            else:
                post = model.sampled_posterior(ranges, surrogates, lab_values, cov, seed, discrepancy=term)
            post.precision_factor = factor
            post.lab_repeats, post.lab_scatter_ratio = count, ratio
            cov = _with_discrepancy(cov, post)
            post.noise_sd = np.sqrt(np.diag(cov)).tolist()
            post.noise_correlation = (cov / np.sqrt(np.outer(np.diag(cov), np.diag(cov)))).round(3).tolist()
    except (FloatingPointError, np.linalg.LinAlgError) as exc:
        raise RuntimeError(f"the posterior cannot be computed ({exc}): no answer is reported") from None
    if not post.finite():
        raise RuntimeError("the posterior is not finite: no answer is reported")
    post.box_dominated = left_out
    post.stiffness = stiffness_at(rows)
    return post, surrogates, table


def stiffness_at(rows) -> dict[float, tuple[float | None, float | None]]:
    """Per stress, the median kappa and mean overlap / d at the peak of the design's tests (None
    where no test recorded them: tests cached before they were)."""
    out = {}
    for sigma in sorted({r.sigma for r in rows if r is not None}):
        at = [r for r in rows if r is not None and r.sigma == sigma]
        kappa = [r.stiffness_number for r in at if r.stiffness_number is not None]
        overlap = [r.mean_overlap_ratio for r in at if r.mean_overlap_ratio is not None]
        out[sigma] = (
            float(np.median(kappa)) if kappa else None,
            float(np.median(overlap)) if overlap else None,
        )
    return out


def _with_discrepancy(cov: np.ndarray, post) -> np.ndarray:
    """The noise covariance with the discrepancy at its posterior median added (the noise sd a
    fit is shown with); ``cov`` itself without a discrepancy term."""
    median = post.discrepancy_at(0.5)
    if median is None:
        return cov
    return Discrepancy(np.array([median]), np.zeros(1)).covariances(cov)[0]


def _precision_factor(values: np.ndarray, observables: int) -> float:
    """The covariance's correction for being estimated (:func:`poro2d.calibration.model.precision_factor`)
    from the complete design points' replicates; 1 with one specimen (no scatter estimated: the
    intervals are reported as unknown). Failed tests can leave too few: then no answer."""
    replicates = values.shape[2]
    if replicates < 2:
        return 1.0
    dof = int(np.isfinite(values).all(axis=(1, 2)).sum()) * (replicates - 1)
    factor = model.precision_factor(dof, observables)
    if factor <= 0:
        raise RuntimeError(
            f"{dof} degrees of freedom of the seed scatter for {observables} observables: the noise"
            " covariance cannot be estimated, no answer is reported"
        )
    return factor


def _wide(ranges: model.Ranges, axis: str, lo: float, hi: float) -> bool:
    """Whether an interval spans more than :data:`~poro2d.calibration.model.WIDE_FRACTION` of its
    range, in the coordinate searched (the logarithm of f_p, kn and ks; mu_r itself)."""
    r_lo, r_hi = getattr(ranges, axis)
    if axis in model.LOG_AXES:
        return bool(np.log(hi / lo) > model.WIDE_FRACTION * np.log(r_hi / r_lo))
    return bool(hi - lo > model.WIDE_FRACTION * (r_hi - r_lo))


def _prior(ranges: model.Ranges) -> str:
    """The prior in words (two parameters: "uniform in log(f_p) and mu_r over the ranges")."""
    words = {"fp": "log(f_p)", "mu_r": "mu_r", "kn": "log(kn)", "ks": "log(ks)"}
    names = [words[a] for a in ranges.axes]
    return f"uniform in {', '.join(names[:-1])} and {names[-1]} over the ranges"


def _chain_record(post: model.SampledPosterior) -> ChainRecord:
    import emcee

    return ChainRecord(
        sampler=f"emcee {emcee.__version__}", walkers=post.walkers, steps=post.steps, burn_in=post.burn_in,
        autocorrelation_steps=[round(t, 1) for t in post.autocorrelation],
    )  # fmt: skip


def unidentified_reason(specimens: int, intervals: dict) -> str | None:
    """Why the intervals of a calibration are unknown, or None when its design estimates its noise.

    One specimen has no seed scatter: the noise would be the surrogate's residual alone and
    the intervals would look narrow for want of a scatter, not for the data. An interval of
    zero width on the grid (one grid cell) says the same of the noise from the model's side.
    """
    if specimens < 2:
        return "one specimen: the seed scatter cannot be estimated, so the intervals are unknown"
    for name, (lo, hi) in intervals.items():
        if not lo < hi:
            return (
                f"the {name} interval has zero width ({lo:.3g} to {hi:.3g}): the noise is not"
                " estimated, so the intervals are unknown"
            )
    return None


def _result(
    case: CalibrationCase, post, surrogates, table, found: SpecimenSet, runner, t0: float
) -> CalibrationResult:
    """The result of the last fit: best values, intervals at ``case.level``, the posterior's summary."""
    ranges, targets, level, base, biaxial = case.ranges, case.targets, case.level, case.base, case.biaxial
    best = dict(zip(ranges.axes, post.best(), strict=True))
    scale = None if biaxial else smallest_box(found)  # ASTM D3080 speaks of shear boxes only
    keys = {axis: PARAMETER_KEYS[axis] for axis in ranges.axes}
    intervals = {keys[a]: list(post.interval(a, level)) for a in ranges.axes}
    wide: dict[str, bool | None] = {keys[a]: _wide(ranges, a, *intervals[keys[a]]) for a in ranges.axes}
    unknown = unidentified_reason(len(found), intervals)
    if unknown is not None:
        intervals = dict.fromkeys(intervals)
        wide = dict.fromkeys(wide)
    best_unit = ranges.to_unit(*best.values())
    stiffness = getattr(post, "stiffness", {})
    fitted = [
        FittedObservable(obs, s, y, float(sg.mean(best_unit)[0]), sd, *stiffness.get(s, (None, None)))
        for (obs, s, y), sg, sd in zip(targets, surrogates, post.noise_sd, strict=True)
    ]
    sampled = isinstance(post, model.SampledPosterior)
    return CalibrationResult(
        best=ParameterValues.from_dict({keys[a]: v for a, v in best.items()}),
        intervals=ParameterValues.from_dict(intervals),
        level=level,
        posterior=PosteriorSummary(
            median=ParameterValues.from_dict({keys[a]: post.median(a) for a in ranges.axes}),
            correlation=post.correlation(),
            wide=ParameterValues.from_dict(wide),
            grid=None if sampled else model.GRID,
            prior=_prior(ranges),
            observables=fitted,
            noise_correlation=post.noise_correlation,
            precision_factor=post.precision_factor,
            lab_repeats=post.lab_repeats if post.lab_repeats > 1 else None,
            lab_scatter_ratio=post.lab_scatter_ratio,
            chain=_chain_record(post) if sampled else None,
            discrepancy=discrepancy_record(post, level),
        ),
        evaluations=table,
        fit={target_key(obs, s): sg for (obs, s, _), sg in zip(targets, surrogates, strict=True)},
        lab=BiaxialLabRecord.of(case.lab) if biaxial else case.repeats.record(),
        specimens={label: str(found[label]) for label in found},
        ranges=ParameterValues.from_dict({keys[a]: list(getattr(ranges, a)) for a in ranges.axes}),
        settings=base,
        cluster=runner.info(),
        failures=runner.failures,
        timings=CalibrationTimings(wall_time_s=time.perf_counter() - t0),
        config=dict(
            case.config,
            points=case.points,
            refine=case.refine,
            design_seed=case.design_seed,
            lab_error=case.lab_error,
            **({"stations": case.stations} if case.stations > 1 else {}),
            **({"discrepancy": case.discrepancy} if case.discrepancy != "none" else {}),
        ),  # fmt: skip
        provenance=Provenance.now(),
        unidentified=unknown,
        box_scale=scale,
        test=BIAXIAL if biaxial else None,
        box_dominated=None
        if scale is None
        else with_box_note(post.box_dominated, case.quick, scale.disks, base.max_displacement),
    )


__all__ = [
    "CalibrationResult",
    "ChainRecord",
    "FittedObservable",
    "PosteriorSummary",
    "run_calibration",
    "unidentified_reason",
]
