"""Multilayer compaction of a specimen in a W x H box (the paper's section 3).

The specimen is built in ``layers`` horizontal bands, bottom first. Each band
receives its share of the disks, placed without overlap at reduced radius
(:func:`poro2d.specimen.placement.place_disks`), under a temporary lid at the
band's top; the radii are then grown back to full size in small increments while
the engine cycles (radius expansion), and the band is cycled to equilibrium
(maximum unbalanced-force ratio below ``ratio``) with the preparation friction.
The lid then moves up to the next band's top. After the last band the lid is at
H and stays there as the top plate; the particle friction is raised to its
working value and the specimen is cycled to equilibrium once more.

A stage that does not reach equilibrium within its budget gets a fallback
(:func:`equilibrate`): a second budget of steps, then a calm stage (velocities
set to zero, higher local damping), then the normal damping and ratio again. A
stage that still fails ends the preparation there: the report says which stage
failed and the ratio it reached, and the specimen is never completed silently.

Undercompaction (Ladd 1978; Jiang, Konrad and Leroueil 2003) is optional: band k
of nt is closed at height (H / nt) (k - 1 + (1 + U_k)), with
U_k = U_1 - U_1 (k - 1) / (nt - 1), so the lower layers start looser and end
near the target density once the layers above compact them.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, fields, replace
from typing import Any, ClassVar

import numpy as np

from poro2d.dem import ContactModel, Every, Particles, Simulation, Walls
from poro2d.dem.contact_law import MAX_ROLLING_FRICTION
from poro2d.dem.ordering import strip_order
from poro2d.dem.simulation import MEASURES
from poro2d.errors import InputError, Integer, OneOf, Ranges, Real, check_fields, check_range
from poro2d.grading import MAX_DRAW, GradingCurve, draw_disks
from poro2d.identity import outside_identity
from poro2d.measure.porosity import box_porosity, porosity_rect
from poro2d.paper_data import TABLE_1
from poro2d.record import Fixed, Record
from poro2d.specimen.placement import Band, place_disks
from poro2d.typed_result import TypedResult

_log = logging.getLogger(__name__)

#: Specimens of more disks than this are refused before any disk is drawn, unless the
#: config raises ``[specimen] max_disks`` (up to ``MAX_DRAW``).
DEFAULT_MAX_DISKS = 2_000_000
#: Memory per disk for the estimate: the engine holds about 0.5 kB per disk (positions,
#: properties, forces, neighbour lists with their history); drawing, placement, checkpoints
#: and figures make copies, so budget twice that.
BYTES_PER_DISK = 1000
#: Particle-steps per second for the run-time estimate: one core, rounded down from the
#: 1.4-2.0e7 measured on the paper's specimen (docs/engine.md).
THROUGHPUT = 1e7
#: Steps to bring a stage (a layer, the working friction) to equilibrium, for the estimate;
#: a typical dense layer needs a few thousand, a loose one many more.
EQUILIBRIUM_STEPS = 5000
#: Preparations estimated to take longer than this (seconds) are announced with a warning.
WARN_SECONDS = 600.0
#: Preparations estimated to take longer than this (seconds) per trial are refused: a criterion
#: takes several trials and a density-aware answer several cases, so 6 h per trial is days of
#: work (the estimate is of dense layers; loose ones take longer). A log-linear grading of Cu 18
#: (0.06-19.4 mm, 760 000 disks in the paper's box) is estimated at 18 h per trial.
REFUSE_SECONDS = 6 * 3600.0


#: the per-disk density scaling's settings (``SpecimenSpec.mass_scaling``)
MASS_SCALING_MODES = ("auto", "on", "off")
#: "auto" raises masses only where r_mean / r_min exceeds this: the finest disk's step is then
#: more than 4 times shorter than the mean disk's. Every built-in grading and example soil but
#: the sandy gravel G1-1 (13) lies below 3 (the paper's 1.9, wide_cu4's 3.0), so their
#: specimens keep their true masses and every number they gave (docs/density-scaling.md)
MASS_SCALING_TRIGGER = 4.0
#: the frictionless fines' settings (``SpecimenSpec.frictionless_fines``): "auto" where r_mean /
#: r_min exceeds ``MASS_SCALING_TRIGGER`` (of the example soils only G1-1), "on" always, "off" never
FRICTIONLESS_FINES_MODES = ("auto", "on", "off")
#: a disk is a fine while a layer grows when its radius is below r_mean / this
FINE_RADIUS_RATIO = 2.0
#: one increment of a layer's radius growth enlarges its largest disk by at most this share of
#: the specimen's finest radius (:func:`growth_increments`). A larger jump presses a fine between
#: coarse disks deeper than it can slide away in the increment's steps, and it is shot out: the
#: sandy gravel G1-1 (d_max / d_min 189) at mu_prep 0.297, seed 1, trial 0.131, lost a frictionless
#: 0.056 mm fine at 14 m/s in the 28th of 40 increments, each enlarging its 9.4 mm disks by 0.077
#: mm. Its layers then grow in 112-123 increments and every disk stays in the box. The growth
#: from the placement scale s needs more than 40 increments only where d_max / d_min exceeds
#: 20 / (1 - s) (about 60 at G1-1's s = 0.68): never on a grading that is not wide
#: (``WIDE_SIZE_RATIO``), so the paper's preparation is unchanged
GROWTH_SHARE_OF_FINEST = 0.5
#: the placement scale the time estimate assumes for a layer's growth (:func:`estimate_size`):
#: G1-1's layers are placed at 0.677-0.679 of full size at the trial 0.131
TYPICAL_PLACEMENT_SCALE = 0.68


#: settings recorded with results only when they differ from these defaults (see ``to_dict``)
OMITTED_AT_DEFAULT = {
    "equilibrium": "max", "settle_drift": None, "settle_window": 10_000, "settle_checks": 3,
    "rolling_friction": 0.0, "rolling_friction_prep": 0.0, "mass_scaling": "auto", "mass_scaling_ratio": 2.0,
    "growth_friction": None, "frictionless_fines": "auto",
}  # fmt: skip


#: what each setting of a :class:`SpecimenSpec` may be (checked in this order)
SPECIMEN_RANGES: Ranges = {
    **{k: Real(0, None, lo_open=True) for k in ("width", "height", "thickness", "solid_density")},
    **{k: Real(0, None, lo_open=True) for k in ("kn_particle", "kn_wall")},
    **{
        k: Real(0, None)
        for k in ("ks_particle", "ks_wall", "friction_prep", "friction_particle", "friction_wall")
    },
    "rolling_friction": Real(0, MAX_ROLLING_FRICTION),
    "rolling_friction_prep": Real(0, MAX_ROLLING_FRICTION),
    "layers": Integer(1, 50),
    "undercompaction": Real(0.0, 0.5),
    "ratio": Real(0.0, 1.0, lo_open=True),
    "equilibrium": OneOf(tuple(MEASURES), quoted=True),
    "settle_drift": Real(0.0, 0.1, lo_open=True, or_none=True),
    "settle_window": Integer(100),
    "settle_checks": Integer(1, 100),
    "local_damping": Real(0.0, 1.0, hi_open=True),
    "gravity": Real(0.0, None),
    **{
        k: Integer(1)
        for k in ("growth_increments", "growth_steps", "max_steps_per_stage", "fallback_steps", "calm_steps")
    },
    "calm_damping": Real(0.0, 1.0, hi_open=True),
    "dt_safety": Real(0.0, 1.0, lo_open=True),
    "threads": Integer(1),
    "max_disks": Integer(1, MAX_DRAW),
    "mass_scaling": OneOf(MASS_SCALING_MODES, quoted=True),
    "mass_scaling_ratio": Real(1.0, 100.0),
    "growth_friction": Real(0, None, or_none=True),
    "frictionless_fines": OneOf(FRICTIONLESS_FINES_MODES, quoted=True),
}


@dataclass
class SpecimenSpec(Record):
    """Box, material and preparation settings; the disks' and walls' defaults are the paper's
    Table 1 (:data:`poro2d.paper_data.TABLE_1`)."""

    OMITTED: ClassVar[dict[str, Any]] = OMITTED_AT_DEFAULT

    width: float = 0.305
    height: float = 0.124
    thickness: float = 0.008
    solid_density: float = TABLE_1.solid_density
    kn_particle: float = TABLE_1.kn_particle
    ks_particle: float = TABLE_1.ks_particle
    kn_wall: float = TABLE_1.kn_wall
    ks_wall: float = TABLE_1.ks_wall
    friction_prep: float = 0.05
    friction_particle: float = TABLE_1.friction_particle
    friction_wall: float = TABLE_1.friction_wall
    # rolling resistance of the working material (docs/engine.md), set with friction_particle
    # on disks and walls; 0: none, the paper's round disks
    rolling_friction: float = 0.0
    # rolling resistance while the layers are built (with friction_prep): it lets a packing
    # hold looser arrangements than sliding friction alone; the working value replaces it
    rolling_friction_prep: float = 0.0
    layers: int = 4
    undercompaction: float = 0.0
    ratio: float = 1e-3
    equilibrium: str = "max"
    settle_drift: float | None = None
    settle_window: int = 10_000
    settle_checks: int = 3
    local_damping: float = 0.7
    gravity: float = 9.81
    growth_increments: int = 40
    growth_steps: int = 150
    max_steps_per_stage: int = 400_000
    fallback_steps: int = 200_000
    calm_steps: int = 50_000
    calm_damping: float = 0.9
    dt_safety: float = 0.8
    # how many threads run the engine: the same numbers on any count (docs/engine.md), so
    # outside the run's identity (a rerun on other threads resumes)
    threads: int = outside_identity(1)
    max_disks: int = DEFAULT_MAX_DISKS
    # the light disks' inertial masses raised in the quasi-static stages (mass_scaling_step):
    # "auto" for a grading whose finest disk steps MASS_SCALING_TRIGGER times shorter than its
    # mean disk, "on" always, "off" never; raised to the mass of a disk mass_scaling_ratio
    # times smaller than the mean one
    mass_scaling: str = "auto"
    mass_scaling_ratio: float = 2.0
    # the disks' friction while a layer's radii grow (the preparation friction returns for its
    # settling); None: friction_prep, the growth the density control is measured with
    growth_friction: float | None = None
    # the fines (radius below r_mean / FINE_RADIUS_RATIO) and the walls are frictionless while a
    # layer grows, so no fine is wedged by a large disk (growing_fines): "auto" for a grading as
    # wide as mass scaling's trigger, "on" always, "off" never
    frictionless_fines: str = "auto"

    def __post_init__(self) -> None:
        check_fields(self, SPECIMEN_RANGES)

    def layout(self) -> tuple:
        """The specimen's settings as recorded with results (its row, :meth:`~poro2d.record.Record.to_dict`).

        ``max_disks`` is left out: it is a guard, not a property of the specimen, so raising
        it does not make a resumable output folder look like another config's. Settings added
        after results were first written (``OMITTED_AT_DEFAULT``) are left out while they hold
        their default: folders written before them still resume. ``extra`` is the key of a
        former field that could not be set: always empty, still written so that records and
        result files keep their keys and earlier folders resume.
        """
        return (*(f.name for f in fields(self) if f.name != "max_disks"), Fixed("extra", {}))

    @classmethod
    def from_dict(cls, row: dict) -> SpecimenSpec:
        """The spec a row describes (:meth:`to_dict`: a ``config.json``'s ``run.specimen``, a
        criterion result's ``specimen``); a setting the row lacks takes its default, as it was
        when the row was written."""
        return cls(**{f.name: row[f.name] for f in fields(cls) if f.name in row})

    def self_weight(self, porosity: float) -> float:
        """G = rho_s (1 - n) W H g per metre of thickness (N/m), as in the paper."""
        return self.solid_density * (1.0 - porosity) * self.width * self.height * self.gravity

    def layer_tops(self) -> np.ndarray:
        nt = self.layers
        h = self.height / nt
        u1 = self.undercompaction
        tops = []
        for k in range(1, nt + 1):
            uk = u1 - (u1 * (k - 1) / (nt - 1) if nt > 1 else u1)
            tops.append(h * (k - 1 + (1.0 + uk)))
        tops[-1] = self.height
        return np.array(tops)


#: a grading is **wide** when its Cu or its d_max / d_min is above these. Measured boundary:
#: the paper's grading (Cu 1.69, d_max / d_min 3.5) and log-linear gradings up to Cu 4
#: (d_max / d_min 15.7) reach the paper's maximum-ratio equilibrium in every seed of the
#: sensitivity study (docs/criterion.md); ``wide_cu4`` (Cu 4.3 with fines, d_max / d_min 25)
#: does not (a layer creeps at a ratio of 1e-2 through the whole fallback)
WIDE_CU = 4.0
WIDE_SIZE_RATIO = 20.0
#: what a wide grading's preparation uses unless the config sets ``settle_drift`` or
#: ``equilibrium``: layers that end once settled (density mode's value) and the ratio over the
#: load-bearing disks (rattlers, common among the fines, never carry a balanced load)
WIDE_PREPARATION = {"settle_drift": 1e-3, "equilibrium": "loaded_max"}


def is_wide(grading: GradingCurve) -> bool:
    """Whether ``grading`` is wide: Cu above ``WIDE_CU`` or d_max / d_min above ``WIDE_SIZE_RATIO``."""
    return grading.uniformity > WIDE_CU or grading.d_max_m / grading.d_min_m > WIDE_SIZE_RATIO


def _grading_words(grading: GradingCurve) -> str:
    return (
        f"Cu {grading.uniformity:.3g}, d_max/d_min {grading.d_max_m / grading.d_min_m:.3g} (wide: Cu > "
        f"{WIDE_CU:g} or d_max/d_min > {WIDE_SIZE_RATIO:g})"
    )


def wide_grading_spec(spec: SpecimenSpec, grading: GradingCurve, table: dict | None) -> SpecimenSpec:
    """The spec a config's ``[specimen]`` table gives, with ``WIDE_PREPARATION`` for a wide grading.

    Only when the grading is wide (:func:`is_wide`) and the table sets neither ``settle_drift``
    nor ``equilibrium``: a config that sets either keeps its settings as they are (set
    ``equilibrium = "max"`` to keep the paper's test on a wide grading). The paper's grading is
    not wide: its spec is returned unchanged.
    """
    table = table or {}
    if not is_wide(grading) or "settle_drift" in table or "equilibrium" in table:
        return spec
    return replace(spec, **WIDE_PREPARATION)


def preparation_note(spec: SpecimenSpec, grading: GradingCurve) -> str | None:
    """What a run says of its equilibrium test on a wide grading (None for a narrow one)."""
    if not is_wide(grading):
        return None
    if spec.settle_drift is not None or spec.equilibrium != "max":
        drift = (
            ""
            if spec.settle_drift is None
            else f"layers end once settled (settle_drift {spec.settle_drift:g} d50), "
        )
        return (
            f"wide grading ({_grading_words(grading)}): {drift}equilibrium judged by the {spec.equilibrium} "
            "unbalanced-force ratio: rattlers among the fines never carry a balanced load, and a "
            "low-friction layer near jamming creeps at a maximum ratio of 1e-2 for hundreds of "
            "thousands of steps while its density no longer changes (docs/criterion.md)"
        )
    return (
        f"wide grading ({_grading_words(grading)}): the paper's maximum-ratio test, as the config sets it; "
        "its layers may creep through the whole fallback without reaching it (leave settle_drift and "
        "equilibrium unset to let poro2d use the settled test)"
    )


def make_walls(spec: SpecimenSpec, lid_height: float) -> Walls:
    """Bottom, right, top (the lid / top plate) and left walls of the box."""
    return Walls.box(0.0, 0.0, spec.width, lid_height, spec.kn_wall, spec.ks_wall, spec.friction_wall)


def check_feasible(spec: SpecimenSpec, grading: GradingCurve, porosity: float) -> None:
    """Reject configurations that cannot work, before any simulation starts."""
    check_box(spec, grading)  # first: a box too small for its disks is named as the box
    check_range("porosity", porosity, 0.0, 1.0, lo_open=True, hi_open=True)
    # Random close packing of polydisperse disks is near 0.16-0.18 porosity; below ~0.09
    # (hexagonal order, 0.0931) no disk arrangement without big overlaps exists.
    if porosity < 0.05:
        raise InputError(
            "porosity", porosity, "[0.05, 1)",
            "disks cannot fill a box to less than about 0.09 porosity without large overlaps",
        )  # fmt: skip
    check_densest(spec, grading, porosity)
    check_size(spec, grading, porosity)


def check_box(spec: SpecimenSpec, grading: GradingCurve) -> None:
    """Refuse a box whose bands are not taller and wider than the largest disk (geometry alone:
    checked before any estimate that needs the disks)."""
    dmax = grading.d_max_m
    band_h = spec.height / spec.layers
    if dmax >= min(spec.width, band_h):
        raise InputError(
            "box",
            f"{spec.width} m x {spec.height} m in {spec.layers} layers (band {band_h:.4g} m)",
            f"a band taller and wider than the largest disk ({dmax:.4g} m)",
        )


#: a trial porosity more than this below the grading's frictionless jamming porosity n_J is
#: refused before any DEM work. A trial denser than n_J is an over-full box, which the
#: criterion handles as Fig. 3 does (the plate moves up, the next trial is looser): the paper's
#: own first trial is 0.013 below n_J of its grading, Eq. 12's 0.08 for a Cu 18 gravel (n_J
#: about 0.12) 0.04 below. 0.05 below, the disks hold 6 % more solid than the grading's densest
#: packing fits in the box, and the swelling specimen outruns the plate: ``wide_cu4`` at 0.06
#: (0.053 below) in a 0.08 m x 0.04 m box pushed the plate up 8.4 mm, and it had not settled
#: after its 600 000 steps (measured; at 0.07 it settles and the next trial is accepted).
OVERFULL_MARGIN = 0.05
#: no disk set jams looser than this without friction (bidisperse 1 : 1.4: 0.159, the paper's
#: grading 0.153; wider gradings and monodisperse crystals pack denser): trials at or above
#: JAMMING_CEILING - OVERFULL_MARGIN need no jamming estimate
JAMMING_CEILING = 0.17
#: the quick jamming estimate of the pre-flight check: disks, bisection tolerance and the
#: compression step (about 2 s; n_J within about 0.003 of the full reference, docs/jamming.md)
PREFLIGHT_JAMMING = {"n_disks": 400, "tol": 1e-3, "dphi": 0.01}

_DENSEST: dict[tuple, float | None] = {}


def densest_porosity(grading: GradingCurve) -> float | None:
    """A quick estimate of the grading's frictionless jamming porosity n_J (None if it cannot be made).

    One seed of :func:`poro2d.oracles.jamming.jamming_reference` on ``PREFLIGHT_JAMMING``
    disks, cached per grading. None when the grading is too wide for that many disks in the
    periodic cell (the largest disks would span it).
    """
    from poro2d.oracles.jamming import jamming_reference

    key = (tuple(grading.sizes.tolist()), tuple(grading.percent.tolist()))
    if key not in _DENSEST:
        o = PREFLIGHT_JAMMING
        try:
            ref = jamming_reference(grading, n_disks=o["n_disks"], seeds=(0,), tol=o["tol"], dphi=o["dphi"])
            n_j = float(ref.porosity_mean)
            _DENSEST[key] = n_j if math.isfinite(n_j) else None
        except InputError as e:
            _log.info("no quick jamming estimate for this grading: %s", e)
            _DENSEST[key] = None
    return _DENSEST[key]


def check_densest(spec: SpecimenSpec, grading: GradingCurve, porosity: float) -> None:
    """Refuse a trial porosity more than ``OVERFULL_MARGIN`` below the grading's densest packing."""
    if porosity >= JAMMING_CEILING - OVERFULL_MARGIN:
        return
    n_j = densest_porosity(grading)
    if n_j is None or porosity >= n_j - OVERFULL_MARGIN:
        return
    excess = (1.0 - porosity) / (1.0 - n_j) - 1.0
    raise InputError(
        "trial porosity", porosity,
        f">= {n_j - OVERFULL_MARGIN:.3f}: at most {OVERFULL_MARGIN:g} below the grading's frictionless "
        f"jamming porosity n_J = {n_j:.3f}",
        f"at {porosity:g} the disks hold {100 * excess:.1f} % more solid than the grading's densest packing "
        f"fits in the box (the specimen would stand about {1000 * excess * spec.height:.3g} mm above H): no "
        f"plate could settle it; give [criterion] trial_porosity near n_J (e.g. "
        f"{math.ceil(n_j * 100) / 100:.2f}), from which the loop finds the answer, or check n_lab",
    )  # fmt: skip


@dataclass(frozen=True)
class SizeEstimate:
    """What a specimen will cost, estimated from the grading without drawing a disk.

    ``dt_s``: the time step the engine will take (set by the smallest disk);
    ``stage_steps``: the steps a stage is estimated to need at that step.
    """

    disks: float
    memory_bytes: float
    steps: int
    seconds: float
    dt_s: float = math.nan
    stage_steps: int = EQUILIBRIUM_STEPS


def time_step(spec: SpecimenSpec, d_min: float) -> float:
    """The time step (s) the engine picks for disks as small as ``d_min`` (m) in this box.

    As :class:`poro2d.dem.Simulation` picks it: ``dt_safety`` x the critical step
    sqrt(2 m_min / (3 k_sum)) (:func:`poro2d.dem.model.critical_time_step`), m_min the mass
    of the smallest disk, k_sum the summed stiffness bound of a disk's contacts
    (:meth:`poro2d.dem.ContactModel.stiffness_sum_bound`, per-body springs in series).
    """
    m_min = spec.solid_density * math.pi * (0.5 * d_min) ** 2 * spec.thickness
    kp = max(spec.kn_particle, spec.ks_particle)
    kw = max(spec.kn_wall, spec.ks_wall)
    kpp = 0.5 * kp
    kpw = kp * kw / (kp + kw)
    k_sum = max(6.0 * kpp, 4.0 * kpp + kpw)
    return spec.dt_safety * math.sqrt(2.0 * m_min / (3.0 * k_sum))


def mass_scaling_step(spec: SpecimenSpec, radii: np.ndarray) -> float | None:
    """The time step (s) the light disks' inertial masses are raised for; None: true masses.

    The floor is the mass of a disk of radius r_mean / ``spec.mass_scaling_ratio`` (2 by
    default: the step the paper's grading runs at, its finest disk being 1.9 times smaller than
    its mean one), so every disk steps as that disk does; under ``"auto"`` only when r_mean /
    r_min exceeds ``MASS_SCALING_TRIGGER``. None too when no disk is lighter than the floor.
    """
    if spec.mass_scaling == "off" or len(radii) == 0:
        return None
    r_mean, r_min = float(np.mean(radii)), float(np.min(radii))
    if spec.mass_scaling == "auto" and not fines_far_finer(radii):
        return None
    r_floor = r_mean / spec.mass_scaling_ratio
    return time_step(spec, 2.0 * r_floor) if r_floor > r_min else None


def growth_friction(spec: SpecimenSpec) -> float:
    """The friction a layer grows at: ``spec.growth_friction``, unset the preparation friction.

    Radius growth with friction wedges a fine between two large disks closing on it: their two
    nearly opposite normals hold it, its overlaps grow past its own radius and it may be shot out
    of the box (the sandy gravel G1-1, r_mean / r_min 13: every calibration case of ``sand`` at
    mu_prep 0.2 to 1.0). Growing frictionless keeps every disk in the box, but the layer then
    fills its band at the trial porosity and its frictional settling only compacts it a little:
    the accepted porosity follows the trial down instead of a friction's own packing (measured:
    G1-1 at mu_prep 1.0, trials 0.172 -> 0.164 -> 0.160 -> 0.157 -> 0.154, each n' 0.003-0.008
    below its trial). So it is a setting (docs/criterion.md), not the default.
    """
    return spec.friction_prep if spec.growth_friction is None else spec.growth_friction


def fines_far_finer(radii: np.ndarray) -> bool:
    """Whether r_mean / r_min of ``radii`` (not empty) exceeds ``MASS_SCALING_TRIGGER``: the
    "auto" test of the density scaling and of the frictionless fines."""
    return float(np.mean(radii)) > MASS_SCALING_TRIGGER * float(np.min(radii))


def slides_while_growing(spec: SpecimenSpec, radii: np.ndarray) -> bool:
    """Whether a layer of the specimen of ``radii`` grows with frictionless fines and walls
    (``spec.frictionless_fines``: under "auto" where r_mean / r_min exceeds ``MASS_SCALING_TRIGGER``)."""
    if spec.frictionless_fines == "off" or len(radii) == 0:
        return False
    return spec.frictionless_fines == "on" or fines_far_finer(radii)


def growing_fines(spec: SpecimenSpec, radii: np.ndarray, grown: np.ndarray) -> np.ndarray:
    """Which of the disks of radii ``grown`` grow frictionless (a mask), in a specimen of ``radii``.

    A fine closed on by a disk many times larger, against a wall or a third disk, is held there
    by friction: growth drives its overlap past its own radius and it is shot out of the box.
    Measured on the sandy gravel G1-1 (r_max / r_min 186): every calibration case of ``sand`` at
    mu_prep 0.2 to 1.0 lost a disk so. Its overlap in a force chain is F / kn whatever the
    radii, so the finest disks suffer it first. Those below ``r_mean / FINE_RADIUS_RATIO``
    slide while their layer grows (and the walls, :func:`slides_while_growing`: a 0.35 mm disk,
    0.51 r_mean, was pressed into the lid by a 7 mm one until its overlap was 1.8 times its
    radius), then take ``friction_prep`` for the layer's settling. The coarse skeleton keeps its
    friction (a contact's is the smaller of its bodies'), so the friction still sets the
    packing: G1-1 in a 0.19 m box at mu_prep 1.0, trials 0.15, 0.17 and 0.19 gave n' 0.168,
    0.168 and 0.176. Freeing every disk that friction could wedge against the largest (up to
    0.38 r_max at mu 1) freed half the solid, and the trial 0.15 was then accepted as it was.
    """
    if not slides_while_growing(spec, radii):
        return np.zeros(len(grown), dtype=bool)
    return grown < float(np.mean(radii)) / FINE_RADIUS_RATIO


def growth_increments(spec: SpecimenSpec, scale: float, r_max: float, r_min: float) -> int:
    """The increments a layer grows in from ``scale`` of full size: ``spec.growth_increments``, or
    more where one of them would enlarge the largest growing disk (radius ``r_max``) by more than
    ``GROWTH_SHARE_OF_FINEST`` of the specimen's finest radius ``r_min``. Each increment runs
    ``spec.growth_steps`` steps, so the growth is slower, not only finer."""
    need = math.ceil((1.0 - scale) * r_max / (GROWTH_SHARE_OF_FINEST * r_min) - 1e-9)
    return max(spec.growth_increments, need)


def grading_increments(spec: SpecimenSpec, grading: GradingCurve) -> int:
    """:func:`growth_increments` a layer of ``grading`` is expected to take, for time estimates
    (at ``TYPICAL_PLACEMENT_SCALE``)."""
    return growth_increments(spec, TYPICAL_PLACEMENT_SCALE, grading.d_max_m / 2.0, grading.d_min_m / 2.0)


def grading_mass_scaling_step(spec: SpecimenSpec, grading: GradingCurve, porosity: float) -> float | None:
    """:func:`mass_scaling_step` of the disks a specimen of ``grading`` at ``porosity`` holds in
    this box (drawn with seed 0: the mean and the finest radius hardly vary with the seed)."""
    radii = draw_disks(grading, spec.width * spec.height * (1.0 - porosity), 0)
    return mass_scaling_step(spec, radii)


#: the simulated time a stage takes to come to equilibrium, for the estimate: ``EQUILIBRIUM_STEPS``
#: at the time step of the paper's specimen (Table 1, the reconstructed grading's 2.0 mm disks).
#: Settling takes about the same time whatever the disks, so a grading with finer disks (a
#: smaller step) needs proportionally more steps.
PAPER_D_MIN = 0.002


def estimate_size(spec: SpecimenSpec, grading: GradingCurve, porosity: float) -> SizeEstimate:
    """Expected disk count, memory and preparation time of a specimen at ``porosity``.

    The count is the box's solid area (1 - n) W H over the grading's mean disk area, the
    number :func:`draw_disks` will draw on average. The steps are those of radius expansion
    in every layer plus a stage's equilibrium per stage: ``EQUILIBRIUM_STEPS`` at the paper's
    time step, more in proportion when the smallest disk sets a smaller one (:func:`time_step`;
    the paper's grading and Table 1 give exactly ``EQUILIBRIUM_STEPS``). The time assumes
    ``THROUGHPUT``. A grading whose light disks get raised masses (:func:`mass_scaling_step`)
    steps at the shared step.
    """
    solid_area = (1.0 - porosity) * spec.width * spec.height
    disks = grading.expected_count(solid_area)
    dt = time_step(spec, grading.d_min_m)
    if spec.mass_scaling != "off" and disks <= spec.max_disks:  # drawn only when they will be
        dt = grading_mass_scaling_step(spec, grading, porosity) or dt
    dt_paper = time_step(SpecimenSpec(), PAPER_D_MIN)
    stage = max(EQUILIBRIUM_STEPS, math.ceil(EQUILIBRIUM_STEPS * dt_paper / dt - 1e-9))
    steps = spec.layers * (grading_increments(spec, grading) * spec.growth_steps + stage) + stage
    return SizeEstimate(disks, disks * BYTES_PER_DISK, steps, disks * steps / THROUGHPUT, dt, stage)


def check_size(spec: SpecimenSpec, grading: GradingCurve, porosity: float) -> SizeEstimate:
    """Refuse a specimen of more than ``spec.max_disks`` disks; warn when it will take long.

    Cheap (no disk is drawn), so a grading that would need 1e8 disks is refused at once
    instead of filling the memory.
    """
    est = estimate_size(spec, grading, porosity)
    if est.disks > spec.max_disks:
        raise InputError(
            "specimen size", f"about {est.disks:.3g} disks ({_gb(est.memory_bytes)})",
            f"at most max_disks = {spec.max_disks} disks",
            f"mean disk area {grading.mean_disk_area():.3g} m^2 in {spec.width:g} m x {spec.height:g} m "
            f"at porosity {porosity:g}; coarsen the grading (upscale, d_min_mm), shrink the box, or "
            "raise [specimen] max_disks",
        )  # fmt: skip
    budget = spec.max_steps_per_stage + spec.fallback_steps + 2 * spec.calm_steps
    if est.stage_steps > EQUILIBRIUM_STEPS and est.stage_steps > budget:  # the smallest disk is the cause
        raise InputError(
            "time step",
            f"{est.dt_s:.3g} s, set by the smallest disk (d_min {1000 * grading.d_min_m:.3g} mm)",
            f"a step at which a stage comes to rest within its budget of {budget} steps "
            f"(it needs about {est.stage_steps})",
            "the time step falls with the smallest disk's diameter: cut the fines with [grading] d_min_mm, "
            "up-scale the grading (upscale), or raise [specimen] max_steps_per_stage",
        )  # fmt: skip
    if est.seconds > REFUSE_SECONDS:
        raise InputError(
            "specimen size", f"about {est.disks:.3g} disks, time step {est.dt_s:.3g} s",
            f"a preparation estimated below {_duration(REFUSE_SECONDS)} per trial (estimated: "
            f"{_duration(est.seconds)}, about {est.steps} steps at {THROUGHPUT:.0e} particle-steps/s)",
            f"d_min {1000 * grading.d_min_m:.3g} mm sets the step and the disk count: cut the fines with "
            "[grading] d_min_mm, up-scale the grading (upscale), use fewer layers or a smaller box",
        )  # fmt: skip
    if est.seconds > WARN_SECONDS:
        _warn_once(
            f"large specimen: about {est.disks:.3g} disks ({_gb(est.memory_bytes)}); preparing it "
            f"takes about {_duration(est.seconds)} per trial (about {est.steps} steps at "
            f"{THROUGHPUT:.0e} particle-steps/s on one core)"
        )
    return est


_WARNED: set[str] = set()


def _warn_once(message: str) -> None:
    """Log a warning once per process (the criterion checks before every trial)."""
    if message not in _WARNED:
        _WARNED.add(message)
        _log.warning(message)


def _gb(nbytes: float) -> str:
    if nbytes >= 1e9:
        return f"about {nbytes / 1e9:.3g} GB of memory"
    return f"about {nbytes / 1e6:.3g} MB of memory"


def _duration(seconds: float) -> str:
    if seconds < 3600:
        return f"{seconds / 60:.0f} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} days"


@dataclass(eq=False, kw_only=True)
class Attempt(TypedResult):
    """One attempt of :func:`equilibrate` (``attempt``: "normal", "second budget", "calm", "normal again").

    Its steps, the three unbalanced-force ratios at its end and the one that decides
    (``measured_ratio``), the rattler fraction and what ended it (``ended_by``).
    """

    attempt: str
    steps: int
    max_ratio: float
    mean_ratio: float
    loaded_max_ratio: float
    measured_ratio: float
    rattler_fraction: float
    ended_by: str


@dataclass(eq=False, kw_only=True)
class Equilibration(TypedResult):
    """How a stage came to equilibrium (:func:`equilibrate`); a preparation's ``final_stage``.

    Whether it ``converged``, the total ``steps``, the last attempt's ``max_ratio``, the
    ratio that decides (``measure``) and its ``measured_ratio``, the rattler fraction, what
    ended it (``ended_by``: ``ratio``, ``settled`` or ``budget``) and every attempt made.
    """

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"attempts": Attempt}

    converged: bool
    steps: int
    max_ratio: float
    measure: str
    measured_ratio: float
    rattler_fraction: float
    ended_by: str
    attempts: list[Attempt]


@dataclass(eq=False)
class LayerReport(TypedResult):
    """One layer of a preparation (a row of its report's ``layers``): its disks, lid, steps and attempts.

    ``band_raised_m``: how far its band was raised above its share of H, only when it was;
    ``growth_increments``: the increments its radii grew in, only when more than the spec's
    (:func:`growth_increments`).
    """

    OPTIONAL = ("band_raised_m", "growth_increments")
    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"attempts": Attempt}

    layer: int
    n_particles: int
    lid_height_m: float
    placement_scale: float
    steps: int
    max_ratio: float
    converged: bool
    attempts: list[Attempt]
    band_raised_m: float | None = None
    growth_increments: int | None = None


