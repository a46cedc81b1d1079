"""Two source trees of poro2d's engine timed in alternation: is a change faster, and by how much?

Each round starts one process per tree (``PYTHONPATH`` set to the tree's ``src``), one after
the other, in an order that flips from round to round, so that the drift of a shared machine
hits both trees alike. A process builds a case of ``bench_engine.py`` (the settled paper
packing, about 2.5k disks, from the cached checkpoint in ``--out``; or its tiled copies,
``25k``, ``250k``), runs a warm-up (compilation, list build, storage growth; not timed),
then times one block per thread count, in flipped order too. A tree's rate is particle-steps
per second of ``Simulation.run``; the answer is the ratio new / old of the two blocks of the
same round and thread count: its median and range over the rounds, with the load average
seen before and after each block.

How fast numba's code is can depend on the compilation itself: the order of some of its
work follows Python's hash seed, and a list build's scan was once twice as fast in one
compilation as in another. So ``--hash-seeds`` compiles each tree once per seed (its own
numba cache folder per tree and seed, ``PYTHONHASHSEED`` set) and runs ``--rounds`` rounds
with each: a ratio then compares the two trees, not two draws of the compiler.

    python benchmarks/paired_trees.py --old ../before/src --new src --cases paper,250k --rounds 5

A measurement script, not a test: the numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
# steps per timed block and warm-up steps, as bench_engine.py's table times them
PLAN = {"paper": (3000, 500), "25k": (400, 500), "250k": (100, 500)}


def worker(case: str, threads: list[int], steps: int, warmup: int, out: Path) -> dict:
    """Time one block per thread count of ``case`` with the poro2d on ``sys.path``."""
    sys.path.insert(0, str(HERE))
    from bench_engine import TILINGS, _set_threads, loadavg, paper_simulation, tiled_simulation

    base, _ = paper_simulation(out, rebuild=False)
    sim = base if case == "paper" else tiled_simulation(base, *TILINGS[case])
    for t in threads:
        _set_threads(sim, t)
        sim.run(warmup)
    import poro2d

    rates: dict = {"source": str(Path(poro2d.__file__).parent)}
    for t in threads:
        _set_threads(sim, t)
        before = loadavg()[0]
        res = sim.run(steps)
        rates[str(t)] = {"rate": res.particle_steps_per_s, "load": [before, loadavg()[0]],
                         "rebuilds": res.rebuilds}  # fmt: skip
    return rates


def run_round(src: str, case: str, threads: list[int], out: Path, seed: str | None, tree: str) -> dict:
    steps, warmup = PLAN[case]
    env = dict(os.environ, PYTHONPATH=str(Path(src).resolve()), OMP_WAIT_POLICY="PASSIVE")
    if seed is not None:
        env.update(
            PYTHONHASHSEED=seed, NUMBA_CACHE_DIR=str((out / "numba_cache" / f"{tree}-{seed}").resolve())
        )
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", case, "--threads",
           ",".join(map(str, threads)), "--steps", str(steps), "--warmup", str(warmup),
           "--out", str(out)]  # fmt: skip
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--old", help="the src folder of the tree before the change")
    ap.add_argument("--new", help="the src folder of the tree with the change")
    ap.add_argument("--cases", default="paper,250k")
    ap.add_argument("--rounds", type=int, default=5, help="rounds (per hash seed, with --hash-seeds)")
    ap.add_argument("--hash-seeds", default=None, help="compile each tree once per seed: e.g. 0,1,2")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--out", default="bench_out", help="where bench_engine.py caches the settled packing")
    ap.add_argument("--json", default=None, help="write every block's numbers to this file")
    ap.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--steps", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--warmup", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args()
    threads = [int(t) for t in args.threads.split(",")]
    out = Path(args.out)
    if args.worker:
        print(json.dumps(worker(args.worker, threads, args.steps, args.warmup, out)))
        return 0
    if not (args.old and args.new):
        ap.error("--old and --new are needed")
    results: dict = {}
    for case in [c.strip() for c in args.cases.split(",") if c.strip()]:
        rounds = []
        seeds = args.hash_seeds.split(",") if args.hash_seeds else [None]
        for k, seed in enumerate(s for s in seeds for _ in range(args.rounds)):
            order = ("old", "new") if k % 2 == 0 else ("new", "old")
            got = {"hash_seed": seed}
            for tree in order:
                tt = threads if k % 2 == 0 else threads[::-1]
                got[tree] = run_round(getattr(args, tree), case, tt, out, seed, tree)
            for tree in order:  # each process ran the tree it was given
                assert Path(got[tree]["source"]).resolve().parent == Path(getattr(args, tree)).resolve(), got[
                    tree
                ]
            rounds.append(got)
            line = ", ".join(
                f"{t}t old {got['old'][str(t)]['rate']:.3e} new {got['new'][str(t)]['rate']:.3e} "
                f"({got['new'][str(t)]['rate'] / got['old'][str(t)]['rate']:.3f}x)"
                for t in threads
            )
            print(f"[{case}] round {k + 1} (hash seed {seed}): {line}", flush=True)
        summary = {}
        for t in threads:
            q = [r["new"][str(t)]["rate"] / r["old"][str(t)]["rate"] for r in rounds]
            loads = [x for r in rounds for tree in ("old", "new") for x in r[tree][str(t)]["load"]]
            summary[str(t)] = {
                "ratio_median": statistics.median(q), "ratio_min": min(q), "ratio_max": max(q),
                "old_median": statistics.median(r["old"][str(t)]["rate"] for r in rounds),
                "new_median": statistics.median(r["new"][str(t)]["rate"] for r in rounds),
                "load_min": min(loads), "load_max": max(loads),
            }  # fmt: skip
            s = summary[str(t)]
            print(
                f"[{case}] {t} thread(s): new / old {s['ratio_median']:.3f}x ({s['ratio_min']:.3f}-"
                f"{s['ratio_max']:.3f}); old {s['old_median']:.3e}, new {s['new_median']:.3e} "
                f"particle-steps/s; load {s['load_min']:.2f}-{s['load_max']:.2f}",
                flush=True,
            )
        results[case] = {"rounds": rounds, "summary": summary}
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
