"""The fabric of the periodic shear cell's steady state over seeds: a_c, a_n, a_t and Z_m.

    python benchmarks/fabric_steady.py [--out fabric-steady] [--disks 600] [--strain 4] [--window 1.5]
                                       [--seeds 3] [--seed 1] [--workers 1]

Runs the critical-state study (paper grading, f_p = 0.5, mu_r = 0, 100 kPa, I = 1e-3) into
``--out`` (a finished folder is read back, not run again), then prints each seed's means over
the steady window gamma >= ``--window`` of the fabric columns of its ``series.csv``, their
spread over the seeds, and the seeds' mean of each column in bins of gamma (how a_c grows from
the isotropic start and settles). The numbers of docs/fabric.md come from it.
"""

from __future__ import annotations

import argparse

import numpy as np

#: the bins of gamma the growth is shown in
BINS = (0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 100.0)
COLUMNS = ("a_c", "a_n", "a_t", "z_mech", "stress_ratio")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="fabric-steady")
    ap.add_argument("--disks", type=int, default=600)
    ap.add_argument("--strain", type=float, default=4.0)
    ap.add_argument("--window", type=float, default=1.5)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=1)
    args = ap.parse_args()

    from poro2d.critical_state import CriticalStateCase
    from poro2d.critical_state.run import CriticalStateStudy, run_critical_states
    from poro2d.execute import RunOptions
    from poro2d.measure.spread import Spread
    from poro2d.store import Store

    case = CriticalStateCase(
        disks=args.disks, particle_friction=0.5, strain=args.strain, window_start=args.window, seed=args.seed
    )
    study = CriticalStateStudy(case, args.seeds)
    options = RunOptions(workers=args.workers, progress=False)
    result = run_critical_states(study, Store(args.out), options=options)
    per_seed = {}
    for seed, test in zip(result.seeds, result.tests, strict=True):
        s = test.series
        steady = s.gamma >= args.window
        per_seed[seed] = {k: float(np.mean(s[k][steady])) for k in COLUMNS}
        row = ", ".join(f"{k} {v:.3f}" for k, v in per_seed[seed].items())
        print(f"seed {seed}: {test.disks} disks, {steady.sum()} rows in the window: {row}")
    for k in COLUMNS:
        print(f"steady {k}: {Spread.of([v[k] for v in per_seed.values()]).text(3)} over seeds {result.seeds}")
    print("gamma bin: seeds' mean of " + ", ".join(COLUMNS))
    for lo, hi in zip(BINS[:-1], BINS[1:], strict=True):
        means = []
        for k in COLUMNS:
            values = [t.series[k][(t.series.gamma > lo) & (t.series.gamma <= hi)] for t in result.tests]
            means.append(np.mean(np.concatenate(values)) if sum(v.size for v in values) else np.nan)
        print(f"  ({lo:g}, {hi:g}]: " + ", ".join(f"{m:.3f}" for m in means))


if __name__ == "__main__":
    main()