@dataclass(eq=False)
class PreparationReport(TypedResult):
    """What a preparation did (:func:`prepare_specimen`), and a criterion trial's ``prepared.json``.

    The counts and porosities of the specimen built, every layer (:class:`LayerReport`), the
    working-friction stage (``final_stage``, None when a layer failed first), whether it
    converged and, if not, the stage that failed with its ratios. ``overfull_m`` and
    ``top_height_m`` only for an over-full box; the trial's seed, time, self weight and wall
    forces only once the criterion added them (``prepared.json``).
    """

    OPTIONAL = (
        "overfull_m", "top_height_m", "seed", "time_s", "weight_n_per_m", "f_top_n_per_m",
        "f_bottom_n_per_m", "side_friction_up_n_per_m", "f_left_n_per_m", "f_right_n_per_m",
    )  # fmt: skip
    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"layers": LayerReport, "final_stage": Equilibration}

    trial_porosity: float
    planned_count: int
    particle_count: int
    solid_area_m2: float
    box_porosity: float
    measured_porosity: float
    layers: list[LayerReport]
    final_stage: Equilibration | None
    converged: bool
    failed_stage: str | None
    failed_max_ratio: float | None
    failed_steps: int | None
    failed_ratio: float | None
    equilibrium: str
    overfull_m: float | None = None
    top_height_m: float | None = None
    seed: int | None = None
    time_s: float | None = None
    weight_n_per_m: float | None = None
    f_top_n_per_m: float | None = None
    f_bottom_n_per_m: float | None = None
    side_friction_up_n_per_m: float | None = None
    f_left_n_per_m: float | None = None
    f_right_n_per_m: float | None = None


