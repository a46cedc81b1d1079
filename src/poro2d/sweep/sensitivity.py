"""Why the paper's case gives what it gives: the criterion against grading width and mu_prep.

The criterion of Fig. 3 steers every trial to the porosity at which the prepared specimen
fills the box without being forced; that porosity is a property of the grading and of
the preparation. The built-in paper grading is a reconstruction (narrow, Cu about 1.7),
so this study measures, with the paper's own protocol (preparation friction 0.05, first
trial from Eq. 12 at nLab = 0.3434):

a. the accepted n2D against the width of the grading: a log-linear family of given Cu at
   the reconstructed grading's mean disk area (the same number of disks in the box), and
   the reconstructed grading itself (:func:`grading_study`);
b. the accepted n2D against the preparation friction mu_prep, for the reconstructed
   grading: the density calibration of :mod:`poro2d.sweep.density` (cached per grading);
c. every point over seeds (mean, sample sd, n; unconverged seeds counted, not averaged);
d. the first trial's F_top and G beside the paper's (3854 kN/m against 846 N/m).

The answer (:func:`answer`) is computed from the numbers: which grading width or friction
accepts the paper's 0.15 within 0.005, or which comes closest and by how much.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Self

import numpy as np

from poro2d.config import check_keys, check_number_list
from poro2d.criterion.settings import CriterionSettings
from poro2d.errors import InputError
from poro2d.execute.options import RunOptions
from poro2d.io_utils import float_or_nan
from poro2d.paper_data import QUICK_CRITERION
from poro2d.store import Store
from poro2d.sweep.cases import SweepConfig
from poro2d.sweep.criterion_base import CriterionBase
from poro2d.sweep.density import CalibrationCase
from poro2d.sweep.output import study_store
from poro2d.sweep.records import CaseRow, LostCaseRow, case_row
from poro2d.sweep.results import SensitivityResult
from poro2d.sweep.sensitivity_records import (
    AVERAGED,
    Answer,
    GradingDescription,
    GradingPoint,
    Match,
    MuPoint,
    PaperNumbers,
    PointRow,
    SeedRecord,
    StudySettings,
)
from poro2d.typed_result import part

#: grading widths of the full study (Cu = d60 / d10), and of ``--quick``: at the paper
#: grading's mean disk area Cu = 4 has disks of about 26 mm, taller than the 20 mm layer
#: bands of the quick box (0.04 m in 2 layers), so the quick list stops at Cu = 3
DEFAULT_CUS = (1.5, 2.0, 2.5, 3.0, 4.0)
QUICK_CUS = (1.5, 2.0, 2.5, 3.0)
DEFAULT_SEEDS = 3
QUICK_SEEDS = 2
#: keys of the optional ``[sensitivity]`` table of a config
SENSITIVITY_KEYS = {"cu", "mu_prep", "seeds"}
#: how close an accepted n2D must be to the paper's to count as reproducing it: the
#: criterion's own porosity tolerance
MATCH_TOLERANCE = 0.005
#: label of the grading given in the config (for the paper preset: the reconstruction)
REFERENCE = "reference"


def paper_numbers() -> PaperNumbers:
    """The numbers the paper reports for its criterion run (held by ``poro2d.paper_data``)."""
    from poro2d.paper_data import PAPER

    return PaperNumbers(n_lab=PAPER["n_lab"], **PAPER["criterion"])


# ------------------------------------------------------------------------------ settings
def check_cus(cus: Any) -> list[float]:
    """Distinct grading widths Cu > 1 (a single size has Cu = 1), at most 20, ascending."""
    # Cu = d60/d10: 1 is a single size
    out = check_number_list("sensitivity.cu", cus, 1.0, 20.0, lo_open=True, max_items=20,
                            what="uniformity coefficients Cu")  # fmt: skip
    if len(set(out)) != len(out):
        raise InputError("sensitivity.cu", cus, "distinct values")
    return sorted(out)


def study_settings(table: dict | None, *, quick: bool, seeds: int | None) -> StudySettings:
    """Cu list, mu_prep list and seeds from ``[sensitivity]`` and the command line."""
    from poro2d.criterion.density import DEFAULT_MUS
    from poro2d.sweep.density import check_mus, check_seeds

    t = dict(table or {})
    check_keys("sensitivity", t, SENSITIVITY_KEYS)
    cus = check_cus(t.get("cu", list(QUICK_CUS if quick else DEFAULT_CUS)))
    mus = check_mus(t.get("mu_prep", list(DEFAULT_MUS)), "sensitivity.mu_prep")
    if seeds is not None:
        n = check_seeds(seeds, "--seeds")
    else:
        n = check_seeds(t.get("seeds", QUICK_SEEDS if quick else DEFAULT_SEEDS), "sensitivity.seeds")
    return StudySettings(cus=cus, mus=mus, seeds=n, quick=bool(quick))


#: the criterion settings of the study unless its config sets them
REFINE_DEFAULTS = {"refine_tolerance": 0.002, "max_iterations": 10}


def study_base(base: CriterionBase, *, quick: bool) -> CriterionBase:
    """The criterion base every case starts from: the given one, smaller in quick mode."""
    from poro2d.sweep.relation import QUICK_SPECIMEN

    study = base.without("sensitivity", "relation", "sweep")
    # trials refined below the paper's 0.01 grid, so the study resolves differences of 0.005
    study = study.with_defaults({"criterion": REFINE_DEFAULTS})
    if quick:
        study = study.with_tables(specimen=dict(study.table("specimen"), **QUICK_SPECIMEN))
        # in a box of a few hundred disks 1 % of G is about two disks' weight: the quick
        # look widens the window as `poro2d paper --quick` does (a config's own value wins)
        study = study.with_defaults({"criterion": QUICK_CRITERION})
    return study


# ------------------------------------------------------------------------------ gradings
@dataclass
class GradingCase:
    """One grading of the study: how it is described to a case, and its sizes."""

    label: str
    cu_nominal: float | None
    params: dict[str, Any]
    curve: Any  # GradingCurve

    def describe(self) -> GradingDescription:
        """The grading as the study's file records it: widths, sizes, where it came from."""
        c = self.curve
        return GradingDescription(
            label=self.label,
            cu_nominal=self.cu_nominal,
            cu=c.uniformity,
            d10_mm=1e3 * c.size_at(10.0),
            d50_mm=1e3 * c.size_at(50.0),
            d_min_mm=1e3 * c.d_min_m,
            d_max_mm=1e3 * c.d_max_m,
            mean_disk_area_m2=c.mean_disk_area(),
            sizes_m=list(c.sizes_m),
            percent_passing=list(c.percent_passing),
            source=c.source,
        )


