"""Accepted porosities with and without density scaling, over seeds, on small boxes.

    PYTHONPATH=src python benchmarks/density_scaling.py OUT.jsonl [--only NAME] [--seeds 3]

For each grading below, the criterion (paper mode, plate acceptance) is run on a small box with
``[specimen] mass_scaling = "off"`` and with the scaling its row names, for every seed; one JSON
line per run goes to OUT (accepted n2D, the interior porosity, trials, steps, the shared time
step, wall time), and the table of docs/density-scaling.md is printed from the lines at the end.
Runs already in OUT are not run again.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

from poro2d.criterion import CriterionCase, run_criterion
from poro2d.execute.options import RunOptions

SOILS = Path(__file__).resolve().parents[1] / "examples" / "soils"

#: name -> (grading table, box (W, H, layers), first trial porosity, the scaled run's settings)
CASES = {
    # G1-1's fines whole (0.1 mm), its coarse end cut at 2.36 mm to fit a 20 x 10 mm box:
    # r_mean / r_min 9, so "auto" raises the masses (shared step 4.4 times the finest disk's)
    "g1-1 (d <= 2.36 mm)": (
        {"csv": str(SOILS / "g1-1_sandy_gravel.csv"), "upscale": 1, "d_max_mm": 2.36},
        (0.02, 0.01, 1),
        0.16,
        {"mass_scaling": "auto"},
    ),
    # the paper's grading and CB-Mix-2 lie below the trigger: forced on, raised to the MEAN disk
    # (mass_scaling_ratio 1), a stronger scaling than "auto" ever applies (about half the disks)
    "paper": ({"preset": "paper"}, (0.06, 0.03, 2), 0.16, {"mass_scaling": "on", "mass_scaling_ratio": 1.0}),
    "cb-mix-2": (
        {"csv": str(SOILS / "cb-mix-2_sand.csv"), "upscale": 4},
        (0.04, 0.02, 2),
        0.17,
        {"mass_scaling": "on", "mass_scaling_ratio": 1.0},
    ),
}


#: step budgets in simulated time, as `poro2d sand` scales them (sand.case.with_step_budgets):
#: with true masses G1-1's finest disk steps 4.4 times shorter than the shared step, and the
#: default budgets (plate 600 000, a stage 400 000 + 200 000 steps) were too few for 2 of 3
#: seeds. A budget only caps a stage that stops at equilibrium: runs that end below it are the same
BUDGETS = {
    "g1-1 (d <= 2.36 mm)": (
        {"max_steps_per_stage": 1_800_000, "fallback_steps": 900_000},
        {"max_plate_steps": 3_000_000},
    ),
}


def _config(name: str, scaled: bool) -> tuple[dict, float]:
    grading, (w, h, layers), trial, scaling = CASES[name]
    specimen_budget, criterion = BUDGETS.get(name, ({}, {}))
    specimen = {"width": w, "height": h, "layers": layers, **(scaling if scaled else {"mass_scaling": "off"})}
    specimen.update(specimen_budget)
    return {"grading": dict(grading), "specimen": specimen, "criterion": dict(criterion)}, trial


def run_one(name: str, scaled: bool, seed: int) -> dict:
    cfg, trial = _config(name, scaled)
    case = CriterionCase.from_config(cfg, seed=seed, trial_porosity=trial)
    t0 = time.perf_counter()
    res = run_criterion(case, None, options=RunOptions(progress=False))
    steps = sum((t.plate.servo.steps if t.plate.servo is not None else 0) for t in res.iterations)
    return {
        "grading": name, "scaled": scaled, "seed": seed, "n2d": res.final_porosity,
        "interior": res.interior_porosity, "box": res.box_porosity, "trials": len(res.iterations),
        "disks": res.iterations[-1].particle_count, "plate_steps": steps,
        "dt_shared_s": res.iterations[-1].mass_scaling_dt_s,
        "scaled_disks": res.iterations[-1].mass_scaled_disks,
        "wall_s": time.perf_counter() - t0, "message": res.message,
    }  # fmt: skip


def _stat(values: list) -> str:
    """mean and sample sd of the measured values ("-" where none was measured)."""
    v = [x for x in values if x is not None]
    if not v:
        return "- | -"
    return f"{statistics.mean(v):.4f} | {statistics.stdev(v) if len(v) > 1 else float('nan'):.4f}"


def table(rows: list[dict]) -> str:
    """The Markdown table: per grading and mode, the accepted runs' mean and seed spread (sd)."""
    out = [
        "| grading | masses | accepted | n2D | sd | n' | sd | interior n | sd | trials | plate steps |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name in CASES:
        for scaled in (False, True):
            runs = [r for r in rows if r["grading"] == name and r["scaled"] == scaled]
            got = [r for r in runs if r["n2d"] is not None]
            if not got:
                continue
            trials, steps = (statistics.mean(r[k] for r in got) for k in ("trials", "plate_steps"))
            cols = " | ".join(_stat([r[k] for r in got]) for k in ("n2d", "box", "interior"))
            mode = "scaled" if scaled else "true"
            out.append(f"| {name} | {mode} | {len(got)}/{len(runs)} | {cols} | {trials:.1f} | {steps:,.0f} |")
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("--only", action="append", choices=list(CASES))
    ap.add_argument("--seeds", type=int, default=3)
    args = ap.parse_args()
    done = [json.loads(line) for line in args.out.read_text().splitlines()] if args.out.exists() else []
    for name in args.only or list(CASES):
        for seed in range(args.seeds):
            for scaled in (True, False):
                if any(r["grading"] == name and r["scaled"] == scaled and r["seed"] == seed for r in done):
                    continue
                row = run_one(name, scaled, seed)
                print(json.dumps(row), flush=True)
                done.append(row)
                with args.out.open("a") as fh:
                    fh.write(json.dumps(row) + "\n")
    print(table(done))


if __name__ == "__main__":
    main()
