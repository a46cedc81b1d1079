"""The compiled engine against the direct NumPy reference step (oracles/engine_step.py).

Random packings (initial overlaps, random velocities and spins, gravity, local
damping 0.7, friction low enough that contacts slide, a moving wall, a disk with
prescribed velocity) are advanced in lock-step by :class:`Simulation` (cell grid,
Verlet lists with history, compiled kernel) and by the O(N^2) reference (every pair
tested directly, history in a dict).

Two comparisons:

* lock-step over 250+ steps, the reference summing each disk's contact forces in the
  order of the engine's neighbour-list slots and starting every step from the engine's
  motion (:meth:`ReferenceDEM.follow`) while carrying its own contact histories through
  contacts made and lost and list rebuilds: the two agree to round-off, 1e-12 of the
  scales (``STEP_TOL``). The engine fuses a product and a sum where its source says (``dem/fma.py``),
  the reference does not: a step's numbers differ by an ulp or so, and a free run would
  not stay together (with local damping ``sign(v)`` is discontinuous and dense packings
  are chaotic: a one-ulp difference grows to O(1) within ~150 steps, measured), so the
  reference follows the engine's motion and compares each step's outcome;
* one-step comparisons from a shared state, the reference in its own (i, j) sum
  order (fully independent of the neighbour list): agreement to 1e-10 relative.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from poro2d.dem import ContactModel, Particles, Simulation, Walls
from poro2d.oracles.engine_step import ReferenceDEM, _ranks, engine_pair_order, engine_partitions

R = 1e-3  # mean radius (m)
# a step's outcome against the reference's, relative to the scales: round-off. A disk's net
# force is a small difference of contact forces, so the fused and the unfused sums of one
# step part by up to 2-3e-13 of the largest speed (measured); a wrong law, lever arm or
# history is off by 1e-6 or more
STEP_TOL = 1e-12


def jammed_packing(
    seed: int, convention="per_body", restitution=None, threads=1, partitions=2, rolling=False
) -> Simulation:
    """~190 disks on a hexagonal lattice with 1-2 % overlaps, squeezed by a moving lid.

    ``rolling``: rolling frictions 0.02-0.3 on the disks (some contacts then reach their
    rolling limit, others stay elastic), 0.1 on the walls.
    """
    rng = np.random.default_rng(seed)
    nx, ny = 14, 14
    pts = [
        (R + 2 * R * c + R * (row % 2), R + np.sqrt(3.0) * R * row)
        for row in range(ny)
        for c in range(nx - row % 2)
    ]
    pos = np.array(pts)
    n = len(pos)
    kn = rng.uniform(0.8e6, 1.2e6, n)
    p = Particles(
        pos=pos,
        radius=R * rng.uniform(0.99, 1.02, n),
        density=rng.uniform(2400.0, 2800.0, n),
        thickness=0.01,
        kn=kn,
        ks=0.7 * kn,
        mu=rng.uniform(0.05, 0.3, n),
        vel=rng.normal(0.0, 0.01, (n, 2)),
        omega=rng.normal(0.0, 5.0, n),
    )
    p.mode[n // 2] = 1  # prescribed velocity
    w = Walls.box(0.0, 0.0, 2 * nx * R, pos[:, 1].max() + R, 2e6, 1.5e6, 0.3, mu_r=0.1 if rolling else 0.0)
    if rolling:  # drawn last: the packing without rolling is unchanged
        p.mu_r[:] = rng.uniform(0.02, 0.3, n)
    contact = None
    if convention == "per_pair_type":
        contact = ContactModel("per_pair_type", pp=(6e5, 4e5, 0.15), pw=(8e5, 5e5, 0.35))
    sim = Simulation(
        p, w, contact=contact, gravity=(0.3, -9.81), local_damping=0.7, restitution=restitution,
        threads=threads, partitions=partitions,
    )  # fmt: skip
    sim.set_wall_velocity("top", (0.0, -0.2))  # 0.4 mm in 300 steps: several list rebuilds
    return sim


def loose_packing(seed: int, rolling=False) -> Simulation:
    """A square grid with large random overlaps: disks fly apart (many rebuilds)."""
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.arange(15), np.arange(13))
    pos = np.column_stack([gx.ravel(), gy.ravel()]) * 2 * R + R
    pos = pos + rng.uniform(-0.08 * R, 0.08 * R, pos.shape)
    n = len(pos)
    p = Particles(
        pos=pos,
        radius=R * rng.uniform(0.88, 1.1, n),
        density=2650.0,
        thickness=0.01,
        kn=1e6,
        ks=rng.uniform(0.5e6, 1e6, n),
        mu=rng.uniform(0.1, 0.4, n),
        vel=rng.normal(0.0, 0.05, (n, 2)),
        omega=rng.normal(0.0, 20.0, n),
    )
    w = Walls.box(0.0, 0.0, 30 * R, 26.5 * R, 2e6, 1.5e6, 0.3, mu_r=0.2 if rolling else 0.0)
    if rolling:
        p.mu_r[:] = rng.uniform(0.05, 0.5, n)
    return Simulation(p, w, gravity=(0.0, -9.81), local_damping=0.7)


def _scales(sim):
    p = sim.particles
    return max(float(np.abs(p.vel).max()), 1e-3), max(float(np.abs(p.omega).max()), 1.0)


def _lockstep(sim: Simulation, steps: int, engine_order: bool, length: float = R):
    """Advance both, each step from the engine's motion; return the worst differences
    (relative to the scales: ``length`` for positions) and counts."""
    ref = ReferenceDEM.from_simulation(sim)
    p = sim.particles
    worst = dict.fromkeys(("pos", "vel", "omega", "wall"), 0.0)
    slid = stuck = rebuilds = 0
    for _ in range(steps):
        ref.follow(sim)
        res = sim.run(1)
        rebuilds += res.rebuilds
        if engine_order:
            ref.step(engine_pair_order(sim), engine_partitions(sim))
        else:
            ref.step()
        vs, ws = _scales(sim)
        fscale = max(1e-3, float(np.abs(ref.wall_force).max()))
        worst["pos"] = max(worst["pos"], float(np.abs(p.pos - ref.pos).max()) / length)
        worst["vel"] = max(worst["vel"], float(np.abs(p.vel - ref.vel).max()) / vs)
        worst["omega"] = max(worst["omega"], float(np.abs(p.omega - ref.omega).max()) / ws)
        worst["wall"] = max(worst["wall"], float(np.abs(sim.wall_force_vec - ref.wall_force).max()) / fscale)
        ns = ref.n_sliding()
        slid += ns
        stuck += len(ref.contacts) - ns
    return worst, slid, stuck, rebuilds, ref


def _contact_keys(sim) -> set:
    c = sim.contacts()
    return {
        (a, b) if kind == 0 else (a, "wall", b)
        for a, b, kind in zip(c.i.tolist(), c.j.tolist(), c.kind.tolist(), strict=True)
    }


def test_a_pairs_rank_is_its_row_in_the_engines_list():
    """The reference sums pairs in the engine's order: a pair's rank is its row in the list
    (the last row when listed twice), a pair the list lacks comes after every listed one."""
    pairs = np.array([[0, 1], [2, 5], [1, 3], [2, 5], [4, 0]])
    i, j = np.array([1, 2, 9, 0, 4, 0]), np.array([3, 5, 9, 1, 0, 4])
    assert _ranks(pairs, i, j).tolist() == [2, 3, 6, 0, 4, 6]
    assert _ranks(pairs[:0], i, j).tolist() == [1] * 6 and _ranks(pairs, i[:0], j[:0]).tolist() == []


@pytest.mark.parametrize(
    "convention, restitution",
    [("per_body", None), ("per_pair_type", None), ("per_body", 0.6)],
)
def test_jammed_packing_matches_reference_step_by_step(convention, restitution):
    sim = jammed_packing(1, convention, restitution)
    worst, slid, stuck, rebuilds, ref = _lockstep(sim, 260, engine_order=True)
    # a meaningful case: hundreds of contacts, some sliding, lists rebuilt with history
    assert slid > 1000 and stuck > 50_000, (slid, stuck)
    assert rebuilds >= 2
    for key, err in worst.items():
        assert err <= STEP_TOL, (key, err)
    assert _contact_keys(sim) == set(ref.contacts)
    for key, (fn, fs, _s) in ref.contacts.items():
        assert key in ref.history and ref.history[key] == fs and fn >= 0.0


def test_loose_packing_matches_reference_step_by_step():
    sim = loose_packing(3)
    worst, slid, stuck, rebuilds, ref = _lockstep(sim, 250, engine_order=True)
    assert slid > 1000 and rebuilds >= 5, (slid, rebuilds)
    for key, err in worst.items():
        assert err <= STEP_TOL, (key, err)
    assert _contact_keys(sim) == set(ref.contacts)


def _rolling_limits(ref) -> tuple[int, int]:
    """(contacts at their rolling limit, contacts below it) of the reference's last step."""
    at_limit = below = 0
    for key, (fn, _fs, _s) in ref.contacts.items():
        a = key[0]
        if len(key) == 2:
            b = key[1]
            reff = ref.radius[a] * ref.radius[b] / (ref.radius[a] + ref.radius[b])
            mur = min(ref.pmu_r[a], ref.pmu_r[b])
        else:
            reff = ref.radius[a]
            mur = min(ref.pmu_r[a], ref.wmu_r[key[2]])
        if abs(ref.rolling[key]) >= mur * reff * fn * (1 - 1e-12):
            at_limit += 1
        else:
            below += 1
    return at_limit, below


