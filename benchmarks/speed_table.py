"""One speed table: poro2d's engine beside LAMMPS, and the protocols where a user waits.

Engine part. The settled paper specimen of ``bench_engine.py`` (about 2.5k disks) and its
tiled copies (about 25k and 250k disks, ``bench_engine.TILINGS``), the same positions,
radii, contact law and time step in both codes (``bench_engine.lammps_params``). Each
round runs one block of poro2d on 1 thread, one on 2 threads, and one block of LAMMPS on
1 core, on 2 MPI ranks and on 2 OpenMP threads; the order within a round flips from round
to round, so that the drift of a shared machine hits both codes alike
(``bench_engine.time_poro2d``). LAMMPS on 1 core and on 2 OpenMP threads runs in
``lammps_reference.LammpsSession`` processes asleep between blocks; the MPI run cannot
take requests on its input (only rank 0 reads it), so each of its blocks is a fresh
``run_lammps`` call whose settling run is not timed. Every rate is the LAMMPS ``Loop
time`` or poro2d's step loop (setup excluded). The table gives the median over the rounds
and the spread (lowest-highest); every ratio is the median of the per-round ratios. For
the larger sizes each round also runs a paper-size block, so that the rate kept at size
(``1t / 2.5k``) compares blocks of the same minute.

Protocol part. ``poro2d paper``, ``poro2d sand examples/soils/toyoura.toml`` and
``poro2d relation --preset paper``, each in a fresh temporary folder with an empty poro2d
cache (``PORO2D_CACHE``; numba's compiled kernels are kept), wall time of the whole
command. The full part takes about half an hour on 2 cores; ``--quick`` times
``paper --quick``, ``sand --preflight`` and ``relation --preset paper --quick`` instead.

Output: ``speed_table.md`` and ``speed_table.csv`` in ``--out`` (the machine: CPU, cores,
poro2d and LAMMPS versions, date, load average at start and end), and the markdown
printed.

    python benchmarks/speed_table.py --only engine --sizes 2.5k,25k
    python benchmarks/speed_table.py --quick                   # small blocks, quick protocols
    python benchmarks/speed_table.py --only protocols          # about 30 min on 2 cores

A measurement script, not a test: the numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from bench_engine import (  # noqa: E402
    TILINGS,
    lammps_params,
    loadavg,
    machine_info,
    paired,
    paper_simulation,
    tiled_simulation,
    time_lammps,
    time_poro2d,
    wall_box,
)

SIZES = ("2.5k", "25k", "250k", "1M")  # 2.5k: the settled paper specimen, the rest tiled from it
# steps per timed block, untimed warm-up steps of poro2d (per thread count, so twice that in
# all), untimed settling steps of LAMMPS. The tiled copies settle where they meet: at 250k
# disks their lists were rebuilt 4, 4, 3, 1, 2, 1 times in the first six blocks of 100 steps,
# then 0-1 times a block, as the settled paper case. Both codes are timed after 1000 steps.
PLAN = {"2.5k": (3000, 500, 2000), "25k": (400, 500, 1000), "250k": (100, 500, 1000), "1M": (40, 500, 1000)}
QUICK_PLAN = {"2.5k": (500, 200, 500), "25k": (100, 20, 100), "250k": (20, 5, 20), "1M": (10, 2, 10)}
TOYOURA = ROOT / "examples" / "soils" / "toyoura.toml"
# name -> (full command, --quick command), after ``python -m poro2d.cli``
PROTOCOLS = {
    "paper": (["paper"], ["paper", "--quick"]),
    "sand toyoura": (["sand", str(TOYOURA)], ["sand", str(TOYOURA), "--preflight"]),
    "relation paper": (["relation", "--preset", "paper"], ["relation", "--preset", "paper", "--quick"]),
}
# engine quantities of the table, in its column order: key -> heading
ENGINE_COLUMNS = {
    "poro2d_1t": "poro2d 1 thread",
    "lammps_1": "LAMMPS 1 core",
    "ratio_1": "ratio",
    "poro2d_2t": "poro2d 2 threads",
    "lammps_mpi2": "LAMMPS MPI-2",
    "ratio_mpi2": "ratio",
    "lammps_omp2": "LAMMPS OpenMP-2",
    "speedup_2t": "poro2d 2t / 1t",
    "kept_1t": "poro2d 1t / 2.5k",
}
CSV_HEADER = (
    "part",
    "case",
    "disks",
    "quantity",
    "median",
    "min",
    "max",
    "rounds",
    "unit",
    "load_min",
    "load_max",
)


# ------------------------------------------------------------------ options


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The command's options, checked: unknown sizes or parts end with a one-line error (exit 2)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", choices=("all", "engine", "protocols"), default="all", help="which part to run")
    ap.add_argument(
        "--sizes", default="2.5k,25k,250k", help=f"engine sizes, comma-separated, of {', '.join(SIZES)}"
    )
    ap.add_argument(
        "--quick", action="store_true", help="short blocks, 3 rounds, the quick protocol commands"
    )
    ap.add_argument(
        "--repeats", type=int, default=None, help="timed rounds per size (default 7; 3 with --quick)"
    )
    ap.add_argument("--no-lammps", action="store_true", help="poro2d only")
    ap.add_argument("--no-omp", action="store_true", help="leave out LAMMPS on 2 OpenMP threads")
    ap.add_argument(
        "--out", type=Path, default=Path("speed_out"), help="folder of the table and the settled specimen"
    )
    ap.add_argument(
        "--rebuild", action="store_true", help="prepare the paper specimen again, not from the cache"
    )
    args = ap.parse_args(argv)
    args.sizes = _sizes(ap, args.sizes)
    if args.repeats is None:
        args.repeats = 3 if args.quick else 7
    if args.repeats < 1:
        ap.error(f"--repeats {args.repeats}: allowed 1 or more")
    return args


def _sizes(ap: argparse.ArgumentParser, text: str) -> list[str]:
    sizes = [s.strip() for s in text.split(",") if s.strip()]
    bad = [s for s in sizes if s not in SIZES]
    if bad or not sizes:
        ap.error(f"--sizes {text!r}: allowed a comma-separated list of {', '.join(SIZES)}")
    return sorted(set(sizes), key=SIZES.index)


# ------------------------------------------------------------------ records


@dataclass
class Measured:
    """One quantity of the table: every round's value, summarised as median and spread."""

    values: list[float]
    unit: str = "particle-steps/s"

    def summary(self) -> tuple[float, float, float]:
        v = [x for x in self.values if math.isfinite(x)]
        if not v:
            return math.nan, math.nan, math.nan
        return statistics.median(v), min(v), max(v)


