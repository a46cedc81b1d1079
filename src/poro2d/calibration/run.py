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

import os
import time
from dataclasses import dataclass, field
from functools import partial
from typing import Any, ClassVar

import numpy as np

from poro2d.biaxial.lab import LabTests
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.calibration import model
from poro2d.calibration.biaxial import (
    BIAXIAL,
    BiaxialLabRecord,
    base_settings,
    biaxial_targets,
    biaxial_unit,
    check_quasi_static,
    read_biaxial_lab,
)
from poro2d.calibration.box_dominated import (
    BoxDominatedPoints,
    TooFewPoints,
    box_dominated_points,
    quick_box_note,
    with_box_note,
)
from poro2d.calibration.cluster import ClusterRecord, UnitFailure, UnitRunner
from poro2d.calibration.discrepancy import Discrepancy, DiscrepancyRecord, discrepancy_record, resolve_mode
from poro2d.calibration.evaluations import PARAMETER_KEYS, DesignPoint, Observed, target_key
from poro2d.calibration.identifiable import check_enough_lab_values
from poro2d.calibration.lab_repeats import LabRepeats, lab_scatter_ratio, lab_share, mean_targets
from poro2d.calibration.specimens import (
    check_preset,
    check_replicates,
    preset_specimens,
    replicate_unit,
)
from poro2d.calibration.units import CACHE, UnitRow, observable_unit, station, window_mean
from poro2d.errors import InputError, check_int, check_range, is_number
from poro2d.execute.dask_cluster import check_reachable
from poro2d.execute.options import RunOptions
from poro2d.io_utils import Provenance, check_output_dir
from poro2d.paper_data import QUICK_SHEAR
from poro2d.shear.box_scale import BoxScale, box_scale
from poro2d.shear.lab import LabData
from poro2d.shear.parts import LabRecord
from poro2d.shear.series import check_stresses
from poro2d.shear.settings import (
    MAX_FRICTION,
    MAX_ROLLING_FRICTION,
    PARTICLE_STIFFNESS_RANGE,
    ShearSettings,
)
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store, claims
from poro2d.typed_result import NOT_IN_FILE, Keyed, TypedResult, part

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "calibrate"

DEFAULT_FP_RANGE = (0.3, 3.0)
DEFAULT_MU_R_RANGE = (0.0, 0.5)
#: most design points of a round (each is replicates x stresses shear tests)
MAX_POINTS = 500
#: most stations along a curve (``stations``): each adds one or two observables per normal stress,
#: and the replicates must estimate the noise covariance of them all
MAX_STATIONS = 10
#: the degrees of freedom left to the surrogate's residual beyond its coefficients: with fewer,
#: the quadratic passes (nearly) through every replicate mean and its misfit, one of the noise
#: terms, cannot be estimated (six points fit its six coefficients exactly: a residual of zero)
RESIDUAL_DOF = 3
#: the fewest design points of the first round (the quadratic surrogate has 6 coefficients)
MIN_POINTS = model.N_COEFFICIENTS + RESIDUAL_DOF
#: the settings calibrated here: given ones would be overridden, so they are refused
CALIBRATED = ("particle_friction", "rolling_friction")
#: the names of the stiffness options, per axis
STIFFNESS_OPTIONS = {"kn": "--kn-range", "ks": "--ks-range"}


def min_points(d: int) -> int:
    """The fewest design points of the first round in ``d`` parameters: the quadratic's
    (d + 1)(d + 2) / 2 coefficients and :data:`RESIDUAL_DOF` more (9, 13 and 18 for 2, 3, 4)."""
    return model.n_coefficients(d) + RESIDUAL_DOF


#: the disks' stiffnesses (N/m) beside the frictions of a calibration's records: absent from the
#: file of a calibration that did not calibrate them
STIFFNESS_KEYS = ("particle_kn", "particle_ks")


@dataclass(eq=False)
class FrictionValues(TypedResult):
    """A value per calibrated parameter: the posterior maximum or median of f_p and mu_r (and of
    the disks' kn, ks in N/m when calibrated)."""

    particle_friction: float
    rolling_friction: float
    particle_kn: float | None = None
    particle_ks: float | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = STIFFNESS_KEYS


@dataclass(eq=False)
class FrictionBounds(TypedResult):
    """A [low, high] pair per calibrated parameter: its range, or its interval (None: unknown)."""

    particle_friction: list[float] | None
    rolling_friction: list[float] | None
    particle_kn: list[float] | None = None
    particle_ks: list[float] | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = STIFFNESS_KEYS


