"""The calibration's shear tests on Dask: one task per unit, the cluster started once.

The cluster helpers are the sweeps' (:mod:`poro2d.sweep.runner`): a LocalCluster of
``workers`` single-threaded processes, or a running scheduler at ``scheduler``.
"""

from __future__ import annotations

import time
import traceback

from poro2d.calibration.units import compute_unit, stored_row
from poro2d.sweep.runner import (
    DEFAULT_DASHBOARD,
    hold_interrupts,
    quiet_shutdown_logs,
    release_interrupts,
    start_client,
)


class UnitRunner:
    """Runs units on a Dask cluster started at the first unit that is not cached."""

    def __init__(
        self,
        scheduler: str | None,
        workers: int | None,
        *,
        progress: bool,
        dashboard: str | None = DEFAULT_DASHBOARD,
    ) -> None:
        self.scheduler, self.workers, self.progress, self.dashboard = scheduler, workers, progress, dashboard
        self.client = self.cluster = None
        self.n_workers: int | None = None
        self.local_cluster = False
        self.failures: list[dict] = []
        self.ran = self.reused = 0
        self.busy_s = 0.0
        self.wall_s = 0.0

    def _client(self):
        if self.client is None:
            held = hold_interrupts() if not self.scheduler else None
            try:
                self.client, self.cluster = start_client(self.scheduler, self.workers, 1, self.dashboard)
                self.local_cluster = self.cluster is not None
                self.n_workers = len(self.client.scheduler_info().get("workers", {}))
            finally:
                release_interrupts(held)
        return self.client

    def run(self, jobs: list[dict], label: str) -> dict[str, dict]:
        """Rows by unit key for ``jobs``: read back when cached, else run as Dask tasks."""
        from poro2d.progress import CountProgress

        rows: dict[str, dict] = {}
        todo = []
        for job in jobs:
            row = stored_row(job)
            if row is None:
                todo.append(job)
            else:
                rows[job["key"]] = row
        self.reused += len(rows)
        if not todo:
            return rows
        from distributed import as_completed

        t0 = time.perf_counter()
        client = self._client()
        futures = {
            client.submit(compute_unit, job, key=f"calibrate-{job['key']}", pure=False): job for job in todo
        }
        done_before = f" ({len(rows)} of {len(jobs)} cached)" if rows else ""
        try:
            with CountProgress(label + done_before, len(todo), "shear tests", enabled=self.progress) as bar:
                for fut in as_completed(list(futures)):
                    job = futures[fut]
                    if fut.status == "finished":
                        row = fut.result()
                        rows[job["key"]] = row
                        self.busy_s += row["wall_time_s"]
                        self.ran += 1
                    else:  # a test that fails (no equilibrium) is left out of the fit, and said
                        exc = fut.exception()
                        self.failures.append(
                            {
                                "key": job["key"],
                                "sigma": job["sigma"],
                                "fp": job["fp"],
                                "mu_r": job["mu_r"],
                                "specimen": job["specimen"],
                                "error": f"{type(exc).__name__}: {exc}".splitlines()[0],
                                "traceback": "".join(traceback.format_tb(fut.traceback())),
                            }
                        )
                    bar.advance(f"{len(self.failures)} failed" if self.failures else "")
                    fut.release()
        except KeyboardInterrupt:
            quiet_shutdown_logs(client)
            raise
        finally:
            self.wall_s += time.perf_counter() - t0
        return rows

    def info(self) -> dict:
        """What is recorded of the cluster and the work: workers, tests run and reused, times."""
        return {
            "scheduler": self.scheduler,
            "workers": self.n_workers,
            "local_cluster": self.local_cluster,
            "tests_run": self.ran,
            "tests_reused": self.reused,
            "tests_failed": len(self.failures),
            "test_time_sum_s": self.busy_s,
            "wall_time_tests_s": self.wall_s,
        }

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()
        self.client = self.cluster = None


__all__ = ["UnitRunner"]
