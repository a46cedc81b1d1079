"""The d-parameter surrogate and the emcee posterior against what is known exactly: a quadratic
fitted to its own values, and a Gaussian likelihood whose posterior is a known Gaussian."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import norm

from poro2d.calibration import model

RANGES = {
    3: model.Ranges((0.3, 3.0), (0.0, 0.5), kn=(1e5, 1e7)),
    4: model.Ranges((0.3, 3.0), (0.0, 0.5), kn=(1e5, 1e7), ks=(1e4, 1e7)),
}


@pytest.mark.parametrize("d", [2, 3, 4])
def test_the_quadratic_in_d_coordinates_recovers_its_coefficients(d):
    rng = np.random.default_rng(d)
    unit = rng.random((40, d))
    n = model.n_coefficients(d)
    assert n == {2: 6, 3: 10, 4: 15}[d]
    truth = rng.normal(size=n)
    features = model.Surrogate(truth, 0.0, 0.0, 1).mean(unit)
    # the same function built term by term: 1, x_i, then x_i x_j for i <= j
    by_hand = truth[0] + unit @ truth[1 : d + 1]
    k = d + 1
    for i in range(d):
        for j in range(i, d):
            by_hand += truth[k] * unit[:, i] * unit[:, j]
            k += 1
    np.testing.assert_allclose(features, by_hand, rtol=1e-12)
    fitted = model.fit_surrogate(unit, np.column_stack([by_hand, by_hand]))
    np.testing.assert_allclose(fitted.coefficients, truth, atol=1e-9)
    assert fitted.residual < 1e-9 and fitted.scatter == 0.0


def linear_surrogates(d: int) -> list[model.Surrogate]:
    """One observable per coordinate, equal to it: the likelihood is the laboratory's Gaussian."""
    out = []
    for j in range(d):
        c = np.zeros(model.n_coefficients(d))
        c[1 + j] = 1.0
        out.append(model.Surrogate(c, 0.0, 0.0, 3))
    return out


@pytest.mark.parametrize("d", [3, 4])
def test_the_sampled_posterior_of_a_gaussian_has_its_medians_intervals_and_correlation(d):
    ranges = RANGES[d]
    mean = np.array([0.45, 0.55, 0.5, 0.4][:d])
    sd = np.array([0.06, 0.08, 0.07, 0.05][:d])
    rho = 0.6  # between the first two coordinates
    cov = np.diag(sd**2)
    cov[0, 1] = cov[1, 0] = rho * sd[0] * sd[1]
    post = model.sampled_posterior(ranges, linear_surrogates(d), mean, cov, seed=3)
    # the posterior is the Gaussian N(mean, cov) (beyond 5 sd of the cube's faces: untruncated)
    assert post.steps - post.burn_in >= model.AUTOCORR_MULTIPLE * max(post.autocorrelation)
    effective = len(post.chain) / max(post.autocorrelation)
    median_error = 1.2533 / np.sqrt(effective)  # the sample median's sd, in sd of the marginal
    tail_error = np.sqrt(0.025 * 0.975) / norm.pdf(1.96) / np.sqrt(effective)
    for k, axis in enumerate(ranges.axes):
        x = post.chain[:, k]
        assert abs(np.median(x) - mean[k]) < 4 * median_error * sd[k]
        lo, hi = np.quantile(x, [0.025, 0.975])
        assert abs(lo - (mean[k] - 1.96 * sd[k])) < 4 * tail_error * sd[k]
        assert abs(hi - (mean[k] + 1.96 * sd[k])) < 4 * tail_error * sd[k]
        # the interval in parameter values is the chain's quantiles mapped through the axis
        values = ranges.axis_values(axis, np.array([lo, hi]))
        np.testing.assert_allclose(post.interval(axis, 0.95), values, rtol=1e-12)
    assert abs(post.correlation() - rho) < 0.1


def test_the_same_seed_gives_the_same_chain_bit_for_bit_and_another_seed_another():
    args = (RANGES[3], linear_surrogates(3), [0.5, 0.5, 0.5], np.diag([0.01, 0.01, 0.01]))
    a, b = model.sampled_posterior(*args, seed=7), model.sampled_posterior(*args, seed=7)
    assert np.array_equal(a.chain, b.chain) and np.array_equal(a.log_prob, b.log_prob)
    assert not np.array_equal(a.chain, model.sampled_posterior(*args, seed=8).chain)


def test_a_chain_too_short_for_its_autocorrelation_is_refused(monkeypatch):
    monkeypatch.setattr(model, "MAX_CHAIN_STEPS", 40)
    args = (RANGES[3], linear_surrogates(3), [0.5, 0.5, 0.5], np.diag([0.01, 0.01, 0.01]))
    with pytest.raises(RuntimeError, match="autocorrelation times"):
        model.sampled_posterior(*args, seed=1, steps=40)


def test_the_second_rounds_draws_are_distinct_chain_samples_in_the_ranges():
    ranges = RANGES[4]
    post = model.sampled_posterior(ranges, linear_surrogates(4), [0.5] * 4, np.diag([0.02] * 4), seed=2)
    drawn = post.draw(10, seed=3)
    assert len(drawn) == len(set(drawn)) == 10 and all(len(p) == 4 for p in drawn)
    for point in drawn:
        for value, axis in zip(point, ranges.axes, strict=True):
            lo, hi = getattr(ranges, axis)
            assert lo <= value <= hi


def test_a_latin_hypercube_in_four_coordinates_fills_every_axis():
    ranges = RANGES[4]
    design = model.space_filling(ranges, 20, seed=0)
    unit = ranges.to_unit(*zip(*design, strict=True))
    assert unit.shape == (20, 4)
    # one point per stratum of 1/20 along every axis (rounding to 4 digits moves none across)
    for k in range(4):
        assert sorted(np.floor(unit[:, k] * 20).astype(int)) == list(range(20))
