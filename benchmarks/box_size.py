"""The box-size study: peak, residual and dilation of the paper's sand in boxes of four sizes.

    python benchmarks/box_size.py --out DIR [--boxes quick,paper,x1.5,x2] [--seeds 2]
        [--quick-seeds 3] [--friction 0.5] [--normal-stress 100] [--workers 2]

The boxes (``BOXES``): the quick look's (0.08 m x 0.04 m, as ``poro2d paper --quick`` builds
it), the paper's (0.305 m x 0.124 m, ``poro2d criterion --preset paper``) and two larger ones
scaled in width and height by 1.5 and 2 (the paper's W/H), with the paper's layer height
(31 mm: 6 and 8 layers) and otherwise the paper preset. Each specimen is built by
``poro2d criterion`` (one process a seed, ``--quiet --threads 1``) in DIR/specimens/<box>-s<seed>,
unless it is there already, and sheared at the normal stress with f_p replaced by
``--friction``, the box's walls and damping as Table 1, ``stop_after_peak = 0`` and the
box's displacement (50 mm; 40 mm, half its width, in the quick box), as docs/shear.md's
residual study shears the paper box; one process a test, kept in DIR/shear/<box>/s<seed>.
A rerun with the same DIR reads finished specimens and tests back.

Per test and per box (mean +- sd over the seeds) it prints: the box in d_max and its disks,
the peak tau/sigma on the plate and on the shear plane, the residual where dilation stopped
(:func:`poro2d.shear.residual.dilation_stopped_residual`, plate and plane, or "not reached"),
beside it the residual study's window from 20 mm to the end less the plate's slope there
(Taylor's correction, which every test has), the plate's rise at the peak and at the end, the
largest dilation rate (the 2 mm secant of ``poro2d strength``, as an angle) and the wall times;
the table goes to DIR/box_size.json.
docs/shear.md ("Box size") has the numbers.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from poro2d.execute import RunOptions

#: the paper's layer height (0.124 m in 4 layers): a larger box keeps it, so every layer is
#: compacted as the paper's are
PAPER_LAYER_M = 0.031
#: mm: the fixed window's start (to the end) of the residual study's Taylor-corrected ratios, which every
#: test has, also where its plate still rises (``benchmarks/box_residual.py``)
WINDOW_FROM_MM = 20.0


@dataclass(frozen=True)
class Box:
    """One box of the study: its size, layers, the criterion's extra settings and the shear length."""

    width: float
    height: float
    layers: int
    max_displacement: float
    criterion: dict = field(default_factory=dict)
    preset: bool = False  # built as ``--preset paper`` (the paper's own box)


def scaled(factor: float) -> Box:
    """The paper's box scaled by ``factor`` in width and height, its layers as high as the paper's."""
    height = round(0.124 * factor, 4)
    return Box(round(0.305 * factor, 4), height, round(height / PAPER_LAYER_M), 0.05)


BOXES = {
    "quick": Box(0.08, 0.04, 2, 0.04, {"force_fraction": 0.05, "acceptance": "plate"}),
    "paper": Box(0.305, 0.124, 4, 0.05, preset=True),
    "x1.5": scaled(1.5),
    "x2": scaled(2.0),
}


def config_text(box: Box) -> str:
    """The criterion config of ``box``: the paper preset with its box, layers and criterion extras."""
    lines = ["seed = 0", "[specimen]", f"width = {box.width!r}", f"height = {box.height!r}",
             f"layers = {box.layers}", "[grading]", 'preset = "paper"',
             "[criterion]", "n_lab = 0.3434"]  # fmt: skip
    lines += [f"{k} = {json.dumps(v)}" for k, v in box.criterion.items()]
    return "\n".join(lines) + "\n"


def build_command(out: Path, name: str, seed: int) -> list[str]:
    """The ``poro2d criterion`` command that builds (or reads back) one specimen."""
    box = BOXES[name]
    if box.preset:
        source = ["--preset", "paper"]
    else:
        config = out / "configs" / f"box_{name}.toml"
        config.parent.mkdir(parents=True, exist_ok=True)
        if not config.exists() or config.read_text() != config_text(box):
            config.write_text(config_text(box))
        source = ["--config", str(config)]
    folder = out / "specimens" / f"{name}-s{seed}"
    return [sys.executable, "-m", "poro2d.cli", "criterion", *source, "--seed", str(seed),
            "--out", str(folder), "--quiet", "--threads", "1"]  # fmt: skip


