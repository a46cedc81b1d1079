"""Laboratory files as a user gives them to `shear --lab`, `calibrate --lab` and `biaxial --lab`:
one reader for all (poro2d.lab_table), a refusal of one line naming file, line and column
before any work, and a byte order mark read (spreadsheets write one)."""

from __future__ import annotations

import pytest

from poro2d.cli import main

SHEAR_HEAD = "normal_stress_kpa,shear_displacement_mm,shear_stress_kpa\n"
# two curves of six readings, to 6 mm (past the quick calibration's end displacement)
SHEAR_GOOD = (
    "50,0,15\n50,0.5,20\n50,1,25\n50,1.5,30\n50,2,30\n50,6,28\n"
    "100,0,30\n100,0.5,40\n100,1,50\n100,1.5,60\n100,2,60\n100,6,56\n"
)
BIAXIAL_HEAD = "axial_strain,stress_ratio\n"
BIAXIAL_GOOD = "0,0\n0.01,0.3\n0.02,0.45\n0.05,0.4\n0.1,0.35\n"


class Reached(Exception):
    """Raised where a command's work would start: its input was accepted."""


def _stop(*args, **kwargs):
    raise Reached


def _argv(command: str, lab, tmp_path, specimen) -> list[str]:
    out = str(tmp_path / "o")
    if command == "shear":
        return ["shear", "--specimen", str(specimen), "--lab", str(lab), "--out", out]
    if command == "calibrate":
        return ["calibrate", "--lab", str(lab), "--preset", "paper", "--quick", "--out", out, "--quiet"]
    return ["biaxial", "--quick", "--lab", str(lab), "--out", out, "--quiet"]


BAD = [
    ("shear", SHEAR_GOOD.replace("50,2,", "50,0.5,"), ["line 6, column 2", "rises"]),  # goes backwards
    ("shear", SHEAR_GOOD.replace("50,1.5,", "50,1,"), ["line 5, column 2", "rises"]),  # repeats
    ("shear", SHEAR_GOOD.replace("50,6,", "50,1e300,"), ["line 7, column 2", "[0, 300] mm"]),
    ("shear", SHEAR_GOOD.replace("50,2,30", "50,2,1e300"), ["line 6, column 3", "strong"]),
    (
        "calibrate",
        "50,1,20\n" + SHEAR_GOOD[SHEAR_GOOD.index("100,") :],
        ["curve at 50 kPa", "line 2", "at least 5"],
    ),
    ("calibrate", SHEAR_GOOD.replace("50,1,", "50,1_0,"), ["line 4, column 2", "1_0"]),
    ("calibrate", SHEAR_GOOD.replace("50,0,15", "50,0,nan"), ["line 2, column 3", "finite"]),
    ("biaxial", "0,0\n0.01,0\n0.02,0\n0.05,0\n0.1,0\n", ["line 2, column 2", "weak"]),  # all zero
    ("biaxial", "0,0\n", ["line 2", "at least 5"]),  # one point
    ("biaxial", BIAXIAL_GOOD.replace("0.45", "-1"), ["line 4, column 2", "[0, 1]"]),
]


@pytest.mark.parametrize(("command", "body", "words"), BAD)
def test_a_lab_file_that_cannot_be_right_is_one_line_before_any_work(
    command, body, words, tmp_path, capsys, specimen
):
    lab = tmp_path / "lab.csv"
    lab.write_text((SHEAR_HEAD if command != "biaxial" else BIAXIAL_HEAD) + body)
    with pytest.raises(SystemExit) as e:
        main(_argv(command, lab, tmp_path, specimen))
    err = capsys.readouterr().err.strip()
    assert e.value.code == 2 and len(err.splitlines()) == 1, err
    for w in [*words, "lab.csv"]:
        assert w in err, (w, err)
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("command", ["shear", "calibrate", "biaxial"])
def test_a_lab_file_with_a_byte_order_mark_goes_on_to_the_work(command, tmp_path, monkeypatch, specimen):
    import poro2d.biaxial.run as biaxial_run
    import poro2d.calibration.run as calibration_run
    import poro2d.shear.run as shear_run

    monkeypatch.setattr(shear_run, "ShearSeries", _stop)
    monkeypatch.setattr(calibration_run, "preset_specimens", _stop)
    monkeypatch.setattr(biaxial_run, "_run", _stop)
    lab = tmp_path / "lab.csv"
    text = (SHEAR_HEAD + SHEAR_GOOD) if command != "biaxial" else (BIAXIAL_HEAD + BIAXIAL_GOOD)
    lab.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    with pytest.raises(Reached):
        main(_argv(command, lab, tmp_path, specimen))
