"""Where a sand run's time went: steps and particle-steps per second, stage by stage.

Read from the criterion stores of its cases through the criterion's own readers (each
trial's ``prepared.json``, the layers' and the working-friction stage's steps, and the
trial's ``time_prepare_s``, ``plate_steps`` and ``time_plate_s`` in ``result.json``, files of
earlier versions included), so a resumed run reports the work of every case, whenever it ran.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from poro2d.criterion.result import CriterionResult
from poro2d.criterion.trial import Trial, trial_name
from poro2d.specimen.compaction import PreparationReport
from poro2d.store import Store
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


def _preparation_steps(trial: Store) -> int:
    """The steps of a trial's layers and working-friction stage (its ``prepared.json``; 0 without one)."""
    prep = trial.read_result("prepared.json", PreparationReport.from_dict)
    if prep is None:
        return 0
    steps = sum(int(layer.steps or 0) for layer in prep.layers or [])
    return steps + int((prep.final_stage.steps if prep.final_stage is not None else 0) or 0)


def _plate_steps(trial: Trial) -> int:
    """The steps of a trial's plate (or lid) stage: the servo's, none when the plate did not move."""
    servo = trial.plate.servo
    return int(servo.steps or 0) if servo is not None else 0


def stage_profile(runs: list[Store]) -> StageProfile:
    """Trials, steps, seconds and particle-steps per second of the preparation and the plate/lid
    stage, summed over the criterion stores ``runs`` (one per case)."""
    tally = {"trials": 0, "prepare": [0.0, 0.0, 0.0], "plate": [0.0, 0.0, 0.0]}  # steps, seconds, disk-steps
    for run in runs:
        res = run.read_result("result.json", CriterionResult.from_dict)
        if res is None:
            continue
        for trial in res.iterations or []:
            n = float(trial.particle_count or 0)
            tally["trials"] += 1
            prep = _preparation_steps(run.child(trial_name(trial.iteration, trial.trial_porosity)))
            for key, steps, secs in (("prepare", prep, trial.time_prepare_s),
                                     ("plate", _plate_steps(trial), trial.time_plate_s)):  # fmt: skip
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
