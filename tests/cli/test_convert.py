"""`poro2d convert` and `poro2d plot relations` through the real entry point."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import pytest

from poro2d import __version__
from poro2d.cli import main
from poro2d.porosity import METHODS

PAPER = ["--n-max", "0.4571", "--n-min", "0.3253"]


def run(argv, capsys):
    """Run poro2d.cli.main(argv); return (exit code, stdout, stderr)."""
    code = 0
    try:
        main(argv)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    out, err = capsys.readouterr()
    return code, out, err


def test_table_has_one_row_per_method(capsys):
    code, out, err = run(["convert", "0.3434", *PAPER], capsys)
    assert code == 0, err
    for mid, m in METHODS.items():
        assert mid in out
        assert m.equation in out
    assert "0.1354" in out  # parabola, 0.42 * 0.3434^2 + 0.25 * 0.3434
    assert "0.1401" in out  # LIM 2D-3D
    assert "-0.0546" in out and "negative" in out  # interval mapping
    assert "decreasing" in out
    assert "warning" in out
    assert "nu_reading = 'printed'" in out


def test_table_shows_skipped_methods_with_reason(capsys):
    code, out, _ = run(["convert", "0.3434"], capsys)
    assert code == 0
    assert out.count("skipped") >= 4
    assert "needs n_max and n_min" in out


def test_json_single_object(capsys):
    code, out, _ = run(["convert", "0.3434", *PAPER, "--format", "json"], capsys)
    assert code == 0
    obj = json.loads(out)
    assert isinstance(obj, dict)
    for mid in METHODS:
        assert mid in obj
    assert obj["parabolic"] == pytest.approx(0.1353779, abs=1e-6)
    assert obj["lim_lab"] == pytest.approx(0.1097855, abs=1e-6)
    assert obj["interval_mapping"] < 0
    assert obj["n_lab"] == 0.3434
    assert obj["inputs"]["n_max"] == 0.4571 and obj["inputs"]["nu_reading"] == "printed"
    assert "negative" in obj["flags"]["interval_mapping"]
    assert obj["relative_density"] == pytest.approx(0.8864513, abs=1e-6)
    assert obj["poro2d_version"] == __version__
    assert obj["notes"] and obj["warnings"]


def test_json_null_where_skipped(capsys):
    code, out, _ = run(["convert", "0.3434", "--format", "json"], capsys)
    assert code == 0
    obj = json.loads(out)
    assert obj["combination"] is None and obj["lim_lab"] is None
    assert obj["densest_state_modified"] is None and obj["quasi_3d"] is None
    assert "combination" in obj["skipped"]
    assert obj["parabolic"] is not None


def test_json_several_values_is_a_list(capsys):
    code, out, _ = run(["convert", "0.33", "0.40", "0.45", *PAPER, "--format", "json"], capsys)
    assert code == 0
    objs = json.loads(out)
    assert isinstance(objs, list) and [o["n_lab"] for o in objs] == [0.33, 0.40, 0.45]
    # 0.42 * 0.16 + 0.25 * 0.4 = 0.1672
    assert objs[1]["parabolic"] == pytest.approx(0.1672, abs=1e-12)


def test_json_extrapolated_flag(capsys):
    code, out, _ = run(["convert", "0.30", *PAPER, "--format", "json"], capsys)
    assert code == 0
    obj = json.loads(out)
    assert "extrapolated" in obj["flags"]["lim_lab"]
    assert any("outside [n_min, n_max]" in w for w in obj["warnings"])


def test_csv_rows(capsys):
    code, out, _ = run(["convert", "0.3434", "0.40", *PAPER, "--format", "csv"], capsys)
    assert code == 0
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == 2 * len(METHODS)
    assert rows[0]["method"] == "densest_state"
    by = {(r["n_lab"], r["method"]): r for r in rows}
    assert float(by[("0.3434", "lim_3d")]["n2d"]) == pytest.approx(0.1400919, abs=1e-6)
    assert by[("0.3434", "interval_mapping")]["flags"] == "negative"


def test_densities_give_n_lab(capsys):
    argv = ["convert", "--dry-density", "1740", "--solid-density", "2650", "--format", "json"]
    code, out, _ = run(argv, capsys)
    assert code == 0
    obj = json.loads(out)
    # 1 - 1740 / 2650 = 0.3433962
    assert obj["n_lab"] == pytest.approx(0.3433962, abs=1e-6)
    assert obj["inputs"]["dry_density_kg_m3"] == 1740.0


def test_nu_reading_and_lattice_exact(capsys):
    argv = ["convert", "0.3434", *PAPER, "--nu-reading", "solid_fraction", "--lattice-exact"]
    code, out, _ = run([*argv, "--format", "json"], capsys)
    assert code == 0
    obj = json.loads(out)
    assert obj["densest_state_modified"] == pytest.approx(0.1093932, abs=1e-6)
    assert obj["inputs"]["nu_reading"] == "solid_fraction"
    assert obj["inputs"]["lattice_exact"] is True


@pytest.mark.parametrize(
    "argv,needle",
    [
        (["convert", "1.2"], "NLAB = 1.2"),
        (["convert", "-0.1"], "NLAB = -0.1"),
        (["convert", "nan"], "NLAB = nan"),
        (["convert", "0.3", "1.0"], "NLAB = 1.0"),
        (["convert", "abc"], "NLAB"),
        (["convert"], "NLAB"),
        (["convert", "0.3", "--n-max", "0.3", "--n-min", "0.4"], "--n-max = 0.3"),
        (["convert", "0.3", "--n-max", "1.5", "--n-min", "0.3"], "--n-max = 1.5"),
        (["convert", "0.3", "--n-max", "nan", "--n-min", "0.3"], "--n-max = nan"),
        (["convert", "--dry-density", "2700", "--solid-density", "2650"], "--dry-density = 2700"),
        (["convert", "--dry-density", "1740"], "--solid-density"),
        (["convert", "0.3", "--dry-density", "1740", "--solid-density", "2650"], "NLAB"),
        (["convert", "0.3", "--format", "xml"], "--format"),
        (["convert", "0.3", "--nu-reading", "guess"], "--nu-reading"),
        (["convert", "0.3", "--n-max", "abc"], "--n-max"),
        (["convert", "0.3", "--bogus"], "--bogus"),
        (["plot", "relations", "--n-max", "0.3"], "--n-max = 0.3"),
        (["plot", "relations", "--bogus"], "--bogus"),
    ],
)
def test_errors_exit_2_one_line_no_traceback(argv, needle, capsys):
    code, out, err = run(argv, capsys)
    assert code == 2
    text = out + err
    assert "Traceback" not in text
    assert needle in err
    assert len(err.strip().splitlines()) == 1


def test_range_error_names_allowed_range(capsys):
    code, _, err = run(["convert", "1.2"], capsys)
    assert code == 2
    assert "NLAB" in err and "1.2" in err and "[0, 1)" in err


# ------------------------------------------------------------------ the state in geotechnical terms
TOYOURA = ["--e-max", "0.977", "--e-min", "0.597"]


def test_void_ratio_state_line_before_the_table(capsys):
    code, out, err = run(["convert", "--e", "0.7", *TOYOURA], capsys)
    assert code == 0, err
    lines = out.splitlines()
    # n = 0.7 / 1.7 = 0.41176, Dr = (0.977 - 0.7) / 0.38 = 0.7289
    assert lines[0].startswith("lab state (given as e = 0.7): e = 0.7000, n_lab = 0.4118, D_r = 0.729")
    assert "e_max = 0.977, e_min = 0.597 (n_max = 0.4942, n_min = 0.3738)" in lines[0]
    assert lines[1].startswith("n_lab = 0.4118, e = 0.7000,") and "D_r = 0.729" in lines[1]
    for mid in METHODS:
        assert mid in out


def test_relative_density_with_void_ratio_extremes(capsys):
    code, out, _ = run(["convert", "--dr", "0.8", *TOYOURA, "--format", "json"], capsys)
    assert code == 0
    obj = json.loads(out)
    # e = 0.977 - 0.8 * 0.38 = 0.673, n = 0.673 / 1.673 = 0.402271
    assert obj["e"] == pytest.approx(0.673, rel=1e-14)
    assert obj["n_lab"] == pytest.approx(0.402271, abs=1e-6)
    assert obj["relative_density"] == 0.8
    assert obj["lab_state"] == {
        "n_lab": obj["n_lab"],
        "e": obj["e"],
        "n_max": pytest.approx(0.977 / 1.977, rel=1e-15),
        "n_min": pytest.approx(0.597 / 1.597, rel=1e-15),
        "relative_density": 0.8,
        "given": "Dr",
    }
    assert obj["inputs"]["e_max"] == 0.977 and obj["inputs"]["e_min"] == 0.597
    assert obj["parabolic"] == pytest.approx(0.42 * obj["n_lab"] ** 2 + 0.25 * obj["n_lab"], rel=1e-14)


def test_relative_density_with_porosity_extremes_gives_the_same_conversion(capsys):
    # Dr = 0.8864513 is the paper's n_lab = 0.3434 between 0.4571 and 0.3253
    dr = "0.8864513100780821"
    code, out, _ = run(["convert", "--dr", dr, *PAPER, "--format", "json"], capsys)
    assert code == 0
    by_dr = json.loads(out)
    code, out, _ = run(["convert", "0.3434", *PAPER, "--format", "json"], capsys)
    by_n = json.loads(out)
    assert by_dr["n_lab"] == pytest.approx(0.3434, abs=1e-12)
    for mid in METHODS:
        assert by_dr[mid] == pytest.approx(by_n[mid], abs=1e-10)


def test_several_void_ratios_in_csv(capsys):
    argv = ["convert", "--e", "0.65", "--e", "0.7", "--e", "0.8", *TOYOURA, "--format", "csv"]
    code, out, err = run(argv, capsys)
    assert code == 0, err
    assert out.splitlines()[0] == ",".join(
        ["n_lab", "n_max", "n_min", "method", "name", "equation", "n2d", "flags", "skipped", "nu_reading"]
        + ["lattice_exact", "e", "relative_density", "given"]
    )
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == 3 * len(METHODS)
    assert [float(r["e"]) for r in rows[:: len(METHODS)]] == [0.65, 0.7, 0.8]
    by = {(r["e"], r["method"]): r for r in rows}
    assert float(by[("0.7", "lim_3d")]["relative_density"]) == pytest.approx(0.277 / 0.38, rel=1e-13)
    assert float(by[("0.7", "lim_3d")]["n_lab"]) == pytest.approx(0.7 / 1.7, rel=1e-15)
    assert {r["given"] for r in rows} == {"e"}


def test_several_void_ratios_json_list(capsys):
    code, out, _ = run(["convert", "--e", "0.65", "--e", "0.8", *TOYOURA, "--format", "json"], capsys)
    assert code == 0
    objs = json.loads(out)
    assert [o["e"] for o in objs] == [0.65, 0.8]
    # Dr = (0.977 - 0.65) / 0.38 = 0.860526, (0.977 - 0.8) / 0.38 = 0.465789
    assert [o["relative_density"] for o in objs] == pytest.approx([0.860526, 0.465789], abs=1e-6)


def test_void_ratio_without_extremes(capsys):
    code, out, _ = run(["convert", "--e", "0.7", "--format", "json"], capsys)
    assert code == 0
    obj = json.loads(out)
    assert obj["e"] == 0.7 and obj["relative_density"] is None and obj["lim_lab"] is None
    code, out, _ = run(["convert", "--e", "0.7"], capsys)
    assert (
        out.splitlines()[0]
        == "lab state (given as e = 0.7): e = 0.7000, n_lab = 0.4118, D_r: no extremes given"
    )


def test_porosity_and_dry_density_with_void_ratio_extremes(capsys):
    code, out, _ = run(["convert", "0.41", *TOYOURA, "--format", "json"], capsys)
    assert code == 0
    obj = json.loads(out)
    assert obj["lab_state"]["given"] == "n" and obj["e"] == pytest.approx(0.41 / 0.59, rel=1e-15)
    argv = ["convert", "--dry-density", "1590", "--solid-density", "2650", *TOYOURA]
    code, out, _ = run(argv, capsys)
    assert code == 0
    # n = 1 - 1590 / 2650 = 0.4, e = 2650 / 1590 - 1 = 0.666667, Dr = (0.977 - 0.666667) / 0.38 = 0.816667
    assert out.startswith(
        "lab state (given as rho_d = 1590, rho_s = 2650 kg/m3): e = 0.6667, n_lab = 0.4000, D_r = 0.817;"
    )
    code, out, _ = run([*argv, "--format", "json"], capsys)
    obj = json.loads(out)
    assert obj["inputs"]["dry_density_kg_m3"] == 1590.0 and obj["lab_state"]["given"] == "dry_density"
    assert obj["e"] == pytest.approx(2650 / 1590 - 1, rel=1e-13)


def test_porosity_options_keep_their_output(capsys):
    """The geotechnical state's additions appear only when it is asked for."""
    code, out, _ = run(["convert", "0.3434", *PAPER], capsys)
    assert not out.startswith("lab state") and "e = " not in out.splitlines()[0]
    code, out, _ = run(["convert", "0.3434", *PAPER, "--format", "json"], capsys)
    obj = json.loads(out)
    assert "e" not in obj and "lab_state" not in obj
    code, out, _ = run(
        ["convert", "--dry-density", "1740", "--solid-density", "2650", "--format", "csv"], capsys
    )
    assert out.splitlines()[0].endswith(",nu_reading,lattice_exact")


