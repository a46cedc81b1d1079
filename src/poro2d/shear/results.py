"""Typed results of direct shear: one test's ``result.json``, a series' ``result.json`` and the
replicate specimens' ``replicates.json`` and a strength study's ``strength.json``."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

from poro2d.dem.summary import EngineSummary
from poro2d.io_utils import Provenance
from poro2d.labtest.records import ByName, ConsolidationRecord, typed_parts
from poro2d.shear.box_dominated import box_verdict
from poro2d.shear.box_scale import BoxScale
from poro2d.shear.curve import CurveSummary, ShearCurve, read_curve
from poro2d.shear.parts import (
    LATER_KEYS,
    FitInterval,
    LabComparison,
    LaterParts,
    MohrCoulombFit,
    QuasiStatic,
    RateCheck,
    ShearTestSummary,
    StrengthCase,
    StrengthDefinitions,
    StressPeaks,
)
from poro2d.shear.settings import ShearSettings
from poro2d.store import Store
from poro2d.typed_result import NOT_IN_FILE, TypedResult, with_fields


@typed_parts
@dataclass(eq=False)
@with_fields(LaterParts, after="provenance")
class ShearTestResult(ByName, CurveSummary):
    """One test (a test folder's ``result.json``): what its curve says, and how it was obtained.

    The first fields are read off the curve (:class:`~poro2d.shear.curve.CurveSummary`, by
    :func:`poro2d.shear.curve.curve_summary`): the smoothed peak and where it lies, the end values
    (``end``: smoothed over one peak window), the servo's stress error, the inertial number and
    the force balance; the last ones those of :class:`~poro2d.shear.parts.LaterParts`. Stresses
    in kPa, lengths in m unless the name says mm. ``curve`` (not in
    the file): the recorded curve (:class:`~poro2d.shear.curve.ShearCurve`; None when the test is
    not at hand).
    """

    inertial_number_at_target_stress: float
    consolidation: ConsolidationRecord
    velocity_m_per_s: float
    density_scale: float
    local_damping: float
    dt_s: float
    d_mean_m: float
    shear_steps: int
    records: int
    wall_time_shear_s: float
    wall_time_s: float
    settings: ShearSettings
    specimen: str
    engine: EngineSummary
    provenance: Provenance
    curve: ShearCurve | None = field(default=None, kw_only=True, repr=False, metadata=NOT_IN_FILE)

    OPTIONAL: ClassVar[tuple[str, ...]] = LATER_KEYS

    @classmethod
    def read(cls, store: Store, data: dict[str, Any] | None = None) -> ShearTestResult:
        """A finished test read back from ``store``: its ``result.json`` and its ``curve.csv``.

        ``data``: the content of ``result.json`` when the caller has read it already.
        """
        if data is None:
            data = store.read_json("result.json")
        if not isinstance(data, dict):
            raise FileNotFoundError(f"no finished direct shear test in {store.root} (result.json)")
        result = cls.from_dict(data)
        result.curve = read_curve(store)
        if result.box_dominated is None and result.curve is not None:
            # a test of an earlier poro2d: the verdict is read off its stored curve
            verdict = box_verdict(result.curve, result.peak_window_m)
            result.box_dominated, result.box_note = verdict.dominated, verdict.note
        return result


@typed_parts
@dataclass(eq=False)
class ShearSeriesResult(TypedResult):
    """Tests at several normal stresses on one specimen (a series' ``result.json``), with the fit.

    ``tests``: one :class:`~poro2d.shear.parts.ShearTestSummary` per test. The Mohr-Coulomb fit (``fit``, and
    its ``friction_angle_deg``, ``cohesion_kpa``, ``r2``) needs two stresses or more, else
    they are None. ``rate_check`` and ``lab`` are in the file only when the series ran with
    them. ``curves`` (not in the file): each test's curve (:attr:`ShearTestResult.curve`)
    by normal stress, for figures and summaries made from the result.
    """

    OPTIONAL: ClassVar[tuple[str, ...]] = ("rate_check", "lab", "box_scale", "box_dominated_tests")

    normal_stresses_kpa: list[float]
    tests: list[ShearTestSummary]
    friction_angle_deg: float | None
    cohesion_kpa: float | None
    r2: float | None
    fit: MohrCoulombFit | None
    friction_angle_through_origin_deg: float
    fit_through_origin: MohrCoulombFit
    quasi_static: QuasiStatic
    peak_definition: str
    shear_stress_definition: str
    settings: ShearSettings
    velocity_m_per_s: float
    density_scale: float
    specimen: str
    specimen_digest: str
    specimen_meta: dict[str, Any]
    processes: int
    config: dict[str, Any]
    rate_check: RateCheck | None = None
    lab: LabComparison | None = None
    box_scale: BoxScale | None = None
    wall_time_s: float | None = None
    provenance: Provenance | None = None
    #: how many of ``tests`` are box-dominated (poro2d.shear.box_dominated); absent in a series
    #: of an earlier poro2d
    box_dominated_tests: int | None = None
    curves: dict[float, ShearCurve] = field(
        default_factory=dict, kw_only=True, repr=False, metadata=NOT_IN_FILE
    )


@dataclass
class ShearStudyRun:
    """How a study of direct shear series ran, in the order its files keep them (absent in a file of
    an earlier poro2d; put in by :func:`poro2d.typed_result.with_fields`): its wall time (s), the
    processes its tests ran on, the config it was given and its provenance."""

    wall_time_s: float
    processes: int
    config: dict[str, Any]
    provenance: Provenance


@typed_parts
@dataclass(eq=False)
@with_fields(ShearStudyRun, after="method", optional=True)
class ReplicateShearResult(TypedResult):
    """The same tests on several specimens (``replicates.json``): peaks over specimens, pooled fits.

    ``per_normal_stress``: per stress the peaks' mean, sd, count and values; ``fit`` (None
    with one stress) and ``fit_through_origin``: the Mohr-Coulomb line through every
    specimen's peaks with Student-t intervals; ``friction_angle_per_specimen_deg`` and its
    mean and sd. ``series`` (not in the file): each specimen's :class:`ShearSeriesResult`
    by label, as the run computed or read them.
    """

    specimens: list[str]
    per_normal_stress: list[StressPeaks]
    fit: FitInterval | None
    fit_through_origin: FitInterval
    friction_angle_per_specimen_deg: list[float]
    friction_angle_mean_deg: float | None
    friction_angle_sd_deg: float | None
    method: str
    #: how many tests of every specimen are box-dominated (poro2d.shear.box_dominated); absent in
    #: a study of an earlier poro2d
    box_dominated_tests: int | None = None
    series: dict[str, ShearSeriesResult] = field(default_factory=dict, kw_only=True, metadata=NOT_IN_FILE)

    OPTIONAL: ClassVar[tuple[str, ...]] = ("box_dominated_tests",)


@typed_parts
@dataclass(eq=False)
@with_fields(ShearStudyRun, after="definitions", optional=True)
class StrengthResult(TypedResult):
    """Strength against rolling and particle friction (a strength study's ``strength.json``).

    ``cases``: one row per (mu_r, f_p) (the rows of ``strength.csv`` with the pooled fits'
    intervals): peak and residual friction angles and the dilation angle, mean and sd over
    the specimens; ``definitions``: how each is measured; ``box_scale``: the smallest box of
    the specimens against ASTM D3080 and the size-insensitive 2D box (its angles are box-scale).
    """

    cases: list[StrengthCase]
    mu_r: list[float]
    particle_friction: list[float]
    specimens: list[str]
    settings: ShearSettings
    definitions: StrengthDefinitions
    box_scale: BoxScale | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = ("box_scale",)


__all__ = ["ReplicateShearResult", "ShearSeriesResult", "ShearStudyRun", "ShearTestResult", "StrengthResult"]
