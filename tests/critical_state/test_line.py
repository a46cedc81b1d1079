"""The critical-state line: the frictionless benchmark, the stiffness number, the fit, the files
and the command's line over several pressures."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.critical_state import CriticalStateCase, run_critical_state
from poro2d.critical_state import run as run_module
from poro2d.critical_state.calibrated import calibrated_values
from poro2d.critical_state.line import CriticalStateLineResult, LineFit, run_critical_state_line
from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.report.critical_state_figures import draw_critical_state_line
from poro2d.store import Store

#: a small fast case (as test_critical_state's): 200 disks at I = 0.01 to gamma 0.6
SMALL = {"disks": 200, "inertial_number": 1e-2, "strain": 0.6, "window_start": 0.3, "blocks": 3}


def test_frictionless_disks_shear_steadily_at_a_stress_ratio_near_one_tenth():
    """The benchmark of docs/critical-state.md: frictionless disks keep a steady friction of about
    0.1 (Peyneau & Roux 2008; Azema et al. for disks) and the isostatic coordination 4."""
    case = CriticalStateCase(disks=500, particle_friction=0.0, inertial_number=3e-3, strain=3.0)
    r = run_critical_state(case)
    assert r.steady, r.note
    assert 0.08 <= r.stress_ratio <= 0.13
    assert 3.7 <= r.coordination <= 4.1
    # denser than frictional disks at their critical state (0.80-0.82): near frictionless jamming
    assert 0.84 <= r.solid_fraction <= 0.87


def test_the_stiffness_number_scales_the_contacts_with_the_pressure():
    default = CriticalStateCase(pressure_kpa=50.0)
    assert default.kappa() == pytest.approx(2e5 / (50e3 * 0.008))  # Table 1's contacts: 500
    held = CriticalStateCase(pressure_kpa=200.0, stiffness_number=1000.0)
    kn, ks = held.contact_stiffness()
    assert kn == pytest.approx(1000.0 * 200e3 * 0.008) and ks == pytest.approx(kn)
    assert held.at_pressure(25.0).kappa() == pytest.approx(1000.0)
    with pytest.raises(InputError) as exc:
        CriticalStateCase(stiffness_number=5.0)
    assert exc.value.parameter == "stiffness_number" and "10" in exc.value.allowed


def test_overlaps_shrink_as_the_stiffness_number_grows():
    """The mean overlap over d is the typical contact strain: about 1 / kappa."""
    soft = run_critical_state(CriticalStateCase(**SMALL))
    assert soft.stiffness_number == pytest.approx(250.0)
    assert 0.3 / 250 < soft.mean_overlap_ratio < 3.0 / 250
    stiff = run_critical_state(CriticalStateCase(**SMALL, stiffness_number=25.0))
    assert stiff.mean_overlap_ratio > 5 * soft.mean_overlap_ratio


def test_the_line_fit_recovers_a_known_line_and_its_scatter():
    p = np.array([25.0, 50.0, 100.0, 200.0, 400.0])
    e = 0.30 - 0.012 * np.log(p)
    fit = LineFit.through(p, e)
    assert fit.e_gamma == pytest.approx(0.30) and fit.lambda_ln == pytest.approx(0.012)
    assert fit.lambda_log10 == pytest.approx(0.012 * math.log(10.0))
    assert fit.r2 == pytest.approx(1.0) and fit.residual_sd == pytest.approx(0.0, abs=1e-12)
    assert fit.void_ratio_at(100.0) == pytest.approx(0.30 - 0.012 * math.log(100.0))
    noisy = LineFit.through(p, e + np.array([0.002, -0.002, 0.002, -0.002, 0.0]))
    assert 0.0 < noisy.r2 < 1.0 and noisy.residual_sd > 0.001
    flat = LineFit.through(p, np.full(5, 0.25))
    assert flat.lambda_ln == pytest.approx(0.0, abs=1e-12) and flat.r2 is None
    with pytest.raises(InputError):
        LineFit.through(np.array([100.0, 100.0]), np.array([0.2, 0.21]))


def test_a_line_keeps_a_study_per_pressure_and_its_own_files(tmp_path, monkeypatch):
    case = CriticalStateCase(**SMALL)
    result = run_critical_state_line(
        case, [50.0, 200.0], Store(tmp_path), seeds=1, options=RunOptions(workers=1)
    )
    draw_critical_state_line(result, Store(tmp_path))  # the figures, drawn from the result after the run
    names = sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith("."))
    assert (tmp_path / "p50kPa" / "critical_state.png").exists()
    assert names == [
        "critical_state_line.png",
        "critical_state_line.svg",
        "line.csv",
        "p200kPa",
        "p50kPa",
        "result.json",
    ]
    assert (tmp_path / "p50kPa" / "result.json").exists() and (tmp_path / "p200kPa" / "series.csv").exists()
    data = json.loads((tmp_path / "result.json").read_text())
    assert CriticalStateLineResult.from_dict(data).to_dict() == result.to_dict()
    assert [pt["stiffness_number"] for pt in data["points"]] == [500.0, 125.0]
    # the softer contacts at 200 kPa overlap more: the line falls with the pressure
    assert result.line.lambda_ln > 0.0
    assert len((tmp_path / "line.csv").read_text().splitlines()) == 3
    # the pressures' own studies are the single-pressure runs of the same cases, bit for bit
    alone = run_critical_state(case.at_pressure(200.0))
    assert result.studies[1].tests[0].stress_ratio == alone.stress_ratio
    # each run was kept in its pressure's seed folder: a rerun after losing a study's files reads
    # every seed back (no run again) and writes the same study
    before = (tmp_path / "p50kPa" / "series.csv").read_bytes()
    (tmp_path / "p50kPa" / "series.csv").unlink()
    monkeypatch.setattr(run_module, "_compute", lambda *_: pytest.fail("a finished run ran again"))
    again = run_critical_state_line(
        case, [50.0, 200.0], Store(tmp_path), seeds=1, options=RunOptions(workers=1)
    )
    assert (tmp_path / "p50kPa" / "series.csv").read_bytes() == before
    assert again.line.to_dict() == result.line.to_dict()


@pytest.mark.parametrize("pressures", [[100.0], [50.0, 50.0], [50.0, 1e6]])
def test_a_bad_list_of_pressures_is_refused(pressures):
    with pytest.raises(InputError) as exc:
        run_critical_state_line(CriticalStateCase(**SMALL), pressures)
    assert exc.value.parameter == "pressures"


def test_the_command_prints_the_line_first_with_a_calibrations_frictions(tmp_path, capsys):
    cal = tmp_path / "calibrated.toml"
    cal.write_text(
        "[specimen]\nfriction_particle = 0.3\n\n[shear]\nparticle_friction = 0.3\nrolling_friction = 0.1\n"
    )
    argv = ["critical-state", "--calibrated", str(cal), "--pressure", "50,100", "--disks", "200"]
    argv += ["--inertial", "0.01", "--strain", "0.6", "--window-start", "0.3", "--quiet", "--workers", "1"]
    main([*argv, "--out", str(tmp_path / "out")])
    out, _err = capsys.readouterr()
    first = out.strip().splitlines()[0]
    assert "line" in first and "e_cs = " in first and "ln(p'/kPa)" in first and "50-100 kPa" in first
    kept = json.loads((tmp_path / "out" / "result.json").read_text())
    assert kept["case"]["particle_friction"] == 0.3 and kept["case"]["rolling_friction"] == 0.1
    assert kept["config"]["pressure_kpa"] == [50.0, 100.0]


def test_a_calibrated_file_without_its_table_is_refused_on_one_line(tmp_path, capsys):
    bad = tmp_path / "calibrated.toml"
    bad.write_text("[specimen]\nfriction_particle = 0.3\n")
    with pytest.raises(InputError):
        calibrated_values(bad)
    with pytest.raises(SystemExit) as exc:
        main(["critical-state", "--calibrated", str(bad), "--out", str(tmp_path / "out")])
    _out, err = capsys.readouterr()
    assert exc.value.code == 2 and "--calibrated" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


SAND_JSON = Path(__file__).resolve().parents[1] / "data" / "before_typed_results" / "sand_result.json"


def test_a_sand_folder_is_held_against_the_line_with_both_maps(tmp_path, capsys):
    """``--sand``: the 2D ends and the answer of a ``poro2d sand`` run (Toyoura sand, Dr 0.8) get
    psi at each pressure; ``--lab-line toyoura`` adds the laboratory's psi and the state map."""
    sand = tmp_path / "sand"
    sand.mkdir()
    (sand / "sand.json").write_text(SAND_JSON.read_text())
    argv = [
        "critical-state",
        "--pressure",
        "50,200",
        "--disks",
        "200",
        "--inertial",
        "0.01",
        "--strain",
        "0.6",
    ]
    argv += [
        "--window-start",
        "0.3",
        "--quiet",
        "--workers",
        "1",
        "--sand",
        str(sand),
        "--lab-line",
        "toyoura",
    ]
    main([*argv, "--out", str(tmp_path / "out")])
    out, _err = capsys.readouterr()
    assert "2D loose end" in out and "Dr map, Dr 0.80" in out and "state map" in out
    kept = json.loads((tmp_path / "out" / "result.json").read_text())
    loose, dense, answer = kept["marks"]
    line = CriticalStateLineResult.from_dict(kept).measured()
    # the loose end's psi is its void ratio less the line's at each pressure, over the 2D span
    span = loose["void_ratio"] - dense["void_ratio"]
    assert loose["span"] == pytest.approx(span)
    for p, psi, norm in zip(kept["pressures_kpa"], loose["psi"], loose["psi_normalised"], strict=True):
        assert psi == pytest.approx(loose["void_ratio"] - line.void_ratio_at(p))
        assert norm == pytest.approx(psi / span)
    # the points' own line: at a point's mean stress it reads that point's void ratio
    point = kept["points"][0]
    assert line.void_ratio_at(point["mean_stress_kpa"]["mean"]) == pytest.approx(point["void_ratio"]["mean"])
    assert dense["void_ratio"] < answer["void_ratio"] < loose["void_ratio"]


def test_sand_and_lab_line_refusals(tmp_path, capsys):
    for argv, name in [
        (["--lab-line", "toyoura"], "--lab-line"),
        (["--sand", str(tmp_path)], "--sand"),
        (["--pressure", "50,100", "--sand", str(tmp_path)], "--sand"),
    ]:
        with pytest.raises(SystemExit) as exc:
            main(["critical-state", *argv, "--out", str(tmp_path / "out")])
        _out, err = capsys.readouterr()
        assert exc.value.code == 2 and name in err
    assert not (tmp_path / "out").exists()


def test_the_measured_line_reads_between_its_points_and_not_far_beyond():
    from poro2d.critical_state.line import MeasuredLine

    line = MeasuredLine((50.0, 100.0, 200.0), (0.24, 0.24, 0.23))
    assert line.void_ratio_at(math.sqrt(100.0 * 200.0)) == pytest.approx(0.235)
    assert line.void_ratio_at(100.0) == pytest.approx(0.24)
    assert line.void_ratio_at(210.0) == pytest.approx(0.23 - 0.01 * math.log(1.05) / math.log(2.0))
    with pytest.raises(InputError):
        line.void_ratio_at(30.0)
