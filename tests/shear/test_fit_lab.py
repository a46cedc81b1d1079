"""Mohr-Coulomb fits, the smoothed peak and laboratory CSV input (no simulation)."""

import math

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.shear import LabData, inertial_number, mohr_coulomb, peak, read_lab_csv, smooth


def test_fit_recovers_an_exact_line():
    s = np.array([50.0, 100.0, 200.0])
    f = mohr_coulomb(s, 10.0 + s * math.tan(math.radians(35.0)))
    assert f.friction_angle_deg == pytest.approx(35.0)
    assert f.cohesion_kpa == pytest.approx(10.0)
    assert f.r2 == pytest.approx(1.0)
    f0 = mohr_coulomb(s, s * 0.7, through_origin=True)
    assert f0.cohesion_kpa == 0.0 and f0.tan_phi == pytest.approx(0.7) and f0.r2 == pytest.approx(1.0)


def test_fit_least_squares_and_errors():
    s = np.array([50.0, 100.0, 200.0])
    t = np.array([40.0, 80.0, 150.0])
    f = mohr_coulomb(s, t)
    slope, c = np.polyfit(s, t, 1)
    assert f.tan_phi == pytest.approx(slope) and f.cohesion_kpa == pytest.approx(c)
    assert 0.9 < f.r2 < 1.0
    with pytest.raises(InputError, match="normal stresses"):
        mohr_coulomb([100.0, 100.0], [50.0, 60.0])
    with pytest.raises(InputError):
        mohr_coulomb([100.0], [50.0, 60.0])


def test_smoothing_and_peak():
    x = np.linspace(0, 0.01, 201)
    y = np.sin(np.pi * x / 0.01) * 100 + np.where(np.arange(201) == 60, 50.0, 0.0)  # one spike
    k, xp, yp = peak(x, y, 0.002)
    assert xp == pytest.approx(0.005, abs=2e-4)  # the spike does not move the smoothed peak
    assert yp < 100
    assert np.array_equal(smooth(x, y, 0.0), y)
    assert smooth(x, np.full(201, 3.0), 0.002) == pytest.approx(3.0)


def test_inertial_number():
    # I = v / k sqrt(rho / sigma): 0.025 m/s, k = 10, 2650 kg/m3, 50 kPa
    assert inertial_number(0.025, 50e3, 2650.0, 10.0) == pytest.approx(0.0025 * math.sqrt(0.053))
    assert inertial_number(0.025, 0.0, 2650.0, 10.0) == math.inf


def test_lab_curves(tmp_path):
    p = tmp_path / "lab.csv"
    p.write_text(
        "# comment\nnormal_stress_kpa,shear_displacement_mm,shear_stress_kpa,note\n"
        "50,0,0,a\n50,1,35,b\n50,2,30,c\n50,3,29,d\n50,4,28,e\n"
        "100,0,0,f\n100,1,40,g\n100,2,60,h\n100,3,70,i\n100,4,66,j\n"
    )
    lab = read_lab_csv(p)
    assert lab.kind == "curves" and lab.normal_stresses() == [50.0, 100.0]
    assert lab.peaks == {50.0: 35.0, 100.0: 70.0}
    d, t = lab.curves[50.0]
    assert np.allclose(d, [0.0, 0.001, 0.002, 0.003, 0.004]) and np.allclose(t, [0, 35, 30, 29, 28])  # in m


LAB_CURVES = "normal_stress_kpa,shear_displacement_mm,shear_stress_kpa\n"


@pytest.mark.parametrize(
    ("body", "words"),
    [
        ("50,0,0\n50,2,30\n50,1,35\n50,3,30\n50,4,30\n", ["line 4", "shear_displacement_mm", "rises"]),
        ("50,0,0\n50,1,30\n50,1,30\n50,2,30\n50,3,30\n", ["line 4", "rises"]),  # a repeated row
        ("50,0,0\n50,1,30\n", ["curve at 50 kPa", "at least 5 readings"]),
        ("50,0,0\n50,1,0\n50,2,0\n50,3,0\n50,4,0\n", ["the curve's peak", "(0, 2.5]"]),
        ("50,0,0\n50,1,300\n50,2,0\n50,3,0\n50,4,0\n", ["line 3", "(0, 2.5]", "strong"]),
        ("50000,0,0\n50000,1,3\n50000,2,3\n50000,3,3\n50000,4,3\n", ["normal_stress_kpa", "in kPa"]),
        ("50,0,0\n50,1,1_000\n50,2,3\n50,3,3\n50,4,3\n", ["line 3", "1_000", "a number"]),
        # absurd magnitudes, each named by file, line and column
        ("50,0,0\n50,1,30\n50,2,30\n50,3,30\n50,1e300,30\n", ["line 6, column 2", "[0, 300] mm", "in mm?"]),
        ("50,0,0\n50,1,30\n50,2,30\n50,3,30\n50,4,1e300\n", ["line 6, column 3", "strong"]),
        ("50,0,0\n50,1,30\n50,2,-30\n50,3,30\n50,4,30\n", ["line 4, column 3", "-0.1 times", "(-5 kPa)"]),
        ("50,0,0\n50,1,30\n50,2,inf\n50,3,30\n50,4,30\n", ["line 4, column 3", "a finite number"]),
        ("50,0,0\n50,1,30\n50,2,nan\n50,3,30\n50,4,30\n", ["line 4, column 3", "a finite number"]),
        ("50,0,0\n50,0,0\n50,0,0\n50,0,0\n50,0,0\n", ["line 3, column 2", "rises"]),  # all zero
    ],
)
def test_lab_curves_that_cannot_be_right_are_refused(tmp_path, body, words):
    p = tmp_path / "lab.csv"
    p.write_text(LAB_CURVES + body)
    with pytest.raises(InputError) as e:
        read_lab_csv(p)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


