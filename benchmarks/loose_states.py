"""Loose states of round disks: rolling resistance while the layers are built, under the criterion.

Runs the density-mode criterion (the quick box, 0.08 m x 0.04 m in 2 layers, the paper's plate,
the window 2 % of G, trials refined to 0.002, layers that end once settled) at a preparation
friction ``--mu-prep`` for every rolling friction of ``--rolling`` and every seed, and prints
the accepted trial, the box porosity n' and the specimen's interior solid fraction (1 - the
interior porosity of measurement circles, as the relation reports it), with the run time.
``--keep-working`` keeps the preparation's rolling friction in the working values
(``rolling_friction``), a choice a user must make knowingly (docs/criterion.md).
``--growth-steps`` sets the steps of each of the layers' growth increments (150 by default):
more steps grow the disks more gently.

    PYTHONPATH=src python benchmarks/loose_states.py --rolling 0 0.2 0.5 1.0 --seeds 0 1 2
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from poro2d.criterion import CriterionCase, run_criterion
from poro2d.execute.options import RunOptions
from poro2d.store import Store


def config(
    mu_prep: float, rolling: float, seed: int, first: float, keep: bool, full: bool = False,
    growth_steps: int | None = None,
) -> dict:  # fmt: skip
    """The criterion config of one case: density mode's settings on the quick box (``full``: on
    the paper's box under the fill acceptance, as the relation runs it)."""
    box = {} if full else {"width": 0.08, "height": 0.04, "layers": 2}
    specimen = {**box, "friction_prep": mu_prep, "rolling_friction_prep": rolling, "settle_drift": 1e-3}
    if keep:
        specimen["rolling_friction"] = rolling
    if growth_steps is not None:
        specimen["growth_steps"] = growth_steps
    criterion = {
        "acceptance": "fill" if full else "plate", "force_fraction": 0.02, "refine_tolerance": 0.002,
        "max_iterations": 10, "trial_porosity": first,
    }  # fmt: skip
    return {"seed": seed, "specimen": specimen, "grading": {"preset": "paper"}, "criterion": criterion}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mu-prep", type=float, default=1.0)
    ap.add_argument("--rolling", type=float, nargs="+", default=[0.0, 0.2, 0.5, 1.0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--first", type=float, default=0.22, help="first trial porosity")
    ap.add_argument("--keep-working", action="store_true", help="keep mu_r in the working values")
    ap.add_argument("--full", action="store_true", help="the paper's box under the fill acceptance")
    ap.add_argument("--growth-steps", type=int, default=None, help="steps per growth increment")
    ap.add_argument("--out", default=None, help="folder to keep each case's criterion files")
    args = ap.parse_args()
    print(
        "mu_prep  mu_r_prep  kept  seed  trial     n2D     n'      interior  solid_fraction  trials  time_s"
    )
    for rolling in args.rolling:
        for seed in args.seeds:
            cfg = config(
                args.mu_prep, rolling, seed, args.first, args.keep_working, args.full, args.growth_steps
            )
            store = None
            if args.out:
                box = "full_" if args.full else ""
                kept = "_kept" if args.keep_working else ""
                grow = "" if args.growth_steps is None else f"_g{args.growth_steps}"
                tag = f"{box}mu{args.mu_prep:g}_r{rolling:g}{kept}{grow}_s{seed}"
                store = Store(Path(args.out) / tag)
            t0 = time.perf_counter()
            res = run_criterion(CriterionCase.from_config(cfg), store, options=RunOptions(progress=False))
            print(row(args, rolling, seed, res, time.perf_counter() - t0), flush=True)


def measured(res) -> dict | None:
    """The accepted trial, else the last trial whose packing was measured (plate settled)."""
    rows = [t.to_dict() for t in res.iterations]
    rows = [t for t in rows if t.get("interior_porosity") is not None]
    accepted = [t for t in rows if t["accepted"]]
    return (accepted or rows or [None])[-1]


def row(args, rolling: float, seed: int, res, seconds: float) -> str:
    """One printed line: the case, what it accepted, the packing it measured, the time."""
    t = measured(res)
    nan = float("nan")
    box = nan if t is None else t["box_porosity"]
    interior = nan if t is None else t["interior_porosity"]
    kept = "yes" if args.keep_working else "no"
    what = "accepted" if res.converged else ("last" if t is not None else "none")
    trial = nan if t is None else t["trial_porosity"]
    return (
        f"{args.mu_prep:7.2f}  {rolling:9.2f}  {kept:4s}  {seed:4d}  {what:8s}  {trial:6.3f}  {box:.4f}  "
        f"{interior:8.4f}  {1.0 - interior:14.4f}  {len(res.iterations):6d}  {seconds:6.0f}"
    )


if __name__ == "__main__":
    main()