@dataclass(eq=False)
class FrictionFlags(TypedResult):
    """A yes/no per calibrated parameter: whether its interval is wide (None: unknown)."""

    particle_friction: bool | None
    rolling_friction: bool | None
    particle_kn: bool | None = None
    particle_ks: bool | None = None

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
class FittedObservable(TypedResult):
    """One laboratory value fitted: the observable (``peak``, ``end`` or ``dilation``) at a normal
    stress, the laboratory's value, the surrogate's at the best parameters and the noise it was
    given, in the observable's unit, named by the keys: ``lab_kpa``, ``model_kpa`` and
    ``noise_sd_kpa`` for a shear stress, ``lab_mm``, ``model_mm`` and ``noise_sd_mm`` for the
    dilation (the other three are absent from the file)."""

    observable: str
    normal_stress_kpa: float
    lab_kpa: float | None = None
    model_kpa: float | None = None
    noise_sd_kpa: float | None = None
    lab_mm: float | None = None
    model_mm: float | None = None
    noise_sd_mm: float | None = None
    #: a dimensionless observable's (biaxial: ``lab_ratio``, ``model_ratio``, ``noise_sd_ratio``)
    lab_ratio: float | None = None
    model_ratio: float | None = None
    noise_sd_ratio: float | None = None
    #: the design's tests at this stress: median kappa = kn / (sigma t) and mean overlap / d at the
    #: peak (how much elastic strain a dilation or volumetric observable carries; None: not recorded)
    stiffness_number: float | None = None
    mean_overlap_ratio_at_peak: float | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = (
        "lab_kpa", "model_kpa", "noise_sd_kpa", "lab_mm", "model_mm", "noise_sd_mm",
        "lab_ratio", "model_ratio", "noise_sd_ratio", "stiffness_number", "mean_overlap_ratio_at_peak",
    )  # fmt: skip

    @classmethod
    def of(cls, observable: str, normal_stress_kpa: float, lab: float, fitted: float, noise_sd: float,
           stiffness: tuple[float | None, float | None] = (None, None)):  # fmt: skip
        """The record of one target, its values under the keys of its unit; ``stiffness``: the
        design's kappa and overlap at its stress."""
        u = observable_unit(observable).lower()
        values = {f"lab_{u}": lab, f"model_{u}": fitted, f"noise_sd_{u}": noise_sd}
        kappa, overlap = stiffness
        return cls(observable, normal_stress_kpa, **values, stiffness_number=kappa,
                   mean_overlap_ratio_at_peak=overlap)  # fmt: skip

    @property
    def unit(self) -> str:
        """The unit of the values (``kPa``, ``mm`` or ``ratio``: dimensionless)."""
        return observable_unit(self.observable)


@dataclass(eq=False)
class PosteriorSummary(TypedResult):
    """What ``result.json`` keeps of the posterior (``posterior``).

    ``median``: per parameter (inside its interval, unlike the maximum on a ridge);
    ``correlation``: of the two parameters (near +-1: a ridge); ``wide``: per parameter,
    whether its interval spans more than :data:`~poro2d.calibration.model.WIDE_FRACTION` of
    its range; ``grid``: points per axis; ``prior``: in words; ``observables``: the values
    fitted; ``noise_correlation``: of the observables' noise.
    """

    median: FrictionValues
    correlation: float
    wide: FrictionFlags
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
        "median": FrictionValues,
        "wide": FrictionFlags,
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

    best: FrictionValues
    intervals: FrictionBounds
    level: float
    posterior: PosteriorSummary
    evaluations: list[DesignPoint]
    fit: dict[str, model.Surrogate]
    lab: LabRecord | BiaxialLabRecord
    specimens: dict[str, str]
    ranges: FrictionBounds
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
        "best": FrictionValues,
        "intervals": FrictionBounds,
        "lab": LabRecord,
        "ranges": FrictionBounds,
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


def check_range_pair(name: str, value, lo: float, hi: float, lo_open: bool = False) -> tuple[float, float]:
    """A (low, high) pair inside [lo, hi] with low < high."""
    if isinstance(value, str | bytes) or not hasattr(value, "__len__") or len(value) != 2:
        raise InputError(name, value, f"two numbers LOW,HIGH in [{lo}, {hi}]")
    a, b = value
    for v in (a, b):
        if not is_number(v):
            raise InputError(name, value, f"two numbers LOW,HIGH in [{lo}, {hi}]")
        check_range(name, float(v), lo, hi, lo_open=lo_open)
    if not float(a) < float(b):
        raise InputError(name, value, "LOW < HIGH")
    return float(a), float(b)