def gradings(base: CriterionBase, cus: list[float]) -> list[GradingCase]:
    """The config's grading, then the log-linear family at its mean disk area."""
    from poro2d.criterion.config import build
    from poro2d.grading import log_linear_grading

    _, ref, _, _ = build(base.as_config(), base.base_dir)
    # the config's own grading as a case's parameters (dotted names, a grading file's path made
    # absolute): the reference case names its grading as the family's cases name theirs
    own = base.with_grading_file_absolute().table("grading") or {"preset": "paper"}
    out = [GradingCase(REFERENCE, None, {f"grading.{k}": v for k, v in own.items()}, ref)]
    area = ref.mean_disk_area()
    for cu in cus:
        g = log_linear_grading(cu, area)
        # model sizes in mm, up-scale 1: the case rebuilds exactly this curve
        params = {
            "grading.sizes_mm": [1e3 * s for s in g.sizes_m],
            "grading.percent_passing": list(g.percent),
        }
        out.append(GradingCase(f"Cu {cu:g}", cu, params, g))
    return out


def check_gradings(base: CriterionBase, cases: list[GradingCase]) -> None:
    """Every grading must fit the box: one clear line naming the Cu, before anything runs."""
    from poro2d.criterion.config import build
    from poro2d.specimen.compaction import check_feasible

    spec, _, settings, _ = build(base.as_config(), base.base_dir)
    band = spec.height / spec.layers
    for g in cases:
        d_max = g.curve.d_max_m
        if d_max >= min(spec.width, band):
            raise InputError(
                "sensitivity.cu" if g.cu_nominal is not None else "grading",
                g.cu_nominal if g.cu_nominal is not None else g.label,
                f"a grading whose largest disk fits the {1e3 * band:.4g} mm layer band "
                f"({spec.height} m in {spec.layers} layers) and the {spec.width} m width",
                f"its largest disk is {1e3 * d_max:.4g} mm: use a smaller Cu or a taller box",
            )
        check_feasible(spec, g.curve, settings.initial_trial())


