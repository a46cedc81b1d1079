"""Speed of the periodic shear cell: particle-steps per second and wall time.

    python benchmarks/bench_critical_state.py [--disks 1500] [--steps 20000] [--inertial 1e-3]

Builds the cell of a critical-state case (paper grading, Table 1's contacts, f_p = 0.5),
compresses it to 100 kPa, then times ``--steps`` steps of steady shear at the inertial number
(after a first short block that compiles the kernels, which is not timed). One thread.
"""

from __future__ import annotations

import argparse
import time


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--disks", type=int, default=1500)
    ap.add_argument("--steps", type=int, default=20_000)
    ap.add_argument("--inertial", type=float, default=1e-3)
    ap.add_argument("--rolling", type=float, default=0.0)
    args = ap.parse_args()

    from poro2d.critical_state import CriticalStateCase
    from poro2d.critical_state.cell import barostat_gain, compress, loose_cell, shear_rate

    case = CriticalStateCase(disks=args.disks, inertial_number=args.inertial, rolling_friction=args.rolling)
    t0 = time.perf_counter()
    cell = loose_cell(case)
    steps = compress(cell, case)
    t_compress = time.perf_counter() - t0
    rate = shear_rate(cell, case)
    cell.shear(rate, case.pressure_kpa * 1e3, barostat_gain(cell, case), rate)
    cell.run(100)
    t1 = time.perf_counter()
    block = cell.run(args.steps)
    wall = time.perf_counter() - t1
    print(
        f"disks {cell.n}, dt {cell.dt:.3g} s, "
        f"compression {steps} steps in {t_compress:.1f} s (with compiling)"
    )
    print(
        f"shear: {args.steps} steps in {wall:.2f} s, {cell.n * args.steps / wall:.3g} particle-steps/s, "
        f"{block.rebuilds} rebuilds, gamma {cell.strain:.3f}"
    )
    per_strain = 1.0 / (rate * cell.dt)
    print(
        f"one unit of shear strain at I = {args.inertial:g}: {per_strain:.3g} steps, "
        f"about {per_strain * wall / args.steps:.0f} s"
    )


if __name__ == "__main__":
    main()
