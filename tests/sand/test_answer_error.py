"""The answer's standard error: the calibration's seeds carried through mu_prep, and the specimens'."""

import math

import numpy as np
import pytest

from poro2d.criterion.density import Calibration, friction_error, seed_errors, target_porosity_2d
from poro2d.sand.spread import AnswerError, interior_slope

MUS = [0.0, 0.05, 0.1, 1.0]


def _curve(mu):
    """A smooth mu_prep -> n' of the Toyoura calibration's shape (0.163 dense, 0.219 loose)."""
    return 0.163 + 0.056 * (1.0 - math.exp(-mu / 0.18)) / (1.0 - math.exp(-1.0 / 0.18))


def test_a_friction_with_one_seed_takes_the_pooled_spread():
    cal = Calibration(MUS, [[0.1630, 0.1632], [0.1720, 0.1730], [0.1780], [0.2190, 0.2210]])
    sd = np.array([0.0002, 0.001, 0.002]) / math.sqrt(2)  # the three frictions with two seeds
    pooled = math.sqrt(np.mean(sd**2))
    assert seed_errors(cal) == pytest.approx(
        [sd[0] / math.sqrt(2), sd[1] / math.sqrt(2), pooled, sd[2] / math.sqrt(2)]
    )
    lone = Calibration(MUS, [[0.163], [0.172], [0.178], [0.219]])
    assert np.isnan(seed_errors(lone)).all() and math.isnan(friction_error(0.8, lone))


def test_the_ends_alone_fix_the_friction_whatever_their_seeds():
    # with only the two ends, the target sits at nearly the same share between them whichever way
    # they move (the Dr mapping is linear in e, nearly so in n), so their sampling hardly moves mu_prep
    cal = Calibration([0.0, 1.0], [[0.1630, 0.1640], [0.2150, 0.2230]])
    assert friction_error(0.8, cal) < 0.1 * friction_error(0.8, Calibration(MUS, [[0.163, 0.164],
        [0.172, 0.173], [0.177, 0.179], [0.215, 0.223]]))  # fmt: skip


def test_the_friction_error_is_the_spread_of_repeated_calibrations():
    # calibrations drawn again and again from one true curve with seed noise: the spread of their
    # mu_prep is what one calibration's error estimates (mean square over the repeats)
    rng = np.random.default_rng(7)
    noise, dr, seeds = np.array([0.0001, 0.0008, 0.0012, 0.0015]), 0.8, 2
    mus_hat, errs = [], []
    for _ in range(1500):
        samples = [
            list(_curve(mu) + s * rng.standard_normal(seeds)) for mu, s in zip(MUS, noise, strict=True)
        ]
        cal = Calibration(MUS, samples)
        mus_hat.append(cal.mu_for(target_porosity_2d(dr, cal.n2d_max, cal.n2d_min)))
        errs.append(friction_error(dr, cal))
    spread = np.std(mus_hat, ddof=1)
    assert 0.001 < spread < 0.03  # a real spread to compare with: a few per cent of the bracket
    assert math.sqrt(np.mean(np.square(errs))) == pytest.approx(spread, rel=0.15)


def test_the_interior_slope_is_the_brackets_and_falls_back_on_the_fit():
    cal = Calibration(MUS, [[0.163, 0.163], [0.172, 0.173], [0.178, 0.177], [0.219, 0.220]])
    interior = [[0.157, 0.157], [0.167, 0.166], [0.171, 0.172], [0.213, None]]
    assert interior_slope(MUS, interior, 0.075, cal) == pytest.approx((0.1715 - 0.1665) / 0.05)
    assert interior_slope(MUS, interior, 0.05, cal) == pytest.approx((0.1715 - 0.1665) / 0.05)
    assert interior_slope(MUS, interior, 1.0, cal) == pytest.approx((0.213 - 0.1715) / 0.9)
    none = [[None, None]] * 4
    assert interior_slope(MUS, none, 0.075, cal) == pytest.approx((0.1775 - 0.1725) / 0.05)


def test_the_answers_error_adds_both_samplings():
    cal = Calibration(MUS, [[0.163, 0.1632], [0.172, 0.1735], [0.1775, 0.1795], [0.219, 0.221]])
    interior = [[0.157, 0.157], [0.167, 0.166], [0.171, 0.172], [0.213, 0.212]]
    inner = [0.1680, 0.1690, 0.1675]
    err = AnswerError.of(0.8, cal, MUS, interior, 0.07, inner)
    assert err.specimens_se == pytest.approx(np.std(inner, ddof=1) / math.sqrt(3))
    assert err.calibration_se == pytest.approx(err.interior_slope * err.mu_prep_se)
    assert err.answer_se == pytest.approx(math.hypot(err.specimens_se, err.calibration_se))
    assert err.calibration_se > err.specimens_se  # these seeds' calibration is the wider sampling
    assert "standard error" in err.text() and f"{err.answer_se:.4f}" in err.text()
    one = AnswerError.of(0.8, cal, MUS, interior, 0.07, inner[:1])
    assert one.answer_se is None and "n/a" in one.text()
    assert AnswerError.from_dict(err.to_dict()).to_dict() == err.to_dict()
