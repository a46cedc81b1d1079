"""The seven protocols of the conformance battery, each the smallest real case that runs in seconds.

A :class:`Protocol` says how to run its case through the public ``run_*`` call (with a store, or
with ``store=None``), which file its result is kept in and how it is read back, and one bad input
with the parameter its refusal must name. The checks themselves are in ``test_conformance.py``,
the same six for every row of :data:`PROTOCOLS`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from poro2d.execute import RunOptions
from poro2d.store import Store

#: the battery's runs: one process, no bars (the executor is made inline by the harness)
QUIET = RunOptions(workers=1, progress=False)

#: the criterion's small box (the tests' 0.05 m x 0.025 m, about 80 disks)
SMALL_BOX = {"width": 0.05, "height": 0.025, "layers": 2}
#: 1 mm of shear in the 60 mm box of the session's specimen, a checkpoint every 0.25 mm
SHORT_SHEAR = {"max_displacement": 0.001, "peak_window": 2.5e-4, "checkpoint_interval": 2.5e-4}


@dataclass(frozen=True)
class Context:
    """What a case is built from: the session's small specimen (0.06 m x 0.03 m, conftest.py)."""

    specimen: Path


@dataclass(frozen=True)
class Protocol:
    """One protocol as the battery drives it.

    ``run(ctx, store)``: the case run into ``store`` (a :class:`Store`, or None unless ``skip``
    names ``store_none``); ``result_file``: where the result is kept, relative to the store;
    ``read(ctx, store, like)``: the result read back from its file, None when the store holds
    none (default: ``like``'s class read from ``result_file``); ``bad(ctx, store)``: a call with
    one bad input, whose :class:`~poro2d.errors.InputError` must name ``parameter``;
    ``jobs(ctx, store)``: a call that hands the protocol's jobs to the executor (default: the
    reference run's own);
    ``volatile``: keys of its result that say how a run went, not what it found (left out when
    two runs are compared); ``skip``: check name -> why it does not apply; ``setup(monkeypatch)``:
    what its runs change to stay small.
    """

    name: str
    run: Callable[[Context, Store | None], Any]
    result_file: str
    bad: Callable[[Context, Store], Any]
    parameter: str
    read: Callable[[Context, Store, Any], Any] | None = None
    jobs: Callable[[Context, Store], Any] | None = None
    volatile: frozenset[str] = frozenset()
    skip: dict[str, str] = field(default_factory=dict)
    setup: Callable[[Any], None] | None = None

    def __str__(self) -> str:
        return self.name

    def read_back(self, ctx: Context, store: Store, like: Any) -> Any:
        """The result kept in ``store`` (None: it holds none), of the class of ``like``."""
        if self.read is not None:
            return self.read(ctx, store, like)
        data = store.read_json(self.result_file)
        return None if data is None else type(like).from_dict(data)


# -- the criterion (Fig. 3) ----------------------------------------------------------------
CRITERION = {"seed": 0, "specimen": SMALL_BOX, "criterion": {"force_fraction": 0.05, "trial_porosity": 0.24}}


def _criterion(ctx: Context, store: Store | None):
    from poro2d.criterion import CriterionCase, run_criterion

    return run_criterion(CriterionCase.from_config(CRITERION), store, options=QUIET)


def _criterion_jobs(ctx: Context, store: Store):
    """The criterion runs as jobs where it has replicate seeds (its run alone has none)."""
    from poro2d.criterion import CriterionSettings
    from poro2d.criterion.replicates import ReplicateCase, run_replicates
    from poro2d.specimen import paper_grading
    from poro2d.specimen.compaction import SpecimenSpec

    settings = CriterionSettings(force_fraction=0.05)
    spec = SpecimenSpec(**SMALL_BOX)
    return run_replicates(ReplicateCase(spec, paper_grading(), settings, 0.21, (1, 2)), store, options=QUIET)


def _criterion_bad(ctx: Context, store: Store):
    from poro2d.criterion import CriterionCase, run_criterion

    return run_criterion(CriterionCase.from_config(CRITERION, n_lab=1.5), store, options=QUIET)


# -- direct shear ---------------------------------------------------------------------------
def _shear(ctx: Context, store: Store | None):
    from poro2d.shear import ShearSeriesCase, run_shear

    return run_shear(ShearSeriesCase(ctx.specimen, [50, 100], SHORT_SHEAR), store, options=QUIET)


def _shear_bad(ctx: Context, store: Store):
    from poro2d.shear import ShearSeriesCase, run_shear

    return run_shear(ShearSeriesCase(ctx.specimen, [50, -100], SHORT_SHEAR), store, options=QUIET)


# -- biaxial ----------------------------------------------------------------------------------
def _biaxial_case(confining_kpa: float = 100.0):
    from poro2d.biaxial import BiaxialCase, BiaxialSettings

    settings = BiaxialSettings(max_strain=0.005, record_strain=0.0005, critical_window=0.3)
    return BiaxialCase.quick(confining_kpa, seed=0, settings=settings)


def _biaxial(ctx: Context, store: Store | None):
    from poro2d.biaxial import run_biaxial

    return run_biaxial(_biaxial_case(), store, replicates=2, options=QUIET)


