"""Density-controlled criterion runs on the sweep runner: calibration and state checks.

The calibration runs the criterion at every preparation friction of a list, for several
seeds (a grid sweep over ``specimen.friction_prep`` and ``seed``); each case's measured
porosity n' of its accepted trial (the box porosity with the plate just touching) is
one sample of mu_prep -> n2D. It is resumable in its own folder and cached per grading
and settings (:func:`cache_dir`), so the relation and single criterion runs share it.

The state checks run the criterion once per laboratory state and seed, with the
preparation friction that the calibration gives for the state's 2D target
(:func:`poro2d.criterion.density.state_target`) and that target as the first trial.
"""

from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass, replace
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from poro2d import __version__
from poro2d.criterion.density import DEFAULT_MUS, Calibration, StateTarget, check_mus
from poro2d.criterion.settings import CriterionSettings
from poro2d.errors import check_int
from poro2d.execute.options import RunOptions
from poro2d.identity import identity_digest, outside_fields
from poro2d.io_utils import Provenance
from poro2d.locks import cache_entry
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.store import Store
from poro2d.sweep.cases import Case, SweepConfig, criterion_objects, grading_by_content, grid_cases
from poro2d.sweep.criterion_base import CriterionBase
from poro2d.sweep.records import CaseRow, LostCaseRow, case_row
from poro2d.sweep.results import CalibrationRun

#: seeds per friction and per state unless the config says otherwise
DEFAULT_SEEDS = 3
#: settings that change the calibration; n_lab and the first trial do not
_CRITERION_KEYS_IGNORED = ("n_lab", "trial_porosity")
#: first trial of every calibration case under the paper's plate: the middle of the 2D range of
#: polydisperse disks (about 0.16 dense to 0.23 loose), whatever the laboratory porosity
CALIBRATION_FIRST_TRIAL = 0.19
#: first trials under the fill acceptance, per preparation friction (mu_prep, n2D): the porosity
#: under the lid that the paper grading's calibration accepted when every case started from 0.19
#: (mean over three seeds), linear in between. A trial far from the answer costs most of a case:
#: 0.19 is too loose for a frictionless preparation (its layers take 1 000 000 steps to settle,
#: 260 000 at the answer) and too dense for mu_prep 1.0 (the plate and lid then take 640 000
#: steps, 320 000 at the answer). A grading that packs otherwise starts further from its answer
#: (the trials still converge to it, in more steps). Above 1.0 the accepted n' under the lid
#: from first trials near it (benchmarks/loose_states.py --full, docs/criterion.md): 0.2208 on
#: both seeds of four accepted at 2.0 (from 0.222), 0.2220 over four seeds at 5.0 (0.2211-0.2231,
#: from 0.224; from 0.222 every seed was accepted too, at 0.2201-0.2211); beyond the last point
#: the table stays flat (np.interp).
FILL_FIRST_TRIALS = (
    (0.0, 0.163), (0.05, 0.171), (0.1, 0.176), (0.2, 0.185), (0.5, 0.202), (1.0, 0.216),
    (2.0, 0.221), (5.0, 0.222),
)  # fmt: skip
#: the paper grading's frictionless jamming porosity (docs/jamming.md: 0.1532 +- 0.0012), the dense
#: end ``FILL_FIRST_TRIALS`` sits above. Another grading's table is this one moved by the difference
#: of the two jamming porosities (:func:`first_trial` with ``dense_end``): the preparation's dense
#: end follows the grading's jamming porosity (0.001-0.007 above it on every grading tried), while
#: the rise with friction and the walls' share change far less between sands.
PAPER_JAMMING_POROSITY = 0.1532
#: two measured ends of a calibration, ((mu_lo, n_lo), (mu_hi, n_hi)): frictions and accepted n'
MeasuredEnds = tuple[tuple[float, float], tuple[float, float]]
#: the share of ``FILL_FIRST_TRIALS``' dense end above the jamming porosity (0.163 - 0.1532) that
#: the loose layer along the walls adds in the paper's box; it scales with the walls' length over
#: the box's area times d50 (:func:`wall_share`): 0.0098 / (22.7 m^-1 x 4.44 mm)
WALL_SHARE_PER_D50 = 0.0098 / ((2 * 0.305 + 2 * 0.124) / (0.305 * 0.124) * 4.4366e-3)


