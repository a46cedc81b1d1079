"""Run the cases of a sweep as Dask tasks; gather one tidy table.

Layout of the sweep's store ``DIR`` (every file through :class:`~poro2d.store.Store`)::

    DIR/sweep.json                 config, cases, cluster, counts, provenance
    DIR/results.csv                one row per case (also results.parquet, where pyarrow is installed)
    DIR/cases/<id>/params.json     the case: kind, parameters, merged config
    DIR/cases/<id>/run/...         what the case kind writes (criterion outputs)
    DIR/cases/<id>/error.txt       traceback of a failed case
    DIR/cases/<id>/result.json     written atomically last: the case is done

Reliability: a case whose ``result.json`` exists is not run again. A case that
raises is caught on the worker, its traceback is stored and the error is put in
the table; the other cases go on. A worker process that dies takes its running
task with it; the scheduler resubmits that task to another (or the restarted)
worker, up to ``distributed.scheduler.allowed-failures`` times, and ``retries``
on submit covers failures outside the case code. A rerun with the same ``DIR``
skips finished cases and runs the rest (failed ones included).
"""

from __future__ import annotations

import json
import os
import socket
import time
import traceback
from contextlib import contextmanager
from dataclasses import asdict, replace
from datetime import UTC, datetime
from typing import Any

import numpy as np

from poro2d.dem.cores import DEFAULT_PARTITIONS, lend_cores, lending, lent_core_seconds
from poro2d.execute import Executor, Failed, Job
from poro2d.execute.core_share import CoreClock, ShareBoard, ThreadLender, WorkerUse, share_board
from poro2d.execute.dask_cluster import ClusterInfo, pin_numba_threads
from poro2d.execute.options import RunOptions
from poro2d.io_utils import Provenance
from poro2d.locks import cache_entry
from poro2d.store import Store
from poro2d.store.stage import Fingerprint, ResumableStage
from poro2d.sweep.cases import KINDS, Case, SweepConfig, axes_of, case_record, config_tables
from poro2d.sweep.records import CaseRow, LostCaseRow, SweepSummary
from poro2d.sweep.results import SweepResult
from poro2d.typed_result import TypedResult

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "sweep"

RESULT = "result.json"
PARAMS = "params.json"
ERROR_TXT = "error.txt"
ERROR_JSON = "error.json"


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


def _scalar(v: Any) -> Any:
    """Values of a table cell: numbers, strings, bools or None; anything else as JSON."""
    if v is None or isinstance(v, (bool, int, float, str)):
        return v
    return v.item() if isinstance(v, np.generic) else json.dumps(v, default=str)


def case_stage(case: dict, store: Store) -> ResumableStage:
    """A case's folder as a resumable stage: ``params.json`` binds it, ``result.json`` marks it done.

    The binding is the case's kind and merged config, as its id (which names the folder)
    is: the parameters (labels relative to a sweep's base case) and the settings that
    change no result (:mod:`poro2d.identity`) are recorded, not compared, so a rerun with
    another thread count finds it; a grading curve file is compared by its content, its
    path recorded (:func:`poro2d.sweep.cases.case_record`).
    """
    return store.stage(
        Fingerprint(
            case_record(case), ignore=("id", "params", "config.grading.csv"), tables=config_tables("config.")
        ),
        record=PARAMS,
        key=None,
        allowed="a sweep folder whose case folders hold the cases their ids name",
        unrecorded="adopt",
    )


def _is_done(row: dict) -> bool:
    """A ``result.json`` marks a finished case only with ``status`` done (what the runner writes)."""
    return row.get("status") == "done"


def finished_row(case: dict, store: Store) -> CaseRow | None:
    """The stored row of a finished case, or None (no marker, unreadable, or another case's)."""
    row = case_stage(case, store).stored(RESULT, accept=_is_done)
    return None if row is None else CaseRow.from_dict(row)


