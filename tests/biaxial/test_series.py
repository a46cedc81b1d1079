"""Biaxial tests at several confining stresses: the envelope of the peak circles (against circles
drawn from a known Mohr-Coulomb line), the series on the quick specimen to 2 % of axial strain
(the same numbers as a test run alone), resuming a series, and the ``[biaxial]`` config table."""

import json
import math

import numpy as np
import pytest

import poro2d.biaxial as biaxial
from poro2d.biaxial import (
    BiaxialCase,
    BiaxialSeriesCase,
    BiaxialSeriesResult,
    BiaxialSettings,
    BiaxialTest,
    run_biaxial_series,
)
from poro2d.biaxial.envelope import envelope, peak_circle
from poro2d.biaxial.series import sigma_3_at_peak
from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.report.biaxial_figures import draw_biaxial_series
from poro2d.store import Store

TINY = {"max_strain": 0.02, "critical_window": 0.5}


def mohr_coulomb_circle(sigma_3: float, phi_deg: float, c_kpa: float) -> float:
    """sigma_1 at failure on the line tau = c + sigma tan(phi) (the textbook closed form)."""
    k = math.tan(math.radians(45.0 + 0.5 * phi_deg))
    return sigma_3 * k**2 + 2.0 * c_kpa * k


@pytest.mark.parametrize(("phi", "c"), [(30.0, 10.0), (22.0, 0.0), (41.0, 3.5)])
def test_the_envelope_is_the_line_the_circles_were_drawn_from(phi, c):
    s3 = np.array([50.0, 100.0, 200.0])
    s1 = np.array([mohr_coulomb_circle(v, phi, c) for v in s3])
    fit = envelope(s1, s3)
    assert fit.friction_angle_deg == pytest.approx(phi, abs=1e-9)
    assert fit.cohesion_kpa == pytest.approx(c, abs=1e-9) and fit.r2 == pytest.approx(1.0)
    # each circle touches the line: its centre lies one radius from it
    centre, radius = 0.5 * (s1 + s3), 0.5 * (s1 - s3)
    t = math.tan(math.radians(phi))
    distance = (c + t * centre) / math.sqrt(1.0 + t * t)
    assert np.allclose(distance, radius)
    origin = envelope(s1, s3, through_origin=True)
    assert origin.cohesion_kpa == 0.0
    if c == 0.0:
        assert origin.friction_angle_deg == pytest.approx(phi, abs=1e-9)
    else:  # a cohesion read as friction: steeper through the origin
        assert origin.friction_angle_deg > phi


def test_a_peak_circle_is_that_of_its_mobilized_friction():
    s1, s3 = peak_circle(100.0, 0.5)
    assert s3 == 100.0 and s1 == pytest.approx(300.0)
    assert (s1 - s3) / (s1 + s3) == pytest.approx(0.5)


def test_an_envelope_needs_two_stresses():
    with pytest.raises(InputError, match="confining stresses"):
        envelope([300.0, 310.0], [100.0, 100.0])
    assert envelope([300.0], [100.0], through_origin=True).friction_angle_deg == pytest.approx(30.0)


@pytest.fixture(scope="module")
def series(tmp_path_factory):
    out = tmp_path_factory.mktemp("series")
    case = BiaxialCase.quick(100.0, seed=2, settings=BiaxialSettings(**TINY))
    result = run_biaxial_series(
        BiaxialSeriesCase(case, [100.0, 50.0], replicates=2), Store(out), options=RunOptions(workers=1)
    )
    draw_biaxial_series(result, Store(out))  # as the command draws them, after the run
    return out, result


def test_a_series_runs_each_stress_on_its_replicates(series):
    out, r = series
    assert r.confining_stresses_kpa == [50.0, 100.0] and r.replicates == 2
    assert [s.folder for s in r.stresses] == ["sigma3_50kPa", "sigma3_100kPa"]
    tests = [t for st in r.studies for t in st.tests]
    assert [t.confining_stress_kpa for t in tests] == [50.0, 50.0, 100.0, 100.0]
    assert r.specimens == ["quick specimen (seed 2)", "quick specimen (seed 3)"]
    assert r.peak_friction_angle.values == [t.peak_friction_angle_deg for t in tests]
    assert r.stresses[1].peak_friction_angle.values == [t.peak_friction_angle_deg for t in tests[2:]]
    # each circle stands on the side walls' stress at its peak: the target, within the servo's tolerance
    at_peak = [sigma_3_at_peak(t) for t in tests]
    assert np.allclose(at_peak, [50.0, 50.0, 100.0, 100.0], rtol=0.03) and r.sigma_3_held
    s1, s3 = zip(*(peak_circle(s, t.peak_sin_phi) for s, t in zip(at_peak, tests, strict=True)), strict=True)
    assert r.envelope.to_dict() == envelope(s1, s3).to_dict() and r.envelope.points == 4
    assert r.headline().startswith(
        "biaxial at sigma_3 = 50, 100 kPa, 2 replicate(s) each, pooled over 4 tests"
    )


