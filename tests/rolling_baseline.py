"""The packing whose state after some steps must not change when rolling resistance is off.

It uses only the engine's API from before rolling resistance existed, so the same
function runs on both sides of the change: ``tests/data/rolling_off_baseline.npz`` holds
its arrays as computed by the engine without rolling resistance (commit ab1c351),
written by ``python3 tests/rolling_baseline.py tests/data/rolling_off_baseline.npz`` with
that version of poro2d on the path. Written again, the same way, when the engine came to
fuse its products and sums (``dem/fma.py``): every number moved by round-off then, on
purpose, and the file pins the numbers from there on. ``tests/dem/test_rolling_resistance.py`` compares them,
bit for bit, with what the current engine computes at ``mu_r = 0``.
"""

from __future__ import annotations

import sys

import numpy as np

from poro2d.dem.simulation import Simulation
from poro2d.dem.state import Particles, Walls

R = 1e-3  # mean radius (m)
STEPS = 400
CASES = {"serial": (1, 2), "threads": (2, 4)}  # (threads, partitions)


def packing(threads: int, partitions: int) -> Simulation:
    """~190 disks of mixed properties on a lattice with small overlaps, squeezed by a moving lid."""
    rng = np.random.default_rng(7)
    nx, ny = 14, 14
    rows = [(row, c) for row in range(ny) for c in range(nx - row % 2)]
    pts = [(R + 2 * R * c + R * (row % 2), R + np.sqrt(3.0) * R * row) for row, c in rows]
    pos = np.array(pts)
    n = len(pos)
    kn = rng.uniform(0.8e6, 1.2e6, n)
    p = Particles(
        pos=pos, radius=R * rng.uniform(0.99, 1.02, n), density=rng.uniform(2400.0, 2800.0, n),
        thickness=0.01, kn=kn, ks=0.7 * kn, mu=rng.uniform(0.05, 0.5, n),
        vel=rng.normal(0.0, 0.01, (n, 2)), omega=rng.normal(0.0, 5.0, n),
    )  # fmt: skip
    w = Walls.box(0.0, 0.0, 2 * nx * R, pos[:, 1].max() + R, 2e6, 1.5e6, 0.3)
    sim = Simulation(p, w, gravity=(0.3, -9.81), local_damping=0.2, threads=threads, partitions=partitions)
    sim.parallel_min_particles = 0  # two threads even on a small packing
    sim.set_wall_velocity("top", (0.0, -0.2))
    return sim


def baseline_state(cases=tuple(CASES)) -> dict[str, np.ndarray]:
    """The state of each case after ``STEPS`` steps, by ``case.field``."""
    out = {}
    for case in cases:
        sim = packing(*CASES[case])
        sim.run(STEPS)
        p = sim.particles
        fields = {
            "pos": p.pos, "vel": p.vel, "theta": p.theta, "omega": p.omega, "force": sim.force,
            "moment": sim.moment, "wall_force": sim.wall_force_vec,
            "nb_fs": sim.pairs.fs[: sim.pairs.used], "wb_fs": sim.wall_pairs.fs[: sim.wall_pairs.used],
        }  # fmt: skip
        for name, arr in fields.items():
            out[f"{case}.{name}"] = np.array(arr)
    return out


if __name__ == "__main__":
    np.savez(sys.argv[1], **baseline_state())
