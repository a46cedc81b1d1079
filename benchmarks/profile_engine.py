"""Where a step's time goes: the engine's phases, its memory traffic and its disk order.

Builds the cases of ``bench_engine.py`` (the settled paper packing, about 2.5k disks, and
copies of it tiled to 25k or 250k) and prints, per case:

* the rate of whole steps (``Simulation.run``) on 1 and 2 threads, several blocks each,
  and the list rebuilds per block;
* the time of each phase, each run alone in a compiled loop of its own on one thread: the
  neighbour rebuild (``kernels._rebuild``), the force pass of each partition (phase 1:
  contact forces and the advance of the disks without cross pairs, one fused loop), the
  deferred pass (phase 2: the disks with cross pairs) and the walls; and the cost of two
  bare barriers on two threads (no work between them);
* the bytes the force pass reads and writes per disk and per pair (the arrays it touches,
  their element sizes), the whole per step, and the rate at which this machine copies a
  large array (a bandwidth yardstick);
* how far apart in memory the two disks of a pair are: mean |i - j| over the Verlet pairs
  and over the touching ones, and the fraction within 64 indices, right after building
  and after the timed steps.

``--order`` renumbers each case before timing: ``strip`` (the engine's strips, as the
specimens are built), ``curve`` (the space-filling order within the strips,
:func:`poro2d.dem.ordering.curve_order`) or ``as-built`` (no renumbering: the tiling's
order, copy by copy); ``random`` (a shuffled numbering, seed 0: what an order decays
towards as the disks mix).

    python benchmarks/profile_engine.py --cases paper,250k --steps 200
    python benchmarks/profile_engine.py --cases 250k --order curve --steps 200
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit, prange

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from bench_engine import TILINGS, paper_simulation, tiled_simulation  # noqa: E402

from poro2d.dem import kernels as K  # noqa: E402
from poro2d.dem.neighbors import (  # noqa: E402
    cell_grid,
    copy_rows,
    count_pair_rows,
    count_wall_rows,
    fill_pair_rows,
    fill_wall_rows,
)
from poro2d.dem.ordering import curve_order, strip_order  # noqa: E402
from poro2d.dem.partition import partition  # noqa: E402
from poro2d.dem.records import BodyProps, RollingProps  # noqa: E402
from poro2d.dem.sync import barrier, fresh_sync, start_handshake  # noqa: E402

# ------------------------------------------------------------------ phase loops


@njit
def _loop_forces(reps, k, disks, walls, nb, wb, work, prm, props, dash, roll, pw_body, stored, skip2):
    dt, gx, gy, damp = prm[K.DT], prm[K.GX], prm[K.GY], prm[K.DAMP]
    for _ in range(reps):
        K._phase_forces(
            k, disks, walls, nb, wb, work, prm, props, dash, roll, pw_body, dt, gx, gy, damp, stored, skip2
        )


@njit
def _loop_deferred(reps, disks, nb, work, roll, prm):
    dt, gx, gy, damp = prm[K.DT], prm[K.GX], prm[K.GY], prm[K.DAMP]
    ndef = work.dstart[work.dstart.shape[0] - 1]
    for _ in range(reps):
        K._phase_deferred(0, ndef, disks, nb, work, roll, gx, gy, damp, dt)


@njit
def _loop_walls(reps, walls, dt):
    for _ in range(reps):
        K._move_walls(walls, dt)


@njit
def _loop_rebuild(reps, disks, walls, nb, wb, work, prm, out, levels):
    ok = True
    for _ in range(reps):
        ok = ok and K._rebuild(0, 1, disks, walls, nb, wb, work, prm, out, levels)
    return ok


@njit(parallel=True)
def _loop_barriers(reps, sync, nthr):
    for _t in prange(nthr):
        if start_handshake(sync, nthr):
            for _ in range(reps):
                barrier(sync, nthr)


@njit
def _loop_rebuild_part(reps, part, disks, walls, nb, wb, work, prm):
    """One part of a list rebuild on one thread (``part``: 0 grid, 1 count pairs, 2 count wall
    pairs, 3 fill pairs with their history, 4 fill wall pairs, 5 copy rows, 6 partitions)."""
    pos, radius, skin, n = disks.pos, disks.radius, prm[K.SKIN], disks.pos.shape[0]
    wp0, wp1 = walls.p0, walls.p1
    cell, members, cstart, ginfo = work.cell, work.members, work.cstart, work.ginfo
    for _ in range(reps):
        if part == 0:
            cell_grid(pos, radius, skin, cell, members, cstart, work.cfill, ginfo)
        elif part == 1:
            count_pair_rows(0, n, pos, radius, skin, cell, members, cstart, ginfo, nb.new_start, work.cand)
        elif part == 2:
            count_wall_rows(0, n, pos, radius, skin, wp0, wp1, wb.new_start)
        elif part == 3:
            fill_pair_rows(0, n, pos, radius, skin, cell, members, cstart, ginfo, nb.start, nb.j, nb.fs,
                           nb.new_start, nb.new_j, nb.new_fs, nb.mr, nb.new_mr, work.cand)  # fmt: skip
        elif part == 4:
            fill_wall_rows(0, n, pos, radius, skin, wp0, wp1, wb.start, wb.w, wb.fs, wb.new_start, wb.new_w,
                           wb.new_fs, wb.mr, wb.new_mr)  # fmt: skip
        elif part == 5:
            copy_rows(0, n, nb.new_start, nb.new_j, nb.new_fs, nb.start, nb.j, nb.fs, nb.new_mr, nb.mr)
        else:
            w = work
            partition(n, nb.start, nb.j, wb.start, w.part, w.xstart, w.xpair, w.dlist, w.dstart)


REBUILD_PARTS = ("grid", "count pairs", "count wall pairs", "fill pairs + history", "fill wall pairs",
                 "copy rows", "partitions")  # fmt: skip


def _kernel_args(sim):
    """The records and variant arguments the kernel takes (as ``kernels.step_block`` makes them)."""
    rec = sim.kernel_records()
    prm, iprm = sim.kernel_params.prm, sim.kernel_params.iprm
    disks = rec.disks
    props = BodyProps(disks.kn, disks.ks, disks.mu) if iprm[K.MODE] == K.PER_BODY else None
    dash = float(prm[K.BETA]) if prm[K.BETA] > 0.0 else None
    roll = RollingProps(disks.mu_r, rec.walls.mu_r) if K.rolling_active(disks.mu_r) else None
    return rec, props, dash, roll, bool(iprm[K.MODE_PW] == K.PER_BODY)


def _arrays(rec) -> list[np.ndarray]:
    """Every array of the kernel's records (the state a phase may change)."""
    found = []
    for group in (rec.disks, rec.walls, rec.nb, rec.wb, rec.work):
        found += [a for a in group if isinstance(a, np.ndarray)]
    return found