@pytest.mark.parametrize(
    "argv,needle",
    [
        (["convert", "0.3", "--e", "0.7"], "--e = '0.7' is invalid; allowed: no --e when NLAB is given"),
        (["convert", "0.3", "0.4", "--e", "0.7", *TOYOURA], "no --e when NLAB is given"),
        (["convert", "--e", "0.7", "--dr", "0.5", *TOYOURA], "no --dr when --e is given"),
        (["convert", "--e", "0.7", "--dry-density", "1600", "--solid-density", "2650"], "no --dry-density"),
        (["convert", "--e", "0.99", *TOYOURA], "--e = 0.99 is invalid; allowed: [0.597, 0.977]"),
        (["convert", "--e", "0.7", "--e", "0.5", *TOYOURA], "--e = 0.5"),
        (["convert", "0.3", *TOYOURA], "NLAB = 0.3 is invalid; allowed: [0.373826, 0.494183]"),
        (
            ["convert", "--dr", "0.8"],
            "--dr = 0.8 is invalid; allowed: a relative density with the extremes --e-max",
        ),
        (["convert", "--dr", "1.3", *TOYOURA], "--dr = 1.3 is invalid; allowed: [0, 1]"),
        (["convert", "--dr", "-0.1", *PAPER], "--dr = -0.1"),
        (["convert", "--e", "0.7", "--e-max", "0.977"], "--e-min = None"),
        (["convert", "--e", "0.7", "--e-min", "0.597"], "--e-max = None"),
        (
            ["convert", "--e", "0.7", *TOYOURA, "--n-max", "0.45"],
            "--n-max = 0.45 is invalid; allowed: either",
        ),
        (
            ["convert", "--e", "0.7", "--e-max", "0.5", "--e-min", "0.6"],
            "--e-max = 0.5 is invalid; allowed: greater",
        ),
        (["convert", "--e", "0.7", "--e-max", "0.9", "--e-min", "-0.1"], "--e-min = -0.1"),
        (["convert", "--e", "-0.1"], "--e = -0.1 is invalid; allowed: a finite void ratio in [0, 100]"),
        (["convert", "--e", "nan"], "--e = nan"),
        (["convert", "--e", "inf"], "--e = inf"),
        (["convert", "--e", "abc"], "--e"),
        (["convert", *TOYOURA], "NLAB = None is invalid; allowed: a laboratory state"),
        (["convert", "--e", "0.7", "--solid-density", "2650"], "--solid-density = 2650.0"),
        (["convert", "--dry-density", "1600", *TOYOURA], "--solid-density = None"),
        (
            ["convert", "--dry-density", "1000", "--solid-density", "2650", *TOYOURA],
            "[1340.41, 1659.36] kg/m3",
        ),
        (
            ["convert", "--dry-density", "1600", "--solid-density", "1e300", *TOYOURA],
            "--solid-density = 1e+300",
        ),
        (["convert", "--e", "0.7", "--e-max", "0.977", "--e-max", "0.9", "--e-min", "0.5"], "--e-max"),
    ],
)
def test_geotechnical_errors_exit_2_one_line(argv, needle, capsys):
    code, out, err = run(argv, capsys)
    assert code == 2, (out, err)
    assert "Traceback" not in out + err
    assert needle in err, err
    assert len(err.strip().splitlines()) == 1


