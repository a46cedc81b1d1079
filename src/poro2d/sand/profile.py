"""Where a sand run's time went: steps and particle-steps per second, stage by stage.

Read from the criterion stores of its cases (each trial's ``prepared.json``, the layers'
and the working-friction stage's steps, and the trial's ``time_prepare_s``, ``plate_steps``
and ``time_plate_s`` in ``result.json``), so a resumed run reports the work of every case,
whenever it ran.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from poro2d.store import Store, walk
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class PhaseProfile(TypedResult):
    """One phase's work (the preparation, or the plate/lid stage): steps, seconds, particle-steps."""

    steps: int
    seconds: float
    particle_steps: float
    particle_steps_per_s: float


@dataclass(eq=False)
class StageProfile(TypedResult):
    """Where a stage's time went (``time_profile``, ``specimens_time_profile`` in ``sand.json``):
    its trials, and the work of its preparation and plate phases."""

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"prepare": PhaseProfile, "plate": PhaseProfile}

    trials: int
    prepare: PhaseProfile
    plate: PhaseProfile


def _read(store: Store, name: str) -> dict | None:
    """A criterion file's raw content (None when it is missing or not a JSON object): only a few
    step counts and times are read from it, whichever version of the criterion wrote it."""
    data = store.read_json(name)
    return data if isinstance(data, dict) else None


def _preparation_steps(trial: Store) -> int:
    prep = _read(trial, "prepared.json") or {}
    steps = sum(int(layer.get("steps") or 0) for layer in prep.get("layers") or [])
    return steps + int((prep.get("final_stage") or {}).get("steps") or 0)


def _trial_stores(run: Store) -> dict[int, Store]:
    """The trial folders of a criterion store by trial number."""
    out = {}
    for trial in walk(run.child("trials"), "*_n*"):
        head = trial.root.name.split("_", 1)[0]
        if head.isdigit():
            out[int(head)] = trial
    return out


def stage_profile(runs: list[Store]) -> StageProfile:
    """Trials, steps, seconds and particle-steps per second of the preparation and the plate/lid
    stage, summed over the criterion stores ``runs`` (one per case)."""
    tally = {"trials": 0, "prepare": [0.0, 0.0, 0.0], "plate": [0.0, 0.0, 0.0]}  # steps, seconds, disk-steps
    for run in runs:
        res = _read(run, "result.json")
        if res is None:
            continue
        folders = _trial_stores(run)
        for it in res.get("iterations") or []:
            n = float(it.get("particle_count") or 0)
            tally["trials"] += 1
            prep = _preparation_steps(folders[it["iteration"]]) if it.get("iteration") in folders else 0
            for key, steps, secs in (("prepare", prep, it.get("time_prepare_s")),
                                     ("plate", it.get("plate_steps"), it.get("time_plate_s"))):  # fmt: skip
                steps = float(steps or 0)
                tally[key][0] += steps
                tally[key][1] += float(secs or 0.0)
                tally[key][2] += steps * n
    phases = {}
    for key in ("prepare", "plate"):
        steps, secs, work = tally[key]
        phases[key] = PhaseProfile(int(steps), secs, work, work / secs if secs > 0 else math.nan)
    return StageProfile(int(tally["trials"]), phases["prepare"], phases["plate"])


def case_runs(sweep: Store, case_ids: list[str]) -> list[Store]:
    """The criterion stores of the cases ``case_ids`` of a sweep's store (a shared calibration
    cache may hold other cases of the same grading and box: other frictions, seeds or first trials)."""
    return [sweep.child("cases", cid, "run") for cid in case_ids]


__all__ = ["PhaseProfile", "StageProfile", "case_runs", "stage_profile"]
