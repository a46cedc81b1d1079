"""Wall and CPU time of one ``poro2d sand`` run, from an empty cache, stage by stage.

Runs :func:`poro2d.sand.run_sand` on a sand config in a fresh cache folder (the jamming
reference and every calibration case computed, nothing read back), then prints:

* the answer (interior porosity and n' +- sd over seeds, mu_prep), so two runs can be held
  side by side;
* wall time, and the workers' time (the cases' preparation and lid stages summed; the Dask
  workers are not this process's children, so for CPU time run the script under
  ``/usr/bin/time -v``);
* each stage's wall time, from the run's own progress lines;
* where the workers' time went (steps, minutes and particle-steps per second of the
  preparation and of the plate/lid stage, for the calibration and for the specimens).

    python benchmarks/bench_sand.py examples/soils/toyoura.toml
    python benchmarks/bench_sand.py examples/soils/toyoura.toml --calibration-seeds 3
    python benchmarks/bench_sand.py examples/soils/paper-sand.toml --workers 1 --json ps.json

A measurement script, not a test: the numbers depend on the machine and its load (run it on
an otherwise idle machine).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path


def _worker_seconds(*profiles: dict | None) -> float:
    """The cases' preparation and lid stages, summed over the profiles."""
    stages = ("prepare", "plate")
    return sum((p or {}).get(stage, {}).get("seconds", 0.0) for p in profiles for stage in stages)


def _config(path: Path, calibration_seeds: int | None) -> dict | Path:
    """The config as given, or as a dict with ``[sand] calibration_seeds`` set."""
    if calibration_seeds is None:
        return path
    import tomllib

    cfg = tomllib.loads(path.read_text())
    # relative paths in the config start from its folder
    grading = cfg.get("grading") or {}
    if "csv" in grading and not Path(grading["csv"]).is_absolute():
        grading["csv"] = str((path.parent / grading["csv"]).resolve())
    cfg.setdefault("sand", {})["calibration_seeds"] = calibration_seeds
    return cfg


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config", type=Path, help="a sand config (TOML)")
    ap.add_argument("--workers", type=int, default=None, help="worker processes (default: cores)")
    ap.add_argument("--calibration-seeds", type=int, default=None, help="override [sand] calibration_seeds")
    ap.add_argument("--out", type=Path, default=None, help="output folder (default: a temporary one)")
    ap.add_argument("--json", type=Path, default=None, help="also write the numbers here")
    args = ap.parse_args(argv)

    from poro2d.execute.options import RunOptions
    from poro2d.sand import load_sand_case, run_sand
    from poro2d.store import Store

    scratch = tempfile.mkdtemp(prefix="bench-sand-")
    os.environ["PORO2D_CACHE"] = str(Path(scratch) / "cache")  # an empty cache: nothing reused
    out = args.out or Path(scratch) / "out"
    stages: list[tuple[float, str]] = []
    t0 = time.perf_counter()
    res = run_sand(
        load_sand_case(_config(args.config, args.calibration_seeds)),
        Store(out),
        options=RunOptions(workers=args.workers, progress=False),
        announce=lambda line: stages.append((time.perf_counter() - t0, line)),
    )
    wall = time.perf_counter() - t0
    profiles = res.calibration.get("time_profile"), res.calibration.get("specimens_time_profile")
    work = _worker_seconds(*profiles)

    numbers = {
        "config": str(args.config),
        "interior_porosity": [res.interior_porosity_mean, res.interior_porosity_sd],
        "box_porosity": [res.box_porosity_mean, res.box_porosity_sd],
        "mu_prep": res.mu_prep,
        "seeds_accepted": res.seeds_accepted,
        "wall_s": wall,
        "worker_s": work,
        "stage_starts_s": [[round(t, 1), line.split(":")[0]] for t, line in stages],
        "calibration_profile": profiles[0],
        "specimens_profile": profiles[1],
        "out": str(out),
    }
    print(f"{args.config}: interior {res.interior_porosity_mean:.4f} +- {res.interior_porosity_sd:.4f}, "
          f"n' {res.box_porosity_mean:.4f} +- {res.box_porosity_sd:.4f}, mu_prep {res.mu_prep:.4f}, "
          f"{res.seeds_accepted} of {res.seeds} seeds")  # fmt: skip
    print(f"wall {wall / 60:.2f} min; workers {work / 60:.2f} min (the cases' stages, summed)")
    for t, line in stages:
        print(f"  at {t / 60:5.2f} min: {line.split(';')[0]}")
    for name in ("calibration_profile", "specimens_profile"):
        prof = numbers[name] or {}
        for stage in ("prepare", "plate"):
            p = prof.get(stage)
            if p:
                print(f"  {name.split('_')[0]} {stage}: {p['steps']:,} steps, {p['seconds'] / 60:.1f} min, "
                      f"{p['particle_steps_per_s']:.3g} particle-steps/s")  # fmt: skip
    if args.json:
        args.json.write_text(json.dumps(numbers, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