def _base_settings(settings: dict | None, calibrated: tuple[str, ...] = CALIBRATED) -> ShearSettings:
    """The shear settings of every test (frictions apart); ``stop_after_peak`` 0 by default so
    that every test ends at ``max_displacement``, where the end stress is compared.

    ``settings``: the caller's table of shear settings (a command's options), read once here;
    ``calibrated``: the settings the calibration sets (a disk stiffness given is kept when it is
    not calibrated)."""
    given = dict(settings or {})
    if not isinstance(settings, dict | None):
        raise InputError("settings", type(settings).__name__, "a dict of shear settings or None")
    for name in calibrated:
        if name in given:
            raise InputError(f"settings.{name}", given[name], "not given: it is calibrated")
    given.setdefault("stop_after_peak", 0.0)
    from poro2d.config import dataclass_from_table

    return dataclass_from_table(ShearSettings, "settings", given)


def _lab_targets(lab: LabData, base: ShearSettings, stations: int = 1) -> list[tuple[str, float, float]]:
    """(observable, normal stress, laboratory value) fitted: every peak; with curves the end stress;
    with the plate's vertical displacement too the dilation (mm); with ``stations`` > 1 the
    readings of each curve at ``stations`` - 1 evenly spaced displacements before the end.

    The end values of a laboratory curve are its means over the last peak window before the
    tests' ``max_displacement`` (the simulated end values are smoothed over the same window);
    a reading is its mean over the peak window before its station, on both sides
    (:func:`poro2d.calibration.units.window_mean`).
    """
    targets = [("peak", s, lab.peaks[s]) for s in lab.normal_stresses()]
    for s in lab.normal_stresses() if lab.curves else []:
        d, t = lab.curves[s]
        if d[-1] < base.max_displacement:
            raise InputError(
                "settings.max_displacement",
                base.max_displacement,
                f"at most {d[-1]:g} m, where the lab curve at {s:g} kPa ends",
            )
        targets.append(("end", s, _end_mean(d, t, base)))
    for s in lab.normal_stresses() if lab.vertical else []:
        targets.append(("dilation", s, 1e3 * _end_mean(lab.curves[s][0], lab.vertical[s], base)))
    return targets + _station_targets(lab, base, stations)


def _station_targets(lab: LabData, base: ShearSettings, stations: int) -> list[tuple[str, float, float]]:
    """The readings of the laboratory curves before their end: the shear stress (kPa) and, when the
    file has it, the plate's rise (mm) at ``max_displacement`` x j / ``stations``, j < ``stations``."""
    targets = []
    for j in range(1, stations):
        at = base.max_displacement * j / stations
        for s in lab.normal_stresses():
            d, t = lab.curves[s]
            targets.append((station("stress", at), s, window_mean(d, t, at, base.peak_window)))
            if lab.vertical:
                rise = window_mean(d, lab.vertical[s], at, base.peak_window)
                targets.append((station("rise", at), s, 1e3 * rise))
    return targets


def _end_mean(d: np.ndarray, y: np.ndarray, base: ShearSettings) -> float:
    """The mean of ``y`` over the readings within the last peak window before ``max_displacement``
    (the value at ``max_displacement`` interpolated when no reading lies in that window)."""
    return window_mean(d, y, base.max_displacement, base.peak_window)