@pytest.mark.parametrize("make", [jammed_packing, loose_packing])
def test_rolling_resistance_matches_reference(make):
    """The kernel's rolling moments and their effect on the motion, against the reference."""
    sim = make(5, rolling=True)
    steps = 200
    limited = elastic = 0
    ref = ReferenceDEM.from_simulation(sim)
    p = sim.particles
    worst = 0.0
    for _ in range(steps):
        ref.follow(sim)
        sim.run(1)
        ref.step(engine_pair_order(sim), engine_partitions(sim))
        vs, ws = _scales(sim)
        worst = max(
            worst,
            float(np.abs(p.pos - ref.pos).max()) / R,
            float(np.abs(p.vel - ref.vel).max()) / vs,
            float(np.abs(p.omega - ref.omega).max()) / ws,
        )
        a, b = _rolling_limits(ref)
        limited += a
        elastic += b
    assert worst <= STEP_TOL, worst
    assert limited > 500 and elastic > 500, (limited, elastic)  # both branches of the law
    # the kernel's stored moments are the reference's, contact by contact
    pp, pw = sim.rolling_moments()
    c = sim.contacts()
    kernel = {}
    for k, (a, b, kind) in enumerate(zip(c.i.tolist(), c.j.tolist(), c.kind.tolist(), strict=True)):
        kernel[(a, b) if kind == 0 else (a, "wall", b)] = k
    assert set(kernel) == set(ref.rolling)
    assert len(pp) + len(pw) == len(ref.rolling)
    got = np.concatenate([pp, pw])
    # sim.contacts() lists disk pairs, then wall contacts, in list order, as rolling_moments()
    want = np.array([ref.rolling[key] for key in sorted(kernel, key=kernel.get)])
    scale = float(np.abs(want).max())
    assert scale > 0.0 and float(np.abs(got - want).max()) <= 1e-12 * scale