def equilibrate(
    sim: Simulation, spec: SpecimenSpec, label: str, progress: bool = False, settle: bool = False
) -> Equilibration:
    """Cycle to equilibrium (the ratio ``spec.equilibrium`` below ``spec.ratio``), with a fallback.

    The measure is the maximum unbalanced-force ratio by default (the paper's); ``mean``
    and ``loaded_max`` are the alternatives of :meth:`poro2d.dem.Simulation.run`. Every
    attempt records all three ratios and the rattler fraction, whichever one decides.

    1. ``normal``: up to ``max_steps_per_stage`` steps;
    2. ``second budget``: up to ``fallback_steps`` more (a packing near its jamming
       density relaxes slowly, and often only needs more time);
    3. ``calm``: velocities set to zero and local damping raised to ``calm_damping``
       for up to ``calm_steps`` steps (removes the kinetic energy of a packing that
       keeps rattling);
    4. ``normal again``: the normal damping restored, up to ``calm_steps`` steps. The
       ratio is a force measure and does not depend on damping, but an equilibrium only
       counts once it holds with the damping of the protocol.

    With ``settle`` and ``spec.settle_drift`` set (stages at the preparation friction), a
    stage also ends once it has **settled**: the disks' mean height (mass-weighted) moved
    less than ``settle_drift`` median diameters in each of ``settle_checks`` windows of
    ``settle_window`` steps running (:class:`SettledTest`). A low-friction packing near
    jamming keeps creeping with an unbalanced-force ratio of 1e-2 for hundreds of thousands
    of steps while its density no longer changes; the working-friction stage that follows,
    judged by the ratio alone, then brings the whole specimen to equilibrium.

    Stops at the first attempt that reaches the ratio (or settles). Returns ``converged``,
    the total ``steps``, the last ``max_ratio``, ``ended_by`` (``ratio``, ``settled`` or
    ``budget``) and every attempt made (name, steps, ratios, rattler fraction, how it ended).
    """
    attempts: list[Attempt] = []
    drift = spec.settle_drift if settle else None

    def attempt(name: str, budget: int) -> bool:
        bar = (label if name == "normal" else f"{label} ({name})") if progress else False
        if drift is None:
            res = sim.solve(spec.ratio, budget, progress=bar, measure=spec.equilibrium)
            calm = False
        else:
            test = SettledTest(sim, drift, spec.settle_checks)
            res = sim.run(budget, until_ratio=spec.ratio, measure=spec.equilibrium,
                          reporters=[Every(spec.settle_window, test)], progress=bar)  # fmt: skip
            calm = test.settled
        ended = "ratio" if res.converged else ("settled" if calm else "budget")
        attempts.append(Attempt(
            attempt=name, steps=res.steps, max_ratio=res.max_ratio, mean_ratio=res.mean_ratio,
            loaded_max_ratio=res.loaded_ratio, measured_ratio=res.measured_ratio,
            rattler_fraction=res.rattler_fraction, ended_by=ended,
        ))  # fmt: skip
        return res.converged or calm

    ok = attempt("normal", spec.max_steps_per_stage)
    if not ok:
        ok = attempt("second budget", spec.fallback_steps)
    if not ok:
        damping = sim.local_damping
        sim.particles.vel[:] = 0.0
        sim.particles.omega[:] = 0.0
        sim.set_local_damping(spec.calm_damping)
        try:
            attempt("calm", spec.calm_steps)
        finally:
            sim.set_local_damping(damping)
        ok = attempt("normal again", spec.calm_steps)
    last = attempts[-1]
    return Equilibration(
        converged=ok,
        steps=sum(a.steps for a in attempts),
        max_ratio=last.max_ratio,
        measure=spec.equilibrium,
        measured_ratio=last.measured_ratio,
        rattler_fraction=last.rattler_fraction,
        ended_by=last.ended_by,
        attempts=attempts,
    )


