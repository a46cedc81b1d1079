"""Laboratory biaxial curves are read by the one laboratory reader (poro2d.lab_table) and held
to physical bounds: each refusal names file, line and column, before any test runs."""

import math

import numpy as np
import pytest

from poro2d.biaxial.lab import MAX_SIN_PHI, LabCurve, read_lab_curve
from poro2d.errors import InputError

HEAD = "axial_strain,stress_ratio,volumetric_strain\n"
GOOD = "0,0,0\n0.01,0.3,0.001\n0.02,0.45,-0.002\n0.05,0.4,-0.01\n0.1,0.35,-0.02\n"


def _write(tmp_path, text: str, bom: bool = False):
    p = tmp_path / "lab.csv"
    p.write_bytes((b"\xef\xbb\xbf" if bom else b"") + text.encode())
    return p


def test_a_valid_curve_is_read_with_or_without_a_byte_order_mark(tmp_path):
    for bom in (False, True):
        lab = read_lab_curve(_write(tmp_path, HEAD + GOOD, bom))
        assert np.array_equal(lab.axial_strain, [0, 0.01, 0.02, 0.05, 0.1])
        assert lab.peak_friction_angle_deg == pytest.approx(math.degrees(math.asin(0.45)))
    # a study's file keeps the curve as its source, rows and angles; read back, it has no arrays
    kept = lab.to_dict()
    assert list(kept) == ["source", "rows", "peak_friction_angle_deg", "end_friction_angle_deg"]
    assert kept["rows"] == 5
    assert kept["end_friction_angle_deg"] == pytest.approx(math.degrees(math.asin(0.35)))
    back = LabCurve.from_dict(kept)
    assert back == lab and back.axial_strain is None and back.to_dict() == kept


def test_the_peak_bound_is_the_direct_shear_files_friction_angle():
    """sin(atan 2.5): the one largest friction angle, 68.2 degrees, for both kinds of file."""
    assert math.degrees(math.asin(MAX_SIN_PHI)) == pytest.approx(math.degrees(math.atan(2.5)))
    assert math.degrees(math.asin(MAX_SIN_PHI)) == pytest.approx(68.2, abs=0.05)


@pytest.mark.parametrize(
    ("body", "words"),
    [
        ("0,0,0\n", ["line 2", "at least 5 readings"]),  # a one-point curve
        (GOOD.replace("0.02,", "0.01,"), ["axial_strain", "line 4, column 1", "rises"]),  # a repeat
        (GOOD.replace("0.05,", "0.005,"), ["axial_strain", "line 5, column 1", "rises"]),  # a step back
        ("0,0,0\n0.01,0,0\n0.02,0,0\n0.05,0,0\n0.1,0,0\n", ["the curve's peak", "weak"]),  # all zero
        (GOOD.replace("0.45", "0.95"), ["line 4, column 2", "strong", "0.928"]),
        (GOOD.replace("0.1,", "1e300,"), ["line 6, column 1", "[0, 0.5]"]),
        (GOOD.replace("-0.02", "-2"), ["volumetric_strain", "line 6, column 3", "percent"]),
        (GOOD.replace("0.45", "0.4_5"), ["line 4, column 2", "0.4_5", "a number"]),
        (GOOD.replace("0.45", "nan"), ["line 4, column 2", "a finite number"]),
        (GOOD.replace("0.45", "-0.45"), ["line 4, column 2", "[0, 1]"]),
    ],
)
def test_curves_that_cannot_be_right_are_refused(tmp_path, body, words):
    with pytest.raises(InputError) as e:
        read_lab_curve(_write(tmp_path, HEAD + body))
    for w in words + ["lab.csv"]:
        assert w in str(e.value), (w, str(e.value))


@pytest.mark.parametrize(
    ("body", "words"),
    [
        (
            "0,100,100\n0.01,200,100\n0.02,1e300,100\n0.05,230,100\n0.1,210,100\n",
            ["line 4, column 2", "times sigma_3"],
        ),
        ("0,100,100\n0.01,200,100\n0.02,250,100\n0.05,230,100\n0.1,-210,-100\n", ["line 6", "sigma_"]),
        (
            "0,100,100\n0.01,90,100\n0.02,250,100\n0.05,230,100\n0.1,210,100\n",
            ["line 3, column 2", "times sigma_3"],
        ),
        (
            "0,100,1e5\n0.01,200,100\n0.02,250,100\n0.05,230,100\n0.1,210,100\n",
            ["sigma_3_kpa", "line 2, column 3"],
        ),
    ],
)
def test_stresses_that_cannot_be_right_are_refused(tmp_path, body, words):
    with pytest.raises(InputError) as e:
        read_lab_curve(_write(tmp_path, "axial_strain,sigma_1_kpa,sigma_3_kpa\n" + body))
    for w in words:
        assert w in str(e.value), (w, str(e.value))