def wall_share(width: float, height: float, d50: float) -> float:
    """What the walls (bottom, sides, lid) add to a box's porosity n' at the dense end.

    A loose layer about half a grain thick lines every wall, so its share of the box is the
    walls' length over the area times d50, with the coefficient measured on the paper's box
    (``WALL_SHARE_PER_D50``): 0.0098 there, 0.025 in a box of 46 x 23 mm with d50 = 2 mm.
    """
    return WALL_SHARE_PER_D50 * (2.0 * width + 2.0 * height) / (width * height) * d50


#: the paper box's share, the one the table's values hold
PAPER_WALL_SHARE = 0.0098


#: settings density mode uses unless the config sets them: trials refined to 0.002 (the paper's
#: 0.01 grid gives a 0.02 loose-to-dense series three values) and layers that end once settled
#: (low-friction layers creep at a ratio of 1e-2 for hundreds of thousands of steps while their
#: density no longer changes; docs/criterion.md has the measurements)
DENSITY_DEFAULTS = {
    "specimen": {"settle_drift": 1e-3},
    # the lid's n' is the porosity of the box the specimen fills (poro2d.criterion.lid); the lid
    # bears on every surface grain where the paper's plate bears on one or two, and on a loose
    # frictional surface rests at 1 to 2 % of G: its window is 2 % (docs/criterion.md)
    "criterion": {
        "refine_tolerance": 0.002,
        "max_iterations": 10,
        "acceptance": "fill",
        "force_fraction": 0.02,
    },
}


def with_density_defaults(base: CriterionBase) -> CriterionBase:
    """``base`` with ``DENSITY_DEFAULTS`` filled in where its config is silent."""
    return base.with_defaults(DENSITY_DEFAULTS)