class SettledTest:
    """A run callback: True once the disks' mean height moved < ``drift_d50`` d50 in ``checks`` calls running.

    The height is mass-weighted (the packing's centre of mass: it falls while the packing
    compacts under gravity); d50 is the median diameter by area of the disks. ``settled``
    says whether it stopped the run.
    """

    def __init__(self, sim: Simulation, drift_d50: float, checks: int) -> None:
        from poro2d.measure.disks import mass_d50

        self.tol = drift_d50 * mass_d50(sim.particles.radius)
        self.checks = checks
        self.calm = 0
        self.last: float | None = None
        self.settled = False

    def __call__(self, sim: Simulation) -> bool:
        p = sim.particles
        y = float(np.sum(p.mass * p.pos[:, 1]) / np.sum(p.mass))
        self.calm = self.calm + 1 if self.last is not None and abs(y - self.last) < self.tol else 0
        self.last = y
        self.settled = self.calm >= self.checks
        return self.settled


def _band_particles(spec: SpecimenSpec, pos, radii) -> Particles:
    return Particles(
        pos, radii, spec.solid_density, spec.thickness,
        spec.kn_particle, spec.ks_particle, spec.friction_prep,
    )  # fmt: skip


def prepare_specimen(
    spec: SpecimenSpec,
    grading: GradingCurve,
    porosity: float,
    seed: int,
    progress: bool = False,
) -> tuple[Simulation, PreparationReport]:
    """Build a specimen at trial ``porosity`` by multilayer compaction.

    Returns the simulation (top plate = wall "top" at H) and a report with the
    particle count, per-layer cycles and the measured box porosity.

    A layer that does not reach equilibrium even with the fallback of
    :func:`equilibrate` ends the preparation: the later layers are not built, the
    lid stays at that layer's top, and the report has ``converged = False``,
    ``failed_stage`` (e.g. ``"layer 2"``), ``failed_max_ratio`` and fewer disks
    (``particle_count``) than planned (``planned_count``). Callers must refuse it.
    """
    check_feasible(spec, grading, porosity)
    W, H = spec.width, spec.height
    rng = np.random.default_rng(seed)
    radii = draw_disks(grading, (1.0 - porosity) * W * H, rng)
    radii = radii[rng.permutation(len(radii))]
    tops = spec.layer_tops()
    sim: Simulation | None = None
    layers: list[LayerReport] = []
    failed = None
    for k, idx in enumerate(_layer_groups(radii, spec.layers)):
        sim, layer, eq = _build_layer(sim, spec, k, idx, radii, tops, rng, progress)
        layers.append(layer)
        if not eq.converged:
            failed = (f"layer {k + 1}", eq)
            break
    assert sim is not None
    final = None
    if failed is None:
        sim.set_particle_friction(spec.friction_particle)
        if spec.rolling_friction > 0.0 or spec.rolling_friction_prep > 0.0:
            sim.set_rolling_friction(spec.rolling_friction, walls=spec.rolling_friction)
        final = equilibrate(sim, spec, "working friction", progress)
        if not final.converged:
            failed = ("working friction", final)
    p = sim.particles
    report = PreparationReport(
        trial_porosity=porosity,
        planned_count=int(len(radii)),
        particle_count=p.n,
        solid_area_m2=p.area(),
        box_porosity=box_porosity(p.area(), W, H),
        measured_porosity=porosity_rect(p.pos, p.radius, 0.0, 0.0, W, H),
        layers=layers,
        final_stage=final,
        converged=failed is None,
        failed_stage=None if failed is None else failed[0],
        failed_max_ratio=None if failed is None else failed[1].max_ratio,
        failed_steps=None if failed is None else failed[1].steps,
        failed_ratio=None if failed is None else failed[1].measured_ratio,
        equilibrium=spec.equilibrium,
    )
    lid_y = float(sim.walls.p0[sim.walls.index("top"), 1])
    if any(layer.band_raised_m is not None for layer in layers) and lid_y > H:
        # an over-full box: the trial is denser than its layers could be built in H; the top
        # plate stands at lid_y, and the criterion's plate stage measures where it settles
        report.overfull_m = lid_y - H
        report.top_height_m = lid_y
    return sim, report


