"""The periodic reference against the literature: the steady state for several I and mu_r.

    python benchmarks/critical_state_reference.py [--inertial 1e-3,1e-2] [--rolling 0]
        [--seeds 3] [--disks 1500] [--strain 3] [--friction 0.5] [--workers 2] [--keep DIR]

For each (inertial number, rolling friction) it runs the periodic cell on the seeds and prints
one row: tau/sigma and the angle with their spread over the seeds, the solid fraction, the
inertial number reached, the coordination, whether every seed was steady, and the wall time.
The paper's grading, P = 100 kPa and the other case defaults (docs/critical-state.md). Results
are kept in DIR (default: a temporary folder), one study per row.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from poro2d.execute import RunOptions


def numbers(text: str) -> list[float]:
    return [float(v) for v in text.split(",") if v.strip()]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--inertial", type=numbers, default=[1e-3, 1e-2])
    ap.add_argument("--rolling", type=numbers, default=[0.0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--disks", type=int, default=1500)
    ap.add_argument("--strain", type=float, default=3.0)
    ap.add_argument("--friction", type=float, default=0.5)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--keep", type=Path, default=None)
    args = ap.parse_args()

    from poro2d.critical_state import CriticalStateCase, CriticalStateStudy, run_critical_states
    from poro2d.store import Store

    root = args.keep or Path(tempfile.mkdtemp(prefix="critical-state-"))
    print(
        f"{'I':>7} {'mu_r':>5} {'tau/sigma':>22} {'phi deg':>6} {'solid fraction':>22} {'I reached':>9} "
        f"{'z':>5} {'steady':>6} {'wall s':>7}",
        flush=True,
    )
    for inertial in args.inertial:
        for mu_r in args.rolling:
            case = CriticalStateCase(
                disks=args.disks,
                inertial_number=inertial,
                rolling_friction=mu_r,
                strain=args.strain,
                particle_friction=args.friction,
            )
            t0 = time.perf_counter()
            r = run_critical_states(
                CriticalStateStudy(case, args.seeds),
                Store(root / f"I{inertial:g}_mur{mu_r:g}"),
                options=RunOptions(workers=args.workers),
            )
            print(
                f"{inertial:7.0e} {mu_r:5.2f} {r.stress_ratio.text():>22} {r.friction_angle_deg.mean:6.1f} "
                f"{r.solid_fraction.text():>22} {r.inertial_number.mean:9.2e} {r.coordination.mean:5.2f} "
                f"{'yes' if r.steady else 'NO':>6} {time.perf_counter() - t0:7.0f}",
                flush=True,
            )
    print(f"results in {root}")


if __name__ == "__main__":
    main()