def cache_dir() -> Path:
    """Where calibrations are kept: ``$PORO2D_CACHE``, else the user's cache folder."""
    env = os.environ.get("PORO2D_CACHE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "poro2d"


def check_seeds(seeds: Any, parameter: str = "density.seeds") -> int:
    """Specimens per state or per case, the sweeps' seeds: an integer in [1, 50]."""
    return check_int(parameter, seeds, 1, 50)


def calibration_base(base: CriterionBase) -> CriterionBase:
    """The parts of a criterion base that fix a calibration (no n_lab, no first trial)."""
    # friction_prep is the calibration's own axis; the marked fields change no result
    left_out = ("friction_prep", *outside_fields(SpecimenSpec))
    spec = {k: v for k, v in base.table("specimen").items() if k not in left_out}
    crit = {k: v for k, v in base.table("criterion").items() if k not in _CRITERION_KEYS_IGNORED}
    grading = base.config.get("grading") or {"preset": "paper"}
    return CriterionBase({"specimen": spec, "grading": grading, "criterion": crit}, base.base_dir)


#: the revision of the criterion's preparation that a cached calibration was made with, raised
#: when a change moves its cases' results: 2, the creeping lid of frictional fill preparations
#: (docs/criterion.md), whose loose-end cases differ from those of the chattering lid before it;
#: 3, the creeping lid accepted at a creeping packing's ratio (criterion.lid.CREEP_RATIO); 4, the
#: fines of a very wide grading grown frictionless (specimen.compaction.growing_fines); 5, a very
#: wide grading's layers grown in increments finer than its finest disk
#: (specimen.compaction.growth_increments)
CALIBRATION_REVISION = 5


def calibration_key(base: CriterionBase) -> str:
    """The run digest of the calibration's cases: grading, box, contact and criterion settings,
    the poro2d version and the preparation's revision (another version or revision may compute
    another criterion, so a calibration cached before it is not read back).

    Spaced as these keys were first written, so cached calibrations keep their folders.
    """
    rec = {"base": calibration_base(base).as_config(), "version": __version__}
    rec["base"]["grading"] = grading_by_content(rec["base"]["grading"], base.base_dir)
    rec["revision"] = CALIBRATION_REVISION
    tables = {"base.specimen": SpecimenSpec, "base.criterion": CriterionSettings}
    return identity_digest(rec, tables=tables, length=16, layout="spaced")


def bracket_first_trial(criterion: dict, mu: float, ends: MeasuredEnds) -> float:
    """The first trial at a friction between two measured ends: on the loose side of its answer.

    ``ends``: ((mu_lo, n_lo), (mu_hi, n_hi)), the accepted n' of the densest and loosest
    preparations. ``mu`` gets the share between them that ``FILL_FIRST_TRIALS`` gives it between
    the same frictions, plus the criterion's acceptance tolerance, rounded to its grid. A trial
    looser than the friction packs costs a preparation and a short lid; a denser one over-fills
    the box, and the plate and then the lid take 100 000-300 000 steps to let it swell (Toyoura
    sand's calibration box: 53 and 101 s at mu_prep 0.05 from 0.171, its answer 0.172-0.174).
    The table's shape puts a friction's answer 0.001-0.003 below the measured one on the gradings
    tried, so the tolerance on top lands the trial just looser, often within the tolerance.
    """
    from poro2d.criterion.protocol import CriterionSettings, round_to

    (mu_lo, n_lo), (mu_hi, n_hi) = ends
    t_lo, t_mu, t_hi = (_table_trial(m) for m in (mu_lo, mu, mu_hi))
    # the table is flat beyond its last friction: halfway between ends that lie there
    share = (t_mu - t_lo) / (t_hi - t_lo) if t_hi > t_lo else 0.5
    refine = criterion.get("refine_tolerance")
    paper = criterion.get("porosity_tolerance", CriterionSettings.porosity_tolerance)
    tol = float(paper if refine is None else refine)
    return round_to(n_lo + share * (n_hi - n_lo) + tol, _trial_grid(criterion))


def _table_trial(mu: float) -> float:
    """``FILL_FIRST_TRIALS`` at ``mu`` (linear between its frictions, flat beyond them)."""
    mu_ref, n_ref = zip(*FILL_FIRST_TRIALS, strict=True)
    return float(np.interp(mu, mu_ref, n_ref))


def _trial_grid(criterion: dict) -> float:
    """The grid the criterion table ``criterion`` steps its trials on (:func:`trial_grid`)."""
    from poro2d.criterion.protocol import CriterionSettings, trial_grid

    resolution = float(criterion.get("resolution", CriterionSettings.resolution))
    return trial_grid(resolution, criterion.get("refine_tolerance"))


def first_trial(
    criterion: dict,
    mu: float,
    dense_end: float | None = None,
    walls: float | None = None,
    loose_bias: float = 0.0,
) -> float:
    """The first trial of the calibration case at preparation friction ``mu``.

    Under the paper's plate every case starts at ``CALIBRATION_FIRST_TRIAL``; under the fill
    acceptance at the porosity ``FILL_FIRST_TRIALS`` gives for ``mu``, rounded to the grid the
    criterion steps on (``criterion``: the calibration's criterion table). ``dense_end``: the
    grading's own frictionless jamming porosity (:mod:`poro2d.oracles.jamming`); the table is
    then moved by its difference from the paper grading's (``PAPER_JAMMING_POROSITY``), and
    ``walls`` (the box's :func:`wall_share`) by its difference from the paper box's.
    ``loose_bias`` x ``mu`` is added on top: a frictional preparation prepared denser than it
    packs by itself is over-compressed under the lid, which then may not settle (a start on the
    loose side lets the lid come down onto the specimen instead).
    """
    from poro2d.criterion.protocol import round_to

    if criterion.get("acceptance", "plate") != "fill":
        return CALIBRATION_FIRST_TRIAL
    n = _table_trial(mu)
    if dense_end is not None:
        n += float(dense_end) - PAPER_JAMMING_POROSITY
    if walls is not None:
        n += float(walls) - PAPER_WALL_SHARE
    return round_to(n + loose_bias * mu, _trial_grid(criterion))


@dataclass(frozen=True)
class CalibrationCase:
    """The calibration of one grading and box, as a value: every friction with every seed.

    ``base``: the criterion base the calibration is of (density mode's defaults filled in);
    a study that wants other frictions or seeds of the same calibration varies it with
    :func:`dataclasses.replace`, and finds the cases already run in the same cache entry
    (:attr:`key`). ``dense_end`` (the grading's jamming porosity) and ``walls`` (the box's
    :func:`wall_share`) move the first trials (:func:`first_trial`); ``loosest_first`` lists
    the most frictional cases first: they take longest (their lid waits for a creeping
    surface), so the workers start them first and fill in with the quick dense ones.
    ``ends``: the accepted n' of the two end frictions, once measured: the frictions between
    them then start from :func:`bracket_first_trial` (the ends keep their own first trials, so
    their cases are the ones already run). ``first_seed``: the seeds run at every friction are
    ``first_seed`` and the ``seeds - 1`` after it, so a calibration from another first seed is an
    independent sample of the same grading (its cases share the cache entry: the seed is a case's
    parameter, not part of the key).
    """

    base: CriterionBase
    mus: tuple[float, ...] = DEFAULT_MUS
    seeds: int = DEFAULT_SEEDS
    dense_end: float | None = None
    walls: float | None = None
    loose_bias: float = 0.0
    loosest_first: bool = False
    ends: MeasuredEnds | None = None
    first_seed: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "mus", tuple(check_mus(list(self.mus))))
        object.__setattr__(self, "seeds", check_seeds(self.seeds))
        object.__setattr__(self, "first_seed", check_int("seed", self.first_seed, 0, 2**31 - 1))

    @property
    def seed_list(self) -> list[int]:
        """The seeds run at every friction, in order."""
        return list(range(self.first_seed, self.first_seed + self.seeds))

    @property
    def key(self) -> str:
        """The digest naming the calibration's cache entry (:func:`calibration_key`)."""
        return calibration_key(self.base)

    @cached_property
    def sweep(self) -> SweepConfig:
        """The calibration's criterion cases, each friction from its first trial.

        Under the paper's plate a grid (one first trial for all); under the fill acceptance a
        list of cases, each friction from its own first trial (:func:`first_trial`).
        """
        tables = calibration_base(self.base)
        threads = self.base.table("specimen").get("threads")
        if threads is not None:
            tables = tables.with_tables(specimen=dict(tables.table("specimen"), threads=threads))
        table: dict[str, Any] = {"kind": "criterion", "title": "mu_prep -> n2D calibration"}
        crit = tables.table("criterion")
        if crit.get("acceptance", "plate") != "fill":
            grid = {"specimen.friction_prep": list(self.mus), "seed": self.seed_list}
            tables = tables.with_tables(criterion=dict(crit, trial_porosity=CALIBRATION_FIRST_TRIAL))
            return tables.sweep(dict(table, **grid), grid_cases(grid))
        firsts = {mu: self.first_trial(crit, mu) for mu in self.mus}
        order = sorted(self.mus, reverse=True) if self.loosest_first else self.mus
        cases = [
            {"specimen.friction_prep": mu, "criterion.trial_porosity": firsts[mu], "seed": s}
            for mu in order
            for s in self.seed_list
        ]
        return tables.sweep(dict(table, cases=cases), cases)

    def first_trial(self, crit: dict, mu: float) -> float:
        """The first trial of the cases at ``mu`` under the fill acceptance (:attr:`sweep`)."""
        if self.ends is not None and self.ends[0][0] < mu < self.ends[1][0]:
            return bracket_first_trial(crit, mu, self.ends)
        return first_trial(crit, mu, self.dense_end, self.walls, self.loose_bias)


