"""Loose and dense specimens in the biaxial test: contraction, dilation, peak minus end friction.

Each specimen (a quick specimen recipe, loose or dense, or a criterion folder given with
``--folders``) is consolidated to ``--confining`` kPa and sheared to ``--strain``; the script
prints its interior solid fraction (quick specimens: measured as prepared), the volumetric
strain (contraction positive) along the axial strain, the peak and end angles, their difference,
and beside it Bolton's (1986) plane-strain phi_peak - phi_cv = 5 I_R with
I_R = Dr (10 - ln p') - 1 (capped to 0..4), a relation for sands, not for round disks.

    PYTHONPATH=src python benchmarks/loose_dense_shear.py --seeds 0 1
    PYTHONPATH=src python benchmarks/loose_dense_shear.py --folders runs/loose0 runs/dense0 --friction 0.5
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from poro2d.biaxial import BiaxialCase, BiaxialSettings, run_biaxial
from poro2d.biaxial.quick import QuickSpecimen
from poro2d.execute import RunOptions
from poro2d.measure.specimen_porosity import measure_specimen

#: the loose quick specimen: built at sliding friction 1.0 and rolling resistance 0.5
LOOSE = {"porosity": 0.25, "friction_prep": 1.0, "rolling_friction_prep": 0.5}
STRAINS = (0.01, 0.02, 0.05, 0.10, 0.15, 0.20)


def bolton(dr: float, p_kpa: float) -> float:
    """Bolton's plane-strain phi_peak - phi_cv (deg) at relative density ``dr`` and p' (kPa)."""
    return 5.0 * min(4.0, max(0.0, dr * (10.0 - math.log(p_kpa)) - 1.0))


def solid_fraction(q: QuickSpecimen) -> float:
    p = q.simulation().particles
    return 1.0 - measure_specimen(p.pos, p.radius, q.width, q.height).interior_porosity


def report(label: str, case: BiaxialCase, fraction: float | None) -> None:
    t0 = time.perf_counter()
    test = run_biaxial(case, None, replicates=1, options=RunOptions(workers=1, progress=False)).tests[0]
    c = test.curve
    eps = "  ".join(
        f"{np.interp(e, c.axial_strain, c.volumetric_strain):+.4f}"
        for e in STRAINS
        if e <= c.axial_strain[-1]
    )
    peak, end = test.peak_friction_angle_deg, test.critical_state_friction_angle_deg
    print(
        f"{label:34s} {'-' if fraction is None else f'{fraction:.3f}':>6s}  {eps}  "
        f"{peak:5.1f} {end:5.1f} {peak - end:5.1f}  "
        f"{test.end_volumetric_strain:+.4f}  {time.perf_counter() - t0:5.0f}",
        flush=True,
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="*", default=[0, 1])
    ap.add_argument("--folders", nargs="*", default=[], help="criterion folders (accepted specimens)")
    ap.add_argument("--friction", type=float, default=None, help="particle friction of the tests")
    ap.add_argument("--confining", type=float, default=100.0)
    ap.add_argument("--strain", type=float, default=0.20)
    args = ap.parse_args()
    settings = BiaxialSettings(max_strain=args.strain)
    if args.friction is not None:
        settings = BiaxialSettings(max_strain=args.strain, particle_friction=args.friction)
    shown = "  ".join(f"{e:>7.0%}" for e in STRAINS if e <= args.strain)
    print(f"{'specimen':34s} {'solid':>6s}  eps_v at eps_1 {shown}  peak  end  diff  eps_v_end  time_s")
    for seed in args.seeds:
        for name, recipe in (("loose", LOOSE), ("dense", {})):
            q = QuickSpecimen(seed, **recipe)
            report(f"{name} quick, seed {seed}", BiaxialCase(q, args.confining, settings), solid_fraction(q))
    for folder in args.folders:
        report(folder[-34:], BiaxialCase.of(folder, args.confining, settings), None)
    p = args.confining
    print(f"Bolton (sands), p' {p:g} kPa: phi_peak - phi_cv = {bolton(0.0, p):.1f} deg at Dr 0, "
          f"{bolton(0.5, p):.1f} at Dr 0.5, {bolton(1.0, p):.1f} at Dr 1")  # fmt: skip


if __name__ == "__main__":
    main()
