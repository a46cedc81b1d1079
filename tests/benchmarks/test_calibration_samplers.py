"""benchmarks/calibration_samplers.py: the grid path and its synthetic surfaces (no optional package
needed); emcee's agreement with the grid only where emcee imports."""

import sys
from pathlib import Path

import numpy as np
import pytest

from poro2d.calibration import model

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

import calibration_samplers as cs  # noqa: E402


def grid_points():
    u = np.linspace(0.0, 1.0, model.GRID)
    uu, vv = np.meshgrid(u, u)
    return np.column_stack([uu.ravel(), vv.ravel()])


def test_the_samplers_likelihood_is_poro2ds_on_its_grid():
    problem = cs.synthetic_two(seed=3)
    ranges = model.Ranges((0.3, 3.0), (0.0, 0.5))
    density = model.posterior(ranges, problem.surrogates, problem.lab, problem.cov).density
    log_like = problem.log_likelihood(grid_points())
    ours = np.exp(log_like - log_like.max()).reshape(density.shape)
    np.testing.assert_allclose(ours / ours.sum(), density, rtol=1e-9, atol=1e-15)
    assert problem.evaluations == model.GRID**2


def test_the_grid_of_any_dimension_reads_the_marginals_as_poro2ds_grid():
    problem = cs.synthetic_two(seed=1)
    ours, per_eval = cs.grid_any(problem, model.GRID)
    poro2d = cs.grid_two(problem)
    for a, b in ((ours.median, poro2d.median), (ours.low, poro2d.low), (ours.high, poro2d.high)):
        np.testing.assert_allclose(a, b, atol=1e-9)
    assert ours.correlation == pytest.approx(poro2d.correlation, abs=1e-9)
    assert per_eval > 0.0


def test_a_narrow_synthetic_surface_is_recovered_within_its_intervals():
    problem = cs.synthetic_two(seed=0, scatter_kpa=1.0)
    grid = cs.grid_two(problem)
    assert np.all(grid.low <= problem.truth) and np.all(problem.truth <= grid.high)
    assert np.all(grid.high - grid.low < 0.25)  # a quarter of each range: the data identify the pair
    wide = cs.grid_two(cs.synthetic_two(seed=0, scatter_kpa=8.0))
    assert np.all(wide.high - wide.low > grid.high - grid.low)  # more specimen noise, wider intervals


def test_the_quadratic_in_any_dimension_is_poro2ds_surrogate_in_two():
    rng = np.random.default_rng(5)
    unit = rng.uniform(size=(14, 2))
    values = 50.0 + 30.0 * unit[:, :1] - 20.0 * unit[:, 1:] ** 2 + rng.normal(0.0, 3.0, (14, 3))
    coefficients, terms = cs.fit_quadratic(unit, values)
    surrogate = model.fit_surrogate(unit, values)
    probe = rng.uniform(size=(7, 2))
    np.testing.assert_allclose(cs.quadratic_features(probe) @ coefficients, surrogate.mean(probe), rtol=1e-10)
    assert terms.residual == pytest.approx(surrogate.residual, rel=1e-10)
    assert terms.replicates == surrogate.replicates


def test_without_the_optional_packages_the_grid_still_answers(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "emcee", None)  # import emcee raises ImportError
    monkeypatch.setitem(sys.modules, "grainlearning", None)
    cs.main([])
    out = capsys.readouterr().out
    assert "emcee is not importable" in out and "grainlearning is not importable" in out
    assert "grid 161x161" in out and "truth: f_p" in out


def test_emcee_agrees_with_the_grid_within_two_grid_steps():
    emcee = pytest.importorskip("emcee")
    problem = cs.synthetic_two(seed=0)
    grid = cs.grid_two(problem)
    chain = cs.run_emcee(emcee, problem, walkers=32, steps=4000, seed=0)
    step = 1.0 / (model.GRID - 1)
    for a, b in ((chain.median, grid.median), (chain.low, grid.low), (chain.high, grid.high)):
        assert np.max(np.abs(a - b)) < 2.0 * step
