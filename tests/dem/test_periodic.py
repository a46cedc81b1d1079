"""The periodic shear cell: contacts through its edges, conservation, the affine flow, the stress."""

from __future__ import annotations

import math

import numpy as np
import pytest

from poro2d.dem.periodic import CellLaw, PeriodicCell
from poro2d.errors import InputError

KN = 2e5
LAW = CellLaw(kn=KN, ks=KN, friction=0.5)
RHO, T = 2650.0, 0.008


def cell_of(radius, pos, width=0.02, height=0.02, law=LAW) -> PeriodicCell:
    return PeriodicCell(np.asarray(radius), np.asarray(pos), width, height, law, density=RHO, thickness=T)


def normal_force(r1, r2, gap_vector) -> np.ndarray:
    """The force on disk 1 of a static pair by hand: kn times the overlap, pushing 1 away from 2."""
    d = float(np.hypot(*gap_vector))
    return -KN * (r1 + r2 - d) * np.asarray(gap_vector) / d


def test_a_contact_across_the_x_edge_feels_what_it_would_in_the_interior():
    r = [1.0e-3, 1.2e-3]
    L = 0.02
    across = cell_of(r, [[0.0003, 0.0100], [L - 0.0015, 0.0102]])
    inside = cell_of(r, [[0.0103, 0.0100], [0.0085, 0.0102]])
    f_across, _ = across.forces()
    f_inside, _ = inside.forces()
    np.testing.assert_allclose(f_across, f_inside, rtol=1e-9, atol=0.0)
    # and against the law by hand: branch from 1 to 2's image is (-0.0018, 0.0002)
    np.testing.assert_allclose(f_across[0], normal_force(r[0], r[1], [-0.0018, 0.0002]), rtol=1e-9)
    np.testing.assert_allclose(f_across.sum(axis=0), 0.0, atol=1e-12)


def test_a_contact_across_the_y_edge_reaches_the_image_shifted_by_the_offset():
    r = [1.0e-3, 1.0e-3]
    a, b = [0.0100, 0.0195], [0.0045, 0.0014]
    cell = cell_of(r, [a, b])
    assert cell.contacts()["i"].size == 0  # without an offset b's image above is far from a
    cell.set_offset(0.006)
    c = cell.contacts()
    assert c["i"].size == 1
    branch = np.array([b[0] + 0.006 - a[0], b[1] + 0.02 - a[1]])  # a -> the image of b above the cell
    np.testing.assert_allclose([c["lx"][0], c["ly"][0]], branch, rtol=1e-9)
    np.testing.assert_allclose(c["fn"][0], KN * (2e-3 - np.hypot(*branch)), rtol=1e-9)


