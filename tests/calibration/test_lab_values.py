"""A calibration needs at least as many laboratory values as frictions it fits (two).

One peak is one equation for f_p and mu_r: a line of pairs fits it equally, so the answer
would look identified without being so. It is refused on one line before any work.
"""

import pytest

from poro2d.calibration.identifiable import check_enough_lab_values
from poro2d.cli import main
from poro2d.errors import InputError


def test_one_peak_is_refused_and_two_values_are_enough():
    with pytest.raises(InputError, match="at least 2 laboratory values") as e:
        check_enough_lab_values("lab.csv", [("peak", 50.0, 40.0)], 2)
    assert "peak at 50 kPa" in str(e.value) and "line of (f_p, mu_r)" in str(e.value)
    check_enough_lab_values("lab.csv", [("peak", 50.0, 40.0), ("end", 50.0, 30.0)], 2)  # one whole curve
    check_enough_lab_values("lab.csv", [("peak", 50.0, 40.0), ("peak", 100.0, 75.0)], 2)


def test_calibrate_with_one_laboratory_peak_stops_before_any_work(tmp_path, capsys):
    lab = tmp_path / "lab.csv"
    lab.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,40\n")
    out = tmp_path / "o"
    with pytest.raises(SystemExit) as e:
        main(["calibrate", "--lab", str(lab), "--preset", "paper", "--quick", "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert e.value.code == 2 and len(err.splitlines()) == 1 and "--lab" in err, err
    assert "1 given" in err and not (out / "specimens").exists()