@dataclass
class EngineRow:
    size: str
    disks: int
    steps: int
    quantities: dict[str, Measured] = field(default_factory=dict)
    loads: list[float] = field(default_factory=list)


@dataclass
class ProtocolRow:
    name: str
    command: str
    wall_s: float
    exit_code: int
    loads: list[float] = field(default_factory=list)


# ------------------------------------------------------------------ engine part


class LammpsBlocks:
    """LAMMPS on 1 core, on 2 MPI ranks and on 2 OpenMP threads: one block each per :meth:`block`.

    Handed to ``bench_engine.time_poro2d`` as its ``lammps``, so the LAMMPS blocks take
    their turn in every round beside poro2d's.
    """

    def __init__(self, sim, steps: int, settle: int, *, mpi: bool = True, omp: bool = True) -> None:
        from lammps_reference import LammpsSession

        p = sim.particles
        args = (p.pos[:, 0], p.pos[:, 1], p.radius, wall_box(sim))
        kw = dict(lammps_params(sim), settle_steps=settle, block_steps=steps)
        self.sim, self.settle = sim, settle
        self.serial = LammpsSession(*args, **kw)
        self.omp = LammpsSession(*args, **kw, threads=2) if omp else None
        self.mpi = [] if mpi else None

    def block(self, steps: int) -> None:
        self.serial.block(steps)
        if self.omp is not None:
            self.omp.block(steps)
        if self.mpi is not None:
            # a fresh process per block, settled as long as the sessions: the same state is timed
            res = time_lammps(self.sim, "MPI-2 block", steps, 1, self.settle, mpi_ranks=2)
            self.mpi.append(math.nan if res is None else res["particle_steps_per_s"])

    def close(self) -> dict[str, list[float]]:
        """Each configuration's rate per round; also the LAMMPS version."""
        serial = self.serial.close()
        out = {"lammps_1": serial["particle_steps_per_s"], "version": serial["lammps_version"]}
        if self.omp is not None:
            out["lammps_omp2"] = self.omp.close()["particle_steps_per_s"]
        if self.mpi is not None:
            out["lammps_mpi2"] = self.mpi
        return out


