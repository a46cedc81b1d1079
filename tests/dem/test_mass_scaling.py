"""Per-disk density scaling (``Simulation(mass_scaling_dt=...)``, ``set_mass_scaling``).

A pile of 36 coarse disks (r 0.8-1 mm) with 25 fines (r 0.15 mm) in its pores: the fines set
an unscaled step 6.7 times shorter than the coarse disks'. Raised for five times the unscaled
step, the fines' inertial masses grow 25-fold. What must hold:

* the scaled system's time step is the one asked for, and its energy stays bounded at that
  step, while the same step without scaling blows up (the kinetic energy grows past every
  bound the weight could supply);
* the settled scaled pile carries its TRUE weight on the bottom wall (gravity acts on the true
  mass): a static equilibrium does not depend on the inertial masses;
* a floor below every disk's mass changes no number: bit for bit the unscaled run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from poro2d.dem import Every, Particles, Simulation, Walls
from poro2d.dem.model import critical_time_step, mass_for_time_step, raised_inertia
from poro2d.dem.summary import EngineSummary

R = 1e-3
FINE = 0.15  # fine radius over R
K = 1e5


def _pile(**kw) -> Simulation:
    """Coarse disks in a staggered stack, a fine disk in the lower triangle of every cell."""
    rng = np.random.default_rng(0)
    nx, ny = 6, 6
    s = 2.05 * R
    h = s * math.sqrt(3) / 2
    coarse = [(s * (i + 0.25 + 0.5 * (j % 2)), s / 2 + h * j) for j in range(ny) for i in range(nx)]
    fines = [
        (s * (i + 0.75 + 0.5 * (j % 2)), s / 2 + h * j + h / 3) for j in range(ny - 1) for i in range(nx - 1)
    ]
    radius = np.concatenate([R * rng.uniform(0.8, 1.0, len(coarse)), np.full(len(fines), FINE * R)])
    p = Particles(
        pos=np.array(coarse + fines), radius=radius, density=2650.0, thickness=0.01, kn=K, ks=K, mu=0.5
    )
    width, top = nx * s + 0.5 * s, 3 * ny * s
    w = Walls()
    w.add((-width, 0.0), (2 * width, 0.0), K, K, 0.5, "bottom")
    w.add((width, -width), (width, top), K, K, 0.0, "right")
    w.add((0.0, top), (0.0, -width), K, K, 0.0, "left")
    return Simulation(p, w, **kw)


def _kinetic_energy(sim: Simulation) -> float:
    """Translational and rotational kinetic energy with the TRUE masses (J)."""
    p = sim.particles
    return float(0.5 * np.sum(p.mass * np.sum(p.vel**2, axis=1)) + 0.5 * np.sum(p.inertia * p.omega**2))


def _largest_energy(sim: Simulation, steps: int) -> float:
    seen = [0.0]
    sim.run(steps, reporters=[Every(250, lambda s: seen.append(_kinetic_energy(s)))])
    return max(seen)


def test_mass_for_time_step_inverts_the_critical_step():
    k_sum, safety = 3.0 * K, 0.8
    m = mass_for_time_step(2e-6, k_sum, safety)
    assert safety * critical_time_step(m, k_sum) == pytest.approx(2e-6, rel=1e-14)


def test_raised_inertia_keeps_heavy_disks_and_the_uniform_disk_ratio():
    mass = np.array([1.0, 4.0, 0.25])
    inertia = np.array([0.5, 2.0 * 3.0, 0.125 * 0.01])
    m, i = raised_inertia(mass, inertia, 2.0)
    assert m.tolist() == [2.0, 4.0, 2.0]
    assert i[1] == inertia[1]  # a disk above the floor is untouched, bit for bit
    assert i / m == pytest.approx(inertia / mass, rel=1e-15)  # I / m = r^2 / 2 kept


def test_the_scaled_step_is_the_chosen_one_and_stays_stable_where_true_masses_blow_up():
    plain = _pile()
    chosen = 5.0 * plain.dt
    scaled = _pile(mass_scaling_dt=chosen)
    assert scaled.dt == pytest.approx(chosen, rel=1e-12)
    assert scaled.mass_scaling.disks == 25
    assert scaled.mass_scaling.largest_ratio == pytest.approx(25.0, rel=1e-9)  # (5 x the step)^2
    # the energy the weight can release: every disk falling the whole pile's height
    bound = float(np.sum(scaled.particles.mass)) * 9.81 * 0.03
    assert _largest_energy(scaled, 20_000) < bound
    plain.dt = chosen  # the same step with the true masses
    assert _largest_energy(plain, 20_000) > 100.0 * bound


def test_settled_scaled_pile_carries_its_true_weight():
    sim = _pile(mass_scaling_dt=5.0 * _pile().dt)
    res = sim.solve(ratio=1e-4, max_steps=200_000)
    assert res.converged
    weight = float(np.sum(sim.particles.mass)) * 9.81  # true masses
    assert -sim.wall_force("bottom")[1] == pytest.approx(weight, rel=1e-3)
    # the inertial masses are 45 % heavier in all: a balance on them would be far off
    assert sim.mass_scaling.added_fraction > 0.4


def test_a_floor_below_every_mass_is_bit_for_bit_the_true_run():
    plain = _pile()
    floored = _pile(mass_scaling_dt=0.5 * plain.dt)
    assert floored.mass_scaling.disks == 0 and floored.dt == plain.dt
    plain.run(3000)
    floored.run(3000)
    for name in ("pos", "vel", "omega"):
        assert np.array_equal(getattr(plain.particles, name), getattr(floored.particles, name))


def test_switching_scaling_off_gives_the_true_masses_back():
    plain = _pile()
    sim = _pile(mass_scaling_dt=5.0 * plain.dt)
    sim.set_mass_scaling(None)
    assert sim.dt == plain.dt and sim.mass_scaling.disks == 0
    assert np.array_equal(sim.masses.inv_mass, plain.masses.inv_mass)
    assert np.array_equal(sim.masses.inv_inertia, plain.masses.inv_inertia)


def test_summary_records_the_scaling_only_when_set():
    plain = _pile()
    assert "mass_scaling" not in plain.summary().to_dict()
    row = _pile(mass_scaling_dt=5.0 * plain.dt).summary().to_dict()
    ms = row["mass_scaling"]
    assert ms["time_step_s"] == pytest.approx(5.0 * plain.dt) and ms["disks_scaled"] == 25
    assert ms["gravity_on"] == "true mass"
    assert EngineSummary.from_dict(row).to_dict() == row


def test_checkpoint_keeps_the_scaling(tmp_path):
    from poro2d.dem import checkpoint

    sim = _pile(mass_scaling_dt=5.0 * _pile().dt)
    sim.run(500)
    back = checkpoint.load(checkpoint.save(sim, tmp_path / "c.npz"))
    assert back.mass_scaling_dt == sim.mass_scaling_dt and back.dt == sim.dt
    assert np.array_equal(back.masses.inv_mass, sim.masses.inv_mass)
