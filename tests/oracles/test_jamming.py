"""The frictionless jamming reference: energy, forces, FIRE, and phi_J against the literature."""

from __future__ import annotations

import math

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.grading import paper_grading
from poro2d.oracles.jamming import (
    E_ZERO,
    energy_and_forces,
    fire_minimise,
    jamming_fraction,
    jamming_reference,
)


def bidisperse(n: int) -> np.ndarray:
    """O'Hern's mixture: half the disks of diameter 1, half of diameter 1.4."""
    return np.where(np.arange(n) < n // 2, 0.5, 0.7)


def triangular_lattice(nx: int, ny: int, spacing: float) -> tuple[np.ndarray, tuple[float, float]]:
    """A triangular lattice filling a periodic rectangle exactly (``ny`` even)."""
    row = spacing * math.sqrt(3.0) / 2.0
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    x = spacing * (i + 0.5 * (j % 2))
    y = row * j
    return np.column_stack([x.ravel(), y.ravel()]).astype(float), (nx * spacing, ny * row)


# ----------------------------------------------------------------------------- energy and forces
def test_known_overlap_gives_the_analytic_energy_and_force():
    # radii 0.5 and 0.7 at centre distance 1.0: overlap 0.2, U = 0.2^2 / 2, force 0.2 along the line
    pos = np.array([[2.0, 3.0], [2.6, 3.8]])  # distance sqrt(0.36 + 0.64) = 1
    energy, force = energy_and_forces(pos, [0.5, 0.7], 10.0)
    assert energy == pytest.approx(0.02, rel=1e-12)
    np.testing.assert_allclose(force[1], 0.2 * np.array([0.6, 0.8]), rtol=1e-12)
    np.testing.assert_allclose(force[0], -force[1], rtol=1e-12)


def test_overlap_across_the_periodic_boundary_uses_the_nearest_image():
    pos = np.array([[0.1, 5.0], [9.2, 5.0]])  # 0.9 apart through the boundary x = 0 = 10
    energy, force = energy_and_forces(pos, [0.5, 0.5], 10.0)
    assert energy == pytest.approx(0.5 * 0.1**2, rel=1e-9)
    assert force[0, 0] == pytest.approx(0.1, rel=1e-9)  # pushed to +x, away from its image
    assert force[1, 0] == pytest.approx(-0.1, rel=1e-9)


def test_separated_disks_have_no_energy():
    energy, force = energy_and_forces([[1.0, 1.0], [2.3, 1.0]], [0.5, 0.7], 10.0)
    assert energy == 0.0
    assert not force.any()


def test_forces_are_minus_the_finite_difference_gradient():
    rng = np.random.default_rng(3)
    n, side = 40, 6.0  # packing fraction ~0.9: many overlaps
    radii = rng.uniform(0.35, 0.6, n)
    pos = rng.random((n, 2)) * side
    _, force = energy_and_forces(pos, radii, side)

    def energy(p):
        return energy_and_forces(p, radii, side)[0]

    h = 1e-6
    grad = np.empty_like(pos)
    for i in range(n):
        for a in range(2):
            up, down = pos.copy(), pos.copy()
            up[i, a] += h
            down[i, a] -= h
            grad[i, a] = (energy(up) - energy(down)) / (2 * h)
    np.testing.assert_allclose(force, -grad, atol=1e-7)
    assert np.abs(force).max() > 0.05  # the configuration really is loaded


def test_compressed_triangular_lattice_has_the_analytic_energy():
    # every disk overlaps its 6 neighbours by 2r - a: U = N * 6 / 2 * (2r - a)^2 / 2
    pos, box = triangular_lattice(6, 6, 1.0)
    r = 0.55
    n = pos.shape[0]
    assert n * math.pi * r * r / (box[0] * box[1]) > math.pi / (2 * math.sqrt(3))  # above close packing
    energy, force = energy_and_forces(pos, np.full(n, r), box)
    assert energy == pytest.approx(n * 3 * 0.5 * (2 * r - 1.0) ** 2, rel=1e-12)
    assert np.abs(force).max() < 1e-12  # balanced by symmetry


# ----------------------------------------------------------------------------- FIRE
def test_fire_separates_two_overlapping_disks_to_contact():
    # every separation >= r1 + r2 is a minimum (zero energy): FIRE stops on the first step after
    # the disks part, so they end at the contact distance plus that step's travel, a few
    # per cent of the initial overlap (here 0.0045 of 0.251)
    radii = np.array([0.5, 0.7])
    start = np.array([[10.0, 10.0], [10.9, 10.3]])
    overlap0 = radii.sum() - np.linalg.norm(start[1] - start[0])
    res = fire_minimise(start, radii, 20.0)
    assert res.status == "zero_energy"
    assert res.energy == 0.0
    gap = np.linalg.norm(res.positions[1] - res.positions[0]) - radii.sum()
    assert 0.0 <= gap < 0.05 * overlap0
    # the pair moved along its centre line, symmetrically (equal and opposite forces, masses 1 and 1.2)
    d = res.positions[1] - res.positions[0]
    assert d[1] / d[0] == pytest.approx(0.3 / 0.9, rel=1e-9)


def test_fire_returns_a_perturbed_lattice_to_the_lattice_energy():
    pos, box = triangular_lattice(6, 6, 1.0)
    n = pos.shape[0]
    r = np.full(n, 0.52)
    exact = n * 3 * 0.5 * (2 * 0.52 - 1.0) ** 2
    shaken = pos + np.random.default_rng(0).normal(scale=0.01, size=pos.shape)
    assert energy_and_forces(shaken, r, box)[0] > exact * 1.01
    res = fire_minimise(shaken, r, box, f_rel=1e-10)
    assert res.status == "force_balance"
    assert res.energy == pytest.approx(exact, rel=1e-9)


def test_fire_respects_max_steps():
    rng = np.random.default_rng(1)
    res = fire_minimise(rng.random((50, 2)) * 7.0, np.full(50, 0.5), 7.0, max_steps=3)
    assert res.steps == 3
    assert res.status == "max_steps"
    assert not res.converged


# ----------------------------------------------------------------------------- phi_J
@pytest.fixture(scope="module")
def bidisperse_1000():
    return jamming_fraction(bidisperse(1000), 0)


def test_bidisperse_jams_at_the_literature_fraction(bidisperse_1000):
    # O'Hern et al. 2003: phi_J = 0.842 for N -> infinity, about 0.84 at N ~ 1000
    res = bidisperse_1000
    assert res.converged
    assert 0.835 <= res.phi_j <= 0.850
    assert 0.0 < res.phi_j - res.phi_unjammed <= 2e-5
    assert res.energy_per_disk > E_ZERO
    assert res.pressure > 0.0


def test_bidisperse_jammed_state_is_isostatic(bidisperse_1000):
    # 2D frictionless: the rigid disks have 4 contacts each on average at jamming (2N' - 1 contacts)
    res = bidisperse_1000
    assert 3.98 < res.contact_number < 4.05
    assert 0 < res.n_rattlers < 0.1 * res.n_disks
    rigid = res.n_disks - res.n_rattlers
    assert 2 * rigid - 1 <= res.n_contacts <= 2 * rigid + 20


def test_same_seed_gives_the_same_result_bit_for_bit():
    radii = bidisperse(300)
    a = jamming_fraction(radii, 7)
    b = jamming_fraction(radii, 7)
    assert a.phi_j == b.phi_j
    assert a.fire_steps == b.fire_steps
    np.testing.assert_array_equal(a.positions, b.positions)
    assert jamming_fraction(radii, 8).phi_j != a.phi_j


def test_reference_of_a_grading_over_seeds():
    ref = jamming_reference(paper_grading(), n_disks=300, seeds=(0, 1))
    assert ref.converged
    assert len(ref.phi_j) == 2 and ref.phi_j[0] != ref.phi_j[1]
    assert all(250 <= n <= 350 for n in ref.n_disks)
    assert 0.83 < ref.mean < 0.87  # a mild grading (Cu = 1.7) jams near the bidisperse value
    assert ref.std > 0.0
    assert ref.porosity_mean == pytest.approx(1.0 - ref.mean)
    assert ref.mean == pytest.approx(np.mean(ref.phi_j))


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        (lambda: jamming_fraction([0.5, -0.1, 0.5], 0), "radii"),
        (lambda: jamming_fraction([[0.5, 0.5]], 0), "radii"),
        (lambda: jamming_fraction(["0.5", "0.5"], 0), "radii"),
        (lambda: jamming_fraction([0.5, 0.5, np.nan], 0), "radii"),
        (lambda: jamming_fraction(bidisperse(10), -1), "seed"),
        (lambda: jamming_fraction(bidisperse(10), 1.5), "seed"),
        (lambda: jamming_fraction(bidisperse(50), 0, tol=0.0), "tol"),
        (lambda: jamming_fraction(bidisperse(50), 0, phi_start=0.9), "phi_start"),
        (lambda: jamming_fraction(bidisperse(50), 0, max_steps=10), "max_steps"),
        (lambda: jamming_fraction(np.r_[np.full(50, 0.5), 8.0], 0), "radii"),  # one disk spans the cell
        (lambda: jamming_reference("paper", 100), "grading"),
        (lambda: jamming_reference(paper_grading(), 5), "n_disks"),
        (lambda: jamming_reference(paper_grading(), 100, seeds=()), "seeds"),
        (lambda: jamming_reference(paper_grading(), 100, seeds=(0, -2)), "seeds"),
        (lambda: energy_and_forces([[0.0, 0.0]], [0.5, 0.5], 10.0), "positions"),
        (lambda: energy_and_forces([[0, 0], [1, 1]], [0.5, 0.5], -1.0), "box"),
        (lambda: energy_and_forces([[0, 0], [1, 1]], [0.5, 0.5], 1.5), "box"),  # too small for min image
    ],
)
def test_bad_input_names_the_parameter(call, parameter):
    with pytest.raises(InputError) as err:
        call()
    assert err.value.parameter == parameter
