"""The direct shear box's biases on one specimen: wall friction and local damping against the shear plane.

    python benchmarks/box_bias.py SPECIMEN [--wall-friction 1.5,0.5,0] [--damping 0.7]
        [--normal-stress 50,100,200] [--max-displacement 0.004] [--workers 2] [--keep DIR]

For each (wall friction, local damping) it shears the specimen at every normal stress and
prints one row per test: the peak tau/sigma on the plate's stress (what every result reports),
the share of the plate's stress the shear plane carries at the peak, the peak tau/sigma on the
plane's own normal stress, and the end tau/sigma. The settings not varied are poro2d's
defaults (the paper's Table 1). Results are kept in DIR (default: a temporary folder), one
series per case, and the table is written as box_bias.json beside them.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from poro2d.execute import RunOptions


def numbers(text: str) -> list[float]:
    return [float(v) for v in text.split(",") if v.strip()]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("specimen", type=Path, help="a specimen checkpoint or a criterion folder")
    ap.add_argument("--wall-friction", type=numbers, default=[1.5, 0.5, 0.0])
    ap.add_argument("--damping", type=numbers, default=[0.7])
    ap.add_argument("--normal-stress", type=numbers, default=[50.0, 100.0, 200.0])
    ap.add_argument("--max-displacement", type=float, default=0.004)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--keep", type=Path, default=None)
    args = ap.parse_args()

    from poro2d.shear import ShearSeriesCase, run_shear
    from poro2d.store import Store

    out = args.keep or Path(tempfile.mkdtemp(prefix="poro2d-box-bias-"))
    rows = []
    print(f"{'mu_wall':>7} {'damping':>7} {'sigma':>6} {'tau/sig plate':>13} {'plane share':>11} "
          f"{'tau/sig plane':>13} {'tau/sig end':>11} {'time s':>7}")  # fmt: skip
    for mu_wall in args.wall_friction:
        for alpha in args.damping:
            settings = {"friction_wall": mu_wall, "local_damping": alpha,
                        "max_displacement": args.max_displacement}  # fmt: skip
            t0 = time.perf_counter()
            series = run_shear(
                ShearSeriesCase(args.specimen, args.normal_stress, settings),
                Store(out / f"wall{mu_wall:g}_damping{alpha:g}"),
                options=RunOptions(workers=args.workers, progress=False),
            )
            wall_s = time.perf_counter() - t0
            for t in series.tests:
                share = t.plane_load_fraction_at_peak
                row = {
                    "friction_wall": mu_wall,
                    "local_damping": alpha,
                    "normal_stress_kpa": t.normal_stress_kpa,
                    "peak_ratio_plate": t.peak_stress_ratio,
                    "plane_share_at_peak": share,
                    "peak_ratio_plane": t.peak_stress_ratio / share if share else None,
                    "end_ratio_plate": t.end["shear_stress_kpa"] / t.normal_stress_kpa,
                    "series_wall_time_s": wall_s,
                }
                rows.append(row)
                plane = "-" if row["peak_ratio_plane"] is None else f"{row['peak_ratio_plane']:.3f}"
                print(f"{mu_wall:7g} {alpha:7g} {t.normal_stress_kpa:6g} {t.peak_stress_ratio:13.3f} "
                      f"{share:11.3f} {plane:>13} {row['end_ratio_plate']:11.3f} {wall_s:7.0f}")  # fmt: skip
    (out / "box_bias.json").write_text(json.dumps({"specimen": str(args.specimen), "rows": rows}, indent=2))
    print(f"series and box_bias.json in {out}")


if __name__ == "__main__":
    main()