def dense_cell(seed=1, n=120, law=LAW) -> PeriodicCell:
    """A small random packing pressed together: disks on a lattice, then compressed isotropically."""
    rng = np.random.default_rng(seed)
    radius = rng.uniform(0.8e-3, 1.2e-3, n)
    cols = math.ceil(math.sqrt(n))
    site = np.arange(n)
    pos = (np.stack([site % cols, site // cols], axis=1) + 0.5) * 2.5e-3
    side = cols * 2.5e-3
    cell = PeriodicCell(radius, pos, side, math.ceil(n / cols) * 2.5e-3, law, density=RHO, thickness=T)
    cell.compress(1e5, 5e-6, 20.0, 20.0)
    cell.run(4000)
    return cell


def test_without_barostat_and_shear_the_forces_sum_to_zero_and_momentum_is_kept():
    cell = dense_cell()
    cell.hold()
    rng = np.random.default_rng(3)
    cell.vel[:] = rng.normal(0.0, 0.01, cell.vel.shape)
    force, _ = cell.forces()
    assert np.abs(force).sum() > 0.0
    assert np.abs(force.sum(axis=0)).max() < 1e-12 * np.abs(force).sum()
    p0 = (cell.mass[:, None] * cell.vel).sum(axis=0)
    cell.run(3000)
    p1 = (cell.mass[:, None] * cell.vel).sum(axis=0)
    scale = float((cell.mass[:, None] * np.abs(cell.vel)).sum())
    assert np.abs(p1 - p0).max() < 1e-12 * scale


def test_disks_without_contacts_follow_the_affine_shear_profile():
    n = 16
    pos = (np.stack([np.arange(n) % 4, np.arange(n) // 4], axis=1) + 0.5) * 0.01
    cell = cell_of(np.full(n, 1e-3), pos, 0.04, 0.04)
    rate = 2.0
    cell.hold(shear_rate=rate)
    steps = 2000
    cell.run(steps)
    t = steps * cell.dt
    v = cell.absolute_velocity()
    np.testing.assert_allclose(v[:, 0], rate * cell.pos[:, 1], rtol=1e-12)
    np.testing.assert_allclose(v[:, 1], 0.0, atol=0.0)
    # each disk has moved by gamma_dot y t (no rebuild wrapped them: strain is tiny next to the skin)
    np.testing.assert_allclose(cell.pos[:, 0] - pos[:, 0], rate * pos[:, 1] * t, rtol=1e-9)
    assert cell.strain == pytest.approx(rate * t, rel=1e-12)
    assert cell.offset == pytest.approx(rate * 0.04 * t, rel=1e-9)


def test_elastic_frictionless_cell_keeps_its_energy():
    """No friction, no dashpot: the energy swings (symplectic Euler: by about dt omega) but does not drift."""
    law = CellLaw(kn=KN, ks=KN, friction=0.0, restitution=1.0)
    packed = dense_cell(seed=2, n=60, law=law)
    cell = PeriodicCell(
        packed.radius, packed.pos, packed.width, packed.height, law, density=RHO, thickness=T, dt_safety=0.2
    )
    cell.hold()
    cell.vel[:] = np.random.default_rng(4).normal(0.0, 0.02, cell.vel.shape)
    e0 = cell.energy()
    energies = []
    for _ in range(40):
        cell.run(2000)
        energies.append(cell.energy() / e0)
    e = np.array(energies)
    assert np.abs(e - 1.0).max() < 0.01
    assert abs(e[-10:].mean() - e[:10].mean()) < 0.005
    assert cell.contacts()["i"].size > 0  # the springs were working


def test_a_blocks_stress_is_the_love_weber_sum_of_its_contacts():
    cell = dense_cell(seed=5)
    cell.hold()
    c = cell.contacts()
    volume = cell.width * cell.height * T
    # force on j is -f_i; sigma = -(1/V) sum f_j l = (1/V) sum f_i l
    expected = (
        np.array(
            [
                [np.sum(c["fx"] * c["lx"]), np.sum(c["fx"] * c["ly"])],
                [np.sum(c["fy"] * c["lx"]), np.sum(c["fy"] * c["ly"])],
            ]
        )
        / volume
    )
    block = cell.run(1)
    np.testing.assert_allclose(block.stress - block.kinetic, expected, rtol=1e-9)
    assert block.normal_stress > 0.0


def test_a_cell_too_small_for_one_image_per_pair_is_refused():
    with pytest.raises(InputError, match="cell width"):
        cell_of([1e-3, 1e-3], [[0.001, 0.001], [0.003, 0.003]], 0.004, 0.02)


def test_a_pair_through_the_edge_moves_as_the_walled_engine_moves_it_in_the_open():
    """An oblique impact with spin (sliding, rolling and the dashpot all at work): the same pair in
    the walled engine (no walls, no gravity, no local damping) and through the periodic cell's
    x edge keep the same branch vector, velocities and spins step for step."""
    from poro2d.dem import Particles, Simulation

    r = np.array([1.0e-3, 1.3e-3])
    law = CellLaw(kn=KN, ks=KN, friction=0.3, rolling_friction=0.2, restitution=0.5)
    vel = np.array([[-0.2, 0.05], [0.3, -0.04]])  # closing along x, sliding along y
    omega = np.array([40.0, -25.0])
    particles = Particles(
        pos=np.array([[0.0100, 0.0100], [0.0100 - 0.00232, 0.0101]]),
        radius=r,
        density=np.full(2, RHO),
        thickness=T,
        kn=np.full(2, 2 * KN),
        ks=np.full(2, 2 * KN),
        mu=np.full(2, 0.3),
        vel=vel.copy(),
        omega=omega.copy(),
        mu_r=np.full(2, 0.2),
    )
    cell = cell_of(r, [[0.0004, 0.0100], [0.0004 - 0.00232 + 0.02, 0.0101]], law=law)
    sim = Simulation(particles, gravity=(0.0, 0.0), local_damping=0.0, restitution=0.5, dt=cell.dt)
    cell.vel[:] = vel
    cell.omega[:] = omega
    cell.hold()
    touched = 0
    for _ in range(60):
        sim.run(1)
        touched += cell.run(1).coordination > 0.0
        branch = cell.pos[1] - cell.pos[0] - [cell.width, 0.0]
        np.testing.assert_allclose(branch, sim.particles.pos[1] - sim.particles.pos[0], rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(cell.vel, sim.particles.vel, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(cell.omega, sim.particles.omega, rtol=1e-9, atol=1e-9)
    assert 5 < touched < 60  # they met and parted
    assert np.all(np.abs(cell.omega - omega) > 1.0)  # the contact turned both disks