def eq2(n_lab: float, nu: float) -> float:
    """Eq. 2 written out here, apart from poro2d.porosity: 1 - [sqrt(pi sqrt 3) / (2 nu) (1 - n)]^(2/3)."""
    return 1.0 - (math.sqrt(math.pi * math.sqrt(3.0)) / (2.0 * nu) * (1.0 - n_lab)) ** (2.0 / 3.0)


@pytest.mark.parametrize(("reading", "other"), [("printed", "solid_fraction"), ("solid_fraction", "printed")])
def test_table_shows_the_other_reading_of_nu(capsys, reading, other):
    """Eq. 2's row names the chosen reading of nu and gives the other's n2D beside it."""
    n_fcc = 1.0 - math.pi / (3.0 * math.sqrt(2.0))
    nus = {"printed": 0.3253 / n_fcc, "solid_fraction": (1.0 - 0.3253) / (1.0 - n_fcc)}
    code, out, err = run(["convert", "0.3434", *PAPER, "--nu-reading", reading], capsys)
    assert code == 0, err
    row = next(line for line in out.splitlines() if "densest_state_modified" in line)
    assert f"{eq2(0.3434, nus[reading]):.4f}" in row
    assert f"nu={reading} ({other}: {eq2(0.3434, nus[other]):.4f})" in row