# ------------------------------------------------------------------------ worker side
def compute_case(case: dict, store: Store, func, board: ShareBoard | None = None) -> CaseRow:
    """Run one case on a worker; never raises for errors of the case itself.

    ``func`` is the kind's callable, shipped with the task so that kinds registered
    at run time (tests, plug-ins) work on any worker. The case folder is held while the
    case runs: a worker left running by a killed sweep may still compute it, and a rerun's
    worker then waits for it and reads its result back instead of writing beside it.
    ``board``: where the run posts the threads per case when fewer cases than workers remain
    (:mod:`poro2d.execute.core_share`): the case's simulations take them at their next block.
    """
    with cache_entry(store.root, parameter="case folder"), lent_cores(board):
        return _run_case(case, store, func)


@contextmanager
def lent_cores(board: ShareBoard | None):
    """The threads posted on ``board`` lent to this process's simulations while the case runs."""
    before = lend_cores(ThreadLender(board)) if board is not None else None
    try:
        yield
    finally:
        if board is not None:
            lend_cores(before)


def _run_case(case: dict, store: Store, func) -> CaseRow:
    done = finished_row(case, store)
    if done is not None:  # a retry after the marker was written
        return done
    pin_numba_threads()
    row: dict[str, Any] = {
        "case_id": case["id"],
        "kind": case["kind"],
        "params": case["params"],
        "host": socket.gethostname(),
        "pid": os.getpid(),
        "worker": _worker_address(),
        "started_utc": _now(),
    }
    t0 = time.perf_counter()
    try:
        return case_stage(case, store).run(lambda: _done_row(case, store, func, row, t0), RESULT,
                                           accept=_is_done, decode=CaseRow.from_dict)  # fmt: skip
    except Exception as exc:
        row.update(
            status="failed",
            error=f"{type(exc).__name__}: {exc}",
            time_s=time.perf_counter() - t0,
            finished_utc=_now(),
            results={},
        )
        store.write_text(ERROR_TXT, traceback.format_exc())
        store.write_json(ERROR_JSON, row)
        return CaseRow.from_dict(row)


def _done_row(case: dict, store: Store, func, row: dict, t0: float) -> CaseRow:
    """Run the case's kind into its sub-store ``run``; its row (``status`` done, results as table cells)."""
    results = func(case["config"], store.child("run"))
    if isinstance(results, TypedResult):  # a kind's typed record of its cells
        results = results.to_dict()
    if not isinstance(results, dict):
        raise TypeError(
            f"case kind {case['kind']!r} returned {type(results).__name__}, not a dict or a record"
        )
    results = {str(k): _scalar(v) for k, v in results.items()}
    row.update(status="done", error=None, time_s=time.perf_counter() - t0, finished_utc=_now())
    if lending():  # the core-time its threads beyond one took (poro2d.execute.core_share)
        row["lent_core_s"] = lent_core_seconds()
    row["results"] = results
    for stale in (ERROR_TXT, ERROR_JSON):
        store.remove(stale)
    return CaseRow.from_dict(row)  # written as result.json, the done marker, last


def _worker_address() -> str:
    try:
        from distributed import get_worker

        return get_worker().address
    except Exception:
        return "local"


# ------------------------------------------------------------------------ driver side
def _failed_row(case: Case, store: Store, err: BaseException, tb: str) -> LostCaseRow:
    error = f"{type(err).__name__}: {err}"
    row = LostCaseRow(case.id, case.kind, case.params, "failed", error, None, {}, None, None, None, _now())
    case_stage(asdict(case), store).bind()
    store.write_text(ERROR_TXT, tb or row.error)
    store.write_result(ERROR_JSON, row)
    return row


