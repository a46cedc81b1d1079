"""The strength study: direct shear over (mu_r, f_p) on replicate specimens, its measures
checked on curves of known answer, a tiny study end to end, its resume, and bad input."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.report.strength_figure import draw_strength
from poro2d.shear import ShearSettings
from poro2d.shear.strength import StrengthStudy, max_dilation_angle, residual_point
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store

TINY = {"max_displacement": 0.002, "peak_window": 5e-4, "checkpoint_interval": 5e-4, "stop_after_peak": 0.0}


def test_residual_point_averages_the_last_fifth():
    x = np.linspace(0.0, 10.0, 101)  # mm
    tau = np.where(x < 8.0, 50.0, 30.0)
    sigma = np.where(x < 8.0, 90.0, 100.0)
    s, t = residual_point({"shear_displacement_mm": x, "shear_stress_kpa": tau, "normal_stress_kpa": sigma})
    assert (s, t) == (100.0, 30.0)


def test_max_dilation_angle_of_a_known_plate_path():
    x = np.linspace(0.0, 10.0, 201)  # mm
    # contracts by 0.05 mm, then rises at slope 0.2 from 2 to 6 mm, then flat
    dy = np.interp(x, [0.0, 1.0, 2.0, 6.0, 10.0], [0.0, -0.05, -0.05, 0.75, 0.75])
    psi = max_dilation_angle({"shear_displacement_mm": x, "plate_displacement_mm": dy}, 1e-3)
    assert psi == pytest.approx(math.degrees(math.atan(0.2)), rel=1e-9)


@pytest.fixture(scope="module")
def study(specimen, tmp_path_factory):
    out = tmp_path_factory.mktemp("strength")
    twice = SpecimenSet.accepted({"a": specimen, "b": specimen})
    s = StrengthStudy(twice, [0.0, 0.3], [0.5], [50, 100], ShearSettings(**TINY),
                      store=Store(out), options=RunOptions(workers=2, progress=False))  # fmt: skip
    result = s.run()
    draw_strength(result, Store(out))  # the figure, as the command draws it after the run
    return out, result


def test_tiny_study_writes_one_row_per_case_and_test(study):
    out, result = study
    assert [(r.mu_r, r.particle_friction) for r in result.cases] == [(0.0, 0.5), (0.3, 0.5)]
    with open(out / "strength_tests.csv", newline="") as fh:
        tests = list(csv.DictReader(fh))
    assert len(tests) == 2 * 2 * 2
    for r in result.cases:
        assert r.specimens == 2 and 0.0 < r.peak_friction_angle_mean_deg < 90.0
        assert 0.0 < r.residual_friction_angle_mean_deg < 90.0
        assert r.residual_stress_ratio_mean == pytest.approx(
            np.mean([float(t["residual_stress_ratio"]) for t in tests if float(t["mu_r"]) == r.mu_r])
        )
        # kappa = kn / (sigma t): the 100 kPa tests' is half the 50 kPa tests' (Table 1's disks)
        assert r.stiffness_number_max == pytest.approx(2.0 * r.stiffness_number_min, rel=1e-6)
        kappa = sorted({round(float(t["stiffness_number"]), 6) for t in tests})
        assert kappa == pytest.approx([r.stiffness_number_min, r.stiffness_number_max])
        assert 0.0 < r.mean_overlap_ratio_at_peak_max < 0.05
    assert (out / "fig_strength.png").stat().st_size > 0
    stored = json.loads((out / "strength.json").read_text())
    assert stored["cases"][1]["mu_r"] == 0.3 and "residual_friction_angle" in stored["definitions"]
    # each case's tests ran with the case's micro-parameters
    rec = json.loads((out / "mur0.3_fp0.5" / "a" / "sn50kPa" / "test.json").read_text())
    assert rec["run"]["settings"]["rolling_friction"] == 0.3
    assert rec["run"]["settings"]["particle_friction"] == 0.5


def test_a_rerun_reads_the_tests_back(specimen, study):
    out, result = study
    test_json = out / "mur0.3_fp0.5" / "b" / "sn100kPa" / "result.json"
    stamp = test_json.stat().st_mtime_ns
    twice = SpecimenSet.accepted({"a": specimen, "b": specimen})
    again = StrengthStudy(twice, [0.0, 0.3], [0.5], [50, 100], ShearSettings(**TINY),
                          store=Store(out), options=RunOptions(workers=1, progress=False)).run()  # fmt: skip
    assert test_json.stat().st_mtime_ns == stamp
    assert again.to_dict()["cases"] == result.to_dict()["cases"]


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--quick", "--mu-r", "0,2"], ["--mu-r", "0,2", "[0, 1]"]),
        (["--quick", "--friction", "0.5,0.5"], ["--friction", "repeated"]),
        (["--quick", "--normal-stress", "50,-1"], ["--normal-stress"]),
        (["--quick", "--seeds", "0"], ["--seeds", "0"]),
        (["--seeds", "2", "x.npz"], ["--seeds", "only with --quick"]),
        (["--quick", "x.npz"], ["SPECIMEN.../--quick"]),
        ([], ["SPECIMEN.../--quick"]),
    ],
)
def test_cli_refuses_bad_input_before_any_work(tmp_path, capsys, args, words):
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as exc:
        main(["strength", "--out", str(out), "--quiet", *args])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err
    assert not out.exists()


def test_study_refuses_bad_grids(specimen, tmp_path):
    with pytest.raises(InputError, match="mu_r"):
        StrengthStudy(SpecimenSet.accepted({"a": specimen}), [0.0, 1.5], [0.5], [50], store=Store(tmp_path))
    with pytest.raises(InputError, match="particle friction"):
        StrengthStudy(SpecimenSet.accepted({"a": specimen}), [0.0], [], [50], store=Store(tmp_path))


def test_cli_runs_a_tiny_study_and_records_its_grid(specimen, tmp_path, capsys):
    out = tmp_path / "out"
    main(["strength", str(specimen), "--mu-r", "0,0.2", "--friction", "0.5", "-n", "50",
          "--max-displacement", "0.002", "--workers", "1", "--out", str(out), "--quiet"])  # fmt: skip
    result = json.loads((out / "strength.json").read_text())
    assert [c["mu_r"] for c in result["cases"]] == [0.0, 0.2]
    assert result["config"]["particle_friction"] == [0.5] and result["settings"]["stop_after_peak"] == 0.0
    assert "phi residual" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["{missing}"], ["specimen", "missing.npz"]),
        (["--max-displacement", "0.05"], ["max_displacement", "0.05"]),
    ],
)
def test_cli_refuses_a_bad_specimen_before_any_folder(specimen, tmp_path, capsys, extra, words):
    out = tmp_path / "out"
    args = [a.format(missing=tmp_path / "missing.npz") for a in extra]
    with pytest.raises(SystemExit) as exc:
        main(["strength", str(specimen), *args, "--mu-r", "0,0.2", "--friction", "0.5", "-n", "50",
              "--out", str(out), "--quiet"])  # fmt: skip
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err
    assert not out.exists()
