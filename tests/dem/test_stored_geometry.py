"""What the kernel stores only on some steps is, after every call, what a step storing all gives.

The force pass writes the contacts' geometry and normal force (``ov``, ``fn``, ``nx``, ``ny``
of both lists) and the disks' unbalanced forces and moments only where someone reads them:
for the cross pairs and the deferred disks at every step (the deferred pass of the same step),
for everything on a stop-check step and on the last step of a call. A run cut into one-step
calls stores at every step, so it is the reference: a run in long calls must leave every
array the same, byte for byte and slot for slot (pairs apart and slots past the list's end
included), stop on the same step, and move the disks the same way. A run whose cross pairs
or check steps missed their geometry would move or stop otherwise.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from poro2d.dem import Every, Particles, Simulation, Walls, checkpoint
from poro2d.dem.state import FREE
from tests.dem.grids import staggered_rows

R = 1e-3
CONTACT_FIELDS = ("start", "other", "fs", "fn", "ov", "nx", "ny", "mr")


def _box(nx: int = 12, ny: int = 22, per_body: bool = False, **kw) -> Simulation:
    """Disks on a loose staggered grid falling into a box, a servo lid pressing on them."""
    rng = np.random.default_rng(5)
    s = 2.02 * R
    pos = staggered_rows(nx, ny, R, rng)
    n = len(pos)
    # per-body stiffnesses make the kernel mix them per contact (its BodyProps variant)
    kn = rng.uniform(0.8e5, 1.2e5, n) if per_body else 1e5
    p = Particles(
        pos=pos, radius=R * rng.uniform(0.8, 1.0, n), density=2650.0, thickness=0.01, kn=kn, ks=kn, mu=0.5
    )
    w = Walls.box(0.0, 0.0, (nx + 1) * s, pos[:, 1].max() + 2 * R, 1e5, 1e5, 0.3)
    rolling = kw.pop("rolling", 0.0)
    held = kw.pop("held", False)
    sim = Simulation(p, w, **kw)
    if rolling:
        sim.set_rolling_friction(rolling, walls=rolling)
    if held:  # every 9th disk held still, in both partitions (the kernel skips their advance)
        sim.fix_particles(np.arange(n) % 9 == 4)
    sim.set_wall_servo("top", 0.5 * float(p.mass.sum()) * 9.81, (0.0, -1.0), max_speed=0.2, integral=1e-3)
    return sim


def _arrays(sim: Simulation) -> dict:
    """Every array of both contact lists, whole (past ``used`` too), and the disks' state and sums."""
    out = {}
    for name in ("pairs", "wall_pairs"):
        store = getattr(sim, name)
        out.update({f"{name}.{f}": getattr(store, f).copy() for f in CONTACT_FIELDS})
    p = sim.particles
    out.update({f: getattr(p, f).copy() for f in ("pos", "vel", "theta", "omega")})
    out.update(force=sim.force.copy(), moment=sim.moment.copy(), wall_force=sim.wall_force_vec.copy())
    out["step_count"] = np.array(sim.step_count)
    return out


