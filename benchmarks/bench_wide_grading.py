"""Throughput of the engine on a narrow and on a very wide grading, at the same number of disks.

Two specimens of about ``--disks`` disks (6000 by default) are drawn, placed in a box and
compacted under gravity; then blocks of steps of the two are timed in alternation on one thread:

* ``narrow``: the paper's grading (d_max/d_min = 3.55), Table 1 properties;
* ``wide``: a sandy gravel of 0.1-18.9 mm (Cu = 18, d_max/d_min = 189), the same properties.

Each box is square; the disks are placed at full size as densely as random placement gets
(solid fraction 0.55, else less) and cycled with friction 0.5 under a gravity raised so that
a free disk would fall 50 % of the box in the settling steps, then 15 %, then 5 % (the same
compaction per step in both cases; the wide grading's time step is 20 times shorter), the
speeds set to zero between stages: the timed blocks are a packing compacting under its
weight, under the last gravity. For each case the script
prints particle-steps per second (disks x steps / wall-clock second of the step loop, median
of the blocks), the wall time of a block, list rebuilds per 1000 steps, Verlet pairs and
touching pairs per disk, and the cost of one list build measured apart (a one-step run with a
forced rebuild minus a one-step run without). It also prints the neighbour search the engine
chose (one cell grid, or cells by size level).

    python benchmarks/bench_wide_grading.py                  # both cases
    python benchmarks/bench_wide_grading.py --search cells   # the one cell grid for both
    python benchmarks/bench_wide_grading.py --disks 5000 --blocks 3
    python benchmarks/bench_wide_grading.py --json wide.json

A measurement script, not a test: the numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import sys
import time

import numpy as np

# the sandy gravel: laboratory sieves (mm) and percent passing by mass (d10 = 0.41 mm,
# d60 = 7.4 mm: Cu = 18)
WIDE_SIZES_MM = (0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 18.9)
WIDE_PASSING = (0.0, 5.0, 12.0, 20.0, 32.0, 45.0, 62.0, 92.0, 100.0)
# how far (a fraction of the box side) gravity would drop a free disk in each settling stage:
# first far (the packing collapses into contact), then lower gravities, each stage calmed
# (the last one is kept for the timed blocks: the weight's overlaps stay a few per cent of
# the fines' radius)
FALL_FRACTIONS = (0.5, 0.15, 0.05)


def grading(name: str):
    from poro2d.grading import GradingCurve, paper_grading

    if name == "narrow":
        return paper_grading()
    return GradingCurve.from_lists(WIDE_SIZES_MM, WIDE_PASSING, source="sandy gravel, Cu 18")


def build(name: str, disks: int, seed: int, settle_steps: int):
    """A specimen of about ``disks`` disks of grading ``name`` in a square box, compacting.

    The disks are placed at full size, without overlap, from the largest down, as densely
    as random placement gets (a solid fraction of 0.55 or the first of 0.5, 0.45, ... that
    works), and cycled under gravity: they settle onto each other. (Placing them smaller and
    growing them back, the specimen builder's way, shoots the fines of a wide grading out:
    a coarse disk grows by more than a fine disk's diameter in one increment.)
    """
    from poro2d.dem import Particles, Simulation, Walls
    from poro2d.dem.ordering import strip_order
    from poro2d.errors import InputError
    from poro2d.grading import draw_disks
    from poro2d.paper_data import TABLE_1
    from poro2d.specimen.placement import place_disks

    curve = grading(name)
    solid = disks / curve.expected_count(1.0)  # m^2 of solid for that many disks
    radii = draw_disks(curve, solid, seed)
    for fraction in (0.55, 0.5, 0.45, 0.4):
        side = max(math.sqrt(solid / fraction), 4.4 * float(radii.max()))
        try:
            placed = place_disks(radii, (0.0, side, 0.0, side), seed, full_size=True, max_attempts=20000)
            break
        except InputError:
            continue
    t = TABLE_1
    p = Particles(placed.positions, placed.radii, density=t.solid_density, thickness=0.008,
                  kn=t.kn_particle, ks=t.ks_particle, mu=0.5)  # fmt: skip
    w = Walls.box(0.0, 0.0, side, side, t.kn_wall, t.ks_wall, 0.5)
    sim = Simulation(p, w, gravity=(0.0, -9.81), local_damping=0.7, threads=1)
    sim.reorder(strip_order(sim.particles.pos, sim.particles.radius))
    # gravity raised so that a free disk would fall FALL_FRACTIONS of the box in settle_steps:
    # the same compaction per step in both cases (the wide grading's step is 20 times shorter)
    for fall in FALL_FRACTIONS:
        g = 2.0 * fall * side / (settle_steps * sim.dt) ** 2
        sim.gravity = (0.0, -max(g, 9.81))
        sim.run(settle_steps)
        sim.particles.vel[:] = 0.0  # calm: the collapse's speed is not carried into the next stage
        sim.particles.omega[:] = 0.0
    return sim, curve, fraction


def build_cost(sim, repeats: int = 5) -> tuple[float, float]:
    """(one step with a list rebuild, one step without), seconds, best of ``repeats``."""
    from poro2d.dem import kernels as K

    with_build, without = [], []
    for _ in range(repeats):
        sim.kernel_params.iprm[K.NEED_BUILD] = 1
        t0 = time.perf_counter()
        sim.run(1)
        with_build.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        sim.run(1)
        without.append(time.perf_counter() - t0)
    return min(with_build), min(without)


def search_name(sim) -> str:
    """The neighbour search the engine chose (engines before it had one kind only)."""
    kind = getattr(sim, "neighbor_search", "cells")
    return "one cell grid" if kind == "cells" else "grids by size level"


def prepare(name: str, args):
    """The compacted specimen of case ``name``, its lists built and the kernel compiled."""
    t0 = time.perf_counter()
    sim, curve, fraction = build(name, args.disks, args.seed, args.settle_steps)
    r = sim.particles.radius
    print(
        f"[{name}] {sim.particles.n} disks, d {2e3 * r.min():.3g}-{2e3 * r.max():.3g} mm (d_max/d_min "
        f"{r.max() / r.min():.0f}, Cu {curve.uniformity:.1f}), dt {sim.dt:.3e} s, g {-sim.gravity[1]:.3g} "
        f"m/s2, skin "
        f"{sim.skin * 1e3:.4f} mm, placed at solid fraction {fraction}, prepared in "
        f"{time.perf_counter() - t0:.0f} s; search: {search_name(sim)}",
        flush=True,
    )
    sim.run(args.steps // 4)  # warm-up: compilation, storage growth
    return sim, curve


def describe(name: str, sim, curve, rates, walls, rebuilds, args) -> dict:
    """The case's row: median rate, block time, rebuilds, pairs, cost of one list build."""
    p = sim.particles
    r = p.radius
    with_b, without_b = build_cost(sim)
    row = {
        "case": name,
        "disks": p.n,
        "d_min_mm": 2e3 * float(r.min()),
        "d_max_mm": 2e3 * float(r.max()),
        "size_ratio": float(r.max() / r.min()),
        "cu": curve.uniformity,
        "dt_s": sim.dt,
        "skin_m": sim.skin,
        "gravity_m_s2": -sim.gravity[1],
        "search": search_name(sim),
        "steps_per_block": args.steps,
        "particle_steps_per_s": statistics.median(rates),
        "all_rates": rates,
        "block_wall_s": statistics.median(walls),
        "rebuilds_per_1000_steps": 1000.0 * statistics.median(rebuilds) / args.steps,
        "verlet_pairs_per_disk": sim.pairs.used / p.n,
        "touching_pairs_per_disk": len(sim.pairs.touching()) / p.n,
        "step_with_build_s": with_b,
        "step_without_build_s": without_b,
        "list_build_s": max(0.0, with_b - without_b),
        "ratio_max": sim.unbalanced_ratios()[0],
        "max_speed_over_skin_per_step": float(np.abs(p.vel).max()) * sim.dt / sim.skin,
    }
    build_time = row["list_build_s"] * row["rebuilds_per_1000_steps"] / 1000.0
    row["build_share_of_step_time"] = build_time / (row["block_wall_s"] / args.steps)
    print(
        f"[{name}] {row['particle_steps_per_s']:.3e} p-steps/s (median of {args.blocks} x {args.steps} "
        f"steps, {row['block_wall_s']:.2f} s a block), {row['rebuilds_per_1000_steps']:.0f} rebuilds / "
        f"1000 steps, {row['verlet_pairs_per_disk']:.2f} Verlet / {row['touching_pairs_per_disk']:.2f} "
        f"touching pairs a disk; one list build {1e3 * row['list_build_s']:.2f} ms, one step "
        f"{1e3 * without_b:.2f} ms: builds take {100 * row['build_share_of_step_time']:.0f} % of the time; "
        f"fastest disk {row['max_speed_over_skin_per_step']:.3f} skins a step",
        flush=True,
    )
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--disks", type=int, default=6000, help="disks per specimen (about)")
    ap.add_argument("--steps", type=int, default=2000, help="steps per timed block")
    ap.add_argument("--blocks", type=int, default=5, help="timed blocks per case")
    ap.add_argument("--settle-steps", type=int, default=5000, help="steps under gravity before timing")
    ap.add_argument(
        "--search",
        choices=("auto", "cells"),
        default="auto",
        help="cells: the one cell grid whatever the size ratio (the engine before grids by level)",
    )
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--cases", default="narrow,wide")
    ap.add_argument("--json", default=None, help="also write the rows to this file")
    args = ap.parse_args(argv)
    import numba

    from poro2d import __version__
    from poro2d.dem import Simulation

    if args.search == "cells":
        Simulation.level_ratio = math.inf

    print(f"poro2d {__version__}, numba {numba.__version__}, load {os.getloadavg()[0]:.2f}", flush=True)
    names = [c.strip() for c in args.cases.split(",") if c.strip()]
    cases = {name: prepare(name, args) for name in names}
    # the cases' blocks alternate (the order flips each round): a busy machine slows both
    rates: dict = {name: [] for name in names}
    walls: dict = {name: [] for name in names}
    rebuilds: dict = {name: [] for name in names}
    for k in range(args.blocks):
        for name in names if k % 2 == 0 else names[::-1]:
            res = cases[name][0].run(args.steps)
            rates[name].append(res.particle_steps_per_s)
            walls[name].append(res.wall_time_s)
            rebuilds[name].append(res.rebuilds)
    rows = [describe(n, *cases[n], rates[n], walls[n], rebuilds[n], args) for n in names]
    if len(rows) == 2:
        q = [b / a for a, b in zip(rates[names[0]], rates[names[1]], strict=True)]
        print(
            f"{names[1]} / {names[0]}: {statistics.median(q):.3f} of the particle-steps per second "
            f"(median of the rounds, {min(q):.3f}-{max(q):.3f}); load {os.getloadavg()[0]:.2f}"
        )
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