@claims(KIND)
def run_calibration(
    lab: str | os.PathLike | LabData | LabTests | list | None = None,
    specimens: list[str | os.PathLike] | None = None,
    *,
    biaxial_lab: str | os.PathLike | list | LabTests | None = None,
    store: Store | None = None,
    preset: str | None = None,
    quick: bool = False,
    replicates: int = 3,
    seed: int = 0,
    fp_range=DEFAULT_FP_RANGE,
    mu_r_range=DEFAULT_MU_R_RANGE,
    kn_range=None,
    ks_range=None,
    points: int = 12,
    refine: int = 6,
    design_seed: int = 0,
    lab_error: float = 0.0,
    level: float = 0.95,
    stations: int = 1,
    settings: dict | None = None,
    options: RunOptions = RunOptions(),
    config: dict | None = None,
    keep_box_dominated: bool = False,
    discrepancy: str | float = "auto",
) -> CalibrationResult:
    """Calibrate f_p and mu_r against ``lab`` on replicate specimens; keeps ``result.json`` in ``store``.

    ``specimens``: checkpoints or criterion folders, or ``preset="paper"`` (``quick``: the
    small box) with ``replicates`` seeds from ``seed``. ``fp_range``, ``mu_r_range``: the
    search ranges. ``kn_range``, ``ks_range``: (low, high) N/m to calibrate the disks' normal and
    shear stiffness too, searched in their logarithm (None: the specimen's, or the settings');
    with either, the posterior is sampled with emcee (docs/calibration.md).
    ``points``: the space-filling design's size; ``refine``: points of the
    second round, drawn from the posterior (0: none). ``lab_error``: the laboratory's own
    error as a fraction of each value, added to the seed scatter. ``level``: of the
    credible intervals. ``stations``: with laboratory curves, each curve is also read (shear stress,
    and the plate's rise when given) at ``stations`` - 1 evenly spaced displacements before its end
    (1: peaks, end values and dilation only). ``settings``: shear settings of every test (the quick preset's
    ``max_displacement`` 4 mm by default). ``options``: where the jobs run and whether bars show
    (:class:`~poro2d.execute.options.RunOptions`, as the sweeps).
    A rerun reuses every finished shear test (cached by content in the store's ``cache``);
    ``store=None`` keeps nothing (every test runs, no figure or report is made).

    ``lab`` may be a list: repeats of one laboratory programme (the same normal stresses and
    readings, new specimens). Their mean values are fitted and the laboratory's share of the noise
    is one simulated specimen's scatter over their number, scaled up when the repeats scatter more
    (:mod:`poro2d.calibration.lab_repeats`).

    ``biaxial_lab`` instead of ``lab``: laboratory biaxial tests (one CSV or several, rows named by
    ``confining_stress_kpa``; or a :class:`poro2d.biaxial.lab.LabTests`, which ``lab`` also takes):
    every unit is then a biaxial test at a laboratory confining stress, the targets its stress
    ratios and volumetric strain (:mod:`poro2d.calibration.biaxial`), and ``settings`` are biaxial
    settings (``max_strain`` 0.2 by default).

    A design point any of whose direct shear tests is box-dominated (:mod:`poro2d.shear.box_dominated`:
    its shear plane carries outside 0.7-1.3 times the plate's load at the peak, or its stress never
    peaked) is left out of the fit, and the result says how many were (``box_dominated``); too few
    left for the surrogate is no answer. ``keep_box_dominated``: fit them all the same (a box where
    every test is box-dominated: the frictions then describe the box).

    ``discrepancy``: the model-discrepancy term (:mod:`poro2d.calibration.discrepancy`): ``estimate``
    (integrated over its unknown size), ``none`` (the noise covariance alone), ``auto`` (``none`` for
    laboratory files poro2d wrote itself, else ``estimate``) or a fixed size in each observable's noise sd.
    """
    t0 = time.perf_counter()
    if store is not None:
        check_output_dir(store.parameter, store.root)
    repeats = _read_lab(lab, biaxial_lab)
    biaxial = isinstance(repeats, LabTests)
    lab_data = repeats if biaxial else repeats.first
    if not biaxial:
        check_stresses(lab_data.normal_stresses())
    check_preset(preset, quick, replicates)
    if preset is not None and specimens:
        raise InputError("--specimen", ", ".join(map(str, specimens)), "nothing with --preset")
    if preset is not None and store is None:
        raise InputError("store", None, "a store to keep the preset's specimens in")
    # every given specimen accepted and read whole (a damaged file refused on one line) before any work
    given = SpecimenSet.named(specimens or []).read() if preset is None else None
    ranges = model.Ranges(
        check_range_pair("--fp-range", fp_range, 0.0, MAX_FRICTION, lo_open=True),
        check_range_pair("--mu-r-range", mu_r_range, 0.0, MAX_ROLLING_FRICTION),
        **_stiffness_ranges(kn_range, ks_range, biaxial),
    )
    fewest = min_points(ranges.dim)
    try:
        points = check_int("--points", points, fewest, MAX_POINTS)
    except InputError:
        raise InputError(
            "--points", points, f"an integer in [{fewest}, {MAX_POINTS}]",
            f"the surrogate's {model.n_coefficients(ranges.dim)} coefficients and {RESIDUAL_DOF} degrees"
            " of freedom to estimate its residual",
        ) from None  # fmt: skip
    refine = check_int("--refine", refine, 0, MAX_POINTS)
    design_seed = check_int("--design-seed", design_seed, 0)
    check_range("--lab-error", lab_error, 0.0, 1.0)
    check_range("--level", level, 0.0, 1.0, lo_open=True, hi_open=True)
    discrepancy = resolve_mode(discrepancy, biaxial_lab if lab is None else lab)
    if not isinstance(keep_box_dominated, bool):
        raise InputError("--keep-box-dominated", keep_box_dominated, "true or false")
    if settings is None and quick and not biaxial:
        settings = dict(QUICK_SHEAR)
    calibrated = CALIBRATED + tuple(PARAMETER_KEYS[a] for a in ranges.axes[2:])
    base = base_settings(settings, CALIBRATED) if biaxial else _base_settings(settings, calibrated)
    stations = check_int("--stations", stations, 1, MAX_STATIONS)
    if stations > 1 and not biaxial and not lab_data.curves:
        why = "readings along a curve need the lab curves"
        raise InputError("--stations", stations, "1 with a peaks file", why)
    lab_series = None  # every laboratory series' values (series x targets), shear only
    if biaxial:
        targets = biaxial_targets(lab_data, base, stations)
    else:
        targets, lab_series = mean_targets([_lab_targets(x, base, stations) for x in repeats.series])
    check_enough_lab_values(lab_data.source, targets, ranges.dim)
    check_noise_dof(points, len(given) if given is not None else replicates, len(targets))
    check_reachable(options.scheduler)

    found = (
        given
        if given is not None
        else preset_specimens(
            store.child("specimens"), quick=quick, seed=seed, replicates=replicates, progress=options.progress
        ).read()
    )
    check_replicates(found)
    if biaxial:
        check_quasi_static(found, lab_data.confining_stresses(), base)
    runner = UnitRunner(options)
    stresses = lab_data.confining_stresses() if biaxial else lab_data.normal_stresses()
    make = biaxial_unit if biaxial else replicate_unit
    cache = _child(store, CACHE)
    try:
        design = model.space_filling(ranges, points, design_seed)
        rows = runner.run(_units(design, found, stresses, base, make, ranges.axes), cache, "round 1")
        infer = partial(_infer, ranges, lab_error=lab_error, lab_series=lab_series, seed=design_seed,
                        keep_box_dominated=keep_box_dominated, discrepancy=discrepancy)  # fmt: skip
        post, surrogates, table = infer(design, found, stresses, rows, targets)
        if refine:
            extra = [p for p in post.draw(refine, design_seed + 1) if p not in design]
            design = design + extra
            rows += runner.run(_units(extra, found, stresses, base, make, ranges.axes), cache, "round 2")
            post, surrogates, table = infer(design, found, stresses, rows, targets)
    except TooFewPoints as exc:
        if not quick or biaxial:
            raise
        raise TooFewPoints(
            f"{quick_box_note(smallest_box(found).disks, base.max_displacement)}; {exc}"
        ) from None
    finally:
        runner.close()
    result = _result(
        post,
        surrogates,
        table,
        targets,
        level,
        repeats,
        found,
        ranges,
        base,
        runner,
        t0,
        config or {},
        lab_error,
        design_seed,
        points,
        refine,
        stations,
        quick=quick,
        discrepancy=discrepancy,
    )
    if store is not None:
        from poro2d.calibration.outputs import write_outputs

        make_unit = partial(make, base=base)
        result.drawing = write_outputs(store, result, post, repeats, found, make_unit, stresses)
    return result