# ------------------------------------------------------------------------------ analysis
def finite_mean_sd(values: list) -> tuple[float, float, int]:
    """Mean, sample sd (0 for one value) and n of the finite values; NaN when there are none."""
    a = np.array([float(v) for v in values if v is not None and math.isfinite(float(v))], dtype=float)
    if a.size == 0:
        return math.nan, math.nan, 0
    return float(a.mean()), float(a.std(ddof=1)) if a.size > 1 else 0.0, int(a.size)


def _finite(v) -> bool:
    """Whether ``v`` is a number (a result keeps a missing one, NaN, as None)."""
    return v is not None and math.isfinite(v)


def _ratio(a, b) -> float | None:
    if a is None or b is None or not b:
        return None
    return float(a) / float(b)


def seed_record(row: CaseRow | LostCaseRow | dict, grading: GradingDescription | dict,
                seed: int) -> SeedRecord:  # fmt: skip
    """One criterion run of the grading study, flattened: accepted n2D, first and last trial."""
    row, grading = case_row(row), part(GradingDescription, grading)
    res = row.results or {}
    ok = row.status == "done" and bool(res.get("converged"))
    return SeedRecord.from_dict({
        "grading": grading.label,
        "cu": grading.cu,
        "seed": seed,
        "status": row.status,
        "converged": ok,
        "accepted_n2d": res.get("final_porosity") if ok else None,
        "accepted_measured_n2d": res.get("last_new_porosity") if ok else None,
        "accepted_interior_porosity": res.get("interior_porosity") if ok else None,
        "last_estimate_n2d": res.get("last_new_porosity"),
        "iterations": res.get("iterations"),
        "first_trial_porosity": res.get("first_trial_porosity", res.get("initial_trial_porosity")),
        "first_f_top_n_per_m": res.get("first_f_top_n_per_m"),
        "first_self_weight_n_per_m": res.get("first_self_weight_n_per_m"),
        "first_f_top_over_g": _ratio(res.get("first_f_top_n_per_m"), res.get("first_self_weight_n_per_m")),
        "first_plate_moved": res.get("first_plate_moved"),
        "first_new_porosity": res.get("first_new_porosity"),
        "accepted_f_top_n_per_m": res.get("f_top_after_n_per_m") if ok else None,
        "accepted_f_bottom_n_per_m": res.get("f_bottom_after_n_per_m") if ok else None,
        "accepted_self_weight_n_per_m": res.get("self_weight_n_per_m") if ok else None,
        "message": res.get("message") or row.error,
        "time_s": row.time_s,
    })  # fmt: skip