def table_from_rows(rows: list[CaseRow | LostCaseRow], axes: list[str]):
    """One row per case: id, kind, parameters, status, results, timing, worker, error."""
    import pandas as pd

    result_keys = axes_of([r.results or {} for r in rows])
    flat = []
    for r in rows:
        rec = {"case_id": r.case_id, "kind": r.kind, **{a: _scalar((r.params or {}).get(a)) for a in axes}}
        rec["status"] = r.status
        rec.update((k, (r.results or {}).get(k)) for k in result_keys)
        rec.update((k, getattr(r, k)) for k in ("time_s", "worker", "host", "pid", "error"))
        flat.append(rec)
    df = pd.DataFrame(flat)
    for col in df.columns:  # mixed object columns (None + numbers) become numeric or text
        if df[col].dtype == object:
            vals = [v for v in df[col] if v is not None]
            if vals and all(isinstance(v, bool) for v in vals):
                df[col] = df[col].astype("boolean")
            elif vals and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
                df[col] = pd.to_numeric(df[col])
            elif vals:
                df[col] = df[col].map(lambda v: None if v is None else str(v))
    return df


def run_sweep(
    sweep: SweepConfig, store: Store, *, options: RunOptions = RunOptions(), client=None
) -> SweepResult:
    """Run every unfinished case of ``sweep`` into ``store``; returns its ``sweep.json``, rows and table.

    The store's folder is held for the call (another run writing there is refused).
    ``options``: where the jobs run and whether bars show
    (:class:`~poro2d.execute.options.RunOptions`): a running scheduler, or a new LocalCluster of
    ``workers`` processes (default: one per core) of one thread each, its dashboard on
    ``dashboard``. ``client``: an existing ``distributed.Client`` (tests, notebooks) instead.
    """
    with store.claim(KIND):
        cases = store.child("cases")
        t_start = time.perf_counter()
        record = {
            "status": "running",
            "title": sweep.title,
            "kind": sweep.kind,
            "axes": sweep.axes,
            "cases": [{"id": c.id, "params": c.params} for c in sweep.cases],
            "config": sweep.raw,
            "base_dir": str(sweep.base_dir) if sweep.base_dir else None,
            "retries": sweep.retries,
            "provenance": Provenance.now().to_dict(),
        }
        store.write_json("sweep.json", record)
        rows: dict[str, CaseRow | LostCaseRow] = {}
        for c in sweep.cases:
            done = finished_row(asdict(c), cases.child(c.id))
            if done is not None:
                rows[c.id] = CaseRow.from_dict(dict(done.to_dict(), status="done", reused=True))
        n_reused = len(rows)
        pending = [c for c in sweep.cases if c.id not in rows]
        cluster_info, use = (
            _run_pending(sweep, pending, rows, cases, options, client) if pending else (None, None)
        )
        ordered = [type(r).from_dict(dict(r.to_dict(), reused=bool(r.extra.get("reused", False))))
                   for r in (rows[c.id] for c in sweep.cases)]  # fmt: skip
        df = table_from_rows(ordered, sweep.axes)
        df["reused"] = [r.extra["reused"] for r in ordered]
        store.write_frame("results.csv", df)
        if store.write_parquet("results.parquet", df) is None:
            say_no_parquet(store)
        summary = _summary(ordered, n_reused, time.perf_counter() - t_start, cluster_info, use)
        record.update(status="finished", cluster=cluster_info or {}, summary=summary, finished_utc=_now())
        store.write_json("sweep.json", record)
    return replace(SweepResult.from_dict(record), rows=ordered, table=df, store=store)


def say_no_parquet(store: Store) -> None:
    """One line on stderr: the table is in results.csv only, and how to have the Parquet copy too."""
    from poro2d.console import OutputConsole, shown

    line = (
        f"note: {store.path('results.parquet')} not written: pyarrow is not installed "
        '(pip install "poro2d[parquet]"); results.csv holds the same table'
    )
    OutputConsole(stderr=True).print(shown(line), highlight=False, soft_wrap=True)  # [parquet] is no markup


