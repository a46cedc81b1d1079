"""Bad input is refused with an InputError naming the parameter; neighbour lists and
contact storage against brute-force oracles."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from poro2d.dem import ContactModel, Particles, Simulation, Walls
from poro2d.dem.neighbors import brute_force_pairs, build_pairs, build_wall_pairs
from poro2d.errors import InputError

R = 1e-3


def _particles(n=4, **kw):
    args = dict(
        pos=np.column_stack([np.arange(n) * 3 * R, np.zeros(n)]), radius=R, density=2650.0,
        thickness=0.01, kn=1e5, ks=1e5, mu=0.5,
    )  # fmt: skip
    args.update(kw)
    return Particles(**args)


def _raises(parameter: str, fn, *a, **kw):
    with pytest.raises(InputError) as e:
        fn(*a, **kw)
    assert e.value.parameter == parameter, e.value.parameter
    assert parameter in str(e.value)
    return e.value


# ------------------------------------------------------------- bad input
def test_negative_or_zero_radius():
    _raises("radius", _particles, radius=np.array([R, -R, R, R]))
    _raises("radius", _particles, radius=0.0)


def test_bad_particle_properties():
    _raises("particle kn", _particles, kn=0.0)
    _raises("particle ks", _particles, ks=-1.0)
    _raises("particle friction", _particles, mu=-0.1)
    _raises("density", _particles, density=0.0)
    _raises("thickness", _particles, thickness=0.0)
    _raises("positions", _particles, pos=np.zeros((3, 3)))
    _raises("positions", _particles, pos=np.array([[0.0, np.nan]]))
    _raises("velocity", _particles, vel=np.zeros((3, 2)))


def test_overlapping_collinear_walls():
    w = Walls()
    w.add((0.0, 0.0), (1.0, 0.0), 1e5, 1e5, 0.5, "a")
    err = _raises("wall b", w.add, (0.5, 0.0), (2.0, 0.0), 1e5, 1e5, 0.5, "b")
    assert "'a'" in str(err)
    _raises("wall c", w.add, (1.0, 0.0), (0.2, 0.0), 1e5, 1e5, 0.5, "c")  # reversed, inside
    # touching end to end, parallel but offset, or crossing: allowed
    w.add((1.0, 0.0), (2.0, 0.0), 1e5, 1e5, 0.5, "d")
    w.add((0.0, 1e-3), (1.0, 1e-3), 1e5, 1e5, 0.5, "e")
    w.add((0.5, -1.0), (0.5, 1.0), 1e5, 1e5, 0.5, "f")
    assert w.n == 4


def test_bad_walls():
    w = Walls()
    _raises("wall z length", w.add, (0.0, 0.0), (0.0, 0.0), 1e5, 1e5, 0.5, "z")
    _raises("wall z kn", w.add, (0.0, 0.0), (1.0, 0.0), 0.0, 1e5, 0.5, "z")
    _raises("wall z ks", w.add, (0.0, 0.0), (1.0, 0.0), 1e5, -1.0, 0.5, "z")
    _raises("wall z friction", w.add, (0.0, 0.0), (1.0, 0.0), 1e5, 1e5, -0.5, "z")
    w.add((0.0, 0.0), (1.0, 0.0), 1e5, 1e5, 0.5, "z")
    _raises("wall name", w.add, (0.0, 1.0), (1.0, 1.0), 1e5, 1e5, 0.5, "z")
    _raises("box", Walls.box, 1.0, 0.0, 0.0, 1.0, 1e5, 1e5, 0.5)


def test_zero_contact_stiffness():
    _raises("contact pp kn", ContactModel, "per_pair_type", (0.0, 1e5, 0.5), (1e5, 1e5, 0.5))
    _raises("contact pw ks", ContactModel, "per_pair_type", (1e5, 1e5, 0.5), (1e5, -1.0, 0.5))
    _raises("contact pp", ContactModel, "per_pair_type", None, (1e5, 1e5, 0.5))
    _raises("contact convention", ContactModel, "pfc6")


def test_unstable_fixed_dt():
    p = _particles()
    sim = Simulation(p, gravity=(0.0, 0.0))
    # a lone disk spinning on one tangential spring: omega^2 = 2 k / m diverges above sqrt(2 m / k)
    limit = np.sqrt(2.0 * p.mass.min() / sim.contact.max_stiffness(p, sim.walls))
    err = _raises("dt", Simulation, _particles(), dt=1.01 * limit)
    assert "unstable" in str(err)
    _raises("dt", Simulation, _particles(), dt=0.0)
    _raises("dt", Simulation, _particles(), dt=-1e-6)
    with pytest.warns(UserWarning, match="critical step"):
        Simulation(_particles(), dt=0.99 * limit)  # accepted, but warned: above the packing limit
    Simulation(_particles(), dt=0.5 * sim.dt_critical)  # accepted silently


@pytest.mark.parametrize("alpha", [-0.1, 1.0, 1.5])
def test_bad_damping(alpha):
    _raises("local_damping", Simulation, _particles(), local_damping=alpha)


@pytest.mark.parametrize("threads", [0, -1, 1.5, "2", numba.config.NUMBA_NUM_THREADS + 1])
def test_bad_threads(threads):
    _raises("threads", Simulation, _particles(), threads=threads)


def test_other_simulation_inputs():
    _raises("restitution", Simulation, _particles(), restitution=0.0)
    _raises("restitution", Simulation, _particles(), restitution=1.2)
    _raises("dt_safety", Simulation, _particles(), dt_safety=0.0)
    _raises("density_scale", Simulation, _particles(), density_scale=0.5)
    _raises("skin", Simulation, _particles(), skin=0.0)
    _raises("gravity", Simulation, _particles(), gravity=(0.0, np.inf))
    sim = Simulation(_particles())
    _raises("steps", sim.run, -1)
    _raises("until_ratio", sim.run, 10, until_ratio=0.0)
    _raises("particle friction", sim.set_particle_friction, -1.0)
    _raises("wall", sim.wall_force, "nowhere")
    sim2 = Simulation(_particles(), Walls.box(-R, -R, 20 * R, 5 * R, 1e5, 1e5, 0.5))
    _raises("servo gain", sim2.set_wall_servo, "top", 1.0, (0.0, -1.0), 0.1, gain=0.0)
    _raises("servo direction", sim2.set_wall_servo, "top", 1.0, (0.0, 0.0), 0.1)


# ---------------------------------------------------------- neighbour lists
def _empty_lists(n, cap):
    return (
        np.zeros(n + 1, np.int64), np.zeros(cap, np.int64), np.zeros(cap),
        np.zeros(n + 1, np.int64), np.zeros(cap, np.int64), np.zeros(cap),
    )  # fmt: skip


def _pairs_of(start, nbj, n):
    rows = np.repeat(np.arange(n), np.diff(start))
    return set(zip(rows.tolist(), nbj[: start[n]].tolist(), strict=True))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    n=st.integers(1, 250),
    spread=st.floats(0.005, 0.2),
    rmax_ratio=st.floats(1.0, 8.0),
    skin=st.floats(0.0, 2e-3),
    seed=st.integers(0, 2**31 - 1),
    runaway=st.booleans(),
)
def test_neighbour_list_equals_brute_force(n, spread, rmax_ratio, skin, seed, runaway):
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0.0, spread, (n, 2))
    rad = R * rng.uniform(1.0, rmax_ratio, n)
    if runaway:  # one disk far away: the cell grid must not explode or miss pairs
        pos[0] = (1e3, -5e2)
    nb_start, nb_j, nb_fs, new_start, new_j, new_fs = _empty_lists(n, 1)
    need = build_pairs(pos, rad, skin, nb_start, nb_j, nb_fs, new_start, new_j, new_fs)
    oracle = brute_force_pairs(pos, rad, skin)
    if len(oracle) > 1:
        assert need == -len(oracle)  # too small: reports the size, changes nothing
        assert np.all(nb_start == 0)
    cap = max(1, len(oracle))
    nb_start, nb_j, nb_fs, new_start, new_j, new_fs = _empty_lists(n, cap)
    got = build_pairs(pos, rad, skin, nb_start, nb_j, nb_fs, new_start, new_j, new_fs)
    assert got == len(oracle)
    assert _pairs_of(nb_start, nb_j, n) == oracle


def test_neighbour_rebuild_carries_history():
    rng = np.random.default_rng(3)
    n = 200
    pos = rng.uniform(0.0, 0.04, (n, 2))
    rad = R * rng.uniform(0.8, 1.2, n)
    skin = 2e-4
    cap = 4000
    nb_start, nb_j, nb_fs, new_start, new_j, new_fs = _empty_lists(n, cap)
    build_pairs(pos, rad, skin, nb_start, nb_j, nb_fs, new_start, new_j, new_fs)
    old = _pairs_of(nb_start, nb_j, n)
    rows = np.repeat(np.arange(n), np.diff(nb_start))
    total = int(nb_start[n])
    nb_fs[:total] = rows * 1000.0 + nb_j[:total]  # a recognisable history per pair
    pos2 = pos + rng.uniform(-1e-4, 1e-4, pos.shape)
    build_pairs(pos2, rad, skin, nb_start, nb_j, nb_fs, new_start, new_j, new_fs)
    new = _pairs_of(nb_start, nb_j, n)
    assert new == brute_force_pairs(pos2, rad, skin)
    rows = np.repeat(np.arange(n), np.diff(nb_start))
    for k in range(int(nb_start[n])):
        key = (int(rows[k]), int(nb_j[k]))
        expect = key[0] * 1000.0 + key[1] if key in old else 0.0
        assert nb_fs[k] == expect
    assert len(new & old) > 100 and len(new - old) > 0


def _wall_oracle(pos, rad, skin, walls) -> set[tuple[int, int]]:
    """Every (disk, wall) whose closest wall point lies within the disk's reach: the O(N W) oracle
    (squared distances, as the kernel compares them, so a disk a hair from its reach is judged alike)."""
    found = set()
    for i in range(len(pos)):
        for k in range(walls.n):
            a, b = walls.p0[k], walls.p1[k]
            t = np.clip(np.dot(pos[i] - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
            c = a + t * (b - a)
            if (pos[i, 0] - c[0]) ** 2 + (pos[i, 1] - c[1]) ** 2 < (rad[i] + skin) ** 2:
                found.add((i, k))
    return found


def test_wall_list_equals_brute_force():
    rng = np.random.default_rng(9)
    n = 300
    pos = rng.uniform(-0.01, 0.05, (n, 2))
    rad = R * rng.uniform(0.5, 2.0, n)
    skin = 3e-4
    w = Walls.box(0.0, 0.0, 0.04, 0.03, 1e5, 1e5, 0.5)
    w.add((0.01, 0.01), (0.02, 0.025), 1e5, 1e5, 0.5, "slant")
    cap = 1000
    start, ww, fs, nstart, nw_, nfs = _empty_lists(n, cap)
    got = build_wall_pairs(pos, rad, skin, w.p0, w.p1, start, ww, fs, nstart, nw_, nfs)
    oracle = _wall_oracle(pos, rad, skin, w)
    assert got == len(oracle) and _pairs_of(start, ww, n) == oracle
    small = _empty_lists(n, 2)
    assert build_wall_pairs(pos, rad, skin, w.p0, w.p1, *small) == -len(oracle)


def test_wall_list_of_a_segmented_lid_equals_brute_force():
    """A lid of 40 short segments: a disk is refused by a segment's bounding box before its
    closest point is taken; disks placed a hair inside and outside the reach of a segment's
    end and of its middle must still be told apart as the closest point tells them."""
    rng = np.random.default_rng(4)
    skin, k, width, top = 2e-4, 40, 0.04, 0.03
    w = Walls.box(0.0, 0.0, width, top + 0.01, 1e5, 1e5, 0.5)
    for s in range(k):
        w.add((s * width / k, top), ((s + 1) * width / k, top), 1e5, 1e5, 0.5, f"lid{s}")
    pos = list(rng.uniform(0.0, width, (200, 2)) * (1.0, top / width))
    rad = list(R * rng.uniform(0.5, 2.0, 200))
    for s in range(k):
        x_end, reach = s * width / k, R + skin
        for f in (1.0 - 1e-12, 1.0 + 1e-12):  # beside an end, below a middle, at reach (1 -+ 1e-12)
            pos += [(x_end - reach * f, top), ((s + 0.5) * width / k, top - reach * f)]
            rad += [R, R]
    pos, rad = np.array(pos), np.array(rad)
    n, cap = len(pos), 4000
    start, ww, fs, nstart, nw_, nfs = _empty_lists(n, cap)
    got = build_wall_pairs(pos, rad, skin, w.p0, w.p1, start, ww, fs, nstart, nw_, nfs)
    oracle = _wall_oracle(pos, rad, skin, w)
    assert got == len(oracle) and _pairs_of(start, ww, n) == oracle
    assert len(oracle) > 200  # the disks at reach found their segments


# ------------------------------------------------------ capacity growth
def _falling_heap(seed=1):
    """Disks fall into a box: the number of neighbour pairs grows as they pack."""
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.arange(12), np.arange(15))
    pos = np.column_stack([gx.ravel(), gy.ravel()]) * 3.0 * R + 2 * R
    n = len(pos)
    p = Particles(
        pos=pos + rng.uniform(-0.3 * R, 0.3 * R, pos.shape), radius=R * rng.uniform(0.8, 1.2, n),
        density=2650.0, thickness=0.01, kn=1e5, ks=1e5, mu=0.4,
        vel=rng.normal(0.0, 0.1, (n, 2)),
    )  # fmt: skip
    w = Walls.box(0.0, 0.0, 37 * R, 60 * R, 1e5, 1e5, 0.4)
    return Simulation(p, w)


def test_contact_capacity_growth_drops_nothing():
    ref = _falling_heap()
    ref.run(30000)
    sim = _falling_heap()
    sim.grow_pairs(16)
    sim.grow_wall_pairs(2)
    sim.run(15000)
    # shrink again to exactly what is in use: the next rebuild overflows mid-run with history
    used_pp, used_pw = sim.pairs.used, sim.wall_pairs.used
    sim.grow_pairs(used_pp, keep=used_pp)
    sim.grow_wall_pairs(max(used_pw, 1), keep=used_pw)
    sim.run(15000)
    assert sim.pairs.capacity > used_pp  # it did grow
    assert np.array_equal(sim.particles.pos, ref.particles.pos)
    assert np.array_equal(sim.particles.omega, ref.particles.omega)
    assert np.array_equal(sim.wall_force_vec, ref.wall_force_vec)
    assert len(sim.contacts()) == len(ref.contacts()) > 100