Seeds = int | list[int] | tuple[int, ...]


def _seed_list(seeds: Seeds) -> list[int]:
    """The calibration's seeds in order: ``range(seeds)`` for a count, else the list given."""
    return list(range(seeds)) if isinstance(seeds, int) else [int(s) for s in seeds]


def _per_friction(rows: list, mus: list[float], seeds: Seeds, key: str) -> list[list[float | None]]:
    """The results' ``key`` of every accepted calibration case (its n' measured), per friction and
    seed (``seeds``: a count from 0, or the seeds in order); None for a case not accepted or not
    there, or a value that is not a number. Rows of other seeds are left out."""

    def finite(v: Any) -> float | None:
        return float(v) if v is not None and math.isfinite(float(v)) else None

    order = {s: k for k, s in enumerate(_seed_list(seeds))}
    out: list[list[float | None]] = [[None] * len(order) for _ in mus]
    for r in map(case_row, rows):
        p, res = r.params or {}, r.results or {}
        k = order.get(int(p["seed"]))
        if k is None or r.status != "done" or not res.get("converged"):
            continue
        if finite(res.get("last_new_porosity")) is not None:
            out[mus.index(float(p["specimen.friction_prep"]))][k] = finite(res.get(key))
    return out


def interior_by_friction(rows: list[CaseRow | LostCaseRow | dict], mus: list[float],
                         seeds: Seeds) -> list[list[float | None]]:  # fmt: skip
    """The interior porosity of every calibration case's accepted specimen, per friction and seed.

    Beside the calibration's samples (box porosities n'), the packing's own porosity: at the
    lowest friction it is the dense end to hold against the grading's jamming porosity.
    """
    return _per_friction(rows, mus, seeds, "interior_porosity")


