"""The model-discrepancy term (poro2d.calibration.discrepancy) on known surfaces (no DEM): a
laboratory the model cannot fit exactly (each value off its surface by a 10 % discrepancy) gets
intervals that hold the truth, where the noise covariance alone misses it; ``none`` is the
posterior of earlier versions; ``auto`` leaves poro2d's own laboratory files alone."""

import math

import numpy as np
import pytest

from poro2d.calibration import model
from poro2d.calibration.discrepancy import (
    SYNTHETIC_HEADER,
    Discrepancy,
    check_mode,
    made_by_poro2d,
    resolve_mode,
)
from poro2d.errors import InputError

RANGES = model.Ranges((0.3, 3.0), (0.0, 0.5))
TRUTH = (0.8, 0.2)
STRESSES = (50.0, 100.0, 200.0)
REPLICATES = 3


def _peak(s: float):
    return lambda x: s * (0.5 + 0.35 * x[:, 0] + 0.25 * x[:, 1] + 0.05 * x[:, 0] * x[:, 1])


def _rise(s: float):
    return lambda x: (0.3 + 0.6 * x[:, 0] - 0.15 * x[:, 1]) * (1.0 - 0.001 * s)


#: (surface, seed scatter sd, unit, observable name): peaks and rises at three stresses
OBSERVABLES = [(_peak(s), 0.04 * s, "kPa", "peak") for s in STRESSES] + [
    (_rise(s), 0.03, "mm", "dilation") for s in STRESSES
]


def _calibrate(repeat: int, discrepancy_sd: float, mode):
    """One calibration: a 12-point design with three noisy replicates, a laboratory off every
    surface at the truth by its seed scatter and a discrepancy of ``discrepancy_sd`` of its value."""
    rng = np.random.default_rng(1000 + repeat)
    bias = np.random.default_rng(repeat).normal(0.0, discrepancy_sd, len(OBSERVABLES))
    design = RANGES.to_unit(*np.array(model.space_filling(RANGES, 12, 0)).T)
    truth = RANGES.to_unit([TRUTH[0]], [TRUTH[1]])
    values = np.stack(
        [
            np.column_stack([f(design) + rng.normal(0.0, sd, len(design)) for _ in range(REPLICATES)])
            for f, sd, *_ in OBSERVABLES
        ],
        axis=1,
    )
    surrogates = [model.fit_surrogate(design, values[:, k]) for k in range(len(OBSERVABLES))]
    lab = []
    for (f, sd, *_), b in zip(OBSERVABLES, bias, strict=True):
        y = float(f(truth)[0])
        lab.append(y + rng.normal(0.0, sd) + b * abs(y))
    units = [u for _, _, u, _ in OBSERVABLES]
    cov = model.noise_covariance(surrogates, model.seed_covariance(values), lab, 0.0, units)
    cov = cov / model.precision_factor(12 * (REPLICATES - 1), len(OBSERVABLES))
    term = None if mode is None else Discrepancy.of(mode)
    return model.posterior(RANGES, surrogates, lab, cov, term)


def _holds(post) -> bool:
    fp, mu_r = post.interval("fp", 0.95), post.interval("mu_r", 0.95)
    return fp[0] <= TRUTH[0] <= fp[1] and mu_r[0] <= TRUTH[1] <= mu_r[1]


def test_a_discrepancy_the_model_cannot_fit_is_covered_only_with_the_term():
    repeats = range(20)
    alone = sum(_holds(_calibrate(r, 0.10, "none")) for r in repeats)
    with_term = [_calibrate(r, 0.10, "estimate") for r in repeats]
    held = sum(_holds(p) for p in with_term)
    assert held >= 18  # at least 90 % of 20 repeats
    assert alone <= 12  # the noise covariance alone misses: the test can tell them apart
    # the term's size is found near the discrepancy that was put in: 10 % of each value is 1.25
    # to 2.5 noise sd on the peaks (4 % of the stress) and 2 to 6 on the rises (0.03 mm)
    medians = [p.discrepancy_at(0.5) for p in with_term]
    assert 0.8 <= float(np.median(medians)) <= 3.0


