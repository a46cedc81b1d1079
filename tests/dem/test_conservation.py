"""Conservation laws of the undamped engine.

Energy: disks bouncing in a box without gravity and local damping. The total
``KE + sum fn^2 / (2 kn) + sum fs^2 / (2 ks)`` (spring energies from
``sim.contacts()``, kn and ks the contact's series springs) is a constant of the
continuous motion when nothing slides. Leapfrog keeps a nearby "shadow" energy, so
the velocity is taken at the time of the positions, ``(v(t - dt/2) + v(t + dt/2)) / 2``;
the remaining oscillation is O((omega dt)^2).

Momentum: disks colliding freely (no walls, no gravity, no damping), with friction
(sliding and sticking contacts) and a dashpot. Contact forces come in equal and
opposite pairs and their moments cancel about any point (the lever arms
``r_i - ov/2 + r_j - ov/2`` add up to the centre distance), so linear momentum and
the angular momentum ``sum m x(t+dt) x v(t+dt/2) + I omega`` (exactly conserved by
leapfrog in that staggered form) stay constant to round-off.
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls
from poro2d.dem.model import ContactModel
from poro2d.measure.energy import kinetic_energy

R = 0.01


def _box_gas(mu: float, seed: int = 0, dt_safety: float = 0.04) -> Simulation:
    """9 disks flying about a 0.1 m box (contacts open and close)."""
    rng = np.random.default_rng(seed)
    g = (np.arange(3) + 0.5) * (0.1 / 3)
    pos = np.array([(x, y) for y in g for x in g]) + rng.uniform(-0.004, 0.004, (9, 2))
    p = Particles(
        pos=pos, radius=R * rng.uniform(0.9, 1.3, 9), density=rng.uniform(2000, 3000, 9), thickness=0.01,
        kn=rng.uniform(5e5, 1.5e6, 9), ks=rng.uniform(3e5, 1e6, 9), mu=mu,
        vel=rng.normal(0.0, 1.0, (9, 2)), omega=rng.normal(0.0, 50.0, 9),
    )  # fmt: skip
    w = Walls.box(0.0, 0.0, 0.1, 0.1, 2e6, 1e6, mu)
    return Simulation(p, w, gravity=(0.0, 0.0), local_damping=0.0, dt_safety=dt_safety)


def _squeezed_box(mu: float, seed: int = 0, dt_safety: float = 0.04) -> Simulation:
    """A 4x4 square lattice squeezed 2 % into a box: every contact stays closed.

    Random velocities and spins make the contacts roll and shear without ever
    opening (a contact that opens, or whose normal force drops to zero, releases
    its shear spring through the Coulomb cap: that energy is lost by design).
    """
    rng = np.random.default_rng(seed)
    g = (np.arange(4) + 0.5) * 2 * R
    pos = np.array([(x, y) for y in g for x in g])
    n = len(pos)
    p = Particles(
        pos=pos, radius=R * 1.02, density=rng.uniform(2000, 3000, n), thickness=0.01,
        kn=rng.uniform(8e5, 1.2e6, n), ks=rng.uniform(3e5, 1e6, n), mu=mu,
        vel=rng.normal(0.0, 0.3, (n, 2)), omega=rng.normal(0.0, 30.0, n),
    )  # fmt: skip
    w = Walls.box(0.0, 0.0, 8 * R, 8 * R, 2e6, 1e6, mu)
    return Simulation(p, w, gravity=(0.0, 0.0), local_damping=0.0, dt_safety=dt_safety)


def _spring_energy(sim: Simulation, parts: bool = False):
    """Normal + shear spring energy of the touching contacts, and how many slide."""
    c = sim.contacts()
    p, w = sim.particles, sim.walls
    pp = c.kind == 0
    jj = np.where(pp, c.j, 0)
    ww = np.where(pp, 0, c.j)
    kn_j = np.where(pp, p.kn[jj], w.kn[ww])
    ks_j = np.where(pp, p.ks[jj], w.ks[ww])
    mu_j = np.where(pp, p.mu[jj], w.mu[ww])
    kn = p.kn[c.i] * kn_j / (p.kn[c.i] + kn_j)
    ks = p.ks[c.i] * ks_j / (p.ks[c.i] + ks_j)
    mu = np.minimum(p.mu[c.i], mu_j)
    en = float(np.sum(c.fn**2 / (2 * kn)))
    stick = ks > 0
    es = float(np.sum(c.fs[stick] ** 2 / (2 * ks[stick])))
    sliding = int(np.sum((mu > 0) & (np.abs(c.fs) >= mu * c.fn * (1 - 1e-12)) & (c.fn > 0)))
    if parts:
        return en, es
    return en + es, sliding


def _energy_history(sim: Simulation, steps: int, every: int = 10):
    p = sim.particles
    m, inertia = p.mass, p.inertia
    out = []
    n_contacts = slid = 0
    for _ in range(steps // every):
        sim.run(every - 1)
        v0, w0 = p.vel.copy(), p.omega.copy()
        sim.run(1)  # forces of this step were computed at the positions of time t
        v = 0.5 * (v0 + p.vel)
        om = 0.5 * (w0 + p.omega)
        ke = 0.5 * float(np.sum(m * np.sum(v * v, axis=1)) + np.sum(inertia * om * om))
        pe, s = _spring_energy(sim)
        n_contacts += len(sim.contacts())
        slid += s
        out.append(ke + pe)
    return np.array(out), n_contacts, slid


def test_energy_is_conserved_without_damping_colliding_disks():
    """Frictionless disks colliding with each other and the walls."""
    sim = _box_gas(0.0)
    e, n_contacts, _slid = _energy_history(sim, 6000)
    assert n_contacts > 30  # collisions happened (disk-disk and disk-wall)
    drift = float(np.max(np.abs(e - e[0])) / e[0])
    assert drift < 1e-3, drift


def test_energy_is_conserved_without_damping_sticking_contacts():
    """Frictional contacts below sliding: normal and shear springs store energy."""
    sim = _squeezed_box(5.0)
    ke0 = sum(kinetic_energy(sim))
    e, n_contacts, slid = _energy_history(sim, 6000)
    assert slid == 0
    assert n_contacts == 600 * 40  # 24 lattice pairs + 16 wall contacts, all the time
    _en, es = _spring_energy(sim, parts=True)
    assert es > 0.01 * ke0  # the shear springs do take part
    drift = float(np.max(np.abs(e - e[0])))
    # most of the energy is the static squeeze: judge against both scales
    assert drift < 1e-4 * e[0], drift / e[0]
    assert drift < 5e-3 * ke0, drift / ke0


def test_sliding_dissipates_energy():
    """With a low friction the sum decreases (never increases beyond the leapfrog ripple)."""
    sim = _squeezed_box(0.02)
    e, _n, slid = _energy_history(sim, 6000)
    assert slid > 0
    assert e[-1] < 0.99 * e[0]
    assert np.all(np.diff(e) < 1e-4 * e[0])


def _free_cluster(seed: int, restitution) -> Simulation:
    rng = np.random.default_rng(seed)
    n = 12
    ang = np.linspace(0, 2 * np.pi, n, endpoint=False)
    pos = np.column_stack([np.cos(ang), np.sin(ang)]) * 0.06 + rng.uniform(-0.005, 0.005, (n, 2))
    # aimed at the centre, with random transverse parts: many oblique collisions
    vel = -pos / 0.06 * 2.0 + rng.normal(0.0, 0.5, (n, 2))
    p = Particles(
        pos=pos, radius=R * rng.uniform(0.8, 1.4, n), density=rng.uniform(2000, 3000, n), thickness=0.01,
        kn=1e6, ks=8e5, mu=rng.uniform(0.1, 0.6, n), vel=vel, omega=rng.normal(0.0, 100.0, n),
    )  # fmt: skip
    return Simulation(p, None, gravity=(0.0, 0.0), local_damping=0.0, restitution=restitution)


def _momenta(sim: Simulation):
    p = sim.particles
    m = p.mass
    lin = (m[:, None] * p.vel).sum(axis=0)
    ang = float(
        np.sum(m * (p.pos[:, 0] * p.vel[:, 1] - p.pos[:, 1] * p.vel[:, 0])) + np.sum(p.inertia * p.omega)
    )
    lin_scale = float(np.sum(m * np.hypot(*p.vel.T)))
    ang_scale = float(
        np.sum(m * np.hypot(*p.pos.T) * np.hypot(*p.vel.T)) + np.sum(p.inertia * np.abs(p.omega))
    )
    return lin, ang, lin_scale, ang_scale


@pytest.mark.parametrize("restitution", [None, 0.7])
def test_linear_and_angular_momentum_in_free_collisions(restitution):
    sim = _free_cluster(11, restitution)
    lin0, ang0, ls, as_ = _momenta(sim)
    touched = slid = 0
    worst_lin = worst_ang = 0.0
    for _ in range(600):
        sim.run(5)
        c = sim.contacts()
        touched += len(c)
        mu = np.minimum(sim.particles.mu[c.i], sim.particles.mu[c.j])
        slid += int(np.sum(np.abs(c.fs) >= mu * c.fn * (1 - 1e-12)))
        lin, ang, _, _ = _momenta(sim)
        worst_lin = max(worst_lin, float(np.max(np.abs(lin - lin0))) / ls)
        worst_ang = max(worst_ang, abs(ang - ang0) / as_)
    assert touched > 20 and slid > 0
    # the spins changed: friction acted
    assert worst_lin < 1e-13, worst_lin
    assert worst_ang < 1e-13, worst_ang


def test_per_pair_type_momentum():
    """Same check with contact-level properties (the PFC 5 convention)."""
    sim = _free_cluster(5, None)
    sim.contact = ContactModel("per_pair_type", pp=(7e5, 5e5, 0.3), pw=(1e6, 1e6, 0.3))
    sim.particles_changed()
    lin0, ang0, ls, as_ = _momenta(sim)
    sim.run(3000)
    lin, ang, _, _ = _momenta(sim)
    assert np.max(np.abs(lin - lin0)) / ls < 1e-13
    assert abs(ang - ang0) / as_ < 1e-13


def _hex_lattice_box(dt_safety) -> Simulation:
    """100 equal disks on a hexagonal lattice, 0.1 % overlaps, ks = kn, no sliding.

    Every inner disk has six contacts. In the mode where all disks turn the same way,
    each contact's shear spring is strained by ``2 r theta``: ``omega^2 = 4 z ks / m``
    with z = 6 and ks the contact's spring, so leapfrog is stable only for
    ``dt < sqrt(m / (6 ks)) = 0.41 sqrt(m / ks)``.
    """
    rng = np.random.default_rng(0)
    r = 1e-3
    nx = ny = 10
    pos = np.array(
        [
            (r + 2 * r * c + r * (row % 2), r + np.sqrt(3.0) * r * row)
            for row in range(ny)
            for c in range(nx - row % 2)
        ]
    )
    n = len(pos)
    p = Particles(
        pos=pos, radius=r * 1.001, density=2650.0, thickness=0.01, kn=1e5, ks=1e5, mu=1e6,
        omega=rng.normal(0.0, 1e-3, n),
    )  # fmt: skip
    w = Walls.box(0.0, 0.0, 2 * nx * r, pos[:, 1].max() + r, 1e5, 1e5, 1e6)
    return Simulation(p, w, gravity=(0.0, 0.0), local_damping=0.0, dt_safety=dt_safety)


def test_energy_conserved_in_hex_lattice_with_small_dt():
    sim = _hex_lattice_box(0.35)
    e, _n, slid = _energy_history(sim, 2000)
    assert slid == 0
    assert np.max(np.abs(e - e[0])) < 1e-2 * e[0]


def test_energy_conserved_in_hex_lattice_with_automatic_dt():
    """The automatic step accounts for the same-sense spin mode of six-contact disks."""
    default = inspect.signature(Simulation).parameters["dt_safety"].default
    sim = _hex_lattice_box(default)
    e, _n, _slid = _energy_history(sim, 2000)
    assert np.max(np.abs(e - e[0])) < 1e-2 * e[0]
