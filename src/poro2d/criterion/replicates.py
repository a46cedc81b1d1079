"""Replicate specimens: the criterion for several seeds at once, one process per core.

A strength from one specimen is one sample of a chaotic packing, so the case study shears
several specimens of the same accepted porosity. Each replicate is a criterion run of its
own seed, first trial the porosity the main seed accepted, in the sub-store ``seed<N>``; it must
pass the criterion itself (a seed may settle on a neighbouring trial porosity: that is
part of the spread). The runs are jobs of the executor's local processes
(:mod:`poro2d.execute`) with one numba thread each: two threads on one specimen of a few
thousand disks run only about 1.6 times as fast as one, two processes twice. A finished seed
is read back from its folder without a process, an unfinished one resumes there.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

from poro2d.console import OutputConsole, shown
from poro2d.criterion.protocol import CriterionSettings, PorosityCriterion
from poro2d.criterion.result import CriterionResult, ReplicateRow, ReplicatesResult
from poro2d.errors import check_int
from poro2d.execute import Job, RunOptions
from poro2d.execute.batch import complete_jobs
from poro2d.grading import GradingCurve
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store

console = OutputConsole()

#: seeds not accepted replaced by the next unused ones, at most (as ``poro2d sand``'s
#: ``[sand] replacements``): a seed refused at a threshold is one sample of a chaotic packing
REPLACEMENTS = 3
MAX_REPLACEMENTS = 50


@dataclass(frozen=True)
class ReplicateCase:
    """Replicate criterion runs as one value: the specimen, grading and thresholds of the main
    run, the first trial ``n2d`` (the porosity the main seed accepted) and the ``seeds`` to run;
    a seed not accepted is replaced by the next unused seed above them, ``replacements`` at most."""

    spec: SpecimenSpec
    grading: GradingCurve
    settings: CriterionSettings
    n2d: float
    seeds: tuple[int, ...]
    replacements: int = REPLACEMENTS

    def __post_init__(self) -> None:
        check_int("replacements", self.replacements, 0, MAX_REPLACEMENTS)

    def criterion(self, seed: int, store: Store) -> PorosityCriterion:
        """Seed ``seed``'s criterion run in ``store``: one numba thread, first trial ``n2d``."""
        spec, settings = replace(self.spec, threads=1), replace(self.settings, trial_porosity=self.n2d)
        return PorosityCriterion(spec, self.grading, settings, seed=seed, store=store, progress=False)


def _run_one(case: ReplicateCase, seed: int, store: Store, report) -> ReplicateRow:
    """One replicate's criterion run (in a worker process); its summary row."""
    report("running")
    t0 = time.perf_counter()
    return _row(case.criterion(seed, store).run(), seed, store, t0)


def _stored(case: ReplicateCase, seed: int, store: Store) -> ReplicateRow | None:
    """A finished replicate's row, read back here (no process started); None when it is to run
    (a folder of another config is left to the run, which refuses it)."""
    t0 = time.perf_counter()
    data = case.criterion(seed, store).stage().stored()
    return None if data is None else _row(CriterionResult.from_dict(data), seed, store, t0)


def _row(res: CriterionResult, seed: int, store: Store, t0: float) -> ReplicateRow:
    return ReplicateRow(seed, res.final_porosity, bool(res.converged), len(res.iterations), res.message,
                        store.root.name, time.perf_counter() - t0)  # fmt: skip