@pytest.mark.parametrize("make", [jammed_packing, loose_packing])
def test_one_step_from_shared_state_independent_order(make):
    """Every step restarts the reference from the engine's state (history included)."""
    sim = make(2)
    sim.run(40)
    p = sim.particles
    worst = 0.0
    for _ in range(60):
        ref = ReferenceDEM.from_simulation(sim)
        sim.run(1)
        ref.step()  # own (i, j) order
        vs, ws = _scales(sim)
        fscale = max(1e-3, float(np.abs(ref.wall_force).max()))
        worst = max(
            worst,
            float(np.abs(p.pos - ref.pos).max()) / R,
            float(np.abs(p.vel - ref.vel).max()) / vs,
            float(np.abs(p.omega - ref.omega).max()) / ws,
            float(np.abs(sim.wall_force_vec - ref.wall_force).max()) / fscale,
            float(np.abs(sim.force - ref.force).max()) / max(1e-9, float(np.abs(ref.force).max())),
        )
    assert worst < 1e-10, worst


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 numba threads")
def test_threads_give_bitwise_identical_results():
    # kept short: two OpenMP threads on a loaded 2-core machine wait at every barrier
    a = jammed_packing(7, threads=1)
    b = jammed_packing(7, threads=2)
    b.parallel_min_particles = 0  # force the parallel path on this small packing
    assert a.effective_threads == 1 and b.effective_threads == 2
    a.run(25)
    b.run(25)
    assert b.threads_used == 2  # the workers really ran side by side
    pa, pb = a.particles, b.particles
    for x, y in [(pa.pos, pb.pos), (pa.vel, pb.vel), (pa.omega, pb.omega), (a.force, b.force)]:
        assert np.array_equal(x, y)
    assert np.array_equal(a.wall_force_vec, b.wall_force_vec)
    c = loose_packing(4)
    d = loose_packing(4)
    d.threads = 2
    d.parallel_min_particles = 0
    rc = c.run(50)
    d.run(50)
    assert rc.rebuilds >= 2
    assert np.array_equal(c.particles.pos, d.particles.pos)
    e = jammed_packing(8, threads=1, partitions=4, rolling=True)
    f = jammed_packing(8, threads=2, partitions=4, rolling=True)
    f.parallel_min_particles = 0
    e.run(25)
    f.run(25)
    assert f.threads_used == 2
    assert np.array_equal(e.particles.omega, f.particles.omega) and np.array_equal(e.moment, f.moment)
    assert np.array_equal(c.particles.omega, d.particles.omega)
    assert np.array_equal(c.wall_force_vec, d.wall_force_vec)


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 numba threads")
def test_partitions_fix_the_numbers_not_the_threads():
    """4 partitions on 1 or 2 threads: bit for bit; 1 vs 4 partitions: round-off only."""
    runs = {}
    for parts, threads in ((4, 1), (4, 2), (1, 1)):
        sim = jammed_packing(5, threads=threads, partitions=parts)
        sim.parallel_min_particles = 0
        sim.run(30)
        assert sim.threads_used == threads
        runs[parts, threads] = sim
    a, b, c = runs[4, 1], runs[4, 2], runs[1, 1]
    assert a.work.dstart[-1] > 10  # many disks wait for partners of earlier partitions
    for x, y, z in [(a.particles.pos, b.particles.pos, c.particles.pos), (a.force, b.force, c.force)]:
        assert np.array_equal(x, y)
        scale = float(np.abs(z).max())
        assert np.abs(x - z).max() <= 1e-9 * scale
    assert np.array_equal(a.wall_force_vec, b.wall_force_vec)
