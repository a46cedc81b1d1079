"""Replicate specimens: the criterion for several seeds at once, one process per core.

A strength from one specimen is one sample of a chaotic packing, so the case study shears
several specimens of the same accepted porosity. Each replicate is a criterion run of its
own seed, first trial the porosity the main seed accepted, in ``out/seed<N>``; it must
pass the criterion itself (a seed may settle on a neighbouring trial porosity: that is
part of the spread). The runs go to spawned processes with one numba thread each: two
threads on one specimen of a few thousand disks run only about 1.6 times as fast as one,
two processes twice. Each run resumes from its own folder, so a rerun continues.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

from poro2d.console import OutputConsole
from poro2d.criterion.protocol import CriterionSettings, PorosityCriterion
from poro2d.criterion.result import ReplicatesResult
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.specimen.grading import GradingCurve

console = OutputConsole()


def _run_one(
    spec: SpecimenSpec, grading: GradingCurve, settings: CriterionSettings, seed: int, out: Path
) -> dict:
    """One replicate's criterion run (in a worker process); its summary row."""
    t0 = time.perf_counter()
    res = PorosityCriterion(spec, grading, settings, seed=seed, out=out, progress=False).run()
    return {"seed": seed, "final_porosity": res["final_porosity"], "converged": bool(res["converged"]),
            "trials": len(res["iterations"]), "message": res["message"], "folder": out.name,
            "time_s": time.perf_counter() - t0}  # fmt: skip


def run_replicates(
    spec: SpecimenSpec,
    grading: GradingCurve,
    settings: CriterionSettings,
    n2d: float,
    seeds: list[int],
    out: Path,
    *,
    processes: int = 2,
    progress: bool = True,
) -> ReplicatesResult:
    """Criterion runs of ``seeds`` from the first trial ``n2d``, ``processes`` at a time.

    Returns one summary row per seed (accepted or not, the criterion's message, its folder
    under ``out``), in seed order, and the accepted specimens by label (``seed1``, ...) as
    the result's ``specimens``.
    """
    spec1 = replace(spec, threads=1)
    first = replace(settings, trial_porosity=n2d)
    jobs = {sd: (spec1, grading, first, sd, Path(out) / f"seed{sd}") for sd in seeds}
    display = _Display(seeds) if progress else None
    try:
        rows = _pool(jobs, processes, display) if processes > 1 and len(seeds) > 1 else _here(jobs, display)
    finally:
        if display is not None:
            display.stop()
    return ReplicatesResult([rows[sd] for sd in seeds], out=Path(out))


def accepted_and_replicates(
    spec: SpecimenSpec,
    grading: GradingCurve,
    settings: CriterionSettings,
    n2d: float,
    seed: int,
    replicates: int,
    out: Path,
    *,
    progress: bool,
) -> tuple[dict[str, Path], list[dict] | None]:
    """The specimen ``seed`` accepted in ``out/criterion`` and, with replicates, those of the next seeds.

    The replicates are criterion runs from the accepted ``n2d`` in ``out/replicates``, one
    process per thread of ``spec`` (:func:`run_replicates`); their rows are None without any.
    """
    specimens = {f"seed{seed}": out / "criterion" / "specimen.npz"}
    if replicates == 1:
        return specimens, None
    more_seeds = list(range(seed + 1, seed + replicates))
    console.print(f"  replicate specimens: seeds {', '.join(map(str, more_seeds))} from n2D = {n2d:.2f}")
    more = run_replicates(spec, grading, settings, n2d, more_seeds, out / "replicates",
                          processes=spec.threads, progress=progress)  # fmt: skip
    return {**specimens, **more.specimens}, more.rows


class _Display:
    """A spinner and the elapsed time per seed on a terminal; a line per finished seed in a log."""

    def __init__(self, seeds: list[int]) -> None:
        from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

        from poro2d.progress import ProgressLines, live_console

        console = live_console()
        self._lines = ProgressLines() if console is None else None
        self._left = len(seeds)
        if self._lines is None:
            self._p = Progress(SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn(),
                               console=console)  # fmt: skip
            self._tasks = {
                sd: self._p.add_task(f"replicate seed {sd}: criterion running", total=1) for sd in seeds
            }
            self._p.start()

    def done(self, row: dict) -> None:
        self._left -= 1
        what = (
            f"accepted n2D = {row['final_porosity']:.4f}"
            if row["converged"]
            else f"not accepted: {row['message']}"
        )
        text = f"replicate seed {row['seed']}: {what} ({row['trials']} trial(s), {row['time_s']:.0f} s)"
        if self._lines is not None:
            self._lines.write(f"  {text}; {self._left} still running", force=True)
        else:
            self._p.update(self._tasks[row["seed"]], description=text, completed=1)

    def stop(self) -> None:
        if self._lines is None:
            self._p.stop()


def _here(jobs: dict, display: _Display | None) -> dict[int, dict]:
    rows = {}
    for sd, job in jobs.items():
        rows[sd] = _run_one(*job)
        if display is not None:
            display.done(rows[sd])
    return rows


def _pool(jobs: dict, processes: int, display: _Display | None) -> dict[int, dict]:
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    rows = {}
    ctx = mp.get_context("spawn")  # a fresh interpreter: numba starts with one thread there
    with ProcessPoolExecutor(max_workers=min(processes, len(jobs)), mp_context=ctx) as pool:
        futs = {pool.submit(_run_one, *job): sd for sd, job in jobs.items()}
        for f in as_completed(futs):
            rows[futs[f]] = f.result()
            if display is not None:
                display.done(rows[futs[f]])
    return rows


__all__ = ["accepted_and_replicates", "run_replicates"]