def _run_pending(sweep: SweepConfig, pending: list[Case], rows: dict, cases: Store, options: RunOptions,
                 client) -> tuple[ClusterInfo | None, WorkerUse]:  # fmt: skip
    """Every pending case as a job on ``client`` (or a cluster made for them), its row into ``rows`` (a
    failed task gives an error row); returns what is recorded of the cluster (scheduler, workers,
    threads, dashboard) and of its use. On a cluster started here, the cores of finished cases go
    to the cases still running as engine threads (:mod:`poro2d.execute.core_share`)."""
    from poro2d.progress import CountProgress

    threads = max(int((c.config.get("specimen") or {}).get("threads", 1) or 1) for c in pending)
    lend = client is None and options.scheduler is None  # the cores of a cluster started here
    n_reused = len(sweep.cases) - len(pending)
    label = f"sweep ({n_reused} of {len(sweep.cases)} already done)" if n_reused else "sweep"
    backend = options.dask_backend(max(threads, DEFAULT_PARTITIONS) if lend else threads)
    with Executor(backend, client=client) as executor, share_board() as board:
        executor.start()
        cluster_info = executor.cluster_info()
        # cores, not workers, are lent: workers beyond the cores (up to two per core) only queue
        workers = min(cluster_info.workers if cluster_info is not None else 1, os.cpu_count() or 1)
        clock = CoreClock(workers, len(pending), DEFAULT_PARTITIONS, board if lend and workers > 1 else None)
        jobs = [
            Job(compute_case, (asdict(c), cases.child(c.id), KINDS[c.kind], clock.board), c.id,
                key=f"{c.kind}-{c.id}", retries=sweep.retries)
            for c in pending
        ]  # fmt: skip
        if options.progress and cluster_info is not None and cluster_info.dashboard:
            from poro2d.console import OutputConsole

            err = OutputConsole(stderr=True)
            err.print(f"Dask dashboard: {cluster_info.dashboard}", highlight=False)
        with CountProgress(label, len(pending), "cases", enabled=options.progress) as bar:

            def ended(index: int, outcome) -> None:
                c = pending[index]
                if isinstance(
                    outcome, Failed
                ):  # the task itself failed: e.g. KilledWorker after worker deaths
                    exc = outcome.error
                    outcome = _failed_row(
                        c, cases.child(c.id), exc, f"{outcome.traceback}{type(exc).__name__}: {exc}\n"
                    )
                rows[c.id] = outcome
                clock.case_ended()
                n_failed = sum(r.status == "failed" for r in rows.values())  # a reused case is done
                bar.advance(", ".join(filter(None, [f"{n_failed} failed" if n_failed else "", clock.note()])))

            executor.map(jobs, on_done=ended)
        use = clock.use([rows[c.id] for c in pending])
    return cluster_info, use


def _summary(
    ordered: list[CaseRow | LostCaseRow], n_reused: int, wall: float, cluster_info: ClusterInfo | None,
    use: WorkerUse | None = None,
) -> SweepSummary:  # fmt: skip
    """Counts, wall and case time, the worker processes, the parallel efficiency of a sweep and how its
    workers were used."""
    busy = sum(r.time_s or 0.0 for r in ordered if not r.extra["reused"])
    summary = {
        "cases": len(ordered),
        "ran": len(ordered) - n_reused,
        "reused": n_reused,
        "done": sum(r.status == "done" for r in ordered),
        "failed": sum(r.status == "failed" for r in ordered),
        "wall_time_s": wall,
        "case_time_sum_s": busy,
        "worker_processes": sorted({f"{r.host}:{r.pid}" for r in ordered if not r.extra["reused"] and r.pid}),
    }
    if cluster_info is not None and cluster_info.threads:
        summary["parallel_efficiency"] = busy / (wall * cluster_info.threads) if wall > 0 else None
    if use is not None:
        summary["worker_use"] = use
    return SweepSummary.from_dict(summary)


__all__ = [
    "SweepResult",
    "case_stage",
    "finished_row",
    "compute_case",
    "run_sweep",
    "table_from_rows",
]
