"""Preparation steps and wall time per specimen, for each equilibrium measure.

    python benchmarks/bench_preparation.py [--grading paper] [--mu 0.05] [--porosity 0.19]
        [--measures max,mean,loaded_max] [--ratio 1e-3] [--mean-ratio 1e-4] [--quick] [--seed 1]

Prepares the same specimen (grading, preparation friction, trial porosity, seed) once per
equilibrium measure and prints, per measure: the steps of every layer and of the
working-friction stage (``s``: the layer ended settled, not by its ratio), whether every stage
reached its measure, the wall time, the rattler
fraction of the last layer, and the interior porosity of the result (2 d50 clear of walls
and surface), so the cost of a measure can be weighed against what it changes in the
packing. The numba kernels are compiled (or loaded from cache) before the clock starts.
"""

from __future__ import annotations

import argparse
import os
import time


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grading", default="paper", help="a built-in grading: paper, wide_cu4, wide_cu6")
    ap.add_argument("--mu", type=float, default=0.05, help="preparation friction")
    ap.add_argument("--porosity", type=float, default=0.19, help="trial porosity")
    ap.add_argument("--measures", default="max,mean,loaded_max")
    ap.add_argument("--ratio", type=float, default=1e-3, help="limit of the max and loaded_max ratios")
    ap.add_argument("--mean-ratio", type=float, default=1e-4, help="limit of the mean ratio")
    ap.add_argument("--quick", action="store_true", help="the quick box (0.08 m x 0.04 m, 2 layers)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--budget", type=int, default=400_000, help="steps per stage before the fallback")
    ap.add_argument(
        "--settle-drift",
        type=float,
        default=None,
        help="end a layer once settled: its centre of mass moves < this many d50 per 10 000 steps",
    )
    args = ap.parse_args()

    from poro2d.grading import paper_grading, preset_grading
    from poro2d.measure.specimen_porosity import measure_specimen
    from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen

    prepare_specimen(SpecimenSpec(width=0.03, height=0.02, layers=1), paper_grading(), 0.2, seed=1)
    grading = preset_grading(args.grading)
    box = {"width": 0.08, "height": 0.04, "layers": 2} if args.quick else {}
    print(f"grading {args.grading}, mu_prep {args.mu:g}, trial porosity {args.porosity:g}, seed {args.seed}, "
          f"{'quick box' if args.quick else 'paper box'}; load average {os.getloadavg()[0]:.2f}")  # fmt: skip
    print(f"{'measure':>10} {'limit':>7} {'steps per stage (layers..., working friction)':>48} "
          f"{'all':>4} {'wall s':>7} {'rattlers':>8} {'interior n':>16} {'box n':>7}")  # fmt: skip
    for measure in args.measures.split(","):
        limit = args.mean_ratio if measure == "mean" else args.ratio
        spec = SpecimenSpec(
            friction_prep=args.mu, equilibrium=measure, ratio=limit, max_steps_per_stage=args.budget,
            settle_drift=args.settle_drift, **box,
        )  # fmt: skip
        t0 = time.perf_counter()
        sim, rep = prepare_specimen(spec, grading, args.porosity, seed=args.seed)
        wall = time.perf_counter() - t0
        stages = [f"{layer['steps']}{'s' if layer['attempts'][-1]['ended_by'] == 'settled' else ''}"
                  for layer in rep["layers"]]  # fmt: skip
        if rep["final_stage"]:
            stages.append(rep["final_stage"]["steps"])
        rattlers = rep["layers"][-1]["attempts"][-1]["rattler_fraction"]
        top = spec.height  # the plate stays at H while a specimen is prepared
        p = sim.particles
        try:
            m = measure_specimen(p.pos, p.radius, spec.width, top)
            inner = f"{m.interior_porosity:.4f}+-{m.interior_porosity_std:.4f}"
        except Exception as e:  # a specimen too small or too broken to measure
            inner = type(e).__name__
        print(f"{measure:>10} {limit:>7.0e} {' '.join(str(s) for s in stages):>48} "
              f"{'yes' if rep['converged'] else 'no':>4} {wall:>7.1f} {rattlers:>8.3f} {inner:>16} "
              f"{rep['box_porosity']:>7.4f}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