def grading_points(records: list[SeedRecord], grads: list[GradingDescription | dict]) -> list[GradingPoint]:
    """One point per grading: accepted n2D and first-trial forces over its seeds."""
    pts = []
    for g in (part(GradingDescription, g) for g in grads):
        recs = [r for r in records if r.grading == g.label]
        mean, sd, n = finite_mean_sd([r.accepted_n2d for r in recs])
        averaged = {}
        for name, key in AVERAGED:
            averaged[f"{name}_mean"], averaged[f"{name}_sd"], _ = finite_mean_sd(
                [getattr(r, key) for r in recs]
            )
        pts.append(GradingPoint.from_dict({
            "axis": "grading",
            "label": g.label,
            "cu": g.cu,
            "cu_nominal": g.cu_nominal,
            "d50_mm": g.d50_mm,
            "d_max_mm": g.d_max_mm,
            "n2d_mean": mean,
            "n2d_sd": sd,
            "n": n,
            "seeds": len(recs),
            "unconverged": len(recs) - n,
            "quantity": "accepted trial n2D",
            **averaged,
            "first_trial_porosity": next((r.first_trial_porosity for r in recs), None),
        }))  # fmt: skip
    return pts


def mu_points(cal: dict) -> list[MuPoint]:
    """One point per preparation friction, from a calibration's samples (n' per seed)."""
    pts = []
    for mu, samples in zip(cal["mus"], cal["samples"], strict=True):
        mean, sd, n = finite_mean_sd(samples)
        pts.append(MuPoint(
            axis="mu_prep", label=f"mu_prep {mu:g}", mu_prep=mu, n2d_mean=mean, n2d_sd=sd, n=n,
            seeds=len(samples), unconverged=len(samples) - n,
            quantity="n' of the accepted trial (first trial 0.19)",
        ))  # fmt: skip
    return pts


# -------------------------------------------------------------------------------- answer
def closest_match(points: list[GradingPoint | MuPoint | dict], x: str, target: float,
                  tol: float = MATCH_TOLERANCE) -> Match:  # fmt: skip
    """Points within ``tol`` of ``target``, the closest point, and where the means cross it.

    ``x`` names the swept quantity ("cu" or "mu_prep"; a point given as a dict is read as the
    point of that axis). The crossing is a linear interpolation between two neighbouring points
    (sorted by ``x``) whose means lie on either side of the target.
    """
    points = [part(MuPoint if x == "mu_prep" else GradingPoint, p) for p in points]
    good = sorted((p for p in points if _finite(p.n2d_mean)), key=lambda p: getattr(p, x))
    if not good:
        return Match.from_dict({"matches": [], "closest": None, "distance": None, "crossing": None})
    best = min(good, key=lambda p: abs(p.n2d_mean - target))
    crossing = None
    for a, b in zip(good, good[1:], strict=False):
        ya, yb = a.n2d_mean - target, b.n2d_mean - target
        if ya * yb <= 0.0 and ya != yb:
            crossing = getattr(a, x) + (getattr(b, x) - getattr(a, x)) * ya / (ya - yb)
            break
    return Match.from_dict({
        "matches": [getattr(p, x) for p in good if abs(p.n2d_mean - target) <= tol + 1e-12],
        "closest": getattr(best, x),
        "closest_mean": best.n2d_mean,
        "closest_sd": best.n2d_sd,
        "closest_n": best.n,
        "distance": best.n2d_mean - target,
        "crossing": crossing,
        "ends": [[getattr(good[0], x), good[0].n2d_mean], [getattr(good[-1], x), good[-1].n2d_mean]],
    })  # fmt: skip


def _pm(p_mean: float, sd: float, n: int) -> str:
    return f"{p_mean:.4f} +- {sd:.4f} (n = {n})"


def _axis_text(name: str, unit: str, m: Match, points: list[GradingPoint | MuPoint], x: str, target: float,
               tol: float) -> str:  # fmt: skip
    if m.closest is None:
        return f"{name}: no point was accepted by any seed."
    if m.matches:
        hits = [p for p in points if getattr(p, x) in m.matches]
        vals = "; ".join(f"{unit}{getattr(p, x):g}: {_pm(p.n2d_mean, p.n2d_sd, p.n)}" for p in hits)
        text = f"{name}: within {tol:g} of {target:g}: {vals}"
    else:
        best = _pm(m.closest_mean, m.closest_sd, m.closest_n)
        side = "above" if m.distance > 0 else "below"
        text = f"{name}: no point within {tol:g} of {target:g}; the closest is {unit}{m.closest:g} with "
        text += f"{best}, {abs(m.distance):.4f} {side}"
    if m.crossing is not None:
        text += f"; the means cross {target:g} at {unit}{m.crossing:.3g} (linear interpolation)"
    else:
        (x0, y0), (x1, y1) = m.ends
        text += f"; from {unit}{x0:g} to {unit}{x1:g} the means run from {y0:.4f} to {y1:.4f}"
    return text + "."