def _assert_same_bytes(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for key in a:
        assert a[key].dtype == b[key].dtype and a[key].shape == b[key].shape, key
        assert a[key].tobytes() == b[key].tobytes(), key


def _settle(sim: Simulation, every: int | None, target: float, threads: int = 1) -> dict:
    """The fall into a packing in one call, then a run to a stop ratio in calls ``every`` steps long."""
    sim.threads = threads
    sim.run(FALL)
    looks = [] if every is None else [Every(every, lambda s: None)]
    res = sim.run(4000, until_ratio=target, check_every=48, measure="mean", reporters=looks)
    # stopped on a check step, contacts opened and closed, the lists were rebuilt meanwhile
    assert res.converged and 0 < res.steps < 4000 and res.rebuilds > 0
    # the same rebuilds: a long call skips the drift of disks too slow to need it
    return {**_arrays(sim), "rebuilds": np.array(res.rebuilds)}


FALL = 20_000
# the packings' settings, and a mean ratio each reaches on a check step of the second run
VARIANTS = {
    "constants": ({}, 0.07),
    "per_body": ({"per_body": True}, 0.075),
    "dashpot": ({"restitution": 0.5}, 0.06),
    "rolling": ({"rolling": 0.2, "per_body": True}, 0.06),
    "held": ({"held": True}, 0.03),
}


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_long_calls_leave_what_one_step_calls_leave(variant):
    settings, target = VARIANTS[variant]
    reference = _settle(_box(**settings), every=1, target=target)  # every step stores
    assert _box(**settings).partitions >= 2  # cross pairs: their geometry feeds each step's deferred pass
    for every in (None, 7, 100):
        _assert_same_bytes(reference, _settle(_box(**settings), every=every, target=target))


def test_cross_pairs_and_pairs_apart_are_stored_on_the_last_step():
    sim = _box(per_body=True)
    sim.run(FALL)
    nb = sim.pairs
    m = nb.used
    apart = nb.ov[:m] <= 0.0
    assert apart.any() and (~apart).any() and sim.work.dstart[-1] > 0
    # a listed pair's normal is of its last step, touching or apart: the unit vector from
    # its first disk towards its second, up to the step the disks advanced since
    rows, other = nb.rows(), nb.other[:m]
    d = sim.particles.pos[other] - sim.particles.pos[rows]
    unit = d / np.hypot(d[:, 0], d[:, 1])[:, None]
    assert np.allclose(np.column_stack([nb.nx[:m], nb.ny[:m]]), unit, atol=1e-3)
    assert np.all(nb.fn[:m][apart] == 0.0) and np.all(nb.fn[:m][~apart] > 0.0)
    assert np.all(nb.ov[m:] == 0.0) and np.all(nb.nx[m:] == 0.0) and np.all(nb.fn[m:] == 0.0)


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 numba threads")
def test_two_threads_store_what_one_does():
    one = _settle(_box(nx=24, ny=30, rolling=0.1), every=None, target=0.06, threads=1)
    two = _settle(_box(nx=24, ny=30, rolling=0.1), every=9, target=0.06, threads=2)
    _assert_same_bytes(one, two)


def test_a_resumed_run_stores_what_the_uninterrupted_one_does(tmp_path):
    a = _box(per_body=True, rolling=0.1)
    a.run(FALL, reporters=[Every(999, lambda s: None)])
    checkpoint.save(a, tmp_path / "mid.npz")
    a.run(900)
    b, c = checkpoint.load(tmp_path / "mid.npz"), checkpoint.load(tmp_path / "mid.npz")
    b.run(900)
    c.run(900, reporters=[Every(31, lambda s: None)])
    _assert_same_bytes(_arrays(a), _arrays(b))
    _assert_same_bytes(_arrays(a), _arrays(c))
    checkpoint.save(a, tmp_path / "a.npz")
    checkpoint.save(b, tmp_path / "b.npz")
    assert checkpoint.state_digest(tmp_path / "a.npz") == checkpoint.state_digest(tmp_path / "b.npz")


def test_held_disks_stay_and_the_others_move_also_after_their_mode_changed():
    # the kernel finds the disks not free by a cursor on a list made before each call
    sim = _box(held=True)
    start = sim.particles.pos.copy()
    held = sim.particles.mode != FREE
    sim.run(3000)
    pos = sim.particles.pos
    assert held.sum() > 20 and np.array_equal(pos[held], start[held])
    assert np.all(pos[~held, 1] < start[~held, 1])  # the free ones fell
    sim.particles.mode[:] = FREE  # set free between calls: they fall too
    before = pos.copy()
    sim.run(3000)
    assert np.all(sim.particles.pos[held, 1] < before[held, 1])