def calibration_from_rows(
    rows: list[CaseRow | LostCaseRow | dict], mus: list[float], seeds: Seeds
) -> Calibration:
    """mu_prep -> n2D: the measured porosity n' of every case's accepted trial, per friction and
    seed (``seeds``: a count from 0, or the seeds in order)."""
    return Calibration(list(mus), _per_friction(rows, mus, seeds, "last_new_porosity"), _seed_list(seeds))


def calibration_store(case: CalibrationCase, store: Store, *, use_cache: bool = True) -> Store:
    """Where the calibration's cases live: the shared cache entry, else ``calibration`` in ``store``.

    A cache that cannot be written (read-only) sends the cases to ``store`` too.
    """
    if not use_cache:
        return store.child("calibration")
    entry = Store(cache_dir() / "calibrations" / case.key)
    try:
        entry.root.mkdir(parents=True, exist_ok=True)
    except OSError:
        return store.child("calibration")
    return entry


def calibrate(
    case: CalibrationCase,
    store: Store,
    *,
    use_cache: bool = True,
    record: str = "calibration.json",
    options: RunOptions = RunOptions(),
    client=None,
) -> tuple[Calibration, CalibrationRun]:
    """The grading's calibration, its cases run on the sweep runner (resumable).

    With ``use_cache`` the cases live in a folder shared by every run of the same grading and
    settings (:func:`cache_dir` / ``calibrations`` / key): a case done once, for any list of
    frictions or number of seeds, is read back, not run again. Without it they go to
    ``calibration`` in ``store``. ``record`` (in ``store``) records the calibration and where
    its cases are. ``options``: where the jobs run and whether bars show
    (:class:`~poro2d.execute.options.RunOptions`), ``client``: an existing Dask client instead
    (:func:`~poro2d.sweep.runner.run_sweep`). Returns the calibration and a record (key, folder,
    how many cases ran).
    """
    from poro2d.sweep.runner import run_sweep

    mus, seeds = list(case.mus), case.seed_list
    cases = calibration_store(case, store, use_cache=use_cache)
    # another run of the same grading may be computing this entry: wait, then reuse its cases
    with cache_entry(cases.root):
        res = run_sweep(case.sweep, cases, options=options, client=client)
    cal = calibration_from_rows(res.rows, mus, seeds)
    ran, reused = res.summary.ran, res.summary.reused
    info = {"key": case.key, "cases": str(cases.root), "ran": ran, "reused": reused,
            "source": "computed" if ran else "cache"}  # fmt: skip
    # the interior porosities for new callers only (the grading's dense end or the box's walls move
    # their first trials): earlier records keep their keys
    if case.dense_end is not None or case.walls is not None:
        info["interior"] = interior_by_friction(res.rows, mus, seeds)
    rec = {
        **info,
        "calibration": cal.to_dict(),
        "settings": calibration_base(case.base).as_config(),
        "sample": "n' of the accepted trial: box porosity, whole disk areas, plate just touching",
        "sweep_summary": res.summary,
        "provenance": Provenance.now().to_dict(),
    }
    store.write_json(record, rec)
    return cal, CalibrationRun.from_dict(dict(info, summary=res.summary, failed=len(res.failed)))


