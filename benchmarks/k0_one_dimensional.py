"""K0 of poro2d's specimens: as prepared, and under one-dimensional (oedometric) loading.

    python benchmarks/k0_one_dimensional.py [--seeds 0,1,2] [--stresses 25,50,100,200]
        [--unload 50] [--specimen DIR ...]

For each specimen (the biaxial quick specimen of each seed, or the accepted specimens given):

1. **as prepared**: K0 = sigma_h / sigma_v averaged over 8 horizontal bands of the specimen as
   the preparation left it (under self-weight, :func:`poro2d.measure.specimen_state.specimen_state`);
2. **one-dimensional loading**: the specimen in the biaxial box (gravity off), brought to an
   isotropic 5 kPa, then its side walls held still (no lateral strain) while the plate is servoed
   to each sigma_v in turn, each to equilibrium (max unbalanced ratio below 1e-3): sigma_h / sigma_v
   at each, and the loading K0 = d sigma_h / d sigma_v between the last two stresses (the
   normally consolidated K0, which the isotropic start no longer sets);
3. **unloading** to ``--unload`` kPa with the walls still held: K0 of the overconsolidated state.

It prints a row per specimen and the means, beside Jaky's 1 - sin(phi) for the friction angles
the periodic cell measures for the same disks (docs/biaxial.md, "K0"). Wall time on one core.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from poro2d.dem import Every

#: the equilibrium every stage reaches before it is read
RATIO = 1e-3
#: the isotropic start (kPa): small against the loading stresses
START_KPA = 5.0


def numbers(text: str) -> list[float]:
    return [float(v) for v in text.split(",") if v.strip()]


def settle(sim, sigma_v: float, settings, box_cls, *, sides: float | None) -> tuple[float, float]:
    """Servo the plate to ``sigma_v`` (Pa), the sides to ``sides`` (Pa) or held still (None), to
    equilibrium; returns (sigma_v, sigma_h) measured (Pa)."""
    state = {"ok": False}

    def targets(sm) -> None:
        s = box_cls.size(sm)
        box_cls.servo(sm, "top", sigma_v * s.width * s.thickness, settings)
        for wall in ("left", "right"):
            if sides is None:
                sm.set_wall_velocity(wall, (0.0, 0.0))
            else:
                box_cls.servo(sm, wall, sides * s.height * s.thickness, settings)

    def check(sm) -> bool:
        ratio, _ = sm.unbalanced_ratios()
        s1, s3, _, _ = box_cls.stresses(sm)
        done = ratio < RATIO and abs(s1 / sigma_v - 1.0) < 0.01
        if sides is not None:
            done = done and abs(s3 / sides - 1.0) < 0.01
        state["ok"] = done
        if not done:
            targets(sm)
        return done

    targets(sim)
    sim.run(2_000_000, reporters=[Every(500, check)])
    if not state["ok"]:
        raise RuntimeError(f"no equilibrium at sigma_v = {sigma_v / 1e3:g} kPa")
    s1, s3, _, _ = box_cls.stresses(sim)
    return s1, s3


def one_specimen(case, stresses: list[float], unload: float) -> dict:
    from poro2d.biaxial.box import BiaxialBox
    from poro2d.biaxial.single import BiaxialTest
    from poro2d.measure.specimen_state import specimen_state

    spec = case.specimen.simulation(threads=1)
    w, h = spec.walls, spec.walls
    top = float(h.p0[h.index("top"), 1])
    width = float(w.p0[w.index("right"), 0] - w.p0[w.index("left"), 0])
    prepared = specimen_state(spec, width, top).k0_mean
    test = BiaxialTest(case)
    sim = test.build()
    settle(sim, START_KPA * 1e3, case.settings, BiaxialBox, sides=START_KPA * 1e3)
    rows = []
    for sv in stresses:
        s1, s3 = settle(sim, sv * 1e3, case.settings, BiaxialBox, sides=None)
        rows.append((sv, s1, s3))
    (_, a1, a3), (_, b1, b3) = rows[-2], rows[-1]
    u1, u3 = settle(sim, unload * 1e3, case.settings, BiaxialBox, sides=None)
    return {
        "prepared": prepared,
        "ratios": [s3 / s1 for _, s1, s3 in rows],
        "loading": (b3 - a3) / (b1 - a1),
        "unloaded": u3 / u1,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=lambda t: [int(v) for v in numbers(t)], default=[0, 1, 2])
    ap.add_argument("--stresses", type=numbers, default=[25.0, 50.0, 100.0, 200.0])
    ap.add_argument("--unload", type=float, default=50.0)
    ap.add_argument("--specimen", action="append", default=[])
    args = ap.parse_args()

    from poro2d.biaxial.case import BiaxialCase

    cases = [BiaxialCase.of(p, 100.0) for p in args.specimen] or [
        BiaxialCase.quick(100.0, seed=s) for s in args.seeds
    ]
    labels = args.specimen or [f"quick seed {s}" for s in args.seeds]
    head = " ".join(f"{'K @' + format(s, 'g'):>8}" for s in args.stresses)
    print(
        f"{'specimen':>16} {'prepared':>8} {head} {'loading':>8} "
        f"{'unl ' + format(args.unload, 'g'):>8} {'s':>5}"
    )
    found = []
    for label, case in zip(labels, cases, strict=True):
        t0 = time.perf_counter()
        r = one_specimen(case, args.stresses, args.unload)
        found.append(r)
        ks = " ".join(f"{k:8.3f}" for k in r["ratios"])
        print(
            f"{label:>16} {r['prepared']:8.3f} {ks} {r['loading']:8.3f} {r['unloaded']:8.3f} "
            f"{time.perf_counter() - t0:5.0f}",
            flush=True,
        )
    for key in ("prepared", "loading", "unloaded"):
        v = np.array([r[key] for r in found])
        print(f"{key}: {v.mean():.3f} +- {v.std(ddof=1) if v.size > 1 else 0.0:.3f}")
    for phi in (16.1, 20.0, 25.0, 30.0):
        print(f"Jaky 1 - sin({phi:g} deg) = {1.0 - math.sin(math.radians(phi)):.3f}")


if __name__ == "__main__":
    main()
