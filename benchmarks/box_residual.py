"""The direct shear box's residual against the periodic critical-state reference, with its biases.

    python benchmarks/box_residual.py SPECIMEN [SPECIMEN ...] [--labels s0,s1] [--friction 3,0.5]
        [--wall-friction 1.5,0.5,0] [--damping 0.3,0.1] [--damping-wall 0] [--half-velocity 0.5]
        [--normal-stress 100] [--max-displacement 0.05] [--window-from 20] [--workers 2] [--keep DIR]

Each specimen (a criterion folder that accepted it; one per seed) is sheared at the normal
stress, long enough for the plate to stop rising, for every particle friction f_p and:

* every wall friction (``--wall-friction``) at the paper's local damping 0.7;
* every other local damping (``--damping``) at the wall friction ``--damping-wall``;
* at half the velocity (f_p in ``--half-velocity``, first specimen only), wall friction
  ``--damping-wall``, damping 0.7: the drag of local damping scales with the disks' speed.

Per test it prints the residual read where dilation has stopped
(:func:`poro2d.shear.residual.dilation_stopped_residual`): tau/sigma on the plate's stress and
on the shear plane's own normal stress, and the plane's share of the plate's load; beside it,
over a fixed window from ``--window-from`` mm to the end, the same ratios, the plate's net
slope and each ratio less that slope (Taylor's correction, which every test has), the mean
over the last fifth of the curve (the strength study's window) and the peak. Then, per case,
the means over the specimens against the periodic cell's steady tau/sigma of the same disks
(``--reference``; docs/critical-state.md: 0.289 +- 0.001 at f_p 0.5, no rolling friction,
100 kPa, I = 1e-3). Tests are kept in DIR/<case>/<label> (default: a temporary folder; a rerun
with the same DIR reads finished tests back, so cases run in parts are printed together) and
the table is written as box_residual.json. docs/shear.md ("The box's biases measured") has the
numbers.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
from dataclasses import replace
from pathlib import Path

from poro2d.execute import RunOptions

PAPER_DAMPING = 0.7


def numbers(text: str) -> list[float]:
    return [float(v) for v in text.split(",") if v.strip()]


def cases(args) -> list[dict]:
    """The settings varied, one dict per case, in the order they run (first specimen first)."""
    out = []
    for fp in args.friction:
        for wall in args.wall_friction:
            out.append(
                {"particle_friction": fp, "friction_wall": wall, "local_damping": PAPER_DAMPING, "speed": 1.0}
            )
        for alpha in args.damping:
            out.append(
                {
                    "particle_friction": fp,
                    "friction_wall": args.damping_wall,
                    "local_damping": alpha,
                    "speed": 1.0,
                }
            )
    for fp in args.half_velocity:
        out.append(
            {
                "particle_friction": fp,
                "friction_wall": args.damping_wall,
                "local_damping": PAPER_DAMPING,
                "speed": 0.5,
            }
        )
    return out


def case_name(c: dict) -> str:
    return f"fp{c['particle_friction']:g}_wall{c['friction_wall']:g}_damping{c['local_damping']:g}" + (
        "" if c["speed"] == 1.0 else f"_v{c['speed']:g}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("specimens", nargs="+", type=Path, help="criterion folders (one per seed)")
    ap.add_argument("--friction", type=numbers, default=[3.0, 0.5], help="particle frictions f_p")
    ap.add_argument("--wall-friction", type=numbers, default=[1.5, 0.5, 0.0])
    ap.add_argument("--damping", type=numbers, default=[0.3, 0.1], help="local damping besides 0.7")
    ap.add_argument("--damping-wall", type=float, default=0.0, help="wall friction of the damping cases")
    ap.add_argument("--half-velocity", type=numbers, default=[0.5], help="f_p of the v/2 case ('' for none)")
    ap.add_argument("--normal-stress", type=float, default=100.0)
    ap.add_argument("--max-displacement", type=float, default=0.05)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--keep", type=Path, default=None)
    ap.add_argument(
        "--labels", default="", help="the specimens' folder names, e.g. s0,s1 (default: s0, s1, ...)"
    )
    ap.add_argument("--reference", type=float, default=0.289, help="the periodic cell's steady tau/sigma")
    ap.add_argument("--window-from", type=float, default=20.0, help="mm: the fixed window's start")
    args = ap.parse_args()

    from poro2d.shear import ShearSettings
    from poro2d.shear.case import ShearCase
    from poro2d.shear.pool import ShearJob, execute_jobs
    from poro2d.specimen.specimen_set import SpecimenSet

    out = args.keep or Path(tempfile.mkdtemp(prefix="poro2d-box-residual-"))
    labels = args.labels.split(",") if args.labels else [f"s{k}" for k in range(len(args.specimens))]
    specimens = SpecimenSet.accepted(dict(zip(labels, args.specimens, strict=True))).read()
    base = ShearSettings(max_displacement=args.max_displacement, stop_after_peak=0.0)
    jobs = []
    for spec_label, specimen in zip(labels, specimens.contents(), strict=True):
        for c in cases(args):
            if c["speed"] != 1.0 and spec_label != labels[0]:
                continue
            settings = replace(
                base,
                particle_friction=c["particle_friction"],
                friction_wall=c["friction_wall"],
                local_damping=c["local_damping"],
                velocity=base.velocity * c["speed"],
            )
            case = ShearCase(specimen, args.normal_stress, settings)
            folder = out / case_name(c) / spec_label
            jobs.append(
                (
                    c,
                    spec_label,
                    ShearJob(
                        ("test", args.normal_stress, case_name(c), spec_label),
                        case,
                        str(folder),
                        keep_peak=False,
                        series=f"{case_name(c)} {spec_label}",
                    ),
                )
            )
    t0 = time.perf_counter()
    results = execute_jobs([j for _, _, j in jobs], args.workers, RunOptions(progress=False))
    print(f"{len(jobs)} tests in {time.perf_counter() - t0:.0f} s (finished ones read back); kept in {out}")
    report(jobs, results, args, out)


def window(curve, from_mm: float) -> dict:
    """Over [from_mm, end]: mean tau over the plate's and the plane's mean normal stress, the plate's
    least-squares slope, and each ratio less that slope (Taylor's balance averaged over the window:
    mean tau / sigma = mu + net rise / shear, so the slope is the dilatancy left in the mean)."""
    import numpy as np

    x = curve["shear_displacement_mm"]
    inside = x >= from_mm
    tau = float(np.mean(curve["shear_stress_kpa"][inside]))
    plate = tau / float(np.mean(curve["normal_stress_kpa"][inside]))
    plane = tau / float(np.mean(curve["plane_normal_stress_kpa"][inside]))
    slope = float(np.polyfit(x[inside], curve["plate_displacement_mm"][inside], 1)[0])
    return {"window_from_mm": from_mm, "window_ratio_plate": plate, "window_ratio_plane": plane,
            "window_plate_slope": slope, "window_taylor_plate": plate - slope,
            "window_taylor_plane": plane - slope}  # fmt: skip


def report(jobs, results, args, out: Path) -> None:
    from poro2d.shear.residual import dilation_stopped_residual, tail_residual

    rows = []
    print(f"{'f_p':>4} {'wall':>4} {'damp':>4} {'v':>4} {'spec':>4} | dilation stopped: {'from':>5} "
          f"{'plate':>6} {'plane':>6} {'share':>5} | from {args.window_from:g} mm: {'plate':>6} {'plane':>6} "
          f"{'slope':>6} {'pl-sl':>6} {'pn-sl':>6} | {'tail':>6} {'peak':>6} {'time s':>6}")  # fmt: skip
    for (c, spec_label, _job), res in zip(jobs, results, strict=True):
        r = dilation_stopped_residual(res.curve, res.d_mean_m)
        w = window(res.curve, args.window_from)
        tail = tail_residual(res.curve)
        row = {**c, "specimen": spec_label, "normal_stress_kpa": res.normal_stress_kpa,
               "peak_stress_ratio": res.peak_stress_ratio, "tail_ratio_plate": tail,
               "wall_time_shear_s": res.wall_time_shear_s, **w, **r.to_dict()}  # fmt: skip
        rows.append(row)
        stopped = (f"{r.start_mm:5.1f} {r.stress_ratio:6.3f} {r.plane_stress_ratio:6.3f} {r.plane_share:5.2f}"
                   if r.reached else f"{'not reached':>26}")  # fmt: skip
        print(f"{c['particle_friction']:4g} {c['friction_wall']:4g} {c['local_damping']:4g} {c['speed']:4g} "
              f"{spec_label:>4} | {'':17} {stopped} | {'':{len(f'from {args.window_from:g} mm:')}} "
              f"{w['window_ratio_plate']:6.3f} {w['window_ratio_plane']:6.3f} "
              f"{w['window_plate_slope']:+6.3f} "
              f"{w['window_taylor_plate']:6.3f} {w['window_taylor_plane']:6.3f} | {tail:6.3f} "
              f"{res.peak_stress_ratio:6.3f} {res.wall_time_shear_s:6.0f}")  # fmt: skip
    summarise(rows, args.reference)
    (out / "box_residual.json").write_text(
        json.dumps(
            {"specimens": [str(s) for s in args.specimens], "reference": args.reference, "rows": rows},
            indent=2,
        )  # fmt: skip
    )
    print(f"table in {out / 'box_residual.json'}")


def summarise(rows: list[dict], reference: float) -> None:
    """Per case, means over the specimens: the residual where dilation stopped (those that reached
    it) and the window's Taylor-corrected ratios, on the plate and on the plane, against the reference."""
    print(f"\nmeans over specimens (reference tau/sigma {reference:g}; differences in brackets):")
    case_of = lambda r: (r["particle_friction"], r["friction_wall"], r["local_damping"], r["speed"])  # noqa: E731
    keys = sorted({case_of(r) for r in rows}, key=lambda k: (-k[0], -k[1], -k[2], -k[3]))

    def mean(got, key):
        vals = [r[key] for r in got if r.get(key) is not None]
        return (sum(vals) / len(vals), len(vals)) if vals else (math.nan, 0)

    for key in keys:
        got = [
            r
            for r in rows
            if (r["particle_friction"], r["friction_wall"], r["local_damping"], r["speed"]) == key
        ]
        plate, k = mean(got, "stress_ratio")
        plane, _ = mean(got, "plane_stress_ratio")
        tp, n = mean(got, "window_taylor_plate")
        tn, _ = mean(got, "window_taylor_plane")
        print(f"  f_p {key[0]:g} wall {key[1]:g} damping {key[2]:g} v x{key[3]:g}: dilation stopped in {k} "
              f"of {len(got)}: plate {plate:.3f} ({plate - reference:+.3f}), plane {plane:.3f} "
              f"({plane - reference:+.3f}); window less slope, {n}: plate {tp:.3f} ({tp - reference:+.3f}), "
              f"plane {tn:.3f} ({tn - reference:+.3f})")  # fmt: skip


if __name__ == "__main__":
    main()