def engine_row(size: str, sim, plan: tuple[int, int, int], repeats: int, *, base=None, base_steps=0,
               lammps=(True, True)):  # fmt: skip
    """One size's rounds: poro2d on 1 and 2 threads, LAMMPS beside it; returns (EngineRow, LAMMPS version).

    ``base`` (the paper-size simulation) adds a ``base_steps`` block of it per thread count
    to each round, for the rate kept at size; ``lammps`` is (run LAMMPS, with its OpenMP-2 run).
    """
    steps, warmup, settle = plan
    blocks = LammpsBlocks(sim, steps, settle, omp=lammps[1]) if lammps[0] else None
    ref = {} if base is None else {"paper": base, "paper_steps": base_steps}
    r = time_poro2d(sim, steps, repeats, warmup, (1, 2), lammps=blocks, **ref)
    row = EngineRow(size, sim.particles.n, steps, loads=[ld[0] for t in r.values() for ld in t["loadavg"]])
    row.quantities["poro2d_1t"] = Measured(r[1]["all"])
    row.quantities["poro2d_2t"] = Measured(r[2]["all"])
    row.quantities["speedup_2t"] = Measured(paired(r[2]["all"], r[1]["all"])["all"], "ratio")
    if base is not None:
        row.quantities["kept_1t"] = Measured(paired(r[1]["all"], r[1]["paper_all"])["all"], "ratio")
    version = None
    if blocks is not None:
        lm = blocks.close()
        version = lm.pop("version")
        row.quantities.update({k: Measured(v) for k, v in lm.items()})
        row.quantities["ratio_1"] = Measured(_round_ratios(r[1]["all"], lm["lammps_1"]), "ratio")
        row.quantities["ratio_mpi2"] = Measured(_round_ratios(r[2]["all"], lm["lammps_mpi2"]), "ratio")
    return row, version


def _round_ratios(a: list[float], b: list[float]) -> list[float]:
    """a / b round by round; a round whose LAMMPS block failed (NaN) gives NaN."""
    return [x / y if math.isfinite(y) and y > 0 else math.nan for x, y in zip(a, b, strict=True)]


def engine_part(args: argparse.Namespace, machine: dict) -> list[EngineRow]:
    """Every size in turn; the table is written after each, so a run stopped keeps what it measured."""
    plan = QUICK_PLAN if args.quick else PLAN
    base, _ = paper_simulation(args.out, args.rebuild)
    rows = []
    for size in args.sizes:
        t0 = time.perf_counter()
        sim = base if size == "2.5k" else tiled_simulation(base, *TILINGS[size])
        print(f"[{size}] {sim.particles.n} disks, {args.repeats} rounds of {plan[size][0]} steps", flush=True)
        row, version = engine_row(
            size, sim, plan[size], args.repeats, base=None if sim is base else base,
            base_steps=plan["2.5k"][0], lammps=(not args.no_lammps, not args.no_omp),
        )  # fmt: skip
        machine["lammps"] = version or machine.get("lammps", "not run")
        print(f"[{size}] done in {time.perf_counter() - t0:.0f} s", flush=True)
        rows.append(row)
        write_table(args.out, machine, rows, [])
        print(engine_markdown([row]), flush=True)
    return rows


# ------------------------------------------------------------------ protocol part


def protocol_part(args: argparse.Namespace, machine: dict, engine: list[EngineRow]) -> list[ProtocolRow]:
    """Every command in turn, the table written after each (with the engine part's rows)."""
    rows = []
    for name, cmds in PROTOCOLS.items():
        rows.append(time_command(name, cmds[1] if args.quick else cmds[0]))
        write_table(args.out, machine, engine, rows)
    return rows


def time_command(name: str, words: list[str]) -> ProtocolRow:
    """Wall time of ``poro2d WORDS`` in a fresh folder with an empty poro2d cache."""
    scratch = Path(tempfile.mkdtemp(prefix="speed-table-"))
    env = dict(os.environ, PORO2D_CACHE=str(scratch / "cache"))
    cmd = [sys.executable, "-m", "poro2d.cli", *words, "--out", str(scratch / "out"), "--quiet"]
    if "--preflight" in words:
        cmd.remove("--quiet")  # the pre-flight has no progress to hide
    shown = "poro2d " + " ".join(w.replace(str(ROOT) + "/", "") for w in words)
    print(f"[protocol] {shown} ...", flush=True)
    loads = [loadavg()[0]]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=scratch, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    loads.append(loadavg()[0])
    if proc.returncode:
        print(proc.stdout[-1500:], proc.stderr[-1500:], sep="\n")
    print(f"[protocol] {shown}: {wall:.0f} s (exit {proc.returncode})", flush=True)
    shutil.rmtree(scratch, ignore_errors=True)
    return ProtocolRow(name, shown, wall, proc.returncode, loads)


# ------------------------------------------------------------------ the table


def _cell(m: Measured | None) -> str:
    if m is None:
        return "-"
    med, lo, hi = m.summary()
    if not math.isfinite(med):
        return "-"
    if m.unit == "ratio":
        return f"{med:.2f}x ({lo:.2f}-{hi:.2f})"
    return f"{med:.2e} ({lo:.2e}-{hi:.2e})"