@dataclass(frozen=True)
class StateChecks:
    """The criterion once per laboratory state and seed, at the state's friction, from its target.

    ``base``: the criterion base of the states (density mode's defaults filled in);
    ``resolution``: the grid the first trials are rounded to (the one the criterion steps on);
    ``first_seed``: the seeds run are ``first_seed`` and the ``seeds - 1`` after it.
    """

    base: CriterionBase
    targets: tuple[StateTarget, ...]
    seeds: int
    resolution: float
    first_seed: int = 0

    @cached_property
    def sweep(self) -> SweepConfig:
        """One case per state and seed; the base's own first trial is left out (each case has one)."""
        from poro2d.criterion.protocol import round_to

        base = self.base.without("relation", "sweep", "density")
        crit = base.table("criterion")
        crit.pop("trial_porosity", None)
        cases = [
            {
                "criterion.n_lab": t.n_lab,
                "specimen.friction_prep": round(t.mu_prep, 6),
                "criterion.trial_porosity": round_to(t.n2d_target, self.resolution),
                "seed": s,
            }
            for t in self.targets
            for s in range(self.first_seed, self.first_seed + self.seeds)
        ]
        table = {"kind": "criterion", "title": "density-controlled states", "cases": cases}
        return base.with_tables(criterion=crit).sweep(table, cases)


def _run_key(case: Case, base_dir: Path | None) -> str:
    """The run digest of what a criterion case computes: specimen, grading, settings, seed.

    The objects the case builds are compared, not its config's text, so defaults spelled
    out or left implicit give the same key. nLab is left out: it only chooses the first
    trial when none is given, and every case here has one.
    """
    spec, grading, settings, seed = criterion_objects(case.config, base_dir)
    run = {"specimen": spec, "grading": [grading.sizes, grading.percent], "criterion": settings, "seed": seed}
    return identity_digest(run, ignore=("criterion.n_lab",))


def _check_key(case: Case, base_dir: Path | None) -> str:
    """What makes a calibration case a state's check: the run (:func:`_run_key`), and under the
    fill acceptance the run whatever its first trial.

    There each calibration case starts from its friction's expected answer
    (:func:`first_trial`), as a check starts from its target: at the same friction and seed
    both ask the criterion the same question from neighbouring first trials, and every trial
    is prepared afresh (seeded by its porosity), so the first trial only steers the search.
    """
    crit = case.config.get("criterion") or {}
    if crit.get("acceptance", "plate") != "fill":
        return _run_key(case, base_dir)
    config = dict(case.config, criterion={k: v for k, v in crit.items() if k != "trial_porosity"})
    return _run_key(replace(case, config=config, id=case.id), base_dir)


def calibration_twins(
    calibration: SweepConfig, states: SweepConfig, base_dir: Path | None, cases: Store
) -> list[CaseRow]:
    """Finished calibration cases that are state checks too, as rows of those checks.

    The check of the densest state (Dr = 1) runs at the calibration's lowest usable friction,
    that of the loosest (Dr = 0) at its highest: at a calibration friction, seed for seed,
    the same criterion run as a calibration case (:func:`_check_key`: under the paper's plate
    only from the same first trial). Whether two cases are the same run is decided on the
    specimen, grading and criterion settings they build, never assumed. ``cases``: the store
    of the calibration's sweep. Returns a row per state check that has a twin, in the order of
    ``states``: the calibration case's finished row relabelled with the check's id and parameters.
    """
    from poro2d.sweep.runner import finished_row

    done = {}
    for c in calibration.cases:
        row = finished_row(asdict(c), cases.child("cases", c.id))
        if row is not None:
            done[_check_key(c, base_dir)] = (c, row)
    twins = []
    for c in states.cases:
        hit = done.get(_check_key(c, base_dir))
        if hit is None:
            continue
        cal_case, row = hit
        results = dict(row.results or {}, n_lab=c.config["criterion"]["n_lab"])
        relabelled = dict(row.to_dict(), case_id=c.id, params=dict(c.params), results=results, reused=True,
                          reused_calibration_case=cal_case.id)  # fmt: skip
        twins.append(CaseRow.from_dict(relabelled))
    return twins


__all__ = [
    "DEFAULT_SEEDS",
    "PAPER_JAMMING_POROSITY",
    "PAPER_WALL_SHARE",
    "CalibrationCase",
    "StateChecks",
    "cache_dir",
    "calibrate",
    "calibration_base",
    "calibration_from_rows",
    "calibration_key",
    "calibration_store",
    "calibration_twins",
    "check_mus",
    "check_seeds",
    "first_trial",
    "interior_by_friction",
    "wall_share",
    "with_density_defaults",
]