def _layer_groups(radii: np.ndarray, layers: int) -> list[np.ndarray]:
    """Disk indices of each layer: every band gets an equal share of the solid area."""
    share = np.full(layers, 1.0 / layers)
    cum = np.cumsum(np.pi * radii**2) / (np.pi * np.sum(radii**2))
    cuts = np.searchsorted(cum, np.cumsum(share)[:-1])
    return np.split(np.arange(len(radii)), cuts)


def _build_layer(sim, spec: SpecimenSpec, k: int, idx: np.ndarray, radii: np.ndarray, tops: np.ndarray,
                 rng: np.random.Generator,
                 progress: bool) -> tuple[Simulation, LayerReport, Equilibration]:  # fmt: skip
    """Place layer ``k`` in its band under the lid, grow it to size, bring it to equilibrium.

    Returns the simulation (made with the first layer), the layer's report and the result of
    :func:`equilibrate`.
    """
    W = spec.width
    y_bot, y_top, raised = layer_band(sim, spec, k, radii[idx], tops)
    plc = place_disks(radii[idx], Band(0.0, W, y_bot, y_top), seed=int(rng.integers(2**31)))
    # number the disks along horizontal strips of about two diameters: neighbours in
    # space are then near in memory, which keeps the contact loops in cache
    # kept though reorder() renumbers after _grow: growth sums forces in this order; another changes results
    strip = 4.0 * float(plc.radii.max())
    order = np.lexsort((plc.positions[:, 0], np.floor(plc.positions[:, 1] / strip)))
    idx = idx[order]
    small = _band_particles(spec, plc.positions[order], plc.radii[order])
    if sim is None:
        sim = Simulation(
            small, make_walls(spec, y_top), ContactModel("per_body"), gravity=(0.0, -spec.gravity),
            local_damping=spec.local_damping, dt_safety=spec.dt_safety, threads=spec.threads,
            mass_scaling_dt=mass_scaling_step(spec, radii),
        )  # fmt: skip
        new = np.arange(small.n)
    else:
        lid = sim.walls.index("top")
        sim.translate_wall(lid, 0.0, y_top - float(sim.walls.p0[lid, 1]))
        new = sim.add_particles(small)
    # the side walls close the box above the lid, with room for the plate to move up and for
    # the fill acceptance's lid to park it higher (criterion.lid): needed above an over-full
    # band and in boxes taller than wide; the paper's box is closed far above that already
    side_walls_reach(sim, SIDE_WALL_REACH * y_top + 4.0 * float(radii.max()))
    if spec.rolling_friction_prep > 0.0:  # the new disks take it too (they are added with none)
        sim.set_rolling_friction(spec.rolling_friction_prep, walls=spec.rolling_friction_prep)
    mu, wall_mu = sim.particles.mu, sim.walls.mu.copy()
    mu[new] = growth_friction(spec)
    mu[new[growing_fines(spec, radii, radii[idx])]] = 0.0
    if slides_while_growing(spec, radii):
        sim.walls.mu[:] = 0.0
    increments = growth_increments(spec, plc.scale, float(radii[idx].max()), float(radii.min()))
    steps = _grow(sim, new, radii[idx], plc.scale, increments, spec.growth_steps)
    mu[new] = spec.friction_prep  # the preparation's friction for settling
    sim.walls.mu[:] = wall_mu
    # renumber the whole packing in strips across its short side (the new layer was
    # appended on top): threads then split it along a short cut (dem.ordering)
    sim.reorder(strip_order(sim.particles.pos, sim.particles.radius))
    eq = equilibrate(sim, spec, f"layer {k + 1}", progress, settle=True)
    steps += eq.steps
    # band_raised_m recorded only when it happens: the reports of ordinary layers keep their keys
    layer = LayerReport(k + 1, len(idx), y_top, plc.scale, steps, eq.max_ratio, eq.converged, eq.attempts,
                        raised if raised > 0.0 else None,
                        increments if increments > spec.growth_increments else None)  # fmt: skip
    return sim, layer, eq


