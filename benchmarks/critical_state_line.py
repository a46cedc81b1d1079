"""The 2D critical-state line e_cs(p') of a grading and its micro-parameters, over seeds.

    python benchmarks/critical_state_line.py [--pressures 50,100,200,400] [--grading paper] [--friction 0.5]
        [--rolling 0] [--stiffness-number K] [--seeds 2] [--disks 1500] [--inertial 1e-3]
        [--strain 3] [--workers 2] [--keep DIR]

Runs the periodic cell at every pressure on the seeds (every run one job) and prints a row per
pressure: the mean stress p', the void ratio e = (1 - phi) / phi and tau/sigma with their spread
over the seeds, the coordination, the stiffness number kappa = kn / (P t) and the mean overlap
over d, whether every seed was steady; then the fitted line e_cs = e_Gamma - lambda ln(p'/kPa)
and the wall time. ``--stiffness-number`` scales the contacts with the pressure (kappa fixed).
The paper's grading and the other case defaults (docs/critical-state.md, "The critical-state
line"). Results are kept in DIR (default: a temporary folder).
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
    ap.add_argument("--pressures", type=numbers, default=[50.0, 100.0, 200.0, 400.0])
    ap.add_argument("--grading", default="paper", help="a built-in grading or a sieve curve CSV")
    ap.add_argument("--friction", type=float, default=0.5)
    ap.add_argument("--rolling", type=float, default=0.0)
    ap.add_argument("--stiffness-number", type=float, default=None)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--disks", type=int, default=1500)
    ap.add_argument("--inertial", type=float, default=1e-3)
    ap.add_argument("--strain", type=float, default=3.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--keep", type=Path, default=None)
    args = ap.parse_args()

    from poro2d.critical_state import CriticalStateCase
    from poro2d.critical_state.line import run_critical_state_line
    from poro2d.store import Store

    root = args.keep or Path(tempfile.mkdtemp(prefix="critical-state-line-"))
    from poro2d.grading import GradingCurve, preset_grading

    is_csv = args.grading.lower().endswith(".csv")
    grading = GradingCurve.from_csv(args.grading) if is_csv else preset_grading(args.grading)
    case = CriticalStateCase(
        grading=grading,
        disks=args.disks,
        particle_friction=args.friction,
        rolling_friction=args.rolling,
        inertial_number=args.inertial,
        strain=args.strain,
        stiffness_number=args.stiffness_number,
    )
    t0 = time.perf_counter()
    r = run_critical_state_line(
        case, args.pressures, Store(root), seeds=args.seeds, options=RunOptions(workers=args.workers)
    )
    print(
        f"{args.grading}: f_p {args.friction:g}, mu_r {args.rolling:g}, I {args.inertial:g}, "
        f"{args.disks} disks, "
        f"{args.seeds} seeds, kappa {'Table 1' if args.stiffness_number is None else args.stiffness_number}"
    )
    print(
        f"{'P kPa':>6} {'p_mean kPa':>10} {'e':>24} {'tau/sigma':>22} {'z':>5} {'kappa':>7} "
        f"{'overlap/d':>9} {'steady':>6}"
    )
    for p in r.points:
        print(
            f"{p.pressure_kpa:6g} {p.mean_stress_kpa.mean:10.1f} {p.void_ratio.text(4):>24} "
            f"{p.stress_ratio.text():>22} {p.coordination.mean:5.2f} {p.stiffness_number:7.0f} "
            f"{p.mean_overlap_ratio.mean:9.2e} {'yes' if p.steady else 'NO':>6}"
        )
    line = r.line
    print(
        f"line: {line.text()} (lambda per decade {line.lambda_log10:.4f}, R2 "
        f"{'n/a' if line.r2 is None else f'{line.r2:.3f}'}, residual sd {line.residual_sd:.4f})"
    )
    print(f"pooled tau/sigma {r.stress_ratio.text()}; wall {time.perf_counter() - t0:.0f} s; kept in {root}")


if __name__ == "__main__":
    main()