def _biaxial_bad(ctx: Context, store: Store):
    from poro2d.biaxial import run_biaxial

    return run_biaxial(_biaxial_case(), store, replicates=0, options=QUIET)


# -- the critical state in a periodic cell ---------------------------------------------------
CELL = {"disks": 200, "inertial_number": 1e-2, "strain": 0.5, "window_start": 0.25, "blocks": 3}


def _critical_state(ctx: Context, store: Store | None):
    from poro2d.critical_state import CriticalStateCase, CriticalStateStudy, run_critical_states

    return run_critical_states(CriticalStateStudy(CriticalStateCase(**CELL), seeds=2), store, options=QUIET)


def _critical_state_bad(ctx: Context, store: Store):
    from poro2d.critical_state import CriticalStateCase, CriticalStateStudy, run_critical_states

    return run_critical_states(CriticalStateStudy(CriticalStateCase(**CELL), seeds=0), store, options=QUIET)


# -- a user's sand -----------------------------------------------------------------------------
SAND = {
    "seed": 0,
    "soil": {"name": "tiny paper sand"},
    "grading": {"preset": "paper"},
    "lab": {"n_max": 0.4571, "n_min": 0.3253, "n": 0.40},
    "specimen": SMALL_BOX,
    "criterion": {"acceptance": "plate", "force_fraction": 0.05, "refine_tolerance": 0.005},
    "sand": {"seeds": 1, "mu_prep": [0.0, 0.5], "calibration_seeds": 1, "calibration_disks": 200},
}


def _sand(ctx: Context, store: Store | None):
    from poro2d.sand import load_sand_case, run_sand

    return run_sand(load_sand_case(SAND), store, options=QUIET, use_cache=False)


def _sand_setup(monkeypatch) -> None:
    """The pre-flight's jamming reference on 200 disks (as tests/sand do): seconds, not a minute."""
    from poro2d.sand import preflight

    monkeypatch.setattr(preflight, "JAMMING_DISKS", 200)


def _sand_bad(ctx: Context, store: Store):
    from poro2d.sand import load_sand_case, run_sand

    return run_sand(load_sand_case({**SAND, "lab": {**SAND["lab"], "n": 0.5}}), store, options=QUIET)


# -- the relation n2D(nLab) -------------------------------------------------------------------
RELATION = {
    "seed": 0,
    "specimen": SMALL_BOX,
    "criterion": {"max_iterations": 1, "max_plate_steps": 5000},
    "relation": {"n_max": 0.4571, "n_min": 0.3253, "mode": "paper"},
}


def _relation(ctx: Context, store: Store | None):
    from poro2d.sweep.relation import RelationCase, run_relation

    return run_relation(RelationCase.from_config(RELATION, points=2), store, options=QUIET)


def _relation_bad(ctx: Context, store: Store):
    from poro2d.sweep.relation import RelationCase, run_relation

    return run_relation(RelationCase.from_config(RELATION, points=1), store, options=QUIET)


# -- one shear test of a calibration ------------------------------------------------------------
def _unit(ctx: Context, particle_friction: float = 0.5):
    from poro2d.calibration.units import CalibrationUnit
    from poro2d.shear import ShearSettings, Specimen

    digest = Specimen.read(ctx.specimen).digest
    base = ShearSettings(**SHORT_SHEAR)
    return CalibrationUnit.at(ctx.specimen, digest, 50.0, base, particle_friction, 0.1)


def _calibration_unit(ctx: Context, store: Store | None):
    from poro2d.calibration.cluster import UnitRunner

    (row,) = UnitRunner(QUIET).run([_unit(ctx)], store, "calibration")
    return row


def _calibration_unit_read(ctx: Context, store: Store, row):
    """The unit's row read back from its test's folder in the cache (None: not finished)."""
    return _unit(ctx).stored_row(store)


def _calibration_unit_bad(ctx: Context, store: Store):
    return _unit(ctx, particle_friction=-0.5)


# fmt: off
#: the battery's table: one row per protocol
PROTOCOLS = [
    Protocol("criterion", _criterion, "result.json", _criterion_bad, "n_lab", jobs=_criterion_jobs),
    Protocol("shear", _shear, "result.json", _shear_bad, "normal stress (kPa)"),
    Protocol("biaxial", _biaxial, "result.json", _biaxial_bad, "replicates"),
    Protocol("critical_state", _critical_state, "result.json", _critical_state_bad, "seeds"),
    Protocol(  # the calibration's cases folder: with store=None, a scratch folder removed at the end
        "sand", _sand, "sand.json", _sand_bad, "lab.n", setup=_sand_setup, volatile=frozenset({"cases"}),
    ),
    Protocol(
        "relation", _relation, "relation.json", _relation_bad, "points",
        volatile=frozenset({"ran", "reused", "worker_processes", "parallel_efficiency"}),
    ),
    Protocol(
        "calibration_unit", _calibration_unit, "<key>/result.json", _calibration_unit_bad,
        "particle_friction", read=_calibration_unit_read,
    ),
]
# fmt: on
