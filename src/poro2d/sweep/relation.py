"""The grading-specific relation n2D(nLab) from the criterion, run as a sweep.

The paper verified its criterion only for a dense specimen (Dr = 0.89). Here the
criterion runs at several laboratory porosities between n_max (loose) and n_min
(dense) for one grading; every accepted n2D is a point of the DEM-derived relation.
A parabola through the origin, n2D = a nLab^2 + b nLab (the form of Eq. 12), is
fitted by least squares to the converged points and shown beside Eq. 12 and the
other conversion methods. Points whose criterion did not converge are kept: they are
drawn hollow at their last estimate n' (the porosity of the box after the plate
moved), flagged in the table and left out of the fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from poro2d import porosity as P
from poro2d.config import check_keys, check_number_list
from poro2d.criterion.run import lab_extremes
from poro2d.errors import InputError, check_int, check_range
from poro2d.execute.options import RunOptions
from poro2d.io_utils import Provenance, float_or_nan
from poro2d.paper_data import QUICK_SPECIMEN as PAPER_QUICK_SPECIMEN
from poro2d.store import Store
from poro2d.sweep.cases import SweepConfig
from poro2d.sweep.criterion_base import CriterionBase
from poro2d.sweep.output import study_store
from poro2d.sweep.records import (
    COMPARE,
    CaseRow,
    DensitySweeps,
    Eq12Coefficients,
    LostCaseRow,
    QuadraticFit,
    case_row,
)
from poro2d.sweep.results import RelationResult

RELATION_KEYS = {"n_max", "n_min", "points", "n_lab", "mode", "seeds", "mu_prep"}
#: how the specimen's density follows the laboratory state (see :mod:`poro2d.criterion.density`)
MODES = ("density", "paper")
#: the small specimen of ``--quick`` (that of ``poro2d paper --quick``)
QUICK_SPECIMEN = dict(PAPER_QUICK_SPECIMEN)


def check_mode(mode) -> str:
    if mode not in MODES:
        raise InputError("relation.mode", mode, " or ".join(MODES))
    return mode


def lab_porosities(n_max: float, n_min: float, points: int) -> list[float]:
    """``points`` laboratory porosities from loose (n_max) to dense (n_min), 4 decimals."""
    P.relative_density(n_min, n_max, n_min)  # validates the extremes
    return [round(float(x), 4) for x in np.linspace(n_max, n_min, check_int("points", points, 2, 50))]


def fit_quadratic_origin(n_lab, n2d) -> QuadraticFit:
    """Least-squares n2D = a nLab^2 + b nLab (no constant: the curve passes the origin).

    Returns a, b, the residuals (data - fit), their RMS and maximum, and R^2 about the
    mean. Needs at least two points with distinct, non-zero nLab.
    """
    x = np.asarray(n_lab, dtype=float).ravel()
    y = np.asarray(n2d, dtype=float).ravel()
    if x.shape != y.shape:
        raise InputError("n2d", y.shape, f"as many values as n_lab ({x.shape[0]})")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise InputError("points", "non-finite", "finite porosities")
    if len(np.unique(x[x != 0.0])) < 2:
        raise InputError("points", list(x), "at least two distinct, non-zero laboratory porosities")
    A = np.column_stack([x * x, x])
    (a, b), *_ = np.linalg.lstsq(A, y, rcond=None)
    resid = y - (a * x * x + b * x)
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    return QuadraticFit(
        a=float(a),
        b=float(b),
        points=int(x.size),
        residuals=resid.tolist(),
        rms_residual=float(np.sqrt(np.mean(resid**2))),
        max_abs_residual=float(np.max(np.abs(resid))),
        r2=float(1.0 - np.sum(resid**2) / ss_tot) if ss_tot > 0 else None,
        form="n2D = a nLab^2 + b nLab",
    )


@dataclass(frozen=True)
class RelationSettings:
    """The laboratory extremes and the states of a relation, loose to dense."""

    n_max: float
    n_min: float
    n_lab: tuple[float, ...]


def relation_settings(
    table: dict | None, *, points: int | None, n_max: float | None, n_min: float | None, preset: bool
) -> RelationSettings:
    """n_max, n_min and the nLab list from ``[relation]`` and the command-line options."""
    check_keys("relation", table or {}, RELATION_KEYS)
    t = dict(table or {})
    for key in ("n_max", "n_min"):  # a wrong value in the file is refused, even when an option wins
        if key in t:
            check_range(f"relation.{key}", t[key], 0.0, 1.0, lo_open=True, hi_open=True)
    hi, lo = lab_extremes(
        "relation", t, n_max, n_min, preset=preset, hint="set them in [relation] or --n-max/--n-min"
    )
    if not hi > lo:
        raise InputError("n_max", hi, f"greater than n_min = {lo}")
    if "n_lab" in t and points is None:
        vals = t["n_lab"]
        # every state between the extremes: its relative density is what the relation is about
        n_labs = [round(v, 4) for v in check_number_list("relation.n_lab", vals, lo, hi, min_items=2,
                                                         what="laboratory porosities")]  # fmt: skip
        if len(set(n_labs)) < len(n_labs):  # one state twice is a typo, not a second point
            raise InputError("relation.n_lab", vals, "distinct laboratory porosities (to 4 decimals)")
        n_labs = sorted(n_labs, reverse=True)
    else:
        n_labs = lab_porosities(hi, lo, points if points is not None else t.get("points", 5))
    return RelationSettings(hi, lo, tuple(n_labs))


def relation_base(base: CriterionBase, *, quick: bool) -> CriterionBase:
    """The criterion base every state of the relation starts from (``quick``: the small box)."""
    tables: dict[str, dict] = {}
    crit = base.table("criterion")
    if quick:
        tables["specimen"] = dict(base.table("specimen"), **QUICK_SPECIMEN)
        # the small box's window is the weight of a few grains: too coarse for the lid's
        # dozens of segments to rest at (docs/porosity.md), so the quick look keeps the plate
        crit.setdefault("acceptance", "plate")
    crit.pop("n_lab", None)
    crit.pop("trial_porosity", None)  # every point starts from Eq. 12 at its own nLab
    tables["criterion"] = crit
    return base.without("relation", "sweep").with_tables(**tables)


def relation_sweep(base: CriterionBase, n_labs: tuple[float, ...]) -> SweepConfig:
    """The criterion at every laboratory porosity, from :func:`relation_base` (paper mode's sweep)."""
    grid = {"criterion.n_lab": list(n_labs)}
    table = {"kind": "criterion", "title": "n2D(nLab) relation", **grid}
    return base.sweep(table, [{"criterion.n_lab": n} for n in n_labs])


def analyse(rows: list[CaseRow | LostCaseRow | dict], n_max: float, n_min: float) -> RelationResult:
    """Relation points (one per case), the fit through the converged ones, comparisons."""
    pts = []
    for r in map(case_row, rows):
        res = r.results or {}
        n_lab = float_or_nan(res.get("n_lab", (r.params or {}).get("criterion.n_lab")))
        converged = bool(res.get("converged")) and r.status == "done"
        if converged:
            n2d, source = float_or_nan(res.get("final_porosity")), "accepted"
        elif r.status == "done":
            n2d, source = float_or_nan(res.get("last_new_porosity")), "last estimate n' (not converged)"
        else:
            n2d, source = math.nan, "case failed"
        pt = {
            "case_id": r.case_id,
            "n_lab": n_lab,
            "relative_density": float(P.relative_density(n_lab, n_max, n_min)),
            "degree_of_density": float(P.degree_of_density(n_lab, n_max, n_min)),
            "n2d_dem": n2d,
            "converged": converged,
            "flag": "" if converged else source,
            "iterations": res.get("iterations"),
            "initial_trial_porosity": res.get("initial_trial_porosity"),
            "particle_count": res.get("particle_count"),
            "message": res.get("message") or r.error,
        }
        pts.append(pt)
    pts.sort(key=lambda p: -p["n_lab"])  # loose to dense
    return _relation(pts, n_max, n_min, "paper")


def _stats(values: list[float]) -> tuple[float, float]:
    """Mean and sample standard deviation (0 for one value, NaN for none)."""
    a = np.asarray(values, dtype=float)
    if a.size == 0:
        return math.nan, math.nan
    return float(a.mean()), float(a.std(ddof=1)) if a.size > 1 else 0.0


def analyse_states(rows: list[CaseRow | LostCaseRow | dict], targets: list, cal, n_max: float,
                   n_min: float) -> RelationResult:  # fmt: skip
    """Density-controlled relation: one point per laboratory state, mean and spread over seeds.

    ``n2d_dem`` is the mean accepted n2D of the seeds whose criterion converged (the
    criterion's answer, on its trial grid); ``n2d_measured`` the mean measured porosity
    n' of those accepted trials. Seeds that did not converge are counted, not averaged.
    """
    by_lab: dict[float, list[CaseRow | LostCaseRow]] = {}
    for r in map(case_row, rows):
        n_lab = float_or_nan((r.params or {}).get("criterion.n_lab"))
        by_lab.setdefault(round(n_lab, 6), []).append(r)
    pts = []
    for t in targets:
        group = by_lab.get(round(t.n_lab, 6), [])
        ok = [r for r in group if r.status == "done" and (r.results or {}).get("converged")]
        acc = [float_or_nan(r.results["final_porosity"]) for r in ok]
        meas = [float_or_nan(r.results["last_new_porosity"]) for r in ok]
        inner = [float_or_nan(r.results.get("interior_porosity")) for r in ok]
        mean, sd = _stats(acc)
        m_mean, m_sd = _stats(meas)
        i_mean, i_sd = _stats(inner)
        pts.append({
            "n_lab": t.n_lab,
            "relative_density": t.relative_density,
            "degree_of_density": float(P.degree_of_density(t.n_lab, n_max, n_min)),
            "n2d_target": t.n2d_target,
            "mu_prep": t.mu_prep,
            "n2d_dem": mean,
            "n2d_sd": sd,
            "n2d_seeds": acc,
            "n2d_measured": m_mean,
            "n2d_measured_sd": m_sd,
            "n2d_interior": i_mean,
            "n2d_interior_sd": i_sd,
            "n2d_interior_seeds": inner,
            "seeds": len(group),
            "seeds_converged": len(ok),
            "converged": len(ok) > 0,
            "flag": "" if group and len(ok) == len(group) else f"{len(group) - len(ok)} seed(s) unconverged",
            "message": "; ".join(str((r.results or {}).get("message") or r.error)
                                 for r in group if not any(r is o for o in ok)),
        })  # fmt: skip
    pts.sort(key=lambda p: -p["n_lab"])
    good = [p for p in pts if p["converged"]]
    spread = None
    if len(good) >= 2:
        loose, dense = good[0], good[-1]
        spread = {
            "loose_n_lab": loose["n_lab"],
            "dense_n_lab": dense["n_lab"],
            "n2d_loose_minus_dense": loose["n2d_dem"] - dense["n2d_dem"],
            "sd": math.hypot(loose["n2d_sd"], dense["n2d_sd"]),
            "monotone": all(a["n2d_dem"] >= b["n2d_dem"] for a, b in zip(good, good[1:], strict=False)),
            # the same for the interior porosity (the packing's own, no gap under the plate)
            "interior_loose_minus_dense": loose["n2d_interior"] - dense["n2d_interior"],
            "interior_sd": math.hypot(loose["n2d_interior_sd"], dense["n2d_interior_sd"]),
            "interior_monotone": all(
                a["n2d_interior"] >= b["n2d_interior"] for a, b in zip(good, good[1:], strict=False)
            ),
        }
    return _relation(pts, n_max, n_min, "density", calibration=cal.to_dict(), n2d_max=cal.n2d_max,
                     n2d_min=cal.n2d_min, spread=spread)  # fmt: skip


def _relation(pts: list[dict], n_max: float, n_min: float, mode: str, **extra: Any) -> RelationResult:
    """The relation of the points (loose to dense): each point's conversions compared, the Eq. 12-form
    fit through the converged ones, each point's residual, and ``extra`` keys after ``mode``."""
    for p in pts:
        conv = P.convert_all(p["n_lab"], n_max, n_min)
        p.update((f"n2d_{m}", conv.results[m].value) for m in COMPARE)
    good = [p for p in pts if p["converged"] and math.isfinite(p["n2d_dem"])]
    fit: QuadraticFit | None = None
    note = ""
    try:
        fit = fit_quadratic_origin([p["n_lab"] for p in good], [p["n2d_dem"] for p in good])
    except InputError:
        note = f"no fit: {len(good)} converged point(s); at least two distinct nLab are needed"
    for p in pts:
        if fit is not None and math.isfinite(p["n2d_dem"]):
            p["n2d_fit"] = fit.a * p["n_lab"] ** 2 + fit.b * p["n_lab"]
            p["residual"] = p["n2d_dem"] - p["n2d_fit"]
        else:
            p["n2d_fit"] = None
            p["residual"] = None
        p["dem_minus_parabola"] = p["n2d_dem"] - p["n2d_parabolic"] if math.isfinite(p["n2d_dem"]) else None
    return RelationResult.from_dict({
        "n_max": n_max,
        "n_min": n_min,
        "points": pts,
        "fit": fit,
        "fit_note": note
        or f"fitted to the {len(good)} converged point(s); non-converged points are shown only",
        "eq12": Eq12Coefficients(a=0.42, b=0.25),
        "converged_points": len(good),
        "flagged_points": len(pts) - len(good),
        "mode": mode,
        **extra,
    })  # fmt: skip


def write_relation(rel: RelationResult, store: Store) -> list[Path]:
    """relation.csv and relation.json in ``store`` (the figures, relation.png and relation.svg, are
    drawn from the result by ``draw_relation`` (``report/relation_figure.py``))."""
    # a seed's missing number is None (NaN as the file keeps it): written as NaN was
    flat = [{k: " ".join(f"{float_or_nan(x):.4f}" for x in v) if isinstance(v, list) else v
             for k, v in p.to_dict().items()} for p in rel.points]  # fmt: skip
    table = store.write_csv("relation.csv", flat)
    record = rel.to_dict()
    record.setdefault("provenance", Provenance.now().to_dict())  # a finished relation carries its own
    file = store.write_json("relation.json", record)
    return [table, file]


def density_relation(
    base: CriterionBase,
    settings: RelationSettings,
    store: Store,
    *,
    quick: bool = False,
    seeds: int = 3,
    mus=None,
    use_cache: bool = True,
    options: RunOptions = RunOptions(),
    replacements: int = 0,
    announce=None,
) -> tuple[RelationResult, DensitySweeps]:
    """The density-controlled relation: calibrate, map every state, check it over seeds.

    ``base``: the criterion config as read; ``settings``: from :func:`relation_settings`;
    ``store``: where the calibration's record and the states' sweep are kept (the
    calibration's cases in the shared cache with ``use_cache``); ``options``: where the jobs run
    and whether bars show (:class:`~poro2d.execute.options.RunOptions`). ``replacements``: while a
    state has fewer than ``seeds`` accepted, the next seeds are run (for every state), this many
    at most, each round said through ``announce`` (the relation's states keep 0: none). Returns
    the analysed relation and a record of the two sweeps (calibration source, summaries; with a
    replacement tried, ``seeds_used`` and ``seeds_replaced``: one state's seeds).
    """
    announce = announce or (lambda _text: None)
    from poro2d.criterion.density import DEFAULT_MUS, state_target
    from poro2d.criterion.protocol import trial_grid
    from poro2d.sweep import density as D
    from poro2d.sweep.runner import run_sweep

    states_base = D.with_density_defaults(relation_base(base, quick=quick))
    calibration = D.CalibrationCase(states_base, tuple(mus or DEFAULT_MUS), seeds)
    cal, cal_info = D.calibrate(calibration, store, use_cache=use_cache, options=options)
    targets = tuple(state_target(n, settings.n_max, settings.n_min, cal) for n in settings.n_lab)
    crit = states_base.table("criterion")
    # the first trial on the grid the criterion steps on: half the refined tolerance, else the resolution
    resolution = trial_grid(float(crit.get("resolution", 0.01)), crit.get("refine_tolerance"))

    def checked(tried: int):
        """The state checks of seeds 0 .. tried - 1: those the calibration ran read back, the rest run."""
        sweep = D.StateChecks(states_base, targets, tried, resolution).sweep
        twins = D.calibration_twins(calibration.sweep, sweep, base.base_dir, Store(cal_info.cases))
        rows, summary, failed = twins, {"ran": 0, "reused": 0}, []
        if len(twins) < len(sweep.cases):
            twin_ids = {row.case_id for row in twins}
            left = replace(sweep, cases=[c for c in sweep.cases if c.id not in twin_ids])
            res = run_sweep(left, store.child("states"), options=options)
            rows, summary, failed = res.rows + rows, res.summary.to_dict(), res.failed
        return rows, dict(summary, from_calibration=len(twins)), failed

    tried = seeds
    rows, summary, failed = checked(tried)
    while (more := min(seeds - least_accepted(rows, targets), seeds + replacements - tried)) > 0:
        announce(replacing_text(rows, range(tried, tried + more)))
        tried += more
        rows, summary, failed = checked(tried)  # the finished seeds read back, the new ones run
    rel = analyse_states(rows, list(targets), cal, settings.n_max, settings.n_min)
    record = {
        "calibration": cal_info,
        "states_summary": summary,
        "failed_cases": len(failed) + cal_info.failed,
    }
    if tried > seeds:
        record |= seeds_record(rows, seeds)
    return rel, DensitySweeps.from_dict(record)


def case_seed(row: CaseRow | LostCaseRow) -> int:
    """The seed a criterion case ran."""
    return int((row.params or {}).get("seed", 0))


def seed_accepted(row: CaseRow | LostCaseRow) -> bool:
    """Whether a seed's criterion case ended with an accepted specimen."""
    return row.status == "done" and bool((row.results or {}).get("converged"))


def least_accepted(rows, targets) -> int:
    """The fewest accepted seeds of any state of ``targets``."""
    by_lab = [round(float_or_nan((r.params or {}).get("criterion.n_lab")), 6) for r in rows]
    return min((sum(seed_accepted(r) for r, n in zip(rows, by_lab, strict=True) if n == round(t.n_lab, 6))
                for t in targets), default=0)  # fmt: skip


def replacing_text(rows, more) -> str:
    """The seeds not accepted, each with why, and those tried in their place."""
    refused = sorted((r for r in rows if not seed_accepted(r)), key=case_seed)
    why = "; ".join(f"seed {case_seed(r)}: {refusal_reason(r)}" for r in refused)
    return f"seed(s) not accepted ({why}): trying seed(s) {', '.join(map(str, more))} in their place"


def refusal_reason(row: CaseRow | LostCaseRow) -> str:
    """Why a seed's case gave no specimen: the criterion's message, else the case's error."""
    return str((row.results or {}).get("message") or row.error or row.status)


def seeds_record(rows, requested: int) -> dict:
    """``seeds_used`` and ``seeds_replaced`` of a single state's checks (seeds from 0, the ones at
    or past ``requested`` tried in place of those refused, in order)."""
    ordered = sorted(rows, key=case_seed)
    extra = [case_seed(r) for r in ordered if case_seed(r) >= requested]
    refused = [r for r in ordered if not seed_accepted(r)]
    by = extra + [None] * (len(refused) - len(extra))
    return {
        "seeds_used": [case_seed(r) for r in ordered if seed_accepted(r)],
        "seeds_replaced": [
            {"seed": case_seed(r), "reason": refusal_reason(r), "replaced_by": b}
            for r, b in zip(refused, by, strict=False)
        ],
    }


def relation_state(table, base: CriterionBase, settings: RelationSettings, mode: str):
    """The ``[state]`` table checked against the relation's disks and extremes (None without one):
    the state-parameter map beside every state's answer (:mod:`poro2d.critical_state.state_table`)."""
    from poro2d.critical_state.state_table import state_request
    from poro2d.lab_state import lab_state_from_table

    if table is None:
        return None
    if mode != "density":
        raise InputError("state", "a [state] table", "density mode only (paper mode has no 2D extremes)")
    spec, grading, _settings, _seed = base.build()
    ends = lab_state_from_table({"n_max": settings.n_max, "n_min": settings.n_min, "n": settings.n_max})
    return state_request(table, ends, base.base_dir, spec.friction_particle, spec.rolling_friction, grading)


def state_maps(state, rel: RelationResult, settings: RelationSettings, base: CriterionBase) -> list[dict]:
    """Both maps of every state of ``rel`` at the ``[state]`` stress (rows of ``state_maps``)."""
    from poro2d.critical_state.state_table import state_map_record
    from poro2d.lab_state import lab_state_from_table

    source = base.build()[1].source
    return [
        state_map_record(
            state, lab_state_from_table({"n_max": settings.n_max, "n_min": settings.n_min, "n": p.n_lab}),
            rel.n2d_max, rel.n2d_min, p.n2d_target, source,
        ).to_dict()
        for p in rel.points
    ]  # fmt: skip


def refuse_density_options(table: dict, seeds: int | None) -> None:
    """Paper mode prepares every state at friction_prep, once: seeds and frictions would be ignored."""
    if seeds is not None:
        raise InputError("--seeds", seeds, "only in density mode (paper mode runs each state once)")
    for key in ("seeds", "mu_prep"):
        if key in table:
            raise InputError(f"relation.{key}", table[key], "only in density mode (paper mode: leave it out)")


@dataclass(frozen=True)
class RelationCase:
    """A relation checked and built, before anything runs (:meth:`from_config`).

    ``config``: the config as loaded (kept in ``relation.json``); ``base``: its criterion
    config, without ``[state]``; ``settings``: the extremes and the states; ``mode``:
    density or paper; ``quick``: the small box; ``seeds``, ``mus``: density mode's specimens
    per state and calibration frictions (None: the defaults); ``state``: the ``[state]``
    request (None without one); ``states``: paper mode's sweep, every case built.
    """

    config: dict
    base: CriterionBase
    settings: RelationSettings
    mode: str
    quick: bool
    states: SweepConfig
    seeds: int | None = None
    mus: list[float] | None = None
    state: Any = None

    @classmethod
    def from_config(cls, config=None, *, preset: str | None = None, points: int | None = None,
                    n_max: float | None = None, n_min: float | None = None, mode: str | None = None,
                    seeds: int | None = None, quick: bool = False) -> RelationCase:  # fmt: skip
        """The case of ``poro2d relation``: ``config`` (a dict, a TOML file, or the paper preset
        when None) with an optional ``[relation]`` table, which the keyword options override;
        every input checked (InputError if not)."""
        from poro2d.criterion.density import check_mus
        from poro2d.criterion.run import load
        from poro2d.sweep.density import check_seeds

        cfg, base_dir = load(config, preset, extra_tables=("relation", "state"))
        # [state] reads the relation's answers; the criterion cases never see it
        base = CriterionBase.from_config({k: v for k, v in cfg.items() if k != "state"}, base_dir)
        table = cfg.get("relation") or {}
        settings = relation_settings(
            table or None, points=points, n_max=n_max, n_min=n_min, preset=config is None
        )
        mode = check_mode(mode if mode is not None else table.get("mode", "density"))
        state = relation_state(cfg.get("state"), base, settings, mode)
        n_seeds = mus = None
        if mode == "density":
            n_seeds = check_seeds(seeds if seeds is not None else table.get("seeds", 3), "relation.seeds")
            mus = check_mus(table["mu_prep"], "relation.mu_prep") if "mu_prep" in table else None
        else:
            refuse_density_options(table, seeds)
        # every criterion case of the relation built once, without running: a bad specimen, grading
        # or criterion setting is refused before the calibration starts, not when its case comes up
        states = relation_sweep(relation_base(base, quick=quick), settings.n_lab)
        return cls(cfg, base, settings, mode, bool(quick), states, n_seeds, mus, state)


def run_relation(
    case: RelationCase, store: Store | None = None, *, options: RunOptions = RunOptions(), announce=None
) -> RelationResult:
    """``poro2d relation`` as one call: the grading's n2D(nLab) relation, written to ``store``.

    ``case``: the relation's :class:`RelationCase`. Density mode (the default) calibrates the
    grading, maps every laboratory state by its relative density and checks it over the
    case's seeds; paper mode runs the criterion once per state at the fixed preparation
    friction. Returns the :class:`RelationResult` written to ``relation.json``; its
    ``failed_cases`` counts the cases that raised (their tracebacks are in ``store``; None:
    nothing is kept but the shared calibration cache). ``announce`` (no arguments) is called
    once the folder and the scheduler are checked, before any work (the command prints its
    banner there, so a refusal stays one line). ``options``: where the jobs run and whether
    bars show (:class:`~poro2d.execute.options.RunOptions`).
    """
    from poro2d.sweep.runner import run_sweep

    extra: dict[str, Any] = {"quick": case.quick}
    with study_store(store, "relation", options, announce) as kept:
        if case.mode == "density":
            rel, record = density_relation(case.base, case.settings, kept, quick=case.quick, seeds=case.seeds,
                                           mus=case.mus, options=options)  # fmt: skip
            extra.update(config=case.config, sweeps=record)
            if case.state is not None:
                extra["state_maps"] = state_maps(case.state, rel, case.settings, case.base)
        else:
            res = run_sweep(case.states, kept, options=options)
            rel = analyse(res.rows, case.settings.n_max, case.settings.n_min)
            extra.update(sweep_summary=res.summary, config=case.config)
        result = RelationResult.from_dict(dict(rel.to_dict(), **extra, provenance=Provenance.now().to_dict()))
        write_relation(result, kept)
    return result
