"""Equilibrium measures of the stop test, and layers that end once settled."""

import math

import numpy as np
import pytest

from poro2d.criterion.protocol import wall_forces
from poro2d.dem import Every, Simulation
from poro2d.dem.contacts import contact_set
from poro2d.errors import InputError
from poro2d.grading import preset_grading
from poro2d.specimen.compaction import SettledTest, SpecimenSpec, prepare_specimen


def _column(seed: int = 0) -> Simulation:
    """A small prepared specimen, shaken: its ratios fall through every level as it settles again."""
    spec = SpecimenSpec(width=0.05, height=0.03, layers=1, friction_prep=0.3, friction_particle=0.3)
    sim, _ = prepare_specimen(spec, preset_grading("paper"), 0.2, seed=seed)
    rng = np.random.default_rng(seed)
    sim.particles.vel[:] = rng.normal(0.0, 0.02, sim.particles.vel.shape)
    return sim


def _by_hand(sim: Simulation) -> dict:
    """The ratios from the contact set and the disks' unbalanced forces, in NumPy."""
    n = sim.particles.n
    c = contact_set(sim)
    fc = np.hypot(c.fn, c.fs)
    pp = c.kind == 0
    touches = np.bincount(c.i, minlength=n)[:n] + np.bincount(c.j[pp], minlength=n)[:n]
    f = np.hypot(sim.force[:n, 0], sim.force[:n, 1])
    loaded = touches >= 2
    return {
        "max": f.max() / fc.max(),
        "mean": f.mean() / fc.mean(),
        "loaded_max": f[loaded].max() / fc.max() if loaded.any() else 0.0,
        "rattler_fraction": float(np.mean(~loaded)),
    }


def test_every_measure_matches_a_numpy_count():
    sim = _column()
    for steps in (3000, 20000):
        sim.run(steps)
        got, want = sim.equilibrium_measures(), _by_hand(sim)
        for key in ("max", "mean", "loaded_max", "rattler_fraction"):
            assert got[key] == pytest.approx(want[key], rel=1e-9, abs=1e-15), key
    assert sim.unbalanced_ratios() == (got["max"], got["mean"])


def test_the_stop_test_compares_the_measure_it_is_given():
    """Each run stops at the first check at which its own measure is below the target."""
    target, horizon = 3e-5, 20_000
    seen = []
    sim = _column(seed=2)
    sim.run(horizon, reporters=[Every(100, lambda s: seen.append(s.equilibrium_measures()))])
    for measure in ("max", "mean", "loaded_max"):
        first = next((100 * (k + 1) for k, m in enumerate(seen) if m[measure] < target), None)
        assert first is not None, measure  # the packing gets there within the horizon
        res = _column(seed=2).run(horizon, until_ratio=target, check_every=100, measure=measure)
        assert res.converged and res.measure == measure
        assert res.steps == first, measure
        assert res.measured_ratio == seen[first // 100 - 1][measure] < target


def test_an_unknown_measure_is_refused_by_name():
    sim = _column()
    with pytest.raises(InputError, match="equilibrium measure"):
        sim.run(10, until_ratio=1e-3, measure="median")
    with pytest.raises(InputError, match="equilibrium"):
        SpecimenSpec(equilibrium="median")


def test_new_settings_are_recorded_only_when_changed():
    d = SpecimenSpec().to_dict()
    assert not {"equilibrium", "settle_drift", "settle_window", "settle_checks"} & set(d)
    d = SpecimenSpec(equilibrium="mean", settle_drift=1e-3).to_dict()
    assert d["equilibrium"] == "mean" and d["settle_drift"] == 1e-3
    with pytest.raises(InputError, match="settle_drift"):
        SpecimenSpec(settle_drift=0.0)


def test_settled_test_needs_its_windows_running():
    sim = _column()
    sim.run(30000)
    test = SettledTest(sim, 1e-3, checks=3)
    calls = [test(sim) for _ in range(4)]  # the state does not move between calls
    assert calls == [False, False, False, True]
    assert test.settled


QUICK_WIDE = {"width": 0.08, "height": 0.04, "layers": 2, "friction_prep": 0.0}


@pytest.mark.slow
def test_a_frictionless_wide_grading_settles_then_comes_to_equilibrium():
    """Frictionless layers of a Cu 4 grading creep at a ratio of 1e-2; settled, the working
    friction brings the specimen to equilibrium (measured: layer 2 fails 406 000 steps without)."""
    budget = {"max_steps_per_stage": 200_000, "fallback_steps": 20_000, "calm_steps": 5_000}
    g = preset_grading("wide_cu4")
    sim, rep = prepare_specimen(SpecimenSpec(**QUICK_WIDE, **budget), g, 0.142, seed=142000)
    assert not rep.converged and rep.failed_stage.startswith("layer")
    assert rep.failed_ratio > 1e-3
    spec = SpecimenSpec(**QUICK_WIDE, **budget, settle_drift=1e-3)
    sim, rep = prepare_specimen(spec, g, 0.142, seed=142000)
    assert rep.converged
    assert rep.layers[-1].attempts[-1].ended_by == "settled"
    assert rep.final_stage.ended_by == "ratio"  # the working friction: by its ratio alone
    assert sim.unbalanced_ratios()[0] < spec.ratio
    f = wall_forces(sim)
    weight = float(np.sum(sim.particles.mass)) * spec.gravity / spec.thickness
    lhs = f.f_bottom_n_per_m + f.side_friction_up_n_per_m
    assert math.isclose(lhs, weight + f.f_top_n_per_m, rel_tol=0.01)
