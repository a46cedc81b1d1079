"""Wall time of the paper-preset criterion (Fig. 3), per stage.

    python benchmarks/bench_criterion.py [--threads 2] [--keep DIR]

Prints one row per trial (preparation and plate stages) and the total, with the
machine's load average, and writes bench_criterion.json next to the results.
The numba kernels are compiled (or loaded from cache) before the clock starts.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--keep", type=Path, default=None, help="output folder to keep (default: temporary)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    from poro2d.criterion import PorosityCriterion
    from poro2d.criterion.config import paper_preset
    from poro2d.grading import paper_grading
    from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen
    from poro2d.store import Store

    # warm-up: compile or load every kernel outside the timed run
    prepare_specimen(SpecimenSpec(width=0.03, height=0.02, layers=1), paper_grading(), 0.2, seed=1)

    spec, grading, settings, seed = paper_preset().with_seed(args.seed).build(threads=args.threads)
    out = args.keep or Path(tempfile.mkdtemp(prefix="poro2d-bench-"))
    if out.exists() and any(out.iterdir()):
        raise SystemExit(f"{out} is not empty: the benchmark needs a fresh folder")
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    result = PorosityCriterion(spec, grading, settings, seed=seed, store=Store(out)).run()
    total = time.perf_counter() - t0
    load1 = os.getloadavg()
    print(f"{'trial':>6} {'n2D':>6} {'disks':>6} {'prepare s':>10} {'plate s':>8} {'n_prime':>8} accepted")
    for r in result["iterations"]:
        print(
            f"{r['iteration']:>6} {r['trial_porosity']:>6.3f} {r['particle_count']:>6} "
            f"{r['time_prepare_s']:>10.1f} {r['time_plate_s']:>8.1f} "
            f"{r['new_porosity']:>8.4f} {r['accepted']}"
        )
    print(f"total {total:.1f} s with {args.threads} thread(s); final n2D = {result['final_porosity']}")
    print(f"load average before {load0[0]:.2f}, after {load1[0]:.2f} (2 cores)")
    rec = {
        "total_s": total,
        "threads": args.threads,
        "load_before": load0,
        "load_after": load1,
        "final_porosity": result["final_porosity"],
        "trials": [
            {k: r[k] for k in ("trial_porosity", "particle_count", "time_prepare_s", "time_plate_s")}
            for r in result["iterations"]
        ],
    }
    (out / "bench_criterion.json").write_text(json.dumps(rec, indent=2))


if __name__ == "__main__":
    main()