def answer(sens: dict, tol: float = MATCH_TOLERANCE) -> Answer:
    """Which grading width and which mu_prep accept the paper's n2D, from the measured points."""
    paper = sens["paper"]
    target = float(paper.accepted_porosity)
    g_pts = sens["points"]["grading"]
    family = [p for p in g_pts if p.cu_nominal is not None]
    ref = next((p for p in g_pts if p.cu_nominal is None), None)
    g = closest_match(family, "cu", target, tol)
    mu = closest_match(sens["points"]["mu_prep"], "mu_prep", target, tol)
    lines = [
        _axis_text("Grading width (log-linear family)", "Cu = ", g, family, "cu", target, tol),
        _axis_text("Preparation friction (reference grading)", "mu_prep = ", mu, sens["points"]["mu_prep"],
                   "mu_prep", target, tol),
    ]  # fmt: skip
    if ref is not None and _finite(ref.n2d_mean):
        d = ref.n2d_mean - target
        acc = _pm(ref.n2d_mean, ref.n2d_sd, ref.n)
        lines.append(
            f"The reference grading (Cu = {ref.cu:.3g}) accepts {acc} with the paper's protocol, "
            f"{abs(d):.4f} {'above' if d > 0 else 'below'} the paper's {target:g}"
            f"{'' if abs(d) > tol else ' (within the tolerance)'}."
        )
    lines.extend(_protocol_lines(sens, ref))
    lines.extend(_first_trial_lines(ref, paper))
    unconv = sum(p.unconverged for p in g_pts + sens["points"]["mu_prep"])
    if unconv:
        lines.append(f"{unconv} seed(s) did not converge; they are counted, not averaged.")
    return Answer(target=target, tolerance=tol, grading=g, mu_prep=mu, lines=lines)


def _protocol_lines(sens: dict, ref: GradingPoint | dict | None) -> list[str]:
    """The paper's protocol (first trial from Eq. 12) against the calibration's (its own first trial)."""
    from poro2d.sweep.density import first_trial, with_density_defaults

    ref = part(GradingPoint, ref)
    mu0 = sens["settings"]["mu_prep"]
    cal = next((p for p in sens["points"]["mu_prep"] if abs(p.mu_prep - mu0) < 1e-12), None)
    if ref is None or cal is None:
        return []
    a, b = ref.measured_mean, cal.n2d_mean
    if not (_finite(a) and _finite(b)):
        return []
    # each trial is a fresh specimen seeded by the seed and the trial porosity: where the two
    # protocols reach the same trial porosity they prepare the same specimen
    study = with_density_defaults(CriterionBase(sens.get("config") or {}))
    first = first_trial(study.table("criterion"), mu0)
    return [
        f"At mu_prep = {mu0:g} the measured porosity n' of the accepted trial is {a:.4f} starting from "
        f"the first trial {ref.first_trial_porosity:g} and {b:.4f} starting from {first:g} (the "
        f"calibration), a difference of {a - b:+.4f}; every trial is prepared afresh, so the first trial "
        "acts only through the trial porosity it leads to."
    ]