def test_the_documented_table_is_what_the_command_prints(capsys):
    """docs/conversions.md shows the paper's sand as `poro2d convert` prints it, row by row."""
    page = (Path(__file__).parents[2] / "docs" / "conversions.md").read_text(encoding="utf-8")
    section = page.split("## The table for the paper's sand")[1].split("\n## ")[0]
    documented = [
        [cell.strip() for cell in line.strip("|").split("|")]
        for line in section.splitlines()
        if line.startswith("| ") and not line.startswith(("| id ", "| ---"))
    ]
    code, out, _ = run(["convert", "0.3434", *PAPER], capsys)
    assert code == 0
    printed = {
        cells[0]: cells
        for line in out.splitlines()
        if line.startswith("│")
        for cells in [[c.strip() for c in line.strip().strip("│").split("│")]]
    }
    assert len(documented) == len(METHODS)
    for row in documented:
        assert printed[row[0]] == row, row[0]
    for line in ("n_lab = 0.3434, n_max = 0.4571, n_min = 0.3253, D_r = 0.886", *conversion_notes(section)):
        assert line in out


def conversion_notes(section: str) -> list[str]:
    """The lines of the page's fenced block of what the command prints after its table."""
    block = section.split("```")[1]
    return [line for line in block.splitlines() if line.startswith(("warning:", "note:"))]