#: the densest solid fraction a layer's band is filled to at full size. A band is planned for
#: its share of the solid area at the trial porosity (about 0.86 on the paper's trials); a
#: trial denser than the grading can pack (its frictionless jamming fraction: 0.85 for the
#: paper's grading, 0.88-0.90 for Cu 4-6, docs/jamming.md), under layers that spring up above
#: their band tops, leaves the last bands too little room. Above this fraction the band's top
#: (and the lid) is raised until the layer fits at it: the specimen then stands above H, an
#: over-full box, which the criterion's plate stage measures as Fig. 3 does (plate up, a
#: looser next trial). Every band of the paper's trials lies below it (0.859-0.868 at 0.14).
BAND_FRACTION_MAX = 0.90


def layer_band(sim: Simulation | None, spec: SpecimenSpec, k: int, radii: np.ndarray,
               tops: np.ndarray) -> tuple[float, float, float]:  # fmt: skip
    """The band (y_bot, y_top) of layer ``k`` of disks ``radii``, and how far its top was raised.

    The band runs from the previous band's top, or from the top of the disks below when they
    stand above it, to the layer's planned top. When the layer's disks would fill that band to
    more than ``BAND_FRACTION_MAX`` (or it is lower than the largest disk), the band starts on
    the disks below and its top is raised until they fit: the third value is the rise (m), 0
    for an ordinary band.
    """
    y_top = float(tops[k])
    y_bot = float(tops[k - 1]) if k else 0.0
    d_max = 2.0 * float(radii.max())
    if sim is not None:
        # the previous layer's disks may not sit above its lid: start the band on them (on
        # those in the box: a disk squeezed out of an over-dense layer is left to the checks)
        p = sim.particles
        lid = float(sim.walls.p0[sim.walls.index("top"), 1])
        x, y = p.pos[:, 0], p.pos[:, 1]
        inside = (x >= 0.0) & (x <= spec.width) & (y <= lid)
        y_bot = max(y_bot, float(np.max(y[inside] + p.radius[inside])) if inside.any() else 0.0)
    area = float(np.sum(np.pi * radii * radii))
    need = max(area / (spec.width * BAND_FRACTION_MAX), d_max)
    if y_top - y_bot >= need:
        return y_bot, y_top, 0.0
    raised_top = y_bot + need
    return y_bot, raised_top, raised_top - y_top


#: the side walls reach at least this many times the lid's height (plus two largest diameters)
SIDE_WALL_REACH = 1.5


def side_walls_reach(sim: Simulation, height: float) -> None:
    """Lengthen the side walls (``left``, ``right``) upwards where they end below ``height``."""
    for name in ("left", "right"):
        sim.extend_wall_up(name, height)


def _grow(sim: Simulation, idx: np.ndarray, full: np.ndarray, scale: float, m: int, steps_each: int) -> int:
    """Radius expansion of the disks ``idx`` from ``scale * full`` to ``full`` in ``m``
    increments of ``steps_each`` steps."""
    steps = 0
    p = sim.particles
    for s in range(1, m + 1):
        f = scale + (1.0 - scale) * s / m
        p.radius[idx] = full * f
        sim.particles_changed()
        steps += sim.run(steps_each).steps
    return steps


__all__ = [
    "PreparationReport",
    "SettledTest",
    "SizeEstimate",
    "SpecimenSpec",
    "check_feasible",
    "growing_fines",
    "growth_increments",
    "slides_while_growing",
    "is_wide",
    "preparation_note",
    "wide_grading_spec",
    "check_size",
    "equilibrate",
    "estimate_size",
    "make_walls",
    "prepare_specimen",
]