def criterion_record(folder: Path) -> dict | None:
    """The finished criterion's ``result.json`` of ``folder`` (None while it has none)."""
    path = folder / "result.json"
    return json.loads(path.read_text()) if path.exists() else None


def build_missing(out: Path, plan: list[tuple[str, int]], processes: int) -> None:
    """Run the criterion for every specimen of ``plan`` without a result, ``processes`` at a time."""
    todo = [(n, s) for n, s in plan if criterion_record(out / "specimens" / f"{n}-s{s}") is None]
    running: list[tuple[str, subprocess.Popen, float]] = []
    while todo or running:
        while todo and len(running) < processes:
            name, seed = todo.pop(0)
            log = out / "specimens" / f"{name}-s{seed}.log"
            log.parent.mkdir(parents=True, exist_ok=True)
            with log.open("w") as f:
                proc = subprocess.Popen(build_command(out, name, seed), stdout=f, stderr=subprocess.STDOUT)
            running.append((f"{name}-s{seed}", proc, time.perf_counter()))
        time.sleep(1.0)
        for item in [r for r in running if r[1].poll() is not None]:
            running.remove(item)
            label, proc, t0 = item
            print(f"built {label}: exit {proc.returncode} after {time.perf_counter() - t0:.0f} s", flush=True)


def accepted_specimens(out: Path, plan: list[tuple[str, int]]) -> dict[tuple[str, int], Path]:
    """The specimens of ``plan`` their criterion accepted; the others are named and left out."""
    found = {}
    for name, seed in plan:
        folder = out / "specimens" / f"{name}-s{seed}"
        rec = criterion_record(folder)
        if rec is not None and rec.get("converged"):
            found[(name, seed)] = folder
        else:
            print(f"{name} seed {seed}: no accepted specimen ({folder}); left out")
    return found


def shear_jobs(out: Path, found: dict[tuple[str, int], Path], args) -> list:
    """One shear job a specimen, each in its own folder: the residual study's settings, the box's length."""
    from poro2d.shear import ShearSettings
    from poro2d.shear.case import ShearCase
    from poro2d.shear.pool import ShearJob
    from poro2d.specimen.specimen_set import SpecimenSet

    labels = {f"{n}-s{s}": folder for (n, s), folder in found.items()}
    contents = SpecimenSet.accepted(labels).read().contents()
    jobs = []
    for ((name, seed), _), specimen in zip(found.items(), contents, strict=True):
        length, fp = BOXES[name].max_displacement, args.friction
        settings = ShearSettings(max_displacement=length, stop_after_peak=0.0, particle_friction=fp)
        folder = out / "shear" / name / f"s{seed}"
        case = ShearCase(specimen, args.normal_stress, settings)
        job = ShearJob(("test", args.normal_stress, name, seed), case, str(folder), keep_peak=False,
                       series=f"{name} s{seed}")  # fmt: skip
        jobs.append((name, seed, specimen, job))
    return jobs