def _stiffness_ranges(kn_range, ks_range, biaxial: bool) -> dict[str, tuple[float, float]]:
    """The search ranges of the disks' stiffnesses that are calibrated (N/m), checked; refused
    with biaxial laboratory tests, whose settings do not replace the disks' stiffness."""
    given = {"kn": kn_range, "ks": ks_range}
    out = {}
    for axis, value in given.items():
        if value is None:
            continue
        option = STIFFNESS_OPTIONS[axis]
        if biaxial:
            raise InputError(
                option, value, "not given with --biaxial-lab", "kn and ks are calibrated on direct shear only"
            )
        out[axis] = check_range_pair(option, value, *PARTICLE_STIFFNESS_RANGE)
    return out


def _read_lab(lab, biaxial_lab) -> LabRepeats | LabTests:
    """The laboratory data: direct shear (``lab``: one series or repeats) or biaxial tests
    (``biaxial_lab``), exactly one."""
    if isinstance(lab, LabTests) and biaxial_lab is None:
        lab, biaxial_lab = None, lab
    if (lab is None) == (biaxial_lab is None):
        given = "neither" if lab is None else "both"
        raise InputError(
            "--lab",
            given,
            "exactly one of --lab (direct shear peaks or curves) and --biaxial-lab (biaxial curves)",
        )
    if biaxial_lab is not None:
        return read_biaxial_lab(biaxial_lab)
    return LabRepeats.of(lab)


