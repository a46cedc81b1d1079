"""The optional column of a laboratory curves CSV: the top plate's vertical displacement (mm,
positive: dilation), kept per normal stress in m, refused with file, line and column when it
cannot be right; files without it read as before (no simulation)."""

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.shear import LabData, read_lab_csv

HEADER = "normal_stress_kpa,shear_displacement_mm,shear_stress_kpa,vertical_displacement_mm\n"
GOOD = (
    "50,0,0,0\n50,1,35,-0.02\n50,2,30,0.05\n50,3,29,0.11\n50,4,28,0.12\n"
    "100,0,0,0\n100,1,40,-0.04\n100,2,60,-0.01\n100,3,70,0.03\n100,4,66,0.05\n"
)


def test_the_plates_rise_is_kept_per_curve_in_metres(tmp_path):
    p = tmp_path / "lab.csv"
    p.write_text(HEADER + GOOD)
    lab = read_lab_csv(p)
    assert lab.kind == "curves" and sorted(lab.vertical) == [50.0, 100.0]
    assert np.allclose(lab.vertical[50.0], [0.0, -2e-5, 5e-5, 1.1e-4, 1.2e-4])
    assert np.allclose(lab.vertical[100.0], [0.0, -4e-5, -1e-5, 3e-5, 5e-5])
    # the other columns read as in a file without the column
    plain = tmp_path / "plain.csv"
    plain.write_text(
        HEADER.rsplit(",", 1)[0] + "\n" + "".join(ln.rsplit(",", 1)[0] + "\n" for ln in GOOD.split())
    )
    without = read_lab_csv(plain)
    assert without.vertical == {} and without.peaks == lab.peaks
    for s in lab.curves:
        assert all(np.array_equal(a, b) for a, b in zip(lab.curves[s], without.curves[s], strict=True))


def test_a_peaks_file_ignores_the_column(tmp_path):
    p = tmp_path / "peaks.csv"
    p.write_text("normal_stress_kpa,peak_shear_stress_kpa,vertical_displacement_mm\n50,38,0.1\n100,72,0.2\n")
    lab = read_lab_csv(p)
    assert lab.kind == "peaks" and lab.vertical == {}


@pytest.mark.parametrize(
    ("row", "words"),
    [
        ("50,4,28,250", ["line 6, column 4", "vertical_displacement_mm", "[-100, 100] mm", "in mm?"]),
        ("50,4,28,-1e300", ["line 6, column 4", "[-100, 100] mm"]),
        ("50,4,28,nan", ["line 6, column 4", "a finite number"]),
        ("50,4,28,inf", ["line 6, column 4", "a finite number"]),
        ("50,4,28,up", ["line 6, column 4", "a number"]),
        ("50,4,28,", ["line 6, column 4", "a number"]),
    ],
)
def test_a_rise_that_cannot_be_right_is_refused_with_its_line_and_column(tmp_path, row, words):
    p = tmp_path / "lab.csv"
    p.write_text(HEADER + "50,0,0,0\n50,1,35,0.01\n50,2,30,0.02\n50,3,29,0.03\n" + row + "\n")
    with pytest.raises(InputError) as e:
        read_lab_csv(p)
    for w in words:
        assert w in str(e.value) and "lab.csv" in str(e.value), (w, str(e.value))


def test_the_bound_itself_is_read(tmp_path):
    p = tmp_path / "lab.csv"
    p.write_text(HEADER + "50,0,0,0\n50,1,35,-100\n50,2,30,100\n50,3,29,0\n50,4,28,0\n")
    assert read_lab_csv(p).vertical[50.0][1:3] == pytest.approx([-0.1, 0.1])


CURVE = (np.arange(5) * 1e-3, np.array([0, 30, 30, 20, 20.0]))


@pytest.mark.parametrize(
    ("vertical", "words"),
    [
        ({50.0: np.zeros(4)}, ["vertical displacement at 50 kPa", "one reading per reading"]),
        ({50.0: np.array([0, 0, np.nan, 0, 0])}, ["vertical displacement at 50 kPa", "finite"]),
        ({50.0: np.array([0, 0, 0.2, 0, 0])}, ["within +-0.1 m"]),
        ({100.0: np.zeros(5)}, ["lab vertical", "one per curve"]),
        ([0.0], ["lab vertical", "a dict"]),
    ],
)
def test_lab_data_made_in_python_is_held_to_the_same_bounds(vertical, words):
    with pytest.raises(InputError) as e:
        LabData("mine", {50.0: 30.0}, {50.0: CURVE}, vertical)
    for w in words:
        assert w in str(e.value), (w, str(e.value))
    assert LabData("mine", {50.0: 30.0}, {50.0: CURVE}, {50.0: np.full(5, 1e-4)}).vertical[50.0][0] == 1e-4
