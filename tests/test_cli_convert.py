"""`poro2d convert` and `poro2d plot relations` through the real entry point."""

from __future__ import annotations

import csv
import io
import json

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
        (["convert", "--dry-density", "2700", "--solid-density", "2650"], "dry_density"),
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
