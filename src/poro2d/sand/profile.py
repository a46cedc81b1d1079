"""Where a sand run's time went: steps and particle-steps per second, stage by stage.

Read from the criterion folders of its cases (each trial's ``prepared.json``, the layers'
and the working-friction stage's steps, and the trial's ``time_prepare_s``, ``plate_steps``
and ``time_plate_s`` in ``result.json``), so a resumed run reports the work of every case,
whenever it ran.
"""

from __future__ import annotations

import json
import math
from pathlib import Path


def _read(path: Path) -> dict | None:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _preparation_steps(trial_folder: Path) -> int:
    prep = _read(trial_folder / "prepared.json") or {}
    steps = sum(int(layer.get("steps") or 0) for layer in prep.get("layers") or [])
    return steps + int((prep.get("final_stage") or {}).get("steps") or 0)


def _trial_folders(run: Path) -> dict[int, Path]:
    out = {}
    for f in sorted((run / "trials").glob("*_n*")):
        head = f.name.split("_", 1)[0]
        if head.isdigit():
            out[int(head)] = f
    return out


def stage_profile(runs: list[Path]) -> dict:
    """Trials, steps, seconds and particle-steps per second of the preparation and the plate/lid
    stage, summed over the criterion folders ``runs`` (one per case)."""
    tally = {"trials": 0, "prepare": [0.0, 0.0, 0.0], "plate": [0.0, 0.0, 0.0]}  # steps, seconds, disk-steps
    for run in runs:
        res = _read(run / "result.json")
        if res is None:
            continue
        folders = _trial_folders(run)
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
    out: dict = {"trials": tally["trials"]}
    for key in ("prepare", "plate"):
        steps, secs, work = tally[key]
        out[key] = {
            "steps": int(steps),
            "seconds": secs,
            "particle_steps": work,
            "particle_steps_per_s": work / secs if secs > 0 else math.nan,
        }
    return out


def case_runs(folder: Path, case_ids: list[str]) -> list[Path]:
    """The criterion folders of the cases ``case_ids`` of a sweep folder (a shared calibration
    cache may hold other cases of the same grading and box: other frictions, seeds or first trials)."""
    return [Path(folder) / "cases" / cid / "run" for cid in case_ids]


__all__ = ["case_runs", "stage_profile"]