def run_replicates(
    case: ReplicateCase, store: Store, *, options: RunOptions = RunOptions()
) -> ReplicatesResult:
    """The criterion runs of ``case``'s seeds, each in ``store``'s ``seed<N>``, on ``options``'
    workers (default one per seed, at most one per core) or its running scheduler.

    A seed not accepted is replaced by the next unused seed above ``case.seeds`` (``case.replacements``
    at most), each named in the printout with why; one line says when fewer seeds than asked were
    accepted. Returns one summary row per seed tried (accepted or not, the criterion's message, its
    sub-store of ``store``), in seed order, and the accepted specimens by label (``seed1``, ...) as
    the result's ``specimens``. A run where every seed is accepted tries no other.
    """
    rows = _run_seeds(case, case.seeds, store, options)
    named: set[int] = set()  # the refused seeds the printout has named
    spare, following = case.replacements, max(case.seeds, default=0) + 1
    while (short := len(case.seeds) - sum(r.converged for r in rows)) > 0 and spare > 0:
        more = tuple(range(following, following + min(short, spare)))
        refused = [r for r in rows if not r.converged and r.seed not in named]
        say_replaced(refused, more)
        named.update(r.seed for r in refused)
        rows += _run_seeds(case, more, store, options)
        spare, following = spare - len(more), following + len(more)
    if short > 0:
        console.print(f"[bold red]only {len(case.seeds) - short} of {len(case.seeds)} replicate seeds "
                      f"accepted[/] ({len(rows) - len(case.seeds)} replacement(s) tried, at most "
                      f"{case.replacements})", soft_wrap=True)  # fmt: skip
    return ReplicatesResult(rows, store=store)


def say_replaced(refused: list[ReplicateRow], more: tuple[int, ...]) -> None:
    """One line per refused seed: why it was not accepted and the seed tried in its place."""
    for k, row in enumerate(refused):
        instead = f"seed {more[k]} in its place" if k < len(more) else "no seed left to replace it"
        console.print(
            f"  replicate seed {row.seed} not accepted ({shown(row.message)}): {instead}", soft_wrap=True
        )


def _run_seeds(case: ReplicateCase, seeds, store: Store, options: RunOptions) -> list[ReplicateRow]:
    """The rows of ``seeds``' criterion runs, each in ``store``'s ``seed<N>`` (finished ones read back)."""
    jobs = [Job(_run_one, (case, sd, store.child(f"seed{sd}")), f"seed {sd}", reports=True) for sd in seeds]
    return complete_jobs(jobs, title="replicate criterion", what="replicate criterion run(s)",
                         options=options, workers=options.local_workers(len(jobs)),
                         finished=[_stored(*job.args) for job in jobs], done_text=_outcome)  # fmt: skip


def accepted_and_replicates(
    spec: SpecimenSpec,
    grading: GradingCurve,
    settings: CriterionSettings,
    n2d: float,
    seed: int,
    replicates: int,
    store: Store,
    *,
    progress: bool,
) -> tuple[SpecimenSet, list[ReplicateRow] | None]:
    """The specimen ``seed`` accepted in ``store``'s ``criterion`` and, with replicates, the next seeds'.

    The replicates are criterion runs from the accepted ``n2d`` in its ``replicates``, one
    process per thread of ``spec`` (:func:`run_replicates`); their rows (as ``results.json``
    holds them) are None without any.
    """
    specimens = SpecimenSet.made([(f"seed{seed}", store.child("criterion").path("specimen.npz"))])
    if replicates == 1:
        return specimens, None
    case = ReplicateCase(spec, grading, settings, n2d, tuple(range(seed + 1, seed + replicates)))
    console.print(f"  replicate specimens: seeds {', '.join(map(str, case.seeds))} from n2D = {n2d:.2f}")
    more = run_replicates(
        case, store.child("replicates"), options=RunOptions(workers=spec.threads, progress=progress)
    )
    return specimens + more.specimens, more.rows


def _outcome(row: ReplicateRow) -> str:
    """How a replicate ended, as its progress shows it."""
    what = f"accepted n2D = {row.final_porosity:.4f}" if row.converged else f"not accepted: {row.message}"
    return f"{what} ({row.trials} trial(s) in {row.time_s:.0f} s)"


__all__ = [
    "MAX_REPLACEMENTS",
    "REPLACEMENTS",
    "ReplicateCase",
    "accepted_and_replicates",
    "run_replicates",
    "say_replaced",
]