def test_row(name: str, seed: int, specimen, res, folder: Path) -> dict:
    """What one test says of its box: size, peak, residual where dilation stopped, dilation, times."""
    from box_residual import window  # the residual study's fixed window with Taylor's correction

    from poro2d.shear.box_scale import box_scale
    from poro2d.shear.residual import dilation_stopped_residual
    from poro2d.shear.strength import max_dilation_angle

    scale = box_scale(*specimen.box(), specimen.arrays["particles.radius"])
    stopped = dilation_stopped_residual(res.curve, res.d_mean_m)
    psi = max_dilation_angle(res.curve, res.peak_window_m)
    share = res.plane_load_fraction_at_peak
    fixed = window(res.curve, WINDOW_FROM_MM)
    build = criterion_record(folder) or {}
    return {
        "box": name, "seed": seed, "width_m": scale.width_m, "height_m": scale.height_m,
        "width_over_d_max": scale.width_over_d_max, "height_over_d_max": scale.height_over_d_max,
        "disks": scale.disks, "n2d": build.get("final_porosity"), "build_time_s": build.get("time_total_s"),
        "peak_plate": res.peak_stress_ratio,
        "peak_plane": res.peak_stress_ratio / share if share else None,
        "peak_at_mm": 1e3 * res.shear_displacement_at_peak_m,
        "residual_reached": stopped.reached, "residual_plate": stopped.stress_ratio,
        "residual_plane": stopped.plane_stress_ratio, "residual_from_mm": stopped.start_mm,
        "taylor_plate": fixed["window_taylor_plate"], "taylor_plane": fixed["window_taylor_plane"],
        "slope_from_window": fixed["window_plate_slope"],
        "rise_at_peak_mm": res.plate_displacement_at_peak_mm, "rise_at_end_mm": res.end.plate_displacement_mm,
        "max_dilation_rate": math.tan(math.radians(psi)), "max_dilation_angle_deg": psi,
        "sheared_mm": 1e3 * res.end_shear_displacement_m, "shear_time_s": res.wall_time_shear_s,
    }  # fmt: skip


def mean_sd(values: list) -> tuple[float, float, int]:
    """(mean, sample sd, count) of the values that are there (NaN when none; sd 0 for one)."""
    v = [float(x) for x in values if x is not None]
    if not v:
        return math.nan, math.nan, 0
    m = sum(v) / len(v)
    sd = math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1)) if len(v) > 1 else 0.0
    return m, sd, len(v)


def text(values: list, digits: int = 3) -> str:
    """``mean +- sd`` of the values there, with ``(k/n)`` when some are missing; ``-`` for none."""
    m, sd, k = mean_sd(values)
    if k == 0:
        return "not reached" if values else "-"
    out = f"{m:.{digits}f} +- {sd:.{digits}f}"
    return out + (f" ({k}/{len(values)})" if k < len(values) else "")


#: the columns of the per-box table: heading, row key, digits
COLUMNS = [
    ("peak t/s plate", "peak_plate", 3), ("peak t/s plane", "peak_plane", 3), ("peak at mm", "peak_at_mm", 1),
    ("resid. plate", "residual_plate", 3), ("resid. plane", "residual_plane", 3),
    ("window less slope plate", "taylor_plate", 3), ("plane", "taylor_plane", 3),
    ("slope", "slope_from_window", 3),
    ("rise at peak mm", "rise_at_peak_mm", 2), ("rise at end mm", "rise_at_end_mm", 2),
    ("max dy/dx", "max_dilation_rate", 3), ("psi_max deg", "max_dilation_angle_deg", 1),
    ("build s", "build_time_s", 0), ("shear s", "shear_time_s", 0),
]  # fmt: skip


def print_tests(rows: list[dict]) -> None:
    """One line a test."""
    print(f"{'box':>5} {'seed':>4} {'W/dmax':>6} {'H/dmax':>6} {'disks':>5} {'n2D':>6} | {'peak':>5} "
          f"{'plane':>5} {'at mm':>5} | {'resid':>5} {'plane':>5} {'from':>5} | {'w-sl':>5} {'plane':>5} "
          f"{'slope':>6} | {'rise pk':>7} {'end':>5} {'dy/dx':>5} {'psi':>4} | "
          f"{'build':>5} {'shear':>5}")  # fmt: skip
    for r in rows:
        resid = (f"{r['residual_plate']:5.3f} {r['residual_plane']:5.3f} {r['residual_from_mm']:5.1f}"
                 if r["residual_reached"] else f"{'not reached':>17}")  # fmt: skip
        print(f"{r['box']:>5} {r['seed']:4d} {r['width_over_d_max']:6.1f} {r['height_over_d_max']:6.1f} "
              f"{r['disks']:5d} {r['n2d']:6.4f} | {r['peak_plate']:5.3f} {r['peak_plane']:5.3f} "
              f"{r['peak_at_mm']:5.1f} | {resid} | {r['taylor_plate']:5.3f} {r['taylor_plane']:5.3f} "
              f"{r['slope_from_window']:+6.3f} | {r['rise_at_peak_mm']:7.2f} {r['rise_at_end_mm']:5.2f} "
              f"{r['max_dilation_rate']:5.3f} {r['max_dilation_angle_deg']:4.1f} | "
              f"{r['build_time_s'] or math.nan:5.0f} {r['shear_time_s']:5.0f}")  # fmt: skip


