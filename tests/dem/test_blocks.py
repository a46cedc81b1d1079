"""How :meth:`Simulation.run` cuts its steps into kernel calls changes no bit.

``run`` hands the compiled loop blocks of steps: the whole run, or pieces up to the
next progress update, the next ``every`` callback, or a pair-storage overflow (the
storage is grown and the call repeated). The stop test of ``until_ratio`` runs every
``check_every`` steps counted from the start of the ``run`` call, so whatever the
blocks, the same state is reached and a run stops on the same step: positions,
velocities, forces, walls, the servo's integral and the clock are compared with
``np.array_equal``.

The packing: 264 disks settling under gravity in a box, a servo lid pressing on them
with half their weight (integral term on), several list rebuilds; the stop ratio is
reached after 16 128 steps (well under a second per run).
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from poro2d.dem import Every, Particles, Simulation, Walls
from poro2d.dem.state import SERVO_ERROR_SUM
from tests.dem.grids import staggered_rows

R = 1e-3
STOP_RATIO = 0.12
CHECK_EVERY = 64  # divides neither 2000 (the progress block) nor most ``every`` below
MAX_STEPS = 30_000


def _settling_box(nx: int = 12, ny: int = 22, cls: type[Simulation] = Simulation) -> Simulation:
    """Disks on a loose staggered grid in a box; the lid is servoed to half their weight."""
    rng = np.random.default_rng(3)
    s = 2.02 * R
    pos = staggered_rows(nx, ny, R, rng)
    n = len(pos)
    p = Particles(
        pos=pos, radius=R * rng.uniform(0.8, 1.0, n), density=2650.0, thickness=0.01,
        kn=1e5, ks=1e5, mu=0.5,
    )  # fmt: skip
    w = Walls.box(0.0, 0.0, (nx + 1) * s, pos[:, 1].max() + 2 * R, 1e5, 1e5, 0.3)
    sim = cls(p, w)
    weight = float(p.mass.sum()) * 9.81
    sim.set_wall_servo("top", 0.5 * weight, (0.0, -1.0), max_speed=0.2, integral=1e-3)
    return sim


def _state(sim: Simulation, res) -> dict:
    """Everything a later step depends on, and what the run reported."""
    p, w = sim.particles, sim.walls
    m = sim.pairs.used
    return {
        "pos": p.pos.copy(), "vel": p.vel.copy(), "theta": p.theta.copy(), "omega": p.omega.copy(),
        "force": sim.force.copy(), "moment": sim.moment.copy(), "wall_p0": w.p0.copy(),
        "wall_p1": w.p1.copy(), "wall_vel": w.vel.copy(), "wall_force": sim.wall_force_vec.copy(),
        "servo": w.servo.copy(), "time": np.array(sim.time), "step_count": np.array(sim.step_count),
        "steps": np.array(res.steps), "converged": np.array(res.converged),
        "pairs": sim.pairs.other[:m].copy(), "shear_history": sim.pairs.fs[:m].copy(),
    }  # fmt: skip


def _assert_same(a: dict, b: dict) -> None:
    for key in a:
        assert np.array_equal(a[key], b[key]), key


def _settle(**kw) -> tuple[Simulation, dict]:
    sim = kw.pop("sim", None) or _settling_box()
    res = sim.run(MAX_STEPS, until_ratio=STOP_RATIO, check_every=CHECK_EVERY, **kw)
    return sim, _state(sim, res)


@pytest.fixture(scope="module")
def one_block():
    sim, state = _settle()
    assert state["converged"] and state["steps"] < MAX_STEPS
    assert state["steps"] % CHECK_EVERY == 0
    assert sim.walls.servo[sim.walls.index("top"), SERVO_ERROR_SUM] != 0.0  # the integral term took part
    return state


def test_progress_bar_changes_nothing(one_block):
    _, state = _settle(progress="settling")
    _assert_same(one_block, state)


@pytest.mark.parametrize("every", [1, 7, 100, 999, 4096])
def test_reporters_change_nothing(one_block, every):
    seen = []

    def look(sim):  # reads the state like a protocol's check does
        seen.append((sim.step_count, sim.unbalanced_ratios()[0], float(sim.wall_force("top")[1])))

    _, state = _settle(reporters=[Every(every, look)])
    _assert_same(one_block, state)
    # called on every multiple of ``every`` before the stop (not on the step that stops)
    assert [s for s, _, _ in seen] == list(range(every, int(one_block["steps"]), every))


class _TightStorage(Simulation):
    """Pair storage grown to exactly what the last list build needed: it overflows again and again."""

    def grow_pairs(self, capacity: int, keep: int = 0) -> None:
        pairs = getattr(self, "pairs", None)
        if pairs is not None and pairs.overflow:
            self.grown_at.append(self.step_count)
            capacity = pairs.needed
        super().grow_pairs(capacity, keep)


def test_storage_overflows_change_nothing(one_block):
    sim = _settling_box(cls=_TightStorage)
    sim.grown_at = []
    sim.grow_pairs(16)
    _, state = _settle(sim=sim)
    _assert_same(one_block, state)
    late = [s for s in sim.grown_at if s % CHECK_EVERY]
    assert len(late) >= 3  # the kernel call was cut and repeated between two stop checks


def test_two_runs_equal_one_without_a_stop_ratio():
    # without a stop ratio the check schedule only looks for instability: any cut of the
    # steps into run() calls gives the same state
    a, b = _settling_box(), _settling_box()
    ra = a.run(3000)
    b.run(1234)
    rb = b.run(1766, reporters=[Every(333, lambda sim: None)])
    assert ra.rebuilds > 0 and b.step_count == a.step_count == 3000
    skip = ("steps",)
    _assert_same(*({k: v for k, v in _state(s, r).items() if k not in skip} for s, r in ((a, ra), (b, rb))))


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 numba threads")
def test_threads_and_blocks_change_nothing_on_a_large_packing():
    # 1056 disks: the kernel runs on two threads by itself. Two threads wait for each
    # other at every step on a loaded 2-core host, so only the last ~260 steps of the
    # fall run on them, and those end with the stop ratio met (chaotic: after 1100 steps of
    # fall, as before the engine fused its products and sums, the ratio hovers at 1.0)
    runs = []
    for threads, every in ((1, None), (2, 7)):
        sim = _settling_box(nx=24, ny=44)
        sim.run(1500)
        sim.threads = threads
        assert sim.effective_threads == threads
        looks = [] if every is None else [Every(every, lambda s: None)]
        res = sim.run(500, until_ratio=0.9, check_every=16, reporters=looks)
        assert sim.threads_used == threads
        runs.append(_state(sim, res))
    assert runs[0]["converged"] and runs[0]["steps"] < 500
    _assert_same(runs[0], runs[1])


def test_the_long_running_kernels_release_python_s_lock():
    # a Dask worker's heartbeat thread must run while a block of steps does (a worker silent
    # for minutes is restarted by its scheduler): every entry point of a long compiled loop
    from poro2d.dem import kernels, periodic_kernels
    from poro2d.oracles import jamming

    for kernel in (kernels._run_threads, kernels.step_block_serial, periodic_kernels.advance, jamming._fire):
        assert kernel.targetoptions.get("nogil") is True, kernel.py_func.__name__
