"""Conversions of Eqs. 1-12 against values worked out by hand from the printed formulas.

The reference numbers were computed separately (a calculator session on the formulas, not
this package); the arithmetic is written next to each. Constants used below:
  s = sqrt(pi sqrt 3) = 2.3326805, s/2 = 1.1663402, s/sqrt 2 = 1.6494542
  FCC 3D porosity 1 - pi/(3 sqrt 2) = 0.2595195, simple cubic 1 - pi/6 = 0.4764012
  square 2D 1 - pi/4 = 0.2146018, hexagonal 2D 1 - pi/(2 sqrt 3) = 0.0931003
The paper's sand: n_max = 0.4571, n_min = 0.3253, test porosity n_lab = 0.3434.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poro2d import porosity as P
from poro2d.errors import InputError

N_MAX, N_MIN, N_LAB = 0.4571, 0.3253, 0.3434
TOL = 1e-6

# ---------------------------------------------------------------------------------------
# Lattice constants and helpers
# ---------------------------------------------------------------------------------------


def test_lattice_constants():
    assert P.SQUARE_2D == pytest.approx(0.2146018366, abs=1e-9)  # 1 - 0.7853981634
    assert P.HEXAGONAL_2D == pytest.approx(0.0931003179, abs=1e-9)  # 1 - 0.9068996821
    assert P.SIMPLE_CUBIC_3D == pytest.approx(0.4764012244, abs=1e-9)  # 1 - 0.5235987756
    assert P.FCC_3D == pytest.approx(0.2595195103, abs=1e-9)  # 1 - 0.7404804897
    # the printed 2D extremes are the rounded lattice values
    assert round(P.SQUARE_2D, 4) == P.N2D_MAX_PRINTED
    assert round(P.HEXAGONAL_2D, 4) == P.N2D_MIN_PRINTED


def test_void_ratio_round_trip():
    # 0.3434 / 0.6566 = 0.5229972586
    assert P.void_ratio(0.3434) == pytest.approx(0.5229972586, abs=1e-9)
    assert P.porosity_from_void_ratio(0.5229972586) == pytest.approx(0.3434, abs=1e-9)
    arr = np.array([[0.0, 0.25], [0.5, 0.75]])
    e = P.void_ratio(arr)
    assert e.shape == (2, 2)
    np.testing.assert_allclose(e, [[0.0, 1.0 / 3.0], [1.0, 3.0]])
    np.testing.assert_allclose(P.porosity_from_void_ratio(e), arr)
    with pytest.raises(InputError):
        P.porosity_from_void_ratio(-0.1)


def test_relative_density_paper_sand():
    # e_max = 0.4571/0.5429 = 0.8419598, e_min = 0.3253/0.6747 = 0.4821402,
    # e = 0.5229973 -> D_r = (0.8419598 - 0.5229973) / 0.3598196 = 0.8864513 (paper: 0.89)
    assert P.relative_density(N_LAB, N_MAX, N_MIN) == pytest.approx(0.8864513, abs=TOL)
    assert P.relative_density(N_MIN, N_MAX, N_MIN) == pytest.approx(1.0)
    assert P.relative_density(N_MAX, N_MAX, N_MIN) == pytest.approx(0.0)


def test_porosity_from_densities():
    # 1 - 1740 / 2650 = 1 - 0.6566038 = 0.3433962 -> 0.3434 rounded
    n = P.porosity_from_densities(1740.0, 2650.0)
    assert n == pytest.approx(0.3433962264, abs=1e-9)
    assert round(n, 4) == 0.3434
    arr = P.porosity_from_densities(np.array([1325.0, 2650.0]), 2650.0)
    np.testing.assert_allclose(arr, [0.5, 0.0])
    for rd, rs in ((2700.0, 2650.0), (0.0, 2650.0), (-1.0, 2650.0), (1740.0, 0.0)):
        with pytest.raises(InputError):
            P.porosity_from_densities(rd, rs)


# ---------------------------------------------------------------------------------------
# Each equation by hand
# ---------------------------------------------------------------------------------------


def test_eq1_densest_state():
    # 1.1663402 * 0.6566 = 0.7658190; ^(2/3) = 0.8370488; 1 - 0.8370488 = 0.1629512
    assert P.densest_state(N_LAB) == pytest.approx(0.1629512, abs=TOL)
    # 1.1663402 * 0.6 = 0.6998041; ^(2/3) = 0.7882264; -> 0.2117736
    assert P.densest_state(0.40) == pytest.approx(0.2117736, abs=TOL)


def test_eq1_maps_fcc_to_hexagonal():
    assert P.densest_state(P.FCC_3D) == pytest.approx(P.HEXAGONAL_2D, abs=1e-12)


def test_eq2_printed_reading():
    # nu = 0.3253 / 0.2595195 = 1.2534703; factor 1.1663402 / 1.2534703 = 0.9304889
    # 0.9304889 * 0.6566 = 0.6109590; ^(2/3) = 0.7200147 -> 0.2799853
    assert P.nu_factor(N_MIN, "printed") == pytest.approx(1.2534703, abs=TOL)
    assert P.densest_state_modified(N_LAB, N_MIN) == pytest.approx(0.2799853, abs=TOL)
    # 0.9304889 * 0.6 = 0.5582933 -> 1 - 0.5582933^(2/3) = 0.3219814
    assert P.densest_state_modified(0.40, N_MIN, "printed") == pytest.approx(0.3219814, abs=TOL)


def test_eq2_solid_fraction_reading():
    # nu = 0.6747 / 0.7404805 = 0.9111651; factor 1.1663402 / 0.9111651 = 1.2800536
    # 1.2800536 * 0.6566 = 0.8404832 -> 1 - 0.8404832^(2/3) = 0.1093932
    assert P.nu_factor(N_MIN, "solid_fraction") == pytest.approx(0.9111651, abs=TOL)
    assert P.densest_state_modified(N_LAB, N_MIN, "solid_fraction") == pytest.approx(0.1093932, abs=TOL)
    # 1.2800536 * 0.6 = 0.7680322 -> 0.1613393
    assert P.densest_state_modified(0.40, N_MIN, "solid_fraction") == pytest.approx(0.1613393, abs=TOL)
    # the solid-fraction reading maps the laboratory's densest state onto the hexagonal lattice
    assert P.densest_state_modified(N_MIN, N_MIN, "solid_fraction") == pytest.approx(
        P.HEXAGONAL_2D, abs=1e-12
    )


def test_eq2_with_nu_one_is_eq1():
    # nu = 1 in the printed reading when n_min equals the FCC porosity
    assert P.densest_state_modified(0.37, P.FCC_3D, "printed") == pytest.approx(
        P.densest_state(0.37), abs=1e-12
    )


def test_eq2_bad_reading_and_zero_nmin():
    with pytest.raises(InputError, match="nu_reading"):
        P.densest_state_modified(0.3, 0.3, "other")
    with pytest.raises(InputError, match="n_min"):
        P.densest_state_modified(0.3, 0.0, "printed")


def test_eq3_loosest_state():
    # 1.5 * 0.3434 - 0.5 = 0.5151 - 0.5 = 0.0151
    assert P.loosest_state(N_LAB) == pytest.approx(0.0151, abs=1e-12)
    # 1.5 * 0.40 - 0.5 = 0.1
    assert P.loosest_state(0.40) == pytest.approx(0.1, abs=1e-12)
    assert P.loosest_state(P.SIMPLE_CUBIC_3D) == pytest.approx(P.SQUARE_2D, abs=1e-12)


def test_eq4_interval_mapping():
    # 1.6494542 * 0.6566 = 1.0830316; ^(2/3) = 1.0546153 -> -0.0546153 (negative)
    assert P.interval_mapping(N_LAB) == pytest.approx(-0.0546153, abs=TOL)
    # 1.6494542 * 0.6 = 0.9896725 -> 1 - 0.9896725^(2/3) = 0.0068969
    assert P.interval_mapping(0.40) == pytest.approx(0.0068969, abs=TOL)
    # zero at 1 - sqrt2 / s = 1 - 0.6062612 = 0.3937388
    assert P.interval_mapping(0.3937388) == pytest.approx(0.0, abs=1e-6)


def test_eq5_combination():
    # D_r = 0.8864513; xi = 0.6062612 + 0.8864513 * (0.8573786 - 0.6062612) = 0.8288682
    # (0.6566 / 0.8288682)^(2/3) = 0.7921728^(2/3) = 0.8561376 -> 0.1438624
    assert P.combination_xi(N_LAB, N_MAX, N_MIN) == pytest.approx(0.8288682, abs=TOL)
    assert P.combination(N_LAB, N_MAX, N_MIN) == pytest.approx(0.1438624, abs=TOL)
    # n = 0.40: e = 0.6666667, D_r = (0.8419598 - 0.6666667)/0.3598196 = 0.4871696,
    # xi = 0.7286000; (0.6 / 0.7286)^(2/3) = 0.8785667 -> 0.1214333
    assert P.combination(0.40, N_MAX, N_MIN) == pytest.approx(0.1214333, abs=TOL)


def test_eq5_limits_as_stated_in_the_paper():
    # D_r = 0 (n_lab = n_max): Interval Mapping; D_r = 1 (n_lab = n_min): Densest State
    assert P.combination(N_MAX, N_MAX, N_MIN) == pytest.approx(P.interval_mapping(N_MAX), abs=1e-12)
    assert P.combination(N_MIN, N_MAX, N_MIN) == pytest.approx(P.densest_state(N_MIN), abs=1e-12)
    # the same for another pair of extremes
    assert P.combination(0.50, 0.50, 0.30) == pytest.approx(P.interval_mapping(0.50), abs=1e-12)
    assert P.combination(0.30, 0.50, 0.30) == pytest.approx(P.densest_state(0.30), abs=1e-12)


def test_eq5_undefined_far_beyond_n_max():
    # D_r very negative near n_lab -> 1 drives xi below zero: NaN, flagged by convert_all
    assert math.isnan(P.combination(0.99, N_MAX, N_MIN))
    r = P.convert_all(0.99, N_MAX, N_MIN).results["combination"]
    assert r.value is None and "undefined" in r.flags and r.warnings


def test_eqs6_7_lim_lab():
    # D = (0.4571 - 0.3434) / 0.1318 = 0.8626707; 0.2146 - 0.8626707 * 0.1215 = 0.1097855
    assert P.degree_of_density(N_LAB, N_MAX, N_MIN) == pytest.approx(0.8626707, abs=TOL)
    assert P.lim_lab(N_LAB, N_MAX, N_MIN) == pytest.approx(0.1097855, abs=TOL)
    # lattice exact: 0.2146018 - 0.8626707 * 0.1215015 = 0.1097860
    assert P.lim_lab(N_LAB, N_MAX, N_MIN, lattice_exact=True) == pytest.approx(0.1097860, abs=TOL)
    # n = 0.40: D = 0.0571 / 0.1318 = 0.4332322; 0.2146 - 0.4332322 * 0.1215 = 0.1619623
    assert P.lim_lab(0.40, N_MAX, N_MIN) == pytest.approx(0.1619623, abs=TOL)
    # end points
    assert P.lim_lab(N_MAX, N_MAX, N_MIN) == pytest.approx(0.2146, abs=1e-12)
    assert P.lim_lab(N_MIN, N_MAX, N_MIN) == pytest.approx(0.0931, abs=1e-12)
    assert round(P.lim_lab(N_LAB, N_MAX, N_MIN), 2) == 0.11  # paper, section 2.2


def test_lim_3d():
    # slope (0.2146018 - 0.0931003) / (0.4764012 - 0.2595195) = 0.1215015 / 0.2168817 = 0.5602202
    # 0.0931003 + 0.5602202 * (0.3434 - 0.2595195) = 0.0931003 + 0.0469915 = 0.1400919
    assert P.lim_3d(N_LAB) == pytest.approx(0.1400919, abs=TOL)
    assert round(P.lim_3d(N_LAB), 2) == 0.14  # paper, section 2.2
    # 0.0931003 + 0.5602202 * 0.1404805 = 0.1718003
    assert P.lim_3d(0.40) == pytest.approx(0.1718003, abs=TOL)
    assert P.lim_3d(P.FCC_3D) == pytest.approx(P.HEXAGONAL_2D, abs=1e-12)
    assert P.lim_3d(P.SIMPLE_CUBIC_3D) == pytest.approx(P.SQUARE_2D, abs=1e-12)


def test_eqs8_11_quasi_3d():
    # n'max = 1/3 + 2/3 * 0.2146 = 0.4764, n'min = 1/3 + 2/3 * 0.0931 = 0.3954
    q_max, q_min = P.quasi_3d_extremes(0.2146, 0.0931)
    assert q_max == pytest.approx(0.4764, abs=1e-12)
    assert q_min == pytest.approx(0.3954, abs=1e-12)
    # n' = 0.4764 - 0.8626707 * 0.081 = 0.4065237; 1.5 * 0.4065237 - 0.5 = 0.1097855
    assert P.quasi_3d(N_LAB, N_MAX, N_MIN) == pytest.approx(0.1097855, abs=TOL)


def test_eq12_parabola():
    # 0.42 * 0.3434^2 + 0.25 * 0.3434 = 0.42 * 0.11792356 + 0.08585 = 0.0495279 + 0.08585
    assert P.parabolic(N_LAB) == pytest.approx(0.1353779, abs=TOL)
    # 0.42 * 0.16 + 0.1 = 0.1672
    assert P.parabolic(0.40) == pytest.approx(0.1672, abs=1e-12)
    assert P.parabolic(0.0) == 0.0


def test_eq12_near_its_three_construction_points():
    # 0.42 * 0.2595195^2 + 0.25 * 0.2595195 = 0.0931670 (hexagonal 0.0931003: +6.7e-5)
    # 0.42 * 0.4764012^2 + 0.25 * 0.4764012 = 0.2144227 (square 0.2146018: -1.8e-4)
    assert P.parabolic(P.FCC_3D) - P.HEXAGONAL_2D == pytest.approx(6.67e-5, abs=1e-6)
    assert P.parabolic(P.SIMPLE_CUBIC_3D) - P.SQUARE_2D == pytest.approx(-1.79e-4, abs=1e-6)


# ---------------------------------------------------------------------------------------
# Shapes and validation
# ---------------------------------------------------------------------------------------

ALL_SINGLE = [P.densest_state, P.loosest_state, P.interval_mapping, P.lim_3d, P.parabolic]


@pytest.mark.parametrize("f", ALL_SINGLE)
def test_scalar_in_float_out_array_in_same_shape_out(f):
    assert isinstance(f(0.35), float)
    arr = np.full((3, 2), 0.35)
    out = f(arr)
    assert isinstance(out, np.ndarray) and out.shape == (3, 2)
    np.testing.assert_allclose(out, f(0.35))


@pytest.mark.parametrize("bad", [1.0, 1.2, -0.1, float("nan"), float("inf")])
def test_bad_porosity_raises(bad):
    for f in ALL_SINGLE:
        with pytest.raises(InputError) as exc:
            f(bad)
        assert exc.value.parameter == "n_lab"
        assert "[0.0, 1.0)" in str(exc.value)
    with pytest.raises(InputError):
        P.densest_state(np.array([0.3, bad]))


@pytest.mark.parametrize("n_max,n_min", [(0.3, 0.3), (0.3, 0.4), (1.0, 0.3), (0.4, -0.1)])
def test_bad_extremes_raise(n_max, n_min):
    for f in (P.combination, P.lim_lab, P.quasi_3d):
        with pytest.raises(InputError):
            f(0.35, n_max, n_min)
    with pytest.raises(InputError):
        P.convert_all(0.35, n_max, n_min)


# ---------------------------------------------------------------------------------------
# convert_all
# ---------------------------------------------------------------------------------------


def test_registry_order_and_metadata():
    assert list(P.METHODS) == [
        "densest_state",
        "densest_state_modified",
        "loosest_state",
        "interval_mapping",
        "combination",
        "lim_lab",
        "lim_3d",
        "quasi_3d",
        "parabolic",
    ]
    for m in P.METHODS.values():
        assert m.name and m.equation and m.source
    assert not P.METHODS["parabolic"].needs_extremes
    assert P.METHODS["combination"].needs == ("n_max", "n_min")
    assert P.METHODS["densest_state_modified"].needs == ("n_min",)


def test_convert_all_paper_sand():
    conv = P.convert_all(N_LAB, N_MAX, N_MIN)
    expected = {  # the hand values of the tests above
        "densest_state": 0.1629512,
        "densest_state_modified": 0.2799853,
        "loosest_state": 0.0151,
        "interval_mapping": -0.0546153,
        "combination": 0.1438624,
        "lim_lab": 0.1097855,
        "lim_3d": 0.1400919,
        "quasi_3d": 0.1097855,
        "parabolic": 0.1353779,
    }
    for k, v in expected.items():
        assert conv.results[k].value == pytest.approx(v, abs=TOL), k
    assert "negative" in conv.results["interval_mapping"].flags
    assert "decreasing" in conv.results["combination"].flags
    assert not any("extrapolated" in r.flags for r in conv.results.values())
    eq2 = conv.results["densest_state_modified"]
    assert eq2.details["nu_reading"] == "printed"
    assert eq2.details["other_reading"]["n2d"] == pytest.approx(0.1093932, abs=TOL)
    assert any("nu_reading = 'printed'" in n for n in conv.notes)


def test_convert_all_records_reading():
    conv = P.convert_all(N_LAB, N_MAX, N_MIN, nu_reading="solid_fraction", lattice_exact=True)
    eq2 = conv.results["densest_state_modified"]
    assert eq2.value == pytest.approx(0.1093932, abs=TOL)
    assert eq2.details["nu_reading"] == "solid_fraction"
    assert "nu=solid_fraction" in eq2.flags
    assert conv.results["lim_lab"].details["lattice_exact"] is True
    with pytest.raises(InputError):
        P.convert_all(N_LAB, N_MAX, N_MIN, nu_reading="guess")
    with pytest.raises(InputError):
        P.convert_all(N_LAB, N_MAX, N_MIN, unknown_option=1)


def test_convert_all_skips_without_extremes():
    conv = P.convert_all(N_LAB)
    for mid in ("densest_state_modified", "combination", "lim_lab", "quasi_3d"):
        r = conv.results[mid]
        assert r.value is None and r.skipped and "n_min" in r.skipped
    for mid in ("densest_state", "loosest_state", "interval_mapping", "lim_3d", "parabolic"):
        assert conv.results[mid].value is not None
    only_min = P.convert_all(N_LAB, n_min=N_MIN)
    assert only_min.results["densest_state_modified"].value is not None
    assert only_min.results["combination"].value is None


def test_convert_all_extrapolation_is_flagged_with_a_warning():
    conv = P.convert_all(0.30, N_MAX, N_MIN)
    for mid in ("combination", "lim_lab", "quasi_3d"):
        r = conv.results[mid]
        assert "extrapolated" in r.flags
        assert r.value is not None
        assert any("outside [n_min, n_max]" in w for w in r.warnings)
    assert "extrapolated" not in conv.results["parabolic"].flags
    assert "negative" in conv.results["loosest_state"].flags  # 1.5*0.3 - 0.5 = -0.05
    assert conv.results["loosest_state"].value == pytest.approx(-0.05, abs=1e-12)


def test_convert_all_rejects_bad_n_lab():
    for bad in (1.2, -0.1, float("nan")):
        with pytest.raises(InputError):
            P.convert_all(bad, N_MAX, N_MIN)


# ---------------------------------------------------------------------------------------
# Properties over the domain
# ---------------------------------------------------------------------------------------

porosity = st.floats(min_value=0.0, max_value=0.999, allow_nan=False)
in_range = st.floats(min_value=N_MIN, max_value=N_MAX, allow_nan=False)
INCREASING = ("densest_state", "loosest_state", "interval_mapping", "lim_3d", "parabolic")


@settings(max_examples=60, deadline=None)
@given(a=porosity, b=porosity)
def test_increasing_methods_are_monotone_over_the_whole_domain(a, b):
    lo, hi = min(a, b), max(a, b)
    for mid in INCREASING:
        f = getattr(P, mid)
        assert f(lo) <= f(hi) + 1e-12, mid
    for reading in P.NU_READINGS:
        assert (
            P.densest_state_modified(lo, N_MIN, reading)
            <= P.densest_state_modified(hi, N_MIN, reading) + 1e-12
        )


@settings(max_examples=60, deadline=None)
@given(a=porosity, b=porosity, lo_ext=st.floats(0.05, 0.6), width=st.floats(0.01, 0.35))
def test_lim_lab_and_quasi_3d_increase_and_agree(a, b, lo_ext, width):
    n_min, n_max = lo_ext, min(lo_ext + width, 0.99)
    lo, hi = min(a, b), max(a, b)
    assert P.lim_lab(lo, n_max, n_min) <= P.lim_lab(hi, n_max, n_min) + 1e-12
    assert P.quasi_3d(a, n_max, n_min) == pytest.approx(P.lim_lab(a, n_max, n_min), abs=1e-12)


@settings(max_examples=60, deadline=None)
@given(a=in_range, b=in_range)
def test_combination_decreases_over_the_paper_range(a, b):
    lo, hi = min(a, b), max(a, b)
    assert P.combination(lo, N_MAX, N_MIN) >= P.combination(hi, N_MAX, N_MIN) - 1e-12
    assert P.combination_slope_sign(a, N_MAX, N_MIN) == -1.0


@settings(max_examples=60, deadline=None)
@given(n=st.floats(0.01, 0.9), lo_ext=st.floats(0.1, 0.45), width=st.floats(0.02, 0.3))
def test_decreasing_flag_matches_a_finite_difference(n, lo_ext, width):
    n_min, n_max = lo_ext, lo_ext + width
    h = 1e-6
    f0 = P.combination(n - h, n_max, n_min)
    f1 = P.combination(n + h, n_max, n_min)
    if math.isnan(f0) or math.isnan(f1) or abs(f1 - f0) < 1e-10:
        return
    flagged = "decreasing" in P.convert_all(n, n_max, n_min).results["combination"].flags
    assert flagged == (f1 < f0)


@settings(max_examples=60, deadline=None)
@given(n=in_range)
def test_which_methods_can_be_negative_over_the_paper_range(n):
    conv = P.convert_all(n, N_MAX, N_MIN)
    for mid, r in conv.results.items():
        if mid in ("loosest_state", "interval_mapping"):
            continue
        assert r.value >= 0.0, mid
        assert "negative" not in r.flags
    for mid in ("loosest_state", "interval_mapping"):
        r = conv.results[mid]
        assert (r.value < 0.0) == ("negative" in r.flags)


def test_loosest_and_interval_mapping_do_go_negative_in_the_paper_range():
    x = np.linspace(N_MIN, N_MAX, 201)
    # loosest: 1.5 * 0.3253 - 0.5 = -0.01205 ; interval mapping negative below 0.3937
    assert P.loosest_state(x).min() == pytest.approx(-0.01205, abs=1e-12)
    assert (P.interval_mapping(x) < 0).mean() > 0.5
    assert P.loosest_state(x).max() > 0 and P.interval_mapping(x).max() > 0


@settings(max_examples=60, deadline=None)
@given(n=porosity)
def test_values_are_never_clipped(n):
    assert P.loosest_state(n) == pytest.approx(1.5 * n - 0.5, abs=1e-12)
    conv = P.convert_all(n)
    assert conv.results["loosest_state"].value == pytest.approx(1.5 * n - 0.5, abs=1e-12)