def test_a_series_test_is_the_test_run_alone_bit_for_bit(series):
    _, r = series
    alone = BiaxialTest(BiaxialCase.quick(50.0, seed=3, settings=BiaxialSettings(**TINY))).run()
    kept = r.studies[0].tests[1]
    for k in alone.curve:
        assert np.array_equal(alone.curve[k], kept.curve[k]), k


def test_a_series_files_and_typed_result(series):
    out, r = series
    for name in ("result.json", "biaxial_series.png", "sigma3_50kPa/result.json", "sigma3_100kPa/curves.csv",
                 "sigma3_100kPa/biaxial.png", "sigma3_100kPa/replicate2/curve.csv",
                 "sigma3_100kPa/replicate2/test.json"):  # fmt: skip
        assert (out / name).stat().st_size > 0, name
    stored = json.loads((out / "result.json").read_text())
    assert r.to_dict() == stored and BiaxialSeriesResult.from_dict(stored).to_dict() == stored
    assert stored["provenance"]["poro2d_version"] and stored["settings"]["max_strain"] == 0.02
    study = json.loads((out / "sigma3_50kPa" / "result.json").read_text())
    assert study["confining_stress_kpa"] == 50.0 and study["replicates"] == 2


def _count_computes(monkeypatch) -> list:
    ran = []
    compute = BiaxialTest.compute

    def counted(self):
        ran.append((self.case.confining_kpa, self.case.specimen.seed))
        return compute(self)

    monkeypatch.setattr(BiaxialTest, "compute", counted)
    return ran


def test_a_rerun_reads_finished_tests_and_reruns_a_changed_or_unfinished_one(tmp_path, monkeypatch):
    case = BiaxialCase.quick(100.0, seed=1, settings=BiaxialSettings(**TINY))
    first = run_biaxial_series(
        BiaxialSeriesCase(case, [50.0, 100.0]), Store(tmp_path), options=RunOptions(workers=1)
    )
    ran = _count_computes(monkeypatch)
    again = run_biaxial_series(
        BiaxialSeriesCase(case, [50.0, 100.0]), Store(tmp_path), options=RunOptions(workers=1)
    )
    assert ran == [] and again.peak_friction_angle.to_dict() == first.peak_friction_angle.to_dict()
    for a, b in zip(first.studies, again.studies, strict=True):
        assert np.array_equal(a.tests[0].curve.sin_phi, b.tests[0].curve.sin_phi)
    # a test killed midway: its record and a partial curve, no result.json (the marker)
    (tmp_path / "sigma3_100kPa" / "replicate1" / "result.json").unlink()
    resumed = run_biaxial_series(
        BiaxialSeriesCase(case, [50.0, 100.0]), Store(tmp_path), options=RunOptions(workers=1)
    )
    assert ran == [(100.0, 1)]
    assert np.array_equal(
        resumed.studies[1].tests[0].curve.sigma_1_kpa, first.studies[1].tests[0].curve.sigma_1_kpa
    )
    # a changed setting: the folders hold other tests, refused before any test runs, kept as they were
    changed = case.with_settings(smoothing_strain=0.005)
    record = (tmp_path / "sigma3_50kPa" / "replicate1" / "test.json").read_text()
    with pytest.raises(
        InputError, match=r"replicate1.*it holds a test of other settings \(smoothing_strain\)"
    ):
        run_biaxial_series(
            BiaxialSeriesCase(changed, [50.0, 100.0]), Store(tmp_path), options=RunOptions(workers=1)
        )
    assert ran == [(100.0, 1)]
    assert (tmp_path / "sigma3_50kPa" / "replicate1" / "test.json").read_text() == record


def test_a_test_folder_written_before_records_runs_again(tmp_path, monkeypatch):
    case = BiaxialCase.quick(100.0, seed=1, settings=BiaxialSettings(**TINY))
    biaxial.run_biaxial(case, Store(tmp_path), options=RunOptions(workers=1))
    (tmp_path / "replicate1" / "test.json").unlink()
    ran = _count_computes(monkeypatch)
    biaxial.run_biaxial(case, Store(tmp_path), options=RunOptions(workers=1))
    assert ran == [(100.0, 1)] and (tmp_path / "replicate1" / "test.json").is_file()


@pytest.mark.parametrize(
    ("value", "name"),
    [
        ([100.0], "confining_kpa"),
        ([50.0, 50.0], "confining_kpa"),
        ([50.0, 0.0], "confining stress"),
        ("50,100", "confining_kpa"),
    ],
)
def test_a_series_refuses_bad_stresses(value, name):
    with pytest.raises(InputError) as exc:
        BiaxialSeriesCase(BiaxialCase.quick(100.0), value)
    assert exc.value.parameter.startswith(name)