def test_a_laboratory_the_model_fits_keeps_intervals_of_the_same_order():
    """No discrepancy put in: the term's posterior stays small and the intervals widen by less
    than half (the price of not knowing there is none; ``auto`` spares poro2d's own files it)."""
    for r in range(3):
        alone, with_term = _calibrate(r, 0.0, "none"), _calibrate(r, 0.0, "estimate")
        assert _holds(alone) and _holds(with_term)
        w0, w1 = (math.log(p.interval("fp", 0.95)[1] / p.interval("fp", 0.95)[0]) for p in (alone, with_term))
        assert w0 <= w1 < 1.6 * w0
        assert with_term.discrepancy_at(0.5) <= 1.5


def test_none_is_the_posterior_without_a_term_bit_for_bit():
    a, b = _calibrate(0, 0.1, None), _calibrate(0, 0.1, "none")
    assert np.array_equal(a.density, b.density)
    assert b.discrepancy is None and b.discrepancy_at(0.5) is None


def test_a_fixed_fraction_widens_the_intervals():
    alone, fixed = _calibrate(1, 0.0, "none"), _calibrate(1, 0.0, 1.0)
    lo0, hi0 = alone.interval("mu_r", 0.95)
    lo1, hi1 = fixed.interval("mu_r", 0.95)
    assert hi1 - lo1 > 1.2 * (hi0 - lo0)
    assert fixed.discrepancy_at(0.5) == pytest.approx(1.0)


def test_the_sampled_posterior_integrates_the_term_too():
    ranges = model.Ranges((0.3, 3.0), (0.0, 0.5), kn=(1e5, 1e7))
    surrogates = [model.Surrogate(np.array(c, float), 0.0, 0.0, 2) for c in _linear(3)]
    lab = [0.5, 0.5, 0.5, 0.9]  # the fourth observable cannot be met where the first three are
    cov = np.diag([0.02**2] * 4)
    post = model.sampled_posterior(
        ranges, surrogates, lab, cov, seed=2, discrepancy=Discrepancy.of("estimate")
    )
    assert post.discrepancy_weights is not None and post.discrepancy_weights.sum() == pytest.approx(1.0)
    assert post.discrepancy_at(0.5) > 1.0


def _linear(d: int) -> list[list[float]]:
    """Coefficients of four surrogates linear in the first d coordinates (the quadratic's feature
    order: 1, x_1..x_d, then the squares and products, zero here)."""
    n = model.n_coefficients(d)
    rows = []
    for k in range(4):
        c = [0.0] * n
        c[0] = 0.2
        c[1 + k % d] = 0.6
        rows.append(c)
    return rows


@pytest.mark.parametrize("mode", ["often", "-0.1", 0.0, 10.5, float("nan"), None])
def test_a_bad_mode_is_refused_by_name(mode):
    with pytest.raises(InputError, match="--discrepancy"):
        check_mode(mode)


def test_auto_leaves_poro2d_own_laboratory_files_alone(tmp_path):
    own = tmp_path / "own.csv"
    own.write_text(
        f"{SYNTHETIC_HEADER}, not measured: made by poro2d's own direct shear\nnormal_stress_kpa,x\n"
    )
    real = tmp_path / "real.csv"
    real.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,40\n")
    assert made_by_poro2d(own) and made_by_poro2d([str(own), own])
    assert not made_by_poro2d(real) and not made_by_poro2d([own, real]) and not made_by_poro2d([])
    assert resolve_mode("auto", own) == "none" and resolve_mode("auto", real) == "estimate"
    assert resolve_mode("AUTO", [own, real]) == "estimate" and resolve_mode("0.1", own) == 0.1


def test_the_record_says_saturated_when_the_interval_reaches_the_prior_top():
    """A laboratory far off every surface (300 % of its values) pushes the term's interval to the
    prior's top level, and the record says so; a laboratory the model fits does not."""
    from poro2d.calibration.discrepancy import discrepancy_record

    far = discrepancy_record(_calibrate(0, 3.0, "estimate"), 0.95)
    near = discrepancy_record(_calibrate(0, 0.0, "estimate"), 0.95)
    assert far.saturated and far.interval[1] == 4.0  # the top of the estimate prior
    assert not near.saturated