def check_noise_dof(points: int, replicates: int, observables: int) -> None:
    """Refuse, before any test, a design whose replicates cannot estimate the noise of its
    observables: the covariance of ``observables`` values needs points x (replicates - 1) >
    observables + 1 degrees of freedom (:func:`poro2d.calibration.model.precision_factor`).
    One specimen is let through: its intervals are reported as unknown."""
    if replicates < 2 or model.precision_factor(points * (replicates - 1), observables) > 0:
        return
    need = -(-(observables + 2) // (replicates - 1))
    raise InputError(
        "--points", points, f"at least {need} for {observables} observables on {replicates} replicates",
        "the noise covariance needs points x (replicates - 1) > observables + 1; or give fewer --stations",
    )  # fmt: skip


def smallest_box(found: SpecimenSet) -> BoxScale:
    """The :class:`BoxScale` of the narrowest box (in largest grains) among the read specimens."""
    scales = [box_scale(*s.box(), s.arrays["particles.radius"]) for s in found.contents()]
    return min(scales, key=lambda b: b.width_over_d_max)


def _child(store: Store | None, name: str) -> Store | None:
    return None if store is None else store.child(name)


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
    """The prior in words: the two-parameter text of earlier files, the stiffnesses added."""
    if ranges.dim == 2:
        return "uniform in log(f_p) and mu_r over the ranges"
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
    post,
    surrogates,
    table,
    targets,
    level,
    lab_data,
    found: SpecimenSet,
    ranges,
    base,
    runner,
    t0,
    config,
    lab_error,
    design_seed,
    points,
    refine,
    stations=1,
    *,
    quick: bool = False,
    discrepancy="none",
) -> CalibrationResult:
    best = dict(zip(ranges.axes, post.best(), strict=True))
    biaxial = isinstance(lab_data, LabTests)
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
        FittedObservable.of(obs, s, y, float(sg.mean(best_unit)[0]), sd, stiffness.get(s, (None, None)))
        for (obs, s, y), sg, sd in zip(targets, surrogates, post.noise_sd, strict=True)
    ]
    sampled = isinstance(post, model.SampledPosterior)
    return CalibrationResult(
        best=FrictionValues.from_dict({keys[a]: v for a, v in best.items()}),
        intervals=FrictionBounds.from_dict(intervals),
        level=level,
        posterior=PosteriorSummary(
            median=FrictionValues.from_dict({keys[a]: post.median(a) for a in ranges.axes}),
            correlation=post.correlation(),
            wide=FrictionFlags.from_dict(wide),
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
        lab=BiaxialLabRecord.of(lab_data) if biaxial else lab_data.record(),
        specimens={label: str(found[label]) for label in found},
        ranges=FrictionBounds.from_dict({keys[a]: list(getattr(ranges, a)) for a in ranges.axes}),
        settings=base,
        cluster=runner.info(),
        failures=runner.failures,
        timings=CalibrationTimings(wall_time_s=time.perf_counter() - t0),
        config=dict(
            config,
            points=points,
            refine=refine,
            design_seed=design_seed,
            lab_error=lab_error,
            **({"stations": stations} if stations > 1 else {}),
            **({"discrepancy": discrepancy} if discrepancy != "none" else {}),
        ),  # fmt: skip
        provenance=Provenance.now(),
        unidentified=unknown,
        box_scale=scale,
        test=BIAXIAL if biaxial else None,
        box_dominated=None
        if scale is None
        else with_box_note(post.box_dominated, quick, scale.disks, base.max_displacement),
    )


__all__ = [
    "DEFAULT_FP_RANGE",
    "DEFAULT_MU_R_RANGE",
    "CalibrationResult",
    "ChainRecord",
    "FittedObservable",
    "PosteriorSummary",
    "run_calibration",
    "unidentified_reason",
]