def box_summaries(rows: list[dict]) -> list[dict]:
    """Per box, in the order of ``BOXES``: its size and each column's mean +- sd over the seeds."""
    out = []
    for name in BOXES:
        got = [r for r in rows if r["box"] == name]
        if not got:
            continue
        summary = {"box": name, "seeds": len(got), "width_over_d_max": got[0]["width_over_d_max"],
                   "height_over_d_max": got[0]["height_over_d_max"],
                   "disks": mean_sd([r["disks"] for r in got])[0],
                   "residual_reached": sum(r["residual_reached"] for r in got)}  # fmt: skip
        for _, key, _ in COLUMNS:
            m, sd, k = mean_sd([r[key] for r in got])
            summary[key] = {"mean": m, "sd": sd, "count": k}
        summary["text"] = {key: text([r[key] for r in got], digits) for _, key, digits in COLUMNS}
        out.append(summary)
    return out


def print_boxes(summaries: list[dict]) -> None:
    """One block a box: its size, then every column's mean +- sd over the seeds."""
    print("\nper box, mean +- sd over the seeds (a residual reached by k of n seeds: (k/n))")
    for s in summaries:
        print(f"  {s['box']}: W = {s['width_over_d_max']:.1f} d_max, H = {s['height_over_d_max']:.1f} "
              f"d_max, {s['disks']:.0f} disks, {s['seeds']} seeds, dilation stopped in "
              f"{s['residual_reached']}")  # fmt: skip
        print("    " + "; ".join(f"{head} {s['text'][key]}" for head, key, _ in COLUMNS))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True, help="the study's folder (a rerun resumes)")
    ap.add_argument("--boxes", default=",".join(BOXES), help=f"of {', '.join(BOXES)}")
    ap.add_argument("--seeds", type=int, default=2, help="specimens per box (seeds 0 ..)")
    ap.add_argument("--quick-seeds", type=int, default=3, help="specimens of the quick box")
    ap.add_argument("--friction", type=float, default=0.5, help="particle friction f_p of the tests")
    ap.add_argument("--normal-stress", type=float, default=100.0, help="kPa")
    ap.add_argument("--workers", type=int, default=2, help="DEM processes at once")
    ap.add_argument("--report", action="store_true", help="build and shear nothing: print the finished tests")
    args = ap.parse_args()
    names = [b for b in args.boxes.split(",") if b]
    unknown = [b for b in names if b not in BOXES]
    if unknown:
        ap.error(f"unknown box(es) {unknown}: choose of {', '.join(BOXES)}")
    plan = [(n, s) for n in names for s in range(args.quick_seeds if n == "quick" else args.seeds)]

    from poro2d.shear.pool import execute_jobs

    t0 = time.perf_counter()
    if not args.report:
        build_missing(args.out, plan, args.workers)
    found = accepted_specimens(args.out, plan)
    jobs = shear_jobs(args.out, found, args)
    if args.report:  # a study still running elsewhere: its finished tests only
        results = [job.test().stored() for *_, job in jobs]
    else:
        results = execute_jobs([j for *_, j in jobs], args.workers, RunOptions(progress=False))
    elapsed = time.perf_counter() - t0
    print(f"{len(plan)} specimens, {len(jobs)} tests in {elapsed:.0f} s (finished ones read back)")
    pairs = [(job, res) for job, res in zip(jobs, results, strict=True) if res is not None]
    rows = [test_row(n, s, spec, res, found[(n, s)]) for (n, s, spec, _), res in pairs]
    print_tests(rows)
    summaries = box_summaries(rows)
    print_boxes(summaries)
    record = {"boxes": {n: vars(BOXES[n]) for n in names}, "friction": args.friction,
              "normal_stress_kpa": args.normal_stress, "tests": rows, "summaries": summaries}  # fmt: skip
    (args.out / "box_size.json").write_text(json.dumps(record, indent=2))
    print(f"table in {args.out / 'box_size.json'}")


if __name__ == "__main__":
    main()
