"""Throughput of poro2d's DEM engine, and the same problem in LAMMPS.

Prints particle-steps per second (disks x steps / wall-clock second of the step loop)
on the settled paper-size packing and on larger packings tiled from it, for 1 and 2
threads, next to LAMMPS on the same positions, radii, contact properties and time step.
This is a measurement script, not a test.

Cases

* ``paper``: ``prepare_specimen(SpecimenSpec(threads=2), paper_grading(), 0.15, seed=0)``
  (about 2560 disks of 2-7 mm in 0.305 m x 0.124 m, Table 1 properties, settled by
  multilayer compaction). The settled state is cached as a checkpoint in the output
  folder (``paper_settled.npz``) and reused unless ``--rebuild`` is given.
* ``25k``, ``250k``, ``1M``: copies of the settled paper packing side by side and stacked
  (no lids between them), with four box walls around the whole; dense at once, no
  settling. The copies are arranged so the box is roughly square.

Physics of every timed run: gravity, local damping 0.7, the working friction left by the
preparation (disk-disk 3.0, disk-wall min(3.0, 1.5) = 1.5), Table 1 stiffnesses in series
(disk-disk 2e5 N/m, disk-wall 3.846e5 N/m), poro2d's automatic time step
(0.5 sqrt(m_min / k_max)); LAMMPS gets exactly that dt.

Timing: a warm-up block (numba compilation, first neighbour build, storage growth) is
never timed; then 1 and 2 threads are timed in alternation, several blocks each, and the
median is reported. The machine's load average is recorded with every number.

    python benchmarks/bench_engine.py                    # full table (a few minutes)
    python benchmarks/bench_engine.py --quick            # paper case only, fewer steps
    python benchmarks/bench_engine.py --skip-lammps --out bench_out
    python benchmarks/bench_engine.py --skin-study       # also: paper case vs. Verlet skin
    python benchmarks/bench_engine.py --quick --skip-lammps --rolling-friction 0.3

``--rolling-friction MU_R`` gives every disk and wall that rolling friction (rolling
resistance on, see docs/engine.md) and keeps the time step of the case without it, so
that a block does the same steps either way and the figures compare the cost of a step.
LAMMPS is not run then.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

# disks per case -> copies of the paper packing (nx side by side, ny stacked)
TILINGS = {
    "25k": (2, 5),
    "250k": (7, 14),
    "1M": (13, 30),
}
# disks per case -> the first disks (from the left) of paper packings side by side: the sizes
# of a user's full-size specimen (``poro2d sand``), where whether a second thread pays is asked
CROPS = {"4k": 4000, "8k": 8000, "12k": 12000}
TARGET_LAMMPS_RATIO = 2.5  # poro2d 1 thread / LAMMPS 1 thread, paper case
TARGET_THREAD_SPEEDUP = 1.7  # poro2d 2 threads / 1 thread
TARGET_LARGE_RETENTION = 0.7  # poro2d 1M / paper case (within 30 %)


def loadavg() -> list[float]:
    try:
        return [round(v, 2) for v in os.getloadavg()]
    except OSError:  # pragma: no cover - not on Linux
        return [math.nan] * 3


def machine_info() -> dict:
    import numba

    import poro2d

    cpu = platform.processor()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpu": cpu,
        "cpu_count": os.cpu_count(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "numba_threads": int(numba.config.NUMBA_NUM_THREADS),
        "poro2d": getattr(poro2d, "__version__", "unknown"),
        "loadavg_start": loadavg(),
    }


# ------------------------------------------------------------------ packings


def paper_simulation(out: Path, rebuild: bool, threads: int = 2):
    """The settled paper-size specimen (from the cached checkpoint when present)."""
    from poro2d.dem import checkpoint

    ck = out / "paper_settled.npz"
    from poro2d.dem import Simulation
    from poro2d.dem.ordering import strip_order
    from poro2d.grading import paper_grading
    from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen

    if ck.is_file() and not rebuild:
        sim = checkpoint.load(ck, threads=threads)
        # a cache written by an engine with another time-step rule is stale
        now = Simulation(
            sim.particles,
            sim.walls,
            sim.contact,
            gravity=sim.gravity,
            local_damping=sim.local_damping,
            dt_safety=SpecimenSpec().dt_safety,
        )
        if math.isclose(now.dt, sim.dt, rel_tol=1e-9):
            print(f"[paper] loaded {ck} ({sim.particles.n} disks)", flush=True)
            # a cache from before the specimen was numbered in strips gets the same layout
            sim.reorder(strip_order(sim.particles.pos, sim.particles.radius))
            return sim, checkpoint.read_meta(ck).get("extra", {}).get("report", {})
        print(
            f"[paper] cached dt {sim.dt:.4e} s differs from the engine's {now.dt:.4e} s: "
            "preparing the specimen again",
            flush=True,
        )

    t0 = time.perf_counter()
    sim, report = prepare_specimen(SpecimenSpec(threads=threads), paper_grading(), 0.15, seed=0)
    report = json.loads(json.dumps(report.to_dict(), default=float))
    print(
        f"[paper] prepared {sim.particles.n} disks in {time.perf_counter() - t0:.0f} s "
        f"(converged={report['converged']}, porosity {report['measured_porosity']:.4f})",
        flush=True,
    )
    out.mkdir(parents=True, exist_ok=True)
    checkpoint.save(sim, ck, extra={"report": report})
    return sim, report


def wall_box(sim) -> tuple[float, float, float, float]:
    """(xlo, xhi, ylo, yhi): the lines of the walls left, right, bottom and top of ``sim``.

    ``Walls.box`` extends each segment past the corners, so the box is read from the
    wall lines, not from the segment ends.
    """
    w = sim.walls
    return (
        float(w.p0[w.index("left"), 0]),
        float(w.p0[w.index("right"), 0]),
        float(w.p0[w.index("bottom"), 1]),
        float(w.p0[w.index("top"), 1]),
    )


def tiled_simulation(base, nx: int, ny: int, threads: int = 1):
    """``nx`` x ``ny`` copies of the settled packing ``base`` in one walled box."""
    from poro2d.dem import ContactModel, Particles, Simulation, Walls

    p = base.particles
    xlo, xhi, ylo, yhi = wall_box(base)
    W, H = xhi - xlo, yhi - ylo
    ox, oy = np.meshgrid(np.arange(nx) * W, np.arange(ny) * H, indexing="ij")
    shift = np.stack([ox.ravel(), oy.ravel()], axis=1)  # (copies, 2)
    ncopy = shift.shape[0]
    pos = (p.pos[None, :, :] + shift[:, None, :]).reshape(-1, 2)

    def rep(a):
        return np.tile(a, ncopy)

    parts = Particles(pos, rep(p.radius), rep(p.density), p.thickness, rep(p.kn), rep(p.ks), rep(p.mu))
    w = base.walls
    walls = Walls.box(xlo, ylo, xlo + nx * W, ylo + ny * H, float(w.kn[0]), float(w.ks[0]), float(w.mu[0]))
    sim = Simulation(
        parts,
        walls,
        ContactModel(base.contact.convention),
        gravity=base.gravity,
        local_damping=base.local_damping,
        dt_safety=base.dt_safety,
        skin=base.skin,
        threads=threads,
    )
    # same lightest disk and stiffest contact: the automatic step is the paper case's
    if not math.isclose(sim.dt, base.dt, rel_tol=1e-12):
        raise RuntimeError(f"tiled dt {sim.dt} differs from the paper case's {base.dt}")
    return sim


def cropped_simulation(base, n: int, threads: int = 1):
    """The ``n`` leftmost disks of paper packings side by side, walls closed around them.

    A strip one packing high, as long as ``n`` disks make it: the right wall is put at the
    kept disks' edge, so the last column is loose (a few disks of the ``n``).
    """
    from poro2d.dem import ContactModel, Particles, Simulation, Walls

    copies = math.ceil(n / base.particles.n)
    tiled = tiled_simulation(base, copies, 1, threads)
    p = tiled.particles
    keep = np.argsort(p.pos[:, 0], kind="stable")[:n]
    parts = Particles(p.pos[keep], p.radius[keep], p.density[keep], p.thickness, p.kn[keep], p.ks[keep],
                      p.mu[keep])  # fmt: skip
    xlo, _, ylo, yhi = wall_box(tiled)
    xhi = float((p.pos[keep, 0] + p.radius[keep]).max())
    w = tiled.walls
    walls = Walls.box(xlo, ylo, xhi, yhi, float(w.kn[0]), float(w.ks[0]), float(w.mu[0]))
    return Simulation(parts, walls, ContactModel(base.contact.convention), gravity=base.gravity,
                      local_damping=base.local_damping, dt_safety=base.dt_safety, skin=base.skin,
                      threads=threads)  # fmt: skip


def with_rolling(sim, mu_r: float) -> None:
    """Rolling friction ``mu_r`` on every disk and wall, at the time step the case had without it."""
    if mu_r > 0.0:
        dt = sim.dt
        sim.set_rolling_friction(mu_r, walls=mu_r)
        sim.dt = dt


# ------------------------------------------------------------------ timing


def _set_threads(sim, threads: int) -> None:
    sim.threads = sim.check_threads(threads)
    sim.parallel_min_particles = 0  # measure what was asked, whatever the size


def time_poro2d(
    sim, steps: int, repeats: int, warmup: int, threads=(1, 2), lammps=None, paper=None, paper_steps=0
) -> dict:
    """Median particle-steps/s per thread count; all runs of a round timed in alternation.

    A round runs one block per thread count; with ``lammps`` (a
    :class:`lammps_reference.LammpsSession`) also one LAMMPS block of the same length,
    and with ``paper`` (the paper-case simulation) one ``paper_steps`` block of it per
    thread count, so that ratios to the paper case compare blocks of the same minute.
    The order within a round flips from round to round: nobody always runs first.
    """
    runs: list = list(threads)
    if paper is not None:
        runs += [("paper", t) for t in threads]
    if lammps is not None:
        runs.append("lammps")
    rates: dict = {r: [] for r in runs if r != "lammps"}
    loads: dict = {t: [] for t in threads}
    rebuilds: dict = {t: [] for t in threads}
    for t in threads:  # compile, build the lists, grow the storage: not timed
        _set_threads(sim, t)
        sim.run(warmup)
    for k in range(repeats):
        for r in runs if k % 2 == 0 else runs[::-1]:
            if r == "lammps":
                lammps.block(steps)
            elif isinstance(r, tuple):
                _set_threads(paper, r[1])
                rates[r].append(paper.run(paper_steps).particle_steps_per_s)
            else:
                _set_threads(sim, r)
                res = sim.run(steps)
                rates[r].append(res.particle_steps_per_s)
                loads[r].append(loadavg())
                rebuilds[r].append(res.rebuilds)
    out: dict = {}
    for t in threads:
        out[t] = {
            "particle_steps_per_s": statistics.median(rates[t]),
            "best": max(rates[t]),
            "all": rates[t],
            "steps": steps,
            "repeats": repeats,
            "rebuilds": rebuilds[t],
            "loadavg": loads[t],
        }
        if paper is not None:
            out[t]["paper_all"] = rates[("paper", t)]
    return out


def paired(a: list[float], b: list[float]) -> dict:
    """Ratios a[k] / b[k] of blocks timed in the same round: their median and range."""
    q = [x / y for x, y in zip(a, b, strict=True)]
    return {"median": statistics.median(q), "min": min(q), "max": max(q), "all": q}


def contact_stats(sim) -> dict:
    nb = sim.pairs.used
    touching = len(sim.pairs.touching())
    return {
        "verlet_pairs_per_disk": nb / sim.particles.n,
        "touching_pairs_per_disk": touching / sim.particles.n,
        "wall_pairs": sim.wall_pairs.used,
    }


def lammps_params(sim) -> dict:
    """Combined contact properties of ``sim`` (PFC 4.0 per body) in run_lammps terms."""
    from lammps_reference import series

    p, w = sim.particles, sim.walls
    kp, sp, mp = float(p.kn[0]), float(p.ks[0]), float(p.mu[0])
    kw, sw, mw = float(w.kn[0]), float(w.ks[0]), float(w.mu[0])
    for name, a in (("kn", p.kn), ("ks", p.ks), ("mu", p.mu)):
        if not np.all(a == a[0]):
            raise ValueError(f"LAMMPS reference needs one disk {name}")
    density = float(p.density[0])
    return dict(
        density=density,
        thickness=p.thickness,
        kn_pp=series(kp, kp),
        kt_pp=series(sp, sp),
        mu_pp=mp,
        kn_pw=series(kp, kw),
        kt_pw=series(sp, sw),
        mu_pw=min(mp, mw),
        gravity=-float(sim.gravity[1]),
        damping_cundall=sim.local_damping,
        dt=sim.dt,
    )


def time_lammps(
    sim,
    label: str,
    steps: int,
    repeats: int,
    settle: int,
    threads=1,
    mpi_ranks=1,
    wait_policy: str | None = "PASSIVE",
    timeout: float = 300.0,
) -> dict | None:
    """LAMMPS on the positions and radii of ``sim``; ``wait_policy`` None: OpenMP default.

    Returns None when the run exceeds ``timeout`` seconds (spinning OpenMP threads on a
    loaded machine ran at ~1e5 particle-steps/s).
    """
    import subprocess

    from lammps_reference import run_lammps

    p = sim.particles
    old = os.environ.get("OMP_WAIT_POLICY")
    if wait_policy is None:
        os.environ.pop("OMP_WAIT_POLICY", None)
    else:
        os.environ["OMP_WAIT_POLICY"] = wait_policy
    try:
        t0 = time.perf_counter()
        res = run_lammps(
            p.pos[:, 0],
            p.pos[:, 1],
            p.radius,
            wall_box(sim),
            **lammps_params(sim),
            settle_steps=settle,
            measure_steps=steps,
            repeats=repeats,
            threads=threads,
            mpi_ranks=mpi_ranks,
            timeout=timeout,
        )
        wall = time.perf_counter() - t0
    except subprocess.TimeoutExpired:
        print(f"  LAMMPS {label:24s} timed out after {timeout:.0f} s (load {loadavg()[0]})", flush=True)
        return None
    finally:
        if old is None:
            os.environ.pop("OMP_WAIT_POLICY", None)
        else:
            os.environ["OMP_WAIT_POLICY"] = old
    res["loadavg"] = loadavg()
    res["label"] = label
    res["omp_wait_policy"] = wait_policy or "default"
    print(
        f"  LAMMPS {label:24s} {res['particle_steps_per_s']:.3e} p-steps/s "
        f"(median of {repeats} x {steps} steps, floor force {res['bottom_wall_force']:.1f} N, "
        f"finite={res['finite']}, {wall:.0f} s incl. setup; load {res['loadavg'][0]})",
        flush=True,
    )
    return res


# ------------------------------------------------------------------ skin study


def skin_study(ck: Path, factors, steps: int, repeats: int, threads: int = 1) -> list[dict]:
    """Paper case (from the checkpoint ``ck``) at several Verlet skins (x the mean radius)."""
    from poro2d.dem import checkpoint
    from poro2d.dem import kernels as K

    rows = []
    for f in factors:
        sim = checkpoint.load(ck, threads=threads)
        rmean = float(sim.particles.radius.mean())
        sim._skin = f * rmean  # the lists are rebuilt with it; shear history is kept
        sim._refresh()
        sim.run(200)
        rates, rb = [], []
        for _ in range(repeats):
            res = sim.run(steps)
            rates.append(res.particle_steps_per_s)
            rb.append(res.rebuilds)
        # cost of one neighbour build (disk-disk + disk-wall + reverse), timed directly
        bt = []
        for _ in range(5):
            t0 = time.perf_counter()
            sim.kernel_params.iprm[K.NEED_BUILD] = 1
            sim.run(1)
            bt.append(time.perf_counter() - t0)
        step1 = []
        for _ in range(5):
            t0 = time.perf_counter()
            sim.run(1)
            step1.append(time.perf_counter() - t0)
        row = {
            "skin_over_rmean": f,
            "skin_m": f * rmean,
            "particle_steps_per_s": statistics.median(rates),
            "all": rates,
            "rebuilds_per_block": rb,
            "steps": steps,
            "step_with_build_s": min(bt),
            "step_without_build_s": min(step1),
            **contact_stats(sim),
            "loadavg": loadavg(),
        }
        rows.append(row)
        print(
            f"  skin {f:.2f} r_mean = {f * rmean * 1e3:.3f} mm: "
            f"{row['particle_steps_per_s']:.3e} p-steps/s, rebuilds/block {rb}, "
            f"pairs/disk {row['verlet_pairs_per_disk']:.2f}, one step with/without build "
            f"{row['step_with_build_s'] * 1e3:.2f}/{row['step_without_build_s'] * 1e3:.2f} ms "
            f"(load {row['loadavg'][0]})",
            flush=True,
        )
    return rows


# ------------------------------------------------------------------ report


def _fmt(v) -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.2e}"


def _ratio(a, b):
    return a / b if a is not None and b is not None and b > 0 else None


def table(results: dict) -> str:
    rows = [
        "| case | N | poro2d 1 thread | poro2d 2 threads | LAMMPS 1 thread | "
        "LAMMPS 2 (best of omp/mpi) | poro2d 1t / LAMMPS 1t | poro2d 2t / 1t | "
        "poro2d / paper (1t, 2t) | load avg |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    paper = results["cases"].get("paper", {}).get("poro2d", {})
    for name, c in results["cases"].items():
        pr = c.get("poro2d", {})
        p1 = pr.get("1", {}).get("particle_steps_per_s")
        p2 = pr.get("2", {}).get("particle_steps_per_s")
        lm = c.get("lammps", {})
        l1 = lm.get("1 thread", {}).get("particle_steps_per_s")
        l2s = [v["particle_steps_per_s"] for k, v in lm.items() if k != "1 thread"]
        l2 = max(l2s) if l2s else None
        pair = c.get("paired", {})
        r_l = pair.get("poro2d 1t / LAMMPS 1t", {}).get("median", _ratio(p1, l1))
        r_t = pair.get("poro2d 2t / 1t", {}).get("median", _ratio(p2, p1))
        if name == "paper":
            r_p = "1"
        else:
            a = pair.get("poro2d 1t / paper 1t", {}).get(
                "median", _ratio(p1, paper.get("1", {}).get("particle_steps_per_s"))
            )
            b = pair.get("poro2d 2t / paper 2t", {}).get(
                "median", _ratio(p2, paper.get("2", {}).get("particle_steps_per_s"))
            )
            r_p = f"{a:.2f}, {b:.2f}" if a is not None and b is not None else "-"
        loads = [ld[0] for t in pr.values() for ld in t.get("loadavg", [])]
        load = f"{min(loads):.1f}-{max(loads):.1f}" if loads else "-"
        rows.append(
            f"| {name} | {c['n']} | {_fmt(p1)} | {_fmt(p2)} | {_fmt(l1)} | {_fmt(l2)} | "
            f"{'-' if r_l is None else f'{r_l:.2f}'} | {'-' if r_t is None else f'{r_t:.2f}'} | "
            f"{r_p} | {load} |"
        )
    return "\n".join(rows)


def targets(results: dict) -> list[tuple[str, float | None, float, bool | None]]:
    cases = results["cases"]
    paper = cases.get("paper", {})
    p1 = paper.get("poro2d", {}).get("1", {}).get("particle_steps_per_s")
    p2 = paper.get("poro2d", {}).get("2", {}).get("particle_steps_per_s")
    l1 = paper.get("lammps", {}).get("1 thread", {}).get("particle_steps_per_s")
    pair = paper.get("paired", {})
    r_l = pair.get("poro2d 1t / LAMMPS 1t", {}).get("median", _ratio(p1, l1))
    r_t = pair.get("poro2d 2t / 1t", {}).get("median", _ratio(p2, p1))
    out = [("paper: poro2d 1 thread / LAMMPS 1 thread", r_l, TARGET_LAMMPS_RATIO)]
    out.append(("paper: poro2d 2 threads / 1 thread", r_t, TARGET_THREAD_SPEEDUP))
    for name, c in cases.items():
        if name == "paper":
            continue
        q1 = c.get("poro2d", {}).get("1", {}).get("particle_steps_per_s")
        q2 = c.get("poro2d", {}).get("2", {}).get("particle_steps_per_s")
        r_t = c.get("paired", {}).get("poro2d 2t / 1t", {}).get("median", _ratio(q2, q1))
        out.append((f"{name}: poro2d 2 threads / 1 thread", r_t, TARGET_THREAD_SPEEDUP))
        if name == "1M":
            pc = c.get("paired", {})
            r1 = pc.get("poro2d 1t / paper 1t", {}).get("median", _ratio(q1, p1))
            r2 = pc.get("poro2d 2t / paper 2t", {}).get("median", _ratio(q2, p2))
            out.append(("1M / paper, 1 thread", r1, TARGET_LARGE_RETENTION))
            out.append(("1M / paper, 2 threads", r2, TARGET_LARGE_RETENTION))
    return [(k, v, t, None if v is None else v >= t) for k, v, t in out]


# ------------------------------------------------------------------ main


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="paper case only, fewer steps")
    ap.add_argument("--skip-lammps", action="store_true", help="poro2d only")
    ap.add_argument(
        "--out", default="bench_out", help="output folder: bench.json and the cached settled packing"
    )
    ap.add_argument(
        "--rebuild", action="store_true", help="prepare the paper specimen again instead of loading the cache"
    )
    ap.add_argument(
        "--cases", default="paper,25k,250k,1M", help="comma-separated subset of paper,25k,250k,1M"
    )
    ap.add_argument(
        "--repeats", type=int, default=9, help="timed rounds (a block per thread count and of LAMMPS)"
    )
    ap.add_argument(
        "--omp-wait-policy",
        default="PASSIVE",
        choices=("PASSIVE", "ACTIVE", "unset"),
        help="OMP_WAIT_POLICY for poro2d's OpenMP threads (set before numba starts "
        "them). PASSIVE by default: on a shared, loaded 2-core machine spinning "
        "threads made 2 threads 10-50x slower than 1",
    )
    ap.add_argument(
        "--skin-study",
        action="store_true",
        help="also time the paper case at skins of 0.1-0.5 x the mean radius",
    )
    ap.add_argument(
        "--rolling-friction",
        type=float,
        default=0.0,
        help="rolling friction of every disk and wall (0: none); the time step stays that without it",
    )
    args = ap.parse_args(argv)
    if not (args.rolling_friction >= 0.0 and math.isfinite(args.rolling_friction)):
        ap.error(f"--rolling-friction {args.rolling_friction}: allowed [0, inf)")
    if args.rolling_friction > 0.0 and not args.skip_lammps:
        print("--rolling-friction: LAMMPS is not run (the timed LAMMPS model has no rolling resistance)")
        args.skip_lammps = True

    sys.path.insert(0, str(HERE))
    # libgomp reads the wait policy when numba first starts its OpenMP threads
    if args.omp_wait_policy == "unset":
        os.environ.pop("OMP_WAIT_POLICY", None)
    else:
        os.environ["OMP_WAIT_POLICY"] = args.omp_wait_policy
    import numba

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    info = machine_info()
    if info["numba_threads"] < 2:
        print("numba sees one thread only; the 2-thread columns stay empty")
    threads = (1, 2) if info["numba_threads"] >= 2 else (1,)
    print(
        f"{info['cpu']}, {info['cpu_count']} cores, numba {info['numba']} "
        f"({info['numba_threads']} threads), load average {info['loadavg_start']}",
        flush=True,
    )

    names = ["paper"] if args.quick else [c.strip() for c in args.cases.split(",") if c.strip()]
    # steps per timed block and warm-up steps
    plan = {
        "paper": (500, 200) if args.quick else (3000, 500),
        "25k": (400, 500),  # the tiled copies settle where they meet: see speed_table.PLAN
        "250k": (100, 500),
        "1M": (40, 500),
        **{name: (1500, 200) for name in CROPS},
    }
    rep = max(1, 3 if args.quick else args.repeats)
    rep_big = {name: rep for name in plan}

    base, prep = paper_simulation(out, args.rebuild)
    results: dict = {
        "machine": info,
        "preparation": prep,
        "cases": {},
        "settings": {
            "dt_s": base.dt,
            "skin_m": base.skin,
            "mean_radius_m": float(base.particles.radius.mean()),
            "friction_disk": float(base.particles.mu[0]),
            "friction_wall": float(base.walls.mu[0]),
            "local_damping": base.local_damping,
            "gravity": list(base.gravity),
            "omp_wait_policy_poro2d": args.omp_wait_policy,
            "threading_layer": None,
            "rolling_friction": args.rolling_friction,
        },
    }
    print(
        f"dt = {base.dt:.4e} s, skin = {base.skin * 1e3:.3f} mm, friction disk "
        f"{base.particles.mu[0]:g} / wall {base.walls.mu[0]:g}, damping {base.local_damping}",
        flush=True,
    )

    for name in names:
        if name == "paper":
            sim = base
        elif name in CROPS:
            sim = cropped_simulation(base, CROPS[name])
            print(f"[{name}] {sim.particles.n} disks cut from paper packings side by side", flush=True)
        else:
            nx, ny = TILINGS[name]
            t0 = time.perf_counter()
            sim = tiled_simulation(base, nx, ny)
            print(
                f"[{name}] tiled {nx} x {ny} copies: {sim.particles.n} disks in "
                f"{wall_box(sim)[1] - wall_box(sim)[0]:.3f} m x "
                f"{wall_box(sim)[3] - wall_box(sim)[2]:.3f} m "
                f"({time.perf_counter() - t0:.1f} s)",
                flush=True,
            )
        with_rolling(sim, args.rolling_friction)
        steps, warm = plan[name]
        session = None
        with_lammps = not args.skip_lammps and name in ("paper", "25k")
        if with_lammps:
            from lammps_reference import LammpsSession

            t0 = time.perf_counter()
            session = LammpsSession(
                sim.particles.pos[:, 0], sim.particles.pos[:, 1], sim.particles.radius, wall_box(sim),
                **lammps_params(sim), settle_steps=500 if args.quick else 2000, block_steps=steps,
            )  # fmt: skip
            print(f"  LAMMPS session started and settled ({time.perf_counter() - t0:.0f} s)", flush=True)
        t0 = time.perf_counter()
        ref = {} if name == "paper" else {"paper": base, "paper_steps": plan["paper"][0]}
        r = time_poro2d(sim, steps, rep_big[name], warm, threads, lammps=session, **ref)
        try:
            results["settings"]["threading_layer"] = numba.threading_layer()
        except ValueError:
            pass
        case = {
            "n": sim.particles.n,
            "box": wall_box(sim),
            "poro2d": {str(t): v for t, v in r.items()},
            "poro2d_floor_force_N": float(-sim.wall_force("bottom")[1]),
            "weight_N": float(sim.particles.mass.sum() * -sim.gravity[1]),
            **contact_stats(sim),
        }
        line = ", ".join(
            f"{t} thread(s) {v['particle_steps_per_s']:.3e} (best {v['best']:.3e})" for t, v in r.items()
        )
        print(
            f"  poro2d {line} p-steps/s (median of {rep_big[name]} x {steps} steps; "
            f"{time.perf_counter() - t0:.0f} s; load {loadavg()[0]}); floor force "
            f"{case['poro2d_floor_force_N']:.1f} N (weight {case['weight_N']:.1f} N: the "
            f"packing is held between floor and top plate)",
            flush=True,
        )
        case["paired"] = {}
        if 2 in r:
            case["paired"]["poro2d 2t / 1t"] = paired(r[2]["all"], r[1]["all"])
        for t in r:
            if "paper_all" in r[t]:
                case["paired"][f"poro2d {t}t / paper {t}t"] = paired(r[t]["all"], r[t]["paper_all"])
        if with_lammps:
            lm = {}
            ls, lrep, lset = (steps, rep, 2000) if name == "paper" else (400, 3, 200)
            if args.quick:
                ls, lset = 1000, 500
            ses = session.close()
            lm["1 thread"] = {
                "particle_steps_per_s": statistics.median(ses["particle_steps_per_s"]),
                "all": ses["particle_steps_per_s"],
                "steps": steps,
                "label": "1 thread, blocks alternating with poro2d's",
                **{k: v for k, v in ses.items() if k != "particle_steps_per_s"},
            }
            case["paired"]["poro2d 1t / LAMMPS 1t"] = paired(r[1]["all"], ses["particle_steps_per_s"])
            print(
                f"  LAMMPS 1 thread {lm['1 thread']['particle_steps_per_s']:.3e} p-steps/s (median of "
                f"{len(ses['loop_times_s'])} blocks alternating with "
                f"poro2d's; floor force {ses['bottom_wall_force']:.1f} N, finite={ses['finite']})",
                flush=True,
            )
            if name == "paper":
                lm["2 OpenMP threads (PASSIVE)"] = time_lammps(
                    sim, "2 OpenMP threads (PASSIVE)", ls, lrep, lset, threads=2
                )
                if not args.quick:
                    lm["2 OpenMP threads (default wait)"] = time_lammps(
                        sim,
                        "2 OpenMP threads (default wait)",
                        ls,
                        lrep,
                        lset,
                        threads=2,
                        wait_policy=None,
                        timeout=120.0,
                    )
                lm["2 MPI ranks"] = time_lammps(sim, "2 MPI ranks", ls, lrep, lset, mpi_ranks=2)
            lm = {k: v for k, v in lm.items() if v is not None}
            for v in lm.values():
                v.pop("x", None), v.pop("y", None), v.pop("radius", None)
            case["lammps"] = lm
        for k, v in case["paired"].items():
            print(f"  paired {k}: median {v['median']:.2f} (rounds {v['min']:.2f}-{v['max']:.2f})")
        results["cases"][name] = case
        if sim is not base:
            del sim

    if args.skin_study:
        print("[skin study] paper case, 1 thread", flush=True)
        results["skin_study"] = skin_study(
            out / "paper_settled.npz", (0.1, 0.15, 0.2, 0.3, 0.4, 0.5), 1000 if args.quick else 3000, 3
        )

    results["machine"]["loadavg_end"] = loadavg()
    try:
        import resource

        results["machine"]["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    except ImportError:  # pragma: no cover - not on Unix
        pass
    results["targets"] = [dict(name=k, value=v, target=t, met=m) for k, v, t, m in targets(results)]
    print()
    print("particle-steps per second (median of the timed blocks); ratios: median of per-round ratios")
    print(table(results))
    print()
    for k, v, t, m in targets(results):
        vs = "-" if v is None else f"{v:.2f}"
        print(f"target {k}: {vs} (>= {t}) {'met' if m else ('not met' if m is not None else '')}")
    print(
        f"load average at start {info['loadavg_start']}, at end "
        f"{results['machine']['loadavg_end']}; peak memory "
        f"{results['machine'].get('peak_rss_mb', math.nan):.0f} MB"
    )
    (out / "bench.json").write_text(json.dumps(results, indent=1, default=float))
    print(f"wrote {out / 'bench.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