@pytest.mark.parametrize(
    ("body", "words"),
    [
        ("50,0\n100,70\n", ["line 2", "peak_shear_stress_kpa", "weak"]),
        ("50,500\n100,70\n", ["line 2", "(0, 2.5]", "strong"]),
        ("50,1e300\n100,70\n", ["line 2", "strong"]),
        ("0,10\n100,70\n", ["normal_stress_kpa", "[1, 1000] kPa"]),
    ],
)
def test_lab_peaks_that_cannot_be_right_are_refused(tmp_path, body, words):
    p = tmp_path / "lab.csv"
    p.write_text("normal_stress_kpa,peak_shear_stress_kpa\n" + body)
    with pytest.raises(InputError) as e:
        read_lab_csv(p)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_a_curve_of_the_largest_displacement_accepted_is_read(tmp_path):
    """300 mm, the bound, is read (and kept in m); the refusals above are the bound's other side."""
    p = tmp_path / "lab.csv"
    p.write_text(LAB_CURVES + "50,0,0\n50,100,30\n50,200,35\n50,250,30\n50,300,30\n")
    d, t = read_lab_csv(p).curves[50.0]
    assert d[-1] == pytest.approx(0.3) and t.max() == 35.0


@pytest.mark.parametrize(
    ("peaks", "curves", "words"),
    [
        ({50.0: 1e300}, {}, ["the peak at 50 kPa", "strong"]),
        ({50.0: 0.0}, {}, ["the peak at 50 kPa", "weak"]),
        ({5e6: 10.0}, {}, ["the peak at 5e+06 kPa", "[1, 1000] kPa"]),
        ({}, {}, ["at least one normal stress"]),
        ({50.0: "40"}, {}, ["finite numbers"]),
        ({50.0: float("nan")}, {}, ["finite numbers"]),
        (
            {50.0: 30.0},
            {50.0: (np.array([0.0, 1e-3]), np.array([0.0, 30.0]))},
            ["curve at 50 kPa", "5 readings"],
        ),
        (
            {50.0: 30.0},
            {50.0: (np.array([0, 1, 1, 2, 3]) * 1e-3, np.array([0, 30, 30, 20, 20.0]))},
            ["repeats"],
        ),
        ({50.0: 30.0}, {50.0: (np.array([0, 1, 2, 3, 1e300]), np.array([0, 30, 30, 20, 20.0]))}, ["0.3] m"]),
        (
            {50.0: 31.0},
            {50.0: (np.arange(5) * 1e-3, np.array([0, 30, 30, 20, 20.0]))},
            ["largest reading 30"],
        ),
    ],
)
def test_lab_data_made_in_python_pass_the_files_checks(peaks, curves, words):
    """A calibration or a series handed LabData is held to what a CSV is held to."""
    with pytest.raises(InputError) as e:
        LabData("mine", peaks, curves)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_lab_peaks(tmp_path):
    p = tmp_path / "lab.csv"
    p.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,38\n100,72\n200,141\n")
    lab = read_lab_csv(p)
    assert lab.kind == "peaks" and lab.peaks[200.0] == 141.0


def test_a_lab_file_with_a_byte_order_mark_is_read(tmp_path):
    """Spreadsheets save UTF-8 CSV with a byte order mark: the header must still be found."""
    p = tmp_path / "lab.csv"
    p.write_bytes(b"\xef\xbb\xbf" + b"normal_stress_kpa,peak_shear_stress_kpa\r\n50,38\r\n100,72\r\n")
    lab = read_lab_csv(p)
    assert lab.kind == "peaks" and lab.peaks == {50.0: 38.0, 100.0: 72.0}


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("sigma,tau\n50,40\n", "lab columns"),
        ("normal_stress_kpa,peak_shear_stress_kpa\n50,abc\n", "peak_shear_stress_kpa"),
        ("normal_stress_kpa,peak_shear_stress_kpa\n-50,40\n", "normal_stress_kpa"),
        ("normal_stress_kpa,shear_displacement_mm,shear_stress_kpa\n50,1,-6\n", "shear_stress_kpa"),
        ("normal_stress_kpa,peak_shear_stress_kpa\n", "data row"),
        ("normal_stress_kpa,peak_shear_stress_kpa\n50,40\n50,41\n", "once"),
    ],
)
def test_lab_errors(tmp_path, text, needle):
    p = tmp_path / "lab.csv"
    p.write_text(text)
    with pytest.raises(InputError, match=needle):
        read_lab_csv(p)


def test_lab_missing_file(tmp_path):
    with pytest.raises(InputError, match="lab"):
        read_lab_csv(tmp_path / "none.csv")


def test_a_curve_may_dip_below_zero_at_its_start_as_a_test_does(tmp_path):
    # the first readings of a direct shear test (poro2d's own too) can be a little below zero
    p = tmp_path / "lab.csv"
    p.write_text(
        "normal_stress_kpa,shear_displacement_mm,shear_stress_kpa\n"
        "100,0.05,-4.9\n100,0.1,-0.5\n100,0.5,30\n100,1,55\n100,2,60\n"
    )
    lab = read_lab_csv(p)
    assert lab.peaks == {100.0: 60.0} and lab.curves[100.0][1][0] == -4.9
    p.write_text(p.read_text().replace("-4.9", "-10.1"))
    with pytest.raises(InputError, match="line 2, column 3"):
        read_lab_csv(p)