def _load(loads: list[float]) -> str:
    return f"{min(loads):.1f}-{max(loads):.1f}" if loads else "-"


def engine_markdown(rows: list[EngineRow]) -> str:
    head = ["disks", *ENGINE_COLUMNS.values(), "steps x rounds", "load"]
    lines = ["| " + " | ".join(head) + " |", "|" + " ---: |" * len(head)]
    for r in rows:
        cells = [f"{r.disks:,}".replace(",", " ")]
        cells += [_cell(r.quantities.get(k)) for k in ENGINE_COLUMNS]
        rounds = len(r.quantities["poro2d_1t"].values) if "poro2d_1t" in r.quantities else 0
        cells += [f"{r.steps} x {rounds}", _load(r.loads)]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def protocol_markdown(rows: list[ProtocolRow]) -> str:
    lines = ["| command | wall time | exit | load |", "| --- | ---: | ---: | ---: |"]
    for r in rows:
        m, s = divmod(round(r.wall_s), 60)
        lines.append(f"| `{r.command}` | {m} min {s:02d} s | {r.exit_code} | {_load(r.loads)} |")
    return "\n".join(lines)


def machine_lines(machine: dict) -> list[str]:
    keys = ("date", "cpu", "cpu_count", "poro2d", "lammps", "numba", "python", "uptime_start", "uptime_end")
    return [f"{k}: {machine[k]}" for k in keys if k in machine]


def markdown(machine: dict, engine: list[EngineRow], protocols: list[ProtocolRow]) -> str:
    parts = ["# poro2d speed table", "", *(f"- {line}" for line in machine_lines(machine))]
    if engine:
        parts += ["", "## Engine: particle-steps per second, median (lowest-highest) over the rounds", ""]
        parts += [
            engine_markdown(engine),
            "",
            "Ratios: poro2d / LAMMPS on the same cores; medians of per-round ratios.",
        ]
    if protocols:
        parts += ["", "## Protocols: wall time from an empty cache", "", protocol_markdown(protocols)]
    return "\n".join(parts) + "\n"


def csv_text(machine: dict, engine: list[EngineRow], protocols: list[ProtocolRow]) -> str:
    """One long table: a row per (case, quantity); the machine as ``#`` lines above it."""
    buf = io.StringIO()
    buf.write("".join(f"# {line}\n" for line in machine_lines(machine)))
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_HEADER)
    for r in engine:
        lo, hi = (min(r.loads), max(r.loads)) if r.loads else ("", "")
        for k in ENGINE_COLUMNS:
            if k in r.quantities:
                q = r.quantities[k]
                w.writerow(("engine", r.size, r.disks, k, *_g(q.summary()), len(q.values), q.unit, lo, hi))
    for p in protocols:
        w.writerow(
            ("protocol", p.name, "", "wall_s", *_g((p.wall_s,) * 3), 1, "s", min(p.loads), max(p.loads))
        )
    return buf.getvalue()


def _g(values) -> list[str]:
    return ["" if not math.isfinite(v) else f"{v:.6g}" for v in values]


def write_table(out: Path, machine: dict, engine: list[EngineRow], protocols: list[ProtocolRow]) -> str:
    """Write ``speed_table.md`` and ``speed_table.csv`` in ``out``; returns the markdown."""
    out.mkdir(parents=True, exist_ok=True)
    md = markdown(machine, engine, protocols)
    (out / "speed_table.md").write_text(md)
    (out / "speed_table.csv").write_text(csv_text(machine, engine, protocols))
    return md


# ------------------------------------------------------------------ main


def _uptime() -> str:
    one, five, fifteen = loadavg()
    return f"load average {one}, {five}, {fifteen}"


def machine(lammps: bool) -> dict:
    info = machine_info()
    info["date"] = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    info["uptime_start"] = _uptime()
    if lammps:
        from lammps_reference import lammps_version

        info["lammps"] = lammps_version()
    return info


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    # libgomp reads the wait policy when numba (and LAMMPS's OpenMP run) first start threads:
    # spinning threads on a shared 2-core machine ran 10-50x slower
    os.environ["OMP_WAIT_POLICY"] = "PASSIVE"
    info = machine(lammps=args.only != "protocols" and not args.no_lammps)
    if info["numba_threads"] < 2 and args.only != "protocols":
        print("numba sees one thread only: the engine part needs 2", file=sys.stderr)
        return 2
    engine = engine_part(args, info) if args.only in ("all", "engine") else []
    protocols = protocol_part(args, info, engine) if args.only in ("all", "protocols") else []
    info["uptime_end"] = _uptime()
    md = write_table(args.out, info, engine, protocols)
    print()
    print(md)
    print(f"wrote {args.out / 'speed_table.md'} and {args.out / 'speed_table.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
