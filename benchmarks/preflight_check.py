"""The pre-flight's estimate against finished `poro2d sand` runs.

    PYTHONPATH=src python benchmarks/preflight_check.py RUN_FOLDER CONFIG.toml [RUN_FOLDER CONFIG.toml ...]

For each finished run (its folder's ``sand.json``), the pre-flight of its config is made again at
the pace the run measured (its particle-steps over its workers' seconds, calibration and
specimens together: the machine's own throughput, whatever else it was running) and at the
default ``THROUGHPUT``; the estimates are printed beside the run's measured wall time. ``--old-lid``
estimates with the lid steps the old lid took (the runs before the creeping lid).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from poro2d.sand import load_sand_case
from poro2d.sand import preflight as PF

#: the lid steps per trial of the lid before the creeping lid (the runs it was fitted on)
OLD_LID_STEPS = ((0.0, 17_000), (0.1, 37_000), (0.5, 71_000), (1.0, 415_000))


def measured_pace(sand: dict, keys: tuple[str, ...]) -> float:
    """Particle-steps per second per worker over the stages ``keys`` of a finished run."""
    work = secs = 0.0
    for key in keys:
        for phase in ("prepare", "plate"):
            p = sand["calibration"][key][phase]
            work, secs = work + p["particle_steps"], secs + p["seconds"]
    return work / secs


def row(folder: Path, config: Path) -> str:
    sand = json.loads((folder / "sand.json").read_text())
    # a calibration read back from the cache ran no case: only the specimens are measured then
    reused = json.loads((folder / "calibration_ends.json").read_text()).get("ran") == 0
    keys = ("specimens_time_profile",) if reused else ("time_profile", "specimens_time_profile")
    case = load_sand_case(config)
    pace = measured_pace(sand, keys)
    at_pace = PF.preflight(case, workers=2, throughput=pace).seconds
    default = PF.preflight(case, workers=2).seconds
    est, est_default = (at_pace.specimens, default.specimens) if reused else (at_pace.total, default.total)
    wall = float(sand["wall_seconds"])
    what = "specimens only (calibration cached)" if reused else "whole run"
    return (
        f"| {case.name} ({folder.name}, {what}) | {wall / 60:.1f} | {pace:.3g} | {est / 60:.1f} "
        f"({at_pace.calibration / 60:.1f} + {at_pace.specimens / 60:.1f}) | {est / wall:.2f} "
        f"| {est_default / 60:.1f} |"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pairs", nargs="+")
    ap.add_argument("--old-lid", action="store_true")
    args = ap.parse_args()
    if args.old_lid:
        PF.LID_STEPS = OLD_LID_STEPS
    print("| run | measured min | pace /worker | estimate at that pace, min (calibration + specimens) "
          "| estimate / measured | estimate at THROUGHPUT, min |")  # fmt: skip
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for folder, config in zip(args.pairs[::2], args.pairs[1::2], strict=True):
        print(row(Path(folder), Path(config)), flush=True)


if __name__ == "__main__":
    main()