def _captured(monkeypatch) -> dict:
    seen: dict = {}

    def capture(name):
        def run(case, *args, **kw):
            seen.update(name=name, case=case, args=args, kw=kw)
            raise RuntimeError("stopped before any test")

        return run

    monkeypatch.setattr(biaxial, "run_biaxial", capture("single"))
    monkeypatch.setattr(biaxial, "run_biaxial_series", capture("series"))
    return seen


def test_the_config_table_builds_the_case_and_options_win(tmp_path, monkeypatch):
    seen = _captured(monkeypatch)
    cfg = tmp_path / "b.toml"
    cfg.write_text("[biaxial]\nmax_strain = 0.05\nstrain_rate = 0.1\nconfining_kpa = [200, 50, 100]\n"
                   "quick = true\nreplicates = 3\nseed = 4\n")  # fmt: skip
    with pytest.raises(SystemExit):
        main(["biaxial", "--config", str(cfg), "--strain", "0.08", "--out", str(tmp_path / "o"), "--quiet"])
    assert seen["name"] == "series" and seen["case"].confining_kpa == (50.0, 100.0, 200.0)
    case = seen["case"].case
    assert case.settings.max_strain == 0.08 and case.settings.strain_rate == 0.1  # the option won
    assert case.specimen.seed == 4 and seen["case"].replicates == 3
    with pytest.raises(SystemExit):
        main(["biaxial", "--config", str(cfg), "--confining", "75", "--out", str(tmp_path / "o"), "--quiet"])
    assert seen["name"] == "single" and seen["case"].confining_kpa == 75.0


@pytest.mark.parametrize(
    ("table", "words"),
    [
        ("max_strian = 0.1", "biaxial.max_strian"),
        ('max_strain = "0.1"', "biaxial.max_strain"),
        ("max_strain = 0.9", "biaxial.max_strain"),
        ("servo_gain = inf", "biaxial.servo_gain"),
        ("consolidation_max_steps = 1.5", "biaxial.consolidation_max_steps"),
        ("confining_kpa = [50, 5000]", "biaxial.confining_kpa"),
        ("confining_kpa = [50, 50]", "biaxial.confining_kpa"),
        ("replicates = 0", "biaxial.replicates"),
        ("quick = 1", "biaxial.quick"),
        ('specimens = "a.npz"', "biaxial.specimens"),
        ("[other]\nx = 1", "config.other"),
    ],
)
def test_a_bad_config_is_refused_on_one_line(table, words, tmp_path, capsys, monkeypatch):
    _captured(monkeypatch)
    cfg = tmp_path / "b.toml"
    body = table if table.startswith("quick") else "quick = true\n" + table
    cfg.write_text(f"[biaxial]\n{body}\n")
    with pytest.raises(SystemExit) as exc:
        main(["biaxial", "--config", str(cfg), "--out", str(tmp_path / "o"), "--quiet"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err, err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("text", ["50,50", "50,abc", "50,,100", "50,2000"])
def test_bad_confining_stresses_are_refused_on_one_line(text, tmp_path, capsys, monkeypatch):
    _captured(monkeypatch)
    with pytest.raises(SystemExit) as exc:
        main(["biaxial", "--quick", "--confining", text, "--out", str(tmp_path / "o"), "--quiet"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--confining" in err, err


@pytest.mark.scenario
def test_a_series_killed_midway_resumes_where_it_stopped(tmp_path, monkeypatch):
    """The command killed (SIGKILL) once its first test is kept: the rerun reads that test back,
    runs the rest, and gives the numbers of an uninterrupted run."""
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "o"
    argv = ["biaxial", "--quick", "--seed", "6", "--confining", "50,100", "--strain", "0.02",
            "--workers", "1", "--out", str(out), "--quiet"]  # fmt: skip
    cfg = tmp_path / "tiny.toml"
    cfg.write_text("[biaxial]\ncritical_window = 0.5\n")
    argv += ["--config", str(cfg)]
    proc = subprocess.Popen([sys.executable, "-m", "poro2d.cli", *argv], start_new_session=True)
    first = out / "sigma3_50kPa" / "replicate1" / "result.json"
    second = out / "sigma3_100kPa" / "replicate1" / "result.json"
    deadline = time.monotonic() + 600
    while not first.is_file() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    assert first.is_file() and not (out / "result.json").exists()
    kept = first.read_bytes()
    second_done = second.is_file()
    ran = _count_computes(monkeypatch)
    main(argv)
    assert first.read_bytes() == kept  # read back, not run again
    assert ran == ([] if second_done else [(100.0, 6)])
    alone = BiaxialTest(BiaxialCase.quick(100.0, seed=6, settings=BiaxialSettings(**TINY))).run()
    resumed = BiaxialSeriesResult.from_dict(json.loads((out / "result.json").read_text()))
    assert resumed.stresses[1].peak_friction_angle.values == [alone.peak_friction_angle_deg]
