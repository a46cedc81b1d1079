"""The critical-state protocol: same seed same numbers, the steady-state reading, refusals, files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.critical_state import CriticalStateCase, CriticalStateTestResult, run_critical_state
from poro2d.critical_state import run as run_module
from poro2d.critical_state.series import COLUMNS, CellSeries
from poro2d.critical_state.steady import read_steady
from poro2d.errors import InputError
from poro2d.report.critical_state_figures import draw_critical_state
from poro2d.store import Store

#: a small fast case: 200 disks sheared at I = 0.01 to gamma 0.6 (a few seconds)
SMALL = {"disks": 200, "inertial_number": 1e-2, "strain": 0.6, "window_start": 0.3, "blocks": 3}


def test_the_same_seed_gives_the_same_series_bit_for_bit():
    a = run_critical_state(CriticalStateCase(**SMALL, seed=7))
    b = run_critical_state(CriticalStateCase(**SMALL, seed=7))
    other = run_critical_state(CriticalStateCase(**SMALL, seed=8))
    for col in COLUMNS:
        np.testing.assert_array_equal(getattr(a.series, col), getattr(b.series, col))
    assert not np.array_equal(a.series.stress_ratio, other.series.stress_ratio)
    assert a.stress_ratio == b.stress_ratio
    # the barostat held the pressure and the rate gave the inertial number asked for, on the
    # mean of the two seeds: 200 disks at I = 0.01 read one seed's stress to +-20 % (seeds 5-12:
    # 78-122 kPa, mean 97, measured)
    assert (a.normal_stress_kpa + other.normal_stress_kpa) / 2 == pytest.approx(100.0, rel=0.15)
    assert (a.inertial_number + other.inertial_number) / 2 == pytest.approx(1e-2, rel=0.15)
    assert 0.1 < a.stress_ratio < 0.5 and 0.7 < a.solid_fraction < 0.9


def series_of(gamma, mu, phi) -> CellSeries:
    n = gamma.size
    sigma = np.full(n, 100.0)
    return CellSeries(
        gamma=gamma,
        stress_ratio=mu,
        normal_stress_kpa=sigma,
        shear_stress_kpa=mu * sigma,
        mean_stress_kpa=sigma,
        solid_fraction=phi,
        inertial_number=np.full(n, 1e-3),
        coordination=np.full(n, 3.0),
    )


def test_the_study_keeps_each_seeds_steady_contact_anisotropy():
    from dataclasses import replace
    from types import SimpleNamespace

    from poro2d.critical_state.run import steady_anisotropy

    g = np.linspace(0.01, 2.0, 200)
    base = series_of(g, np.full(g.size, 0.3), np.full(g.size, 0.82))
    assert np.isnan(base.a_c).all()  # a series of an earlier poro2d: no fabric
    assert steady_anisotropy([SimpleNamespace(series=base)], 1.0) is None
    # a_c rising to its steady value 0.2 (seed 1) and 0.3 (seed 2) before the window starts
    seeds = [SimpleNamespace(series=replace(base, a_c=np.minimum(g, 1.0) * v)) for v in (0.2, 0.3)]
    spread = steady_anisotropy(seeds, 1.0)
    assert spread.values == pytest.approx([0.2, 0.3]) and spread.mean == pytest.approx(0.25)


def test_the_case_is_its_own_file_record():
    """Every field in order, the grading as its sizes, percent passing and source, stiffness_number
    only when set; read back, the grading is a curve again and the case writes the same keys."""
    case = CriticalStateCase(**SMALL)
    kept = case.to_dict()
    assert list(kept)[:3] == ["grading", "disks", "particle_friction"] and "stiffness_number" not in kept
    assert list(kept["grading"]) == ["sizes_m", "percent_passing", "source"]
    back = CriticalStateCase.from_dict(json.loads(json.dumps(kept)))
    assert back.grading.sizes_m == case.grading.sizes_m and back.to_dict() == kept
    assert CriticalStateCase(**SMALL, stiffness_number=100.0).to_dict()["stiffness_number"] == 100.0


def test_a_flat_noisy_window_is_steady_and_its_error_is_the_blocks_spread():
    rng = np.random.default_rng(0)
    g = np.linspace(0.01, 3.0, 300)
    mu = 0.27 + rng.normal(0.0, 0.02, g.size)
    phi = 0.81 + rng.normal(0.0, 0.001, g.size)
    state = read_steady(series_of(g, mu, phi), 1.0, 5, 0.03, 0.005)
    assert state.steady and state.note.startswith("steady")
    assert state.stress_ratio == pytest.approx(0.27, abs=0.006)
    # independent rows: the block error is about sd / sqrt(rows in the window)
    assert state.stress_ratio_se == pytest.approx(0.02 / np.sqrt(state.rows), rel=0.8)
    assert state.rows == int(np.sum(g >= 1.0))


def test_a_drifting_solid_fraction_or_stress_ratio_is_not_steady():
    g = np.linspace(0.01, 3.0, 300)
    flat_mu = np.full(g.size, 0.27)
    compacting = 0.79 + 0.01 * g  # still compacting: +0.02 over the window
    state = read_steady(series_of(g, flat_mu, compacting), 1.0, 5, 0.03, 0.005)
    assert not state.steady and "solid fraction drifts" in state.note and state.note.startswith("not steady")
    rising = 0.2 + 0.05 * g
    state = read_steady(series_of(g, rising, np.full(g.size, 0.81)), 1.0, 5, 0.03, 0.005)
    assert not state.steady and "stress ratio drifts" in state.note


@pytest.mark.parametrize(
    ("changes", "parameter"),
    [
        ({"inertial_number": 0.5}, "inertial_number"),
        ({"disks": 10}, "disks"),
        ({"rolling_friction": 2.0}, "rolling_friction"),
        ({"strain": 1.0, "window_start": 1.0}, "strain"),
        ({"pressure_kpa": -5.0}, "pressure_kpa"),
        ({"restitution": 0.01}, "restitution"),
    ],
)
def test_a_bad_case_is_refused_naming_its_field(changes, parameter):
    with pytest.raises(InputError) as exc:
        CriticalStateCase(**changes)
    assert exc.value.parameter == parameter


def test_a_run_keeps_its_result_series_and_figure_in_the_store(tmp_path, monkeypatch):
    case = CriticalStateCase(**SMALL)
    result = run_critical_state(case, Store(tmp_path))
    draw_critical_state(result, Store(tmp_path))  # the figure, drawn from the result after the run
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == [
        "critical_state.png",
        "critical_state.svg",
        "fabric_rose.json",
        "result.json",
        "series.csv",
        "test.json",
    ]
    data = json.loads((tmp_path / "result.json").read_text())
    assert CriticalStateTestResult.from_dict(data).to_dict() == result.to_dict()
    assert data["case"]["disks"] == 200 and data["provenance"]["poro2d_version"]
    assert len((tmp_path / "series.csv").read_text().splitlines()) == result.series.gamma.size + 1
    # a rerun reads the finished run back, series and all; a run of another case is refused
    monkeypatch.setattr(run_module, "_compute", lambda *_: pytest.fail("a finished run ran again"))
    back = run_critical_state(case, Store(tmp_path))
    assert back == result and np.array_equal(back.series.stress_ratio, result.series.stress_ratio)
    # the fabric is recorded along the series, its orientations kept at the peak and the end
    assert np.array_equal(back.series.a_c, result.series.a_c) and np.isfinite(result.series.a_c[-1])
    assert (
        back.roses.to_dict() == result.roses.to_dict()
        and back.roses.end.record == result.series.gamma.size - 1
    )
    with pytest.raises(InputError, match="another pressure") as exc:
        run_critical_state(case.at_pressure(200.0), Store(tmp_path))
    assert exc.value.parameter == "--out"


def test_the_command_refuses_a_bad_option_on_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exc:
        main(["critical-state", "--inertial", "3"])
    _out, err = capsys.readouterr()
    assert exc.value.code == 2
    assert err.strip().splitlines() == [err.strip()] and "--inertial" in err
    assert list(tmp_path.iterdir()) == []


def test_the_command_prints_the_steady_state_first(tmp_path, capsys):
    argv = [
        "critical-state",
        "--disks",
        "200",
        "--inertial",
        "0.01",
        "--strain",
        "0.6",
        "--window-start",
        "0.3",
        "--quiet",
        "--workers",
        "1",
        "--out",
        str(tmp_path / "out"),
    ]
    main(argv)
    out, _err = capsys.readouterr()
    first = out.strip().splitlines()[0]
    assert "tau/sigma = " in first and "solid fraction = " in first and "deg" in first
    assert (tmp_path / "out" / "result.json").exists()


def test_a_users_sieve_curve_is_the_cells_grading(tmp_path, capsys):
    """``--grading`` takes a sieve curve CSV: the cell's disks span its sizes (mm in, m kept)."""
    soil = tmp_path / "soil.csv"
    soil.write_text("size_mm,percent_passing\n0.25,0\n0.5,30\n1.0,70\n2.0,100\n")
    argv = ["critical-state", "--grading", str(soil), "--disks", "200", "--inertial", "0.01"]
    argv += ["--strain", "0.6", "--window-start", "0.3", "--quiet", "--workers", "1"]
    argv += ["--out", str(tmp_path / "out")]
    main(argv)
    kept = json.loads((tmp_path / "out" / "result.json").read_text())
    assert kept["config"]["grading"] == str(soil)
    grading = kept["case"]["grading"]
    assert grading["sizes_m"] == [0.25e-3, 0.5e-3, 1.0e-3, 2.0e-3] and grading["source"] == str(soil)


def test_a_bad_sieve_curve_is_refused_naming_its_line_and_column(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("size_mm,percent_passing\n0.25,0\n0.5,x\n")
    with pytest.raises(SystemExit) as exc:
        main(["critical-state", "--grading", str(bad), "--out", str(tmp_path / "out")])
    _out, err = capsys.readouterr()
    assert exc.value.code == 2 and "--grading" in err and "line 3, column 2" in err
    assert not (tmp_path / "out").exists()


def test_a_single_run_folder_is_taken_for_a_critical_state_folder_not_a_shear_one(tmp_path):
    """Its test.json is every laboratory test's record, no shear sign: the critical-state command
    resumes the folder and the shear command refuses it."""
    from poro2d.locks import output_folder, signed_kinds

    run_critical_state(CriticalStateCase(**SMALL), Store(tmp_path))
    assert (tmp_path / "test.json").is_file() and signed_kinds(tmp_path) == ["critical-state"]
    with pytest.raises(InputError, match="critical-state run"):
        with output_folder("--out", tmp_path, kind="shear"):
            pass
    with output_folder("--out", tmp_path, kind="critical-state"):
        pass
