"""Round 4 of the refusals, on the laboratory commands (issue 42): a laboratory series counted
twice, an option of the preset given with specimens, a laboratory CSV with a byte order mark and a
biaxial strain rate refused after its folder was started. Each refusal is one line, exit 2,
naming what the user typed, and leaves nothing behind."""

from __future__ import annotations

import pytest

from poro2d.calibration.lab_repeats import LabRepeats
from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.shear import LabData

PEAKS = "normal_stress_kpa,peak_shear_stress_kpa\n50,38\n100,72\n200,140\n"
CURVE = "axial_strain,stress_ratio\n0,0\n0.01,0.3\n0.02,0.45\n0.05,0.4\n0.1,0.35\n"


class Reached(Exception):
    """Raised where a command's work would start: its input was accepted."""


def _stop(*args, **kwargs):
    raise Reached


def _refused(argv: list[str], capsys) -> str:
    """The one line a refused command prints (exit 2, nothing on stdout)."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert exc.value.code == 2 and len(lines) == 1 and not out.strip(), (out, err)
    return lines[0]


# 1. a laboratory series counted twice


@pytest.mark.parametrize("copy", ["same path", "copy", "saved again"])
def test_the_same_laboratory_series_twice_is_refused_naming_both_files(copy, tmp_path, capsys):
    first = tmp_path / "a.csv"
    first.write_text(PEAKS)
    second = first if copy == "same path" else tmp_path / "b.csv"
    if copy == "copy":
        second.write_text(PEAKS)
    elif copy == "saved again":  # a spreadsheet's save: a byte order mark and CRLF, the same readings
        second.write_bytes(b"\xef\xbb\xbf" + PEAKS.replace("\n", "\r\n").encode())
    out = tmp_path / "o"
    line = _refused(
        [
            "calibrate",
            "--lab",
            str(first),
            "--lab",
            str(second),
            "--preset",
            "paper",
            "--quick",
            "--out",
            str(out),
        ],
        capsys,
    )
    assert "--lab" in line and "a.csv" in line and second.name in line and "twice" in line, line
    assert not out.exists()


def test_repeats_are_distinct_measurements_and_one_series_keeps_its_share():
    a = LabData("a.csv", {50.0: 40.0, 100.0: 70.0})
    with pytest.raises(InputError, match=r"b\.csv.*not those of a\.csv"):
        LabRepeats.of([a, LabData("b.csv", dict(a.peaks))])
    # one series is the laboratory's whole share (1): the copy's would have been a half, with no scatter
    assert LabRepeats.of([a]).count == 1
    assert LabRepeats.of([a, LabData("b.csv", {50.0: 40.0, 100.0: 71.0})]).count == 2


def test_a_biaxial_test_given_twice_is_refused_naming_the_file_it_was_read_from(tmp_path, capsys):
    first, copy = tmp_path / "a.csv", tmp_path / "b.csv"
    for p in (first, copy):
        p.write_text(
            CURVE.replace("axial_strain,", "confining_stress_kpa,axial_strain,").replace("\n0", "\n100,0")
        )
    out = tmp_path / "o"
    line = _refused(
        ["calibrate", "--biaxial-lab", str(first), "--biaxial-lab", str(copy), "--preset", "paper", "--out",
         str(out)],
        capsys,
    )  # fmt: skip
    assert "b.csv" in line and "read from" in line and "a.csv" in line, line
    assert not out.exists()


# 2. an option of the preset given with specimens


@pytest.mark.parametrize("option", [["--seed", "5"], ["--replicates", "5"], ["--seed", "0"]])
def test_an_option_of_the_preset_is_refused_with_given_specimens(option, tmp_path, capsys, specimen):
    lab = tmp_path / "lab.csv"
    lab.write_text(PEAKS)
    out = tmp_path / "o"
    argv = ["calibrate", "--lab", str(lab), "--specimen", str(specimen), "--specimen", str(specimen), *option]
    line = _refused([*argv, "--out", str(out)], capsys)
    assert f"{option[0]} = {option[1]}" in line and "only with --preset paper" in line, line
    assert not out.exists()


# 3. a byte order mark on every laboratory CSV reader


def test_a_byte_order_mark_is_read_by_every_laboratory_reader(tmp_path, monkeypatch, specimen):
    import poro2d.biaxial.run as biaxial_run
    import poro2d.calibration.run as calibration_run
    import poro2d.shear.run as shear_run

    monkeypatch.setattr(shear_run, "ShearSeries", _stop)
    monkeypatch.setattr(calibration_run, "preset_specimens", _stop)
    monkeypatch.setattr(biaxial_run, "_run", _stop)
    bom = b"\xef\xbb\xbf"
    peaks, curve, tests = tmp_path / "peaks.csv", tmp_path / "curve.csv", tmp_path / "tests.csv"
    peaks.write_bytes(bom + PEAKS.replace("\n", "\r\n").encode())
    curve.write_bytes(bom + CURVE.encode())
    tests.write_bytes(bom + CURVE.replace("axial_strain,", "confining_stress_kpa,axial_strain,")
                      .replace("\n0", "\n100,0").encode())  # fmt: skip
    out = str(tmp_path / "o")
    for argv in (
        ["shear", "--specimen", str(specimen), "--lab", str(peaks), "--out", out],
        ["calibrate", "--lab", str(peaks), "--preset", "paper", "--quick", "--out", out, "--quiet"],
        ["calibrate", "--biaxial-lab", str(tests), "--max-strain", "0.1", "--preset", "paper", "--out", out],
        ["biaxial", "--quick", "--lab", str(curve), "--out", out, "--quiet"],
    ):
        with pytest.raises(Reached):
            main(argv)


def test_a_utf16_laboratory_file_is_one_line_naming_it(tmp_path, capsys, specimen):
    lab = tmp_path / "lab16.csv"
    lab.write_bytes(PEAKS.encode("utf-16"))  # a byte order mark of UTF-16: not UTF-8 text
    out = tmp_path / "o"
    line = _refused(["shear", "--specimen", str(specimen), "--lab", str(lab), "--out", str(out)], capsys)
    assert "lab16.csv" in line and "UTF-8" in line, line
    assert not out.exists()


# 4. a biaxial strain rate refused before any file or progress line


@pytest.mark.parametrize("source", ["quick", "file", "config"])
def test_a_strain_rate_too_fast_is_refused_before_any_file(source, tmp_path, capsys, specimen):
    out = tmp_path / "o"
    given = ["--quick"] if source != "file" else [str(specimen)]
    if source == "config":
        config = tmp_path / "b.toml"
        config.write_text("[biaxial]\nstrain_rate = 100\n")
        rate, name = ["--config", str(config)], "biaxial.strain_rate"
    else:
        rate, name = ["--strain-rate", "100"], "--strain-rate"
    extra = ["--replicates", "2"] if source == "quick" else []
    line = _refused(["biaxial", *given, *extra, *rate, "--out", str(out)], capsys)
    assert line.startswith(f"error: {name} = 100") and "quasi-static" in line, line
    assert not out.exists()


def test_a_series_checks_every_stress_before_its_first_test(tmp_path, capsys):
    out = tmp_path / "o"  # fast enough at 1000 kPa, not at 50 kPa: refused, nothing started
    argv = ["biaxial", "--quick", "--confining", "50,1000", "--strain-rate", "2", "--out", str(out)]
    line = _refused(argv, capsys)
    assert "--strain-rate = 2.0" in line and "at 50 kPa" in line, line
    assert not out.exists()


@pytest.mark.parametrize("strain", ["0.01", "1e-9"])
def test_a_test_too_short_for_its_curve_names_the_strain_typed(strain, tmp_path, capsys):
    line = _refused(["biaxial", "--quick", "--strain", strain, "--out", str(tmp_path / "o")], capsys)
    assert line.startswith(f"error: --strain = {float(strain)!r}") and "rows of the curve" in line, line
