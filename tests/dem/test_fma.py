"""The kernels' fused multiply-add: one rounding, IEEE's fusedMultiplyAdd, in compiled code."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from numba import njit

from poro2d.dem.fma import fma


@njit(cache=True)
def _fused(a, b, c):
    return fma(a, b, c)


def _exact(a: float, b: float, c: float) -> float:
    """``a * b + c`` computed exactly, then rounded once to the nearest double."""
    return float(Fraction(a) * Fraction(b) + Fraction(c))


def test_one_rounding_where_two_lose_the_result():
    # (1 + 2^-30)(1 - 2^-30) - 1 = -2^-60 exactly; the product alone rounds to 1.0
    a, b = 1.0 + 2.0**-30, 1.0 - 2.0**-30
    assert a * b - 1.0 == 0.0
    assert _fused(a, b, -1.0) == -(2.0**-60)


def test_random_operands_round_as_the_exact_value_does():
    rng = np.random.default_rng(3)
    x = rng.normal(0.0, 1.0, (2000, 3)) * 10.0 ** rng.integers(-8, 8, (2000, 3))
    for a, b, c in x.tolist():
        assert _fused(a, b, c) == _exact(a, b, c)


def test_special_values_pass_through():
    assert np.isnan(_fused(np.nan, 1.0, 0.0))
    assert _fused(np.inf, 2.0, 1.0) == np.inf
    assert np.isnan(_fused(np.inf, 0.0, 1.0))


def test_only_doubles():
    @njit
    def ints(a, b, c):
        return fma(a, b, c)

    with pytest.raises(Exception, match="fma"):
        ints(1, 2, 3)