def _first_trial_lines(ref: GradingPoint | None, paper: PaperNumbers) -> list[str]:
    if ref is None or not _finite(ref.first_f_top_mean):
        return []
    paper_f = 1e3 * paper.f_top_first_trial_kn_per_m
    paper_g = paper.self_weight_first_trial_n_per_m
    paper_n = paper.trials[0] + paper.porosity_change_first_trial
    # a mean over no seed is None (NaN as the file keeps it): printed as NaN was
    means = (ref.first_f_top_mean, ref.first_f_top_sd, ref.first_g_mean, ref.first_f_top_over_g_mean,
             ref.first_n_prime_mean)  # fmt: skip
    f, sd, g, ratio, n_prime = map(float_or_nan, means)
    return [
        f"First trial ({ref.first_trial_porosity:g}) with the reference grading: F_top = {f:.4g} +- "
        f"{sd:.3g} N/m = {ratio:.4g} G (G = {g:.4g} N/m); the paper: {paper_f:.4g} "
        f"N/m = {paper_f / paper_g:.4g} G (G = {paper_g:g} N/m), {paper_f / f:.3g} times poro2d's; after "
        f"the plate moved n' = {n_prime:.4f} (paper: {paper_n:.3f})."
    ]


# ----------------------------------------------------------------------------------- run
@dataclass(frozen=True)
class SensitivityCase:
    """The study checked and built, before anything runs (:meth:`from_config`, :meth:`from_base`).

    ``study``: the criterion base every case starts from (:func:`study_base`); ``settings``:
    the Cu list, frictions and seeds; ``crit``: the base's criterion settings; ``gradings``:
    the reference grading and the family; ``sweep``: the grading sweep, every case built;
    ``calibration``: the friction axis, the density calibration of the reference grading.
    """

    study: CriterionBase
    settings: StudySettings
    crit: CriterionSettings
    gradings: list[GradingCase]
    sweep: SweepConfig
    calibration: CalibrationCase

    @classmethod
    def from_config(
        cls, config=None, *, preset: str | None = None, quick: bool = False, seeds: int | None = None
    ) -> Self:
        """The case of ``poro2d sensitivity``: ``config`` (a dict, a TOML file, or the paper preset
        when None) with an optional ``[sensitivity]`` table (``cu``, ``mu_prep``, ``seeds``)."""
        from poro2d.criterion.run import load

        cfg, base_dir = load(config, preset, extra_tables=("sensitivity",))
        return cls.from_base(CriterionBase.from_config(cfg, base_dir), quick=quick, seeds=seeds)

    @classmethod
    def from_base(cls, base: CriterionBase, *, quick: bool = False, seeds: int | None = None) -> Self:
        """The case of a criterion config as read, ``seeds`` (None: the table's) and ``quick`` applied;
        every grading checked against the box (InputError if not)."""
        from poro2d.criterion.config import build
        from poro2d.sweep import density as D

        settings = study_settings(base.config.get("sensitivity"), quick=quick, seeds=seeds)
        study = study_base(base, quick=quick)
        _, _, crit, _ = build(study.as_config(), study.base_dir)
        cases = gradings(study, settings.cus)
        check_gradings(study, cases)
        # one criterion case per grading and seed, everything else as in the study's base
        params = [dict(g.params, seed=s) for g in cases for s in range(settings.seeds)]
        table = {"kind": "criterion", "title": "accepted n2D against grading width", "cases": params}
        sweep = study.with_tables(grading={}).sweep(table, params)  # each case names its own grading
        # the friction axis is the density calibration, with its settings (layers that settle):
        # the same cases as the relation's, read back from the shared cache when it ran them
        calibration = CalibrationCase(D.with_density_defaults(study), tuple(settings.mus), settings.seeds)
        calibration.sweep  # noqa: B018 (its cases are built, so checked, now)
        return cls(study, settings, crit, cases, sweep, calibration)


