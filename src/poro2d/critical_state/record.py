"""What one periodic run's folder holds, and how a finished run is read back from it.

A run keeps ``series.csv``, then ``result.json`` (the marker: present means done), bound to its
case by ``test.json`` through the one rule of a laboratory test's folder
(:func:`poro2d.store.test_stage`): a folder holding a run of another case is refused, naming
what differs; the same case is read back, so a study killed midway reruns only the seeds it
had not finished. The record holds the case's content and no path, so a moved folder resumes.
A folder written before records existed (a ``result.json`` alone) is adopted: its run is not
trusted and runs again.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from poro2d.critical_state.case import CriticalStateCase
from poro2d.critical_state.results import CriticalStateTestResult
from poro2d.critical_state.series import CellSeries
from poro2d.identity import identity_digest
from poro2d.measure.fabric import ROSE_FILE, FabricRoses
from poro2d.store import Fingerprint, ResumableStage, Store, test_stage

#: a run's table of rows, written before its result
SERIES_CSV = "series.csv"


def content_of(case: CriticalStateCase) -> dict[str, Any]:
    """What a stored run must share with ``case`` to be reused. Its "specimen" is the cell's
    drawn disks (grading, count, seed), so that a refusal names a change of them as such."""
    packing = {"grading": case.to_dict()["grading"], "disks": case.disks, "seed": case.seed}
    return {
        "specimen_digest": identity_digest(packing),
        "pressure_kpa": case.pressure_kpa,
        "settings": case.to_dict(),
    }


def folder_stage(store: Store, case: CriticalStateCase) -> ResumableStage:
    """The stage of ``case``'s run in ``store``, bound by ``test.json``."""
    return test_stage(
        store.root, Fingerprint(content_of(case), tables={"settings": CriticalStateCase}),
        specimen=f"{case.disks} disks of seed {case.seed}", stress=("pressure_kpa", "pressure"),
        parameter=store.parameter, unrecorded="adopt",
    )  # fmt: skip


def stored_run(store: Store, case: CriticalStateCase) -> CriticalStateTestResult | None:
    """``case``'s run when ``store`` holds it finished, with its series; else None.

    Raises :class:`~poro2d.errors.InputError` when the folder holds a run of another case."""
    stage = folder_stage(store, case)
    stage.check()
    data = stage.stored(accept=lambda _: store.intact(SERIES_CSV))
    rows = None if data is None else store.read_rows(SERIES_CSV)
    if data is None or not rows:
        return None
    roses = store.read_result(ROSE_FILE, FabricRoses.from_dict)
    return replace(CriticalStateTestResult.from_dict(data), series=CellSeries.of_rows(rows), roses=roses)


__all__ = ["SERIES_CSV", "content_of", "folder_stage", "stored_run"]