def _best_per_call(fn, reps: int, arrays: list[np.ndarray], rounds: int = 5) -> dict:
    """Seconds per repetition of ``fn(reps)``: median and spread over ``rounds`` calls.

    Every call starts from the same state: ``arrays`` are put back as they were before
    each (a phase repeated alone adds its forces again and again).
    """
    saved = [a.copy() for a in arrays]

    def restore():
        for a, s in zip(arrays, saved, strict=True):
            a[...] = s

    fn(1)  # compile
    per = []
    for _ in range(rounds):
        restore()
        t0 = time.perf_counter()
        fn(reps)
        per.append((time.perf_counter() - t0) / reps)
    restore()
    return {"median_s": statistics.median(per), "min_s": min(per), "max_s": max(per)}


def phase_times(sim, reps: int) -> dict:
    """Each phase alone, on one thread, ``reps`` times in a compiled loop, from the same state."""
    sim.threads = 1
    sim.run(1)  # lists built, partitions set, parameters loaded
    rec, props, dash, roll, pw_body = _kernel_args(sim)
    prm, out = sim.kernel_params.prm, sim.kernel_params.out
    d, w, nb, wb, work = rec.disks, rec.walls, rec.nb, rec.wb, rec.work
    state = _arrays(rec)
    res = {}
    res["rebuild"] = _best_per_call(
        lambda r: _loop_rebuild(r, d, w, nb, wb, work, prm, out, rec.levels), max(1, reps // 5), state
    )
    if rec.levels is None:  # the one cell grid: its parts one by one, in the order a rebuild runs them
        for q, name in enumerate(REBUILD_PARTS):
            res[f"  rebuild: {name}"] = _best_per_call(
                lambda r, q=q: _loop_rebuild_part(r, q, d, w, nb, wb, work, prm), max(1, reps // 5), state
            )
    # the pass of most steps (the history stored, no drift computed), and of a check step
    # (everything stored, every drift computed)
    for stored, skip2, label in ((None, np.inf, ""), (True, -1.0, ", check step")):
        for k in range(work.part.shape[0] - 1):
            res[f"force pass{label}, partition {k}"] = _best_per_call(
                lambda r, k=k, s=stored, v=skip2: _loop_forces(
                    r, k, d, w, nb, wb, work, prm, props, dash, roll, pw_body, s, v
                ),
                reps,
                state,
            )
    res["deferred pass"] = _best_per_call(lambda r: _loop_deferred(r, d, nb, work, roll, prm), reps, state)
    res["walls"] = _best_per_call(lambda r: _loop_walls(r, w, 0.0), reps, state)
    sync = fresh_sync()
    res["two barriers, 2 threads"] = _best_per_call(
        lambda r: (sync.fill(0), _loop_barriers(2 * r, sync, 2)), reps, [sync]
    )
    return res


# ------------------------------------------------------------------ memory


def force_pass_bytes(sim) -> dict:
    """Bytes the force pass of most steps touches per disk (its own row) and per Verlet pair, by array.

    A disk's mode and its cross-pair rows are not read: cursors on the few disks held and
    deferred stand for them. Most steps store no geometry and no unbalanced force (``fn``,
    ``ov``, ``nx``, ``ny``, ``force``, ``moment``: a check step and a call's last step do,
    and the few cross pairs and deferred disks at every step), and read no build position
    of a disk too slow to need its drift (``pos_build``); those are counted apart, as
    ``stored_*``.
    """
    p = sim.particles
    per_disk = {
        "pos": p.pos.itemsize * 2, "vel": p.vel.itemsize * 2, "omega": 8, "theta": 8, "acc": 24,
        "radius": 8, "mass": 8, "inv_mass": 8, "inv_inertia": 8, "nb.start": 8, "wb.start": 8,
    }  # fmt: skip
    stored_disk = {"force": 16, "moment": 8, "pos_build": 16}
    if sim.kernel_params.iprm[K.MODE] == K.PER_BODY:
        per_disk.update({"kn": 8, "ks": 8, "mu": 8})
    nb = sim.pairs
    per_pair = {"j": nb.other.itemsize, "fs": 8}
    stored_pair = {"fn": 8, "ov": 8, "nx": 8, "ny": 8}
    if K.rolling_active(p.mu_r):
        per_pair["mr"] = 8
    n, m = p.n, nb.used
    disk_b, pair_b = sum(per_disk.values()), sum(per_pair.values())
    sdisk_b, spair_b = sum(stored_disk.values()), sum(stored_pair.values())
    return {
        "per_disk": per_disk, "per_pair": per_pair, "bytes_per_disk": disk_b, "bytes_per_pair": pair_b,
        "stored_per_disk": stored_disk, "stored_per_pair": stored_pair,
        "pairs_per_disk": m / n, "touching_per_disk": len(nb.touching()) / n,
        "step_mb": (n * disk_b + m * pair_b) / 1e6,
        "stored_step_mb": (n * (disk_b + sdisk_b) + m * (pair_b + spair_b)) / 1e6,
    }  # fmt: skip


def copy_bandwidth(mb: float = 256.0) -> float:
    """GB/s of a large array copy (read + write counted), a yardstick of memory traffic."""
    a = np.ones(int(mb * 1e6 / 8))
    b = np.empty_like(a)
    np.copyto(b, a)
    best = min(_timed(lambda: np.copyto(b, a)) for _ in range(5))
    return 2 * a.nbytes / best / 1e9


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def index_distance(sim) -> dict:
    """Mean |i - j| of the Verlet pairs and of the touching ones, and the fractions within 64."""
    nb = sim.pairs
    m = nb.used
    gap = np.abs(nb.other[:m] - nb.rows())
    touch = nb.ov[:m] > 0.0
    out = {}
    for name, g in (("verlet", gap), ("touching", gap[touch])):
        out[name] = {
            "mean": float(g.mean()) if g.size else 0.0,
            "median": float(np.median(g)) if g.size else 0.0,
            "within_64": float((g <= 64).mean()) if g.size else 1.0,
        }
    return out


# ------------------------------------------------------------------ a case


def renumber(sim, order: str) -> None:
    p = sim.particles
    if order == "strip":
        sim.reorder(strip_order(p.pos, p.radius))
    elif order == "curve":
        sim.reorder(curve_order(p.pos, p.radius))
    elif order == "random":  # the worst case: what a numbering decays towards as disks mix
        sim.reorder(np.random.default_rng(0).permutation(p.n))


def step_rates(sim, steps: int, blocks: int, threads=(1, 2)) -> dict:
    """Particle-steps/s of whole steps, blocks on 1 and 2 threads in alternation."""
    sim.parallel_min_particles = 0
    rates = {t: [] for t in threads}
    rebuilds = {t: [] for t in threads}
    for t in threads:
        sim.threads = t
        sim.run(10)  # compiled, lists built
    for b in range(blocks):
        for t in threads if b % 2 == 0 else threads[::-1]:
            sim.threads = t
            res = sim.run(steps)
            rates[t].append(res.particle_steps_per_s)
            rebuilds[t].append(res.rebuilds)
    return {
        str(t): {"median": statistics.median(rates[t]), "min": min(rates[t]), "max": max(rates[t]),
                 "all": rates[t], "rebuilds": rebuilds[t]}
        for t in threads
    }  # fmt: skip


def profile_case(sim, steps: int, blocks: int, reps: int, threads=(1, 2)) -> dict:
    t0 = time.perf_counter()
    sim.run(1)
    first_build = time.perf_counter() - t0
    before = index_distance(sim)
    rates = step_rates(sim, steps, blocks, threads)
    after = index_distance(sim)
    phases = phase_times(sim, reps) if reps else {}
    return {
        "n": sim.particles.n, "skin_m": sim.skin, "first_step_with_build_s": first_build,
        "rates": rates, "phases": phases, "bytes": force_pass_bytes(sim),
        "index_distance": {"built": before, "after_steps": after, "steps_between": 10 + 2 * blocks * steps},
        "deferred_disks": int(sim.work.dstart[-1]),
    }  # fmt: skip


def show(name: str, r: dict) -> None:
    n = r["n"]
    print(f"[{name}] {n} disks, skin {r['skin_m'] * 1e3:.3f} mm, deferred disks {r['deferred_disks']}")
    for t, v in r["rates"].items():
        print(
            f"  {t} thread(s): {v['median']:.3e} p-steps/s (blocks {v['min']:.3e}-{v['max']:.3e}), "
            f"rebuilds per block {v['rebuilds']}"
        )
    step1 = n / r["rates"][next(iter(r["rates"]))]["median"]
    print(f"  one step on 1 thread: {step1 * 1e3:.3f} ms")
    for ph, v in r["phases"].items():
        print(
            f"  {ph:26s} {v['median_s'] * 1e3:8.3f} ms ({v['min_s'] * 1e3:.3f}-{v['max_s'] * 1e3:.3f})"
            f"  {v['median_s'] / step1 * 100:5.1f} % of a step"
        )
    b = r["bytes"]
    print(
        f"  force pass: {b['bytes_per_disk']} B per disk, {b['bytes_per_pair']} B per pair, "
        f"{b['pairs_per_disk']:.2f} pairs ({b['touching_per_disk']:.2f} touching) per disk: "
        f"{b['step_mb']:.1f} MB per step ({b['stored_step_mb']:.1f} MB on a step storing all)"
    )
    for when in ("built", "after_steps"):
        d = r["index_distance"][when]
        print(
            f"  |i-j| {when:11s}: verlet mean {d['verlet']['mean']:.0f} (median {d['verlet']['median']:.0f}, "
            f"{d['verlet']['within_64'] * 100:.1f} % within 64); touching mean {d['touching']['mean']:.0f} "
            f"({d['touching']['within_64'] * 100:.1f} % within 64)"
        )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="paper,250k")
    ap.add_argument("--out", default="bench_out")
    ap.add_argument("--steps", type=int, default=200, help="steps per timed block (the paper case runs 20x)")
    ap.add_argument("--blocks", type=int, default=3)
    ap.add_argument("--reps", type=int, default=20, help="repetitions of each phase alone")
    ap.add_argument("--order", choices=("as-built", "strip", "curve", "random"), default="as-built")
    ap.add_argument("--json", default=None, help="write the numbers to this file")
    ap.add_argument("--threads", default="1,2", help="thread counts of the timed blocks")
    ap.add_argument("--sort-every", type=int, default=None, help="renumber along the curve every K steps")
    args = ap.parse_args()
    out = Path(args.out)
    threads = tuple(int(t) for t in args.threads.split(","))
    results = {"copy_bandwidth_gb_s": copy_bandwidth(), "order": args.order, "cases": {}}
    print(f"large-array copy: {results['copy_bandwidth_gb_s']:.1f} GB/s (read + write)")
    for name in [c.strip() for c in args.cases.split(",") if c.strip()]:
        small = name == "paper"
        base, _ = paper_simulation(out, rebuild=False)
        sim = base if small else tiled_simulation(base, *TILINGS[name])
        del base
        renumber(sim, args.order)
        sim.set_sorting(args.sort_every)
        steps = args.steps * (20 if small else 1)
        results["cases"][name] = r = profile_case(
            sim, steps, args.blocks, args.reps * (20 if small else 1), threads
        )
        show(name, r)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