def run_sensitivity(
    case: SensitivityCase,
    store: Store | None = None,
    *,
    options: RunOptions = RunOptions(),
    announce=None,
    use_cache: bool = True,
    client=None,
) -> SensitivityResult:
    """The whole study into ``store``; returns the :class:`SensitivityResult` of its ``sensitivity.json``.

    ``case``: the study's :class:`SensitivityCase`; ``store``: where the study is kept (None:
    nothing is kept but the shared calibration cache). ``announce`` (no arguments) is called
    once the folder and the scheduler are checked, before any work; ``use_cache``: the
    calibration's cases in the shared cache. ``options``: where the jobs run and whether bars
    show (:class:`~poro2d.execute.options.RunOptions`); ``client``: an existing Dask client
    instead (:func:`~poro2d.sweep.runner.run_sweep`).
    """
    from poro2d.sweep import density as D
    from poro2d.sweep.runner import run_sweep

    with study_store(store, "sensitivity", options, announce) as store:
        study, crit, settings = case.study, case.crit, case.settings
        timings: dict[str, float] = {}
        t0 = time.perf_counter()
        res = run_sweep(case.sweep, store.child("grading"), options=options, client=client)
        timings["grading_s"] = time.perf_counter() - t0
        t1 = time.perf_counter()
        cal, cal_info = D.calibrate(
            case.calibration, store.child("mu_prep"), use_cache=use_cache, options=options, client=client
        )
        timings["mu_prep_s"] = time.perf_counter() - t1

        grads = [g.describe() for g in case.gradings]
        labels = [(g, s) for g in grads for s in range(settings.seeds)]
        records = [seed_record(r, g, s) for r, (g, s) in zip(res.rows, labels, strict=True)]
        spec = study.table("specimen")
        sens = {
            "title": "accepted n2D against grading width and preparation friction (paper protocol)",
            "settings": dict(
                settings.to_dict(),
                seed_list=list(range(settings.seeds)),
                mu_prep=float(spec.get("friction_prep", 0.05)),
                n_lab=crit.n_lab,
                first_trial=crit.initial_trial(),
                first_trial_from="given" if crit.trial_porosity is not None else "Eq. 12",
            ),
            "gradings": grads,
            "seeds": records,
            "points": {"grading": grading_points(records, grads), "mu_prep": mu_points(cal.to_dict())},
            "calibration": dict(cal.to_dict(), **cal_info.to_dict()),
            "paper": paper_numbers(),
            "config": study.as_config(),
            "sweeps": {"grading": res.summary, "failed_cases": len(res.failed)},
            "timings": timings,
        }
        sens["answer"] = answer(sens)
        timings["total_s"] = time.perf_counter() - t0
        return write_sensitivity(sens, store)


def write_sensitivity(sens: dict, store: Store) -> SensitivityResult:
    """sensitivity.json, sensitivity.csv (points) and sensitivity_seeds.csv; the study typed.

    Its ``figure`` names ``sensitivity.png`` in ``store``, which
    ``draw_sensitivity`` (``report/sensitivity_report.py``) draws from the result."""
    from poro2d.io_utils import Provenance

    sens = dict(sens, figure=str(store.path("sensitivity.png")), provenance=Provenance.now().to_dict())
    result = SensitivityResult.from_dict(sens)
    store.write_csv("sensitivity_seeds.csv", sens["seeds"])
    # the grading points, then the friction points, each saying whether it reproduces the paper
    answer, version = result.answer, result.provenance.poro2d_version
    points = result.points.grading + result.points.mu_prep
    rows = [
        PointRow.of(p, answer.target, answer.tolerance, result.settings.seed_list, version) for p in points
    ]
    store.write_csv("sensitivity.csv", rows)
    store.write_result("sensitivity.json", result)
    return result


def load_sensitivity(store: Store) -> SensitivityResult:
    """A finished study read back, its figure path pointing into ``store``."""
    sens = store.read_result("sensitivity.json", SensitivityResult.from_dict)
    if sens is None:
        raise InputError("sensitivity", str(store.root), "a folder holding sensitivity.json")
    sens.figure = str(store.path("sensitivity.png"))
    return sens


__all__ = [
    "DEFAULT_CUS",
    "QUICK_CUS",
    "answer",
    "check_cus",
    "closest_match",
    "grading_points",
    "gradings",
    "load_sensitivity",
    "mu_points",
    "run_sensitivity",
    "SensitivityCase",
    "seed_record",
    "study_settings",
    "finite_mean_sd",
    "write_sensitivity",
]
