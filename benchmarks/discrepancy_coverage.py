"""Do the calibration's 95 % intervals hold the truth when the laboratory is not the model?

Each "laboratory" is poro2d's own biaxial test at known frictions (the truth), but of disks
whose contacts are softer than the replicates' (their kn and ks scaled so that kappa =
kn / (sigma_3 t) is ``--lab-kappa`` at every confining stress, where the replicates keep Table 1's
stiffness: kappa 1000 at 50 kPa, 250 at 200 kPa): no (f_p, mu_r) of the replicates' disks
reproduces its curves exactly. Every laboratory is made on a quick specimen of its own seed, so
the repeats are independent, and is calibrated twice on the same design (the tests run once,
cached): with the noise covariance alone (``--discrepancy none``) and with the model-discrepancy
term integrated over its size (``estimate``, :mod:`poro2d.calibration.discrepancy`).

    PYTHONPATH=src python benchmarks/discrepancy_coverage.py --labs 10 --out runs/coverage

Prints the coverage of both (the headline), then one row per laboratory: each interval, whether
it holds the truth, and the discrepancy's posterior median. Writes ``coverage.json`` in ``--out``.
"""

from __future__ import annotations

import argparse
import json
import shutil
import time
from pathlib import Path

from poro2d.biaxial.quick import QuickSpecimen
from poro2d.calibration import CalibrationCase, run_calibration, synthetic_biaxial_lab
from poro2d.dem import checkpoint
from poro2d.execute.options import RunOptions
from poro2d.io_utils import Provenance
from poro2d.store import Store

TRUTH = {"fp": 0.5, "mu_r": 0.1}
STRESSES = (50.0, 200.0)
FP_RANGE = (0.2, 2.0)
MU_R_RANGE = (0.0, 0.3)
#: the laboratories' stiffness number by default
KAPPA = 100.0


def quick_specimen(seed: int, folder: Path) -> Path:
    """The quick biaxial specimen of ``seed`` (about 320 disks) as a checkpoint, built once."""
    path = folder / f"quick{seed}.npz"
    if not path.exists():
        folder.mkdir(parents=True, exist_ok=True)
        checkpoint.save(QuickSpecimen(seed=seed).simulation(), path)
    return path


def make_lab(seed: int, out: Path, strain: float, kappa: float) -> Path:
    """The laboratory of ``seed``: the truth's biaxial curves of disks at ``kappa`` (0: the
    replicates' own disks, a laboratory the model fits), written once."""
    path = out / "labs" / (f"lab{seed}.csv" if kappa == KAPPA else f"lab{seed}-kappa{kappa:g}.csv")
    if not path.exists():
        settings = {"max_strain": strain, **({"stiffness_number": kappa} if kappa else {})}
        synthetic_biaxial_lab(quick_specimen(seed, out / "specimens"), STRESSES, TRUTH["fp"], TRUTH["mu_r"],
                              path, settings=settings)  # fmt: skip
    return path


def shared_cache(out: Path, name: str) -> Path:
    """A calibration folder seeded with the study's test cache (a copy: an output folder holds no
    link out of itself), so that only the first calibration runs the design's tests; the cache
    is keyed by each test's content, and what a calibration adds is copied back."""
    folder = out / name
    shared = out / "cache"
    if shared.exists() and not (folder / "cache").exists():
        shutil.copytree(shared, folder / "cache")
    return folder


def keep_cache(out: Path, folder: Path) -> None:
    """The tests ``folder``'s calibration ran, added to the study's cache."""
    shutil.copytree(folder / "cache", out / "cache", dirs_exist_ok=True)


def calibrate(lab: Path, replicates: list[Path], out: Path, mode: str, args) -> dict:
    result = run_calibration(
        CalibrationCase.of(
            biaxial_lab=str(lab),
            specimens=[str(p) for p in replicates],
            fp_range=FP_RANGE,
            mu_r_range=MU_R_RANGE,
            points=args.points,
            refine=0,
            settings={"max_strain": args.strain},
            discrepancy=mode,
        ),
        Store(out),
        options=RunOptions(workers=args.workers, progress=False),
    )
    fp, mu_r = result.intervals["particle_friction"], result.intervals["rolling_friction"]
    term = result.posterior.get("discrepancy")
    return {
        "fp": list(fp),
        "mu_r": list(mu_r),
        "holds": bool(fp[0] <= TRUTH["fp"] <= fp[1] and mu_r[0] <= TRUTH["mu_r"] <= mu_r[1]),
        "best": [result.best["particle_friction"], result.best["rolling_friction"]],
        "discrepancy_median": None if not term else term["median"],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--labs", type=int, default=10, help="laboratories (repeats), seeds 10, 11, ...")
    ap.add_argument("--replicates", type=int, default=3, help="replicate specimens, seeds 0, 1, ...")
    ap.add_argument("--points", type=int, default=12, help="design points")
    ap.add_argument("--strain", type=float, default=0.10, help="axial strain of every test")
    ap.add_argument("--lab-kappa", type=float, default=KAPPA, help="the laboratory disks' kappa (0: own)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("runs/discrepancy-coverage"))
    args = ap.parse_args()
    t0 = time.perf_counter()
    out = args.out
    replicates = [quick_specimen(s, out / "specimens") for s in range(args.replicates)]
    rows = []
    for k in range(args.labs):
        seed = 10 + k
        lab = make_lab(seed, out, args.strain, args.lab_kappa)
        row = {"seed": seed}
        for mode in ("none", "estimate"):
            suffix = "" if args.lab_kappa == KAPPA else f"-kappa{args.lab_kappa:g}"
            folder = shared_cache(out, f"cal-{mode}-{seed}{suffix}")
            row[mode] = calibrate(lab, replicates, folder, mode, args)
            keep_cache(out, folder)
        rows.append(row)
        print(
            f"lab seed {seed}: none f_p {row['none']['fp'][0]:.3f}-{row['none']['fp'][1]:.3f}"
            f" mu_r {row['none']['mu_r'][0]:.3f}-{row['none']['mu_r'][1]:.3f} holds {row['none']['holds']};"
            f" estimate f_p {row['estimate']['fp'][0]:.3f}-{row['estimate']['fp'][1]:.3f}"
            f" mu_r {row['estimate']['mu_r'][0]:.3f}-{row['estimate']['mu_r'][1]:.3f}"
            f" holds {row['estimate']['holds']} (s median {row['estimate']['discrepancy_median']:.3f})",
            flush=True,
        )
    n = len(rows)
    held = {mode: sum(r[mode]["holds"] for r in rows) for mode in ("none", "estimate")}
    wall = time.perf_counter() - t0
    print(
        f"coverage of the 95 % intervals over {n} laboratories (kappa {args.lab_kappa:g}, 0: the replicates'"
        f" own disks of Table 1): estimate {held['estimate']}/{n}, none {held['none']}/{n}; wall {wall:.0f} s"
    )
    summary = {
        "truth": TRUTH, "stresses_kpa": STRESSES, "lab_kappa": args.lab_kappa, "strain": args.strain,
        "replicates": args.replicates, "points": args.points, "rows": rows, "held": held, "labs": n,
        "wall_seconds": wall, "provenance": Provenance.now().to_dict(),
    }  # fmt: skip
    name = "coverage.json" if args.lab_kappa == KAPPA else f"coverage-kappa{args.lab_kappa:g}.json"
    (out / name).write_text(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
