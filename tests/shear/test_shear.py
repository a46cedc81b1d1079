"""Direct shear on a small specimen (0.06 m x 0.03 m, about 110 disks): force balance,
servo, friction, stress dependence, resume, CLI and bad input. Every test runs in seconds."""

import json

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.shear import DirectShearTest, ShearSeries, ShearSettings, build_split_box, smooth
from poro2d.shear.box import LOWER, UPPER
from poro2d.shear.case import ShearCase
from poro2d.store import Store

#: the tests one after the other in this process, no bars
SERIAL = RunOptions(workers=1, progress=False)

# 2 mm of shear in the 60 mm box: the peak of this small specimen lies near the end
SHORT = {"max_displacement": 0.002, "peak_window": 5e-4, "checkpoint_interval": 5e-4}


@pytest.fixture(scope="module")
def series(specimen, tmp_path_factory):
    out = tmp_path_factory.mktemp("series")
    s = ShearSeries(
        specimen, [50, 100, 200], ShearSettings(**SHORT), store=Store(out), options=SERIAL,
        keep_peak=False,
    )  # fmt: skip
    return out, s.run()


def _curve(path):
    import csv

    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def test_split_box_numbers_the_disks_in_columns(specimen):
    spec = checkpoint.load(specimen)
    spec.reorder(np.random.default_rng(0).permutation(spec.particles.n))
    sim, _ = build_split_box(spec, 0.01)
    p = sim.particles
    strip = np.floor((p.pos[:, 0] - p.pos[:, 0].min()) / (4.0 * p.radius.max()))
    assert np.all(np.diff(strip) >= 0)


def test_split_box_walls(specimen):
    sim, box = build_split_box(checkpoint.load(specimen), 0.01)
    assert set(sim.walls.names) == set(LOWER) | set(UPPER)
    assert box.width == pytest.approx(0.06) and box.split_y == pytest.approx(0.015)
    w = sim.walls
    # the lips sit on the shear plane and reach past the largest displacement
    lo, up = w.index("lower_lip"), w.index("upper_lip")
    assert w.p0[lo, 1] == w.p1[lo, 1] == pytest.approx(0.015)
    assert min(w.p0[lo, 0], w.p1[lo, 0]) <= -0.01 and max(w.p0[up, 0], w.p1[up, 0]) >= 0.07
    # the bottom covers the lower half after the full displacement
    b = w.index("bottom")
    assert max(w.p0[b, 0], w.p1[b, 0]) >= 0.07
    assert box.shear_displacement(sim) == 0.0


def test_peak_grows_with_normal_stress_and_outputs(series):
    out, r = series
    peaks = [t.peak_shear_stress_kpa for t in r.tests]
    assert peaks[0] < peaks[1] < peaks[2]
    assert r.friction_angle_deg > 0 and r.r2 > 0.5
    assert r.fit_through_origin.cohesion_kpa == 0.0
    for t in r.tests:
        assert {"normal_stress_kpa", "peak_shear_stress_kpa", "shear_displacement_at_peak_m", "end"} <= set(
            t.to_dict()
        )
        assert 0 < t.shear_displacement_at_peak_m <= 0.0021
        assert t.max_inertial_number < 1e-3
    for f in ("result.json", "curves.csv", "peaks.csv"):
        assert (out / f).stat().st_size > 0
    for sig in ("sn50kPa", "sn100kPa", "sn200kPa"):
        assert (out / sig / "curve.csv").stat().st_size > 0
        assert not (out / sig / "shear_checkpoint.npz").exists()  # removed once the test is done
    assert r.settings.velocity == r.velocity_m_per_s and r.density_scale == 1.0
    assert "poro2d_version" in r.provenance.to_dict()


def test_the_fabric_is_recorded_along_each_curve_and_drawn(series):
    """The fabric columns close each curve.csv; the orientations at the peak and the end are kept
    (fabric_rose.json) and drawn with the anisotropies against displacement by the command's figures."""
    from poro2d.measure.fabric import FABRIC_COLUMNS, FabricRoses
    from poro2d.report.fabric_figures import draw_shear_fabric

    out, r = series
    draw_shear_fabric(r, Store(out))
    assert (out / "fabric.png").stat().st_size > 0
    for t in r.tests:
        folder = out / t.folder
        curve = _curve(folder / "curve.csv")
        assert list(curve)[-len(FABRIC_COLUMNS) :] == list(FABRIC_COLUMNS)
        assert np.isfinite(curve["a_c"]).all() and ((curve["a_c"] >= 0) & (curve["a_c"] <= 2)).all()
        assert ((curve["z_mech"] > 2.0) & (curve["z_mech"] < 6.0)).all()
        roses = FabricRoses.from_dict(json.loads((folder / "fabric_rose.json").read_text()))
        assert roses.end.record == curve["step"].size - 1 and roses.peak is not None
        assert roses.peak.at == pytest.approx(1e3 * t.shear_displacement_at_peak_m)
        assert (folder / "fabric_rose.png").stat().st_size > 0


def test_each_curve_travels_in_the_result_as_its_file_holds_it(specimen, series):
    """The series' result carries every test's curve (not in result.json); a rerun reads them back
    through ShearTestResult.read, with the same values bit for bit, and they pickle (the pool's way)."""
    import pickle

    from poro2d.shear.results import ShearTestResult

    out, r = series
    assert set(r.curves) == {50.0, 100.0, 200.0} and "curves" not in r.to_dict()
    for sigma, curve in r.curves.items():
        on_file = _curve(out / f"sn{sigma:g}kPa" / "curve.csv")
        assert list(curve) == list(on_file)
        for k in curve:
            np.testing.assert_array_equal(curve[k], on_file[k])
        read = ShearTestResult.read(Store(out / f"sn{sigma:g}kPa"))
        assert read.normal_stress_kpa == sigma and read.curve["step"].size == read.records
        back = pickle.loads(pickle.dumps(read))
        np.testing.assert_array_equal(back.curve["shear_stress_kpa"], curve["shear_stress_kpa"])
    again = ShearSeries(
        specimen, [50, 100, 200], ShearSettings(**SHORT), store=Store(out), options=SERIAL,
        keep_peak=False,
    ).run()  # fmt: skip  # every test finished: read back, nothing run
    for sigma, curve in r.curves.items():
        for k in curve:
            np.testing.assert_array_equal(again.curves[sigma][k], curve[k])


def test_force_balance_during_shear(series):
    """Upper half, lower half and the contact forces across the shear plane agree.

    Exactly, upper = plane - (net contact force on the upper disks); in quasi-static
    shearing that remainder is small. Tolerance: mean absolute difference within 5 %
    of the mean shear stress (the lower half also carries the local damping's drag on
    the moving disks, hence its looser bound of 10 %).
    """
    out, _ = series
    for sig in ("sn50kPa", "sn100kPa", "sn200kPa"):
        c = _curve(out / sig / "curve.csv")
        up, plane, low = c["shear_stress_kpa"], c["plane_stress_kpa"], c["lower_half_stress_kpa"]
        np.testing.assert_allclose(up, plane - c["upper_unbalanced_kpa"], rtol=1e-9, atol=1e-9)
        late = c["shear_displacement_mm"] > 0.5
        ref = np.mean(up[late])
        assert np.mean(np.abs(up - plane)[late]) < 0.05 * ref
        assert np.mean(np.abs(up - low)[late]) < 0.10 * ref
        assert np.all(c["contacts_across_plane"] > 0)


def test_servo_holds_the_normal_stress(series):
    out, _ = series
    for sig, target in (("sn50kPa", 50.0), ("sn100kPa", 100.0), ("sn200kPa", 200.0)):
        cons = json.loads((out / sig / "consolidation.json").read_text())
        assert abs(cons["normal_stress_measured_kpa"] / target - 1) < 0.02
        assert cons["max_unbalanced_ratio"] < 1e-3
        c = _curve(out / sig / "curve.csv")
        x = c["shear_displacement_mm"] * 1e-3
        sm = smooth(x, c["normal_stress_kpa"], 5e-4)
        assert np.max(np.abs(sm / target - 1)) < 0.02


def test_frictionless_disks_are_far_weaker(specimen, series, tmp_path):
    _, r = series
    s = ShearSettings(particle_friction=0.0, **SHORT)
    r0 = DirectShearTest(ShearCase.of(specimen, 100, s), Store(tmp_path), keep_peak=False).run()
    tau3 = next(t.peak_shear_stress_kpa for t in r.tests if t.normal_stress_kpa == 100)
    assert r0.peak_shear_stress_kpa < 0.5 * tau3


class _Stop(Exception):
    pass


def test_killed_test_resumes_from_its_checkpoint(specimen, series, tmp_path):
    """Interrupted after its second checkpoint, a rerun continues and gives the same curve."""
    out, _ = series

    def stop(phase, fraction):
        if phase == "shearing" and fraction > 0.6:
            raise _Stop

    with pytest.raises(_Stop):
        DirectShearTest(
            ShearCase.of(specimen, 100, ShearSettings(**SHORT)), Store(tmp_path), progress=stop
        ).run()
    assert (tmp_path / "shear_checkpoint.npz").is_file() and not (tmp_path / "result.json").exists()
    r = DirectShearTest(ShearCase.of(specimen, 100, ShearSettings(**SHORT)), Store(tmp_path)).run()
    a = _curve(tmp_path / "curve.csv")
    b = _curve(out / "sn100kPa" / "curve.csv")
    np.testing.assert_array_equal(a["shear_stress_kpa"], b["shear_stress_kpa"])
    np.testing.assert_array_equal(a["plate_displacement_mm"], b["plate_displacement_mm"])
    assert (
        r.peak_shear_stress_kpa
        == json.loads((out / "sn100kPa" / "result.json").read_text())["peak_shear_stress_kpa"]
    )


def test_cli_parallel_with_lab_peaks_and_skip_on_rerun(specimen, series, tmp_path, capsys):
    out, r = series
    lab = tmp_path / "lab.csv"
    lab.write_text(
        "# made-up numbers for the test only\nnormal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,75\n"
    )
    dest = tmp_path / "cli"
    args = ["shear", "--specimen", str(specimen), "--normal-stress", "50,100", "--lab", str(lab),
            "--out", str(dest), "--max-displacement", "0.002", "--workers", "2", "--quiet",
            "--config", str(_cfg(tmp_path))]  # fmt: skip
    main(args)
    res = json.loads((dest / "result.json").read_text())
    assert res["processes"] == 2
    for f in ("fig8a_shear_curves.png", "fig8b_peak_strength.png", "sn50kPa/forces_peak.png"):
        assert (dest / f).stat().st_size > 0
    assert res["lab"]["friction_angle_deg"] == pytest.approx(np.degrees(np.arctan(35 / 50)))
    assert res["lab"]["friction_angle_difference_deg"] == pytest.approx(
        res["friction_angle_deg"] - res["lab"]["friction_angle_deg"]
    )
    # same settings as the series fixture: the same peaks, from independent processes
    for t in res["tests"]:
        ref = next(u for u in r.tests if u.normal_stress_kpa == t["normal_stress_kpa"])
        assert t["peak_shear_stress_kpa"] == ref.peak_shear_stress_kpa
    stamp = (dest / "sn50kPa" / "result.json").stat().st_mtime_ns
    main(args)  # finished tests are skipped
    assert (dest / "sn50kPa" / "result.json").stat().st_mtime_ns == stamp


def _cfg(tmp_path):
    p = tmp_path / "shear.toml"
    p.write_text("[shear]\npeak_window = 5e-4\ncheckpoint_interval = 5e-4\n")
    return p


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--normal-stress", "50,-100"], "--normal-stress"),
        (["--normal-stress", "50,abc"], "--normal-stress"),
        (["--max-displacement", "0.031"], "max_displacement"),
        (["--velocity", "-1"], "velocity"),
        (["--stop-after-peak", "1e-4"], "--stop-after-peak"),
    ],
)
def test_cli_bad_input(specimen, tmp_path, capsys, extra, needle):
    dest = tmp_path / "out"
    args = ["shear", "--specimen", str(specimen), "--out", str(dest), "--quiet"]
    with pytest.raises(SystemExit) as exc:
        main(args + (extra if "--normal-stress" in extra else ["--normal-stress", "50"] + extra))
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err
    assert not (dest / "result.json").exists()


def test_cli_missing_specimen_and_bad_lab(specimen, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(
            [
                "shear",
                "--specimen",
                str(tmp_path / "nope"),
                "--normal-stress",
                "50",
                "--out",
                str(tmp_path / "o"),
            ]
        )
    assert exc.value.code == 2 and "specimen" in capsys.readouterr().err
    lab = tmp_path / "lab.csv"
    lab.write_text("sigma,tau\n50,40\n")
    with pytest.raises(SystemExit) as exc:
        main(["shear", "--specimen", str(specimen), "--lab", str(lab), "--out", str(tmp_path / "o2")])
    assert exc.value.code == 2 and "lab columns" in capsys.readouterr().err
    assert not (tmp_path / "o2" / "result.json").exists()


def test_api_bad_input(specimen, tmp_path):
    with pytest.raises(InputError, match="normal stress"):
        ShearCase.of(specimen, -50)
    with pytest.raises(InputError, match="max_displacement"):
        ShearCase.of(specimen, 50, ShearSettings(max_displacement=0.05))
    with pytest.raises(InputError, match="specimen"):
        ShearSeries(tmp_path / "missing.npz", [50])
    with pytest.raises(InputError, match="normal stress"):
        ShearSeries(specimen, [50, 50], store=Store(tmp_path))


def test_a_folder_holding_another_test_is_not_overwritten(specimen, series):
    out, _ = series
    with pytest.raises(InputError, match="another normal stress"):
        DirectShearTest(ShearCase.of(specimen, 100, ShearSettings(**SHORT)), Store(out / "sn50kPa")).run()
    with pytest.raises(InputError, match=r"other settings \(velocity\)"):
        DirectShearTest(
            ShearCase.of(specimen, 50, ShearSettings(**dict(SHORT, velocity=0.02))), Store(out / "sn50kPa")
        ).run()


def test_rate_check_reruns_at_half_velocity(specimen, series, tmp_path):
    import shutil

    out, r = series
    shutil.copytree(out / "sn100kPa", tmp_path / "sn100kPa")  # done: only the v/2 rerun runs
    s = ShearSeries(
        specimen, [100], ShearSettings(**SHORT), store=Store(tmp_path), rate_check=True, options=SERIAL,
        keep_peak=False,
    )  # fmt: skip
    res = s.run()
    rc = res.rate_check
    assert rc.half_velocity_m_per_s == pytest.approx(0.5 * ShearSettings().velocity)
    (row,) = rc.tests
    half = json.loads((tmp_path / "rate_check" / "sn100kPa" / "result.json").read_text())
    assert half["velocity_m_per_s"] == pytest.approx(0.5 * ShearSettings().velocity)
    assert row.relative_change == pytest.approx(
        half["peak_shear_stress_kpa"] / r.tests[1].peak_shear_stress_kpa - 1
    )
    assert row.max_inertial_number_half_velocity < r.tests[1].max_inertial_number
    assert 0 <= row.mean_abs_change_before_peak < 1
    assert rc.passed == (abs(row.relative_change) < 0.02)


def _other_state(src, dest):
    """A copy of the specimen at ``src`` with one disk moved by a micrometre."""
    sim = checkpoint.load(src)
    sim.particles.pos[0, 0] += 1e-6
    checkpoint.save(sim, dest)


def test_state_digest_follows_content_not_file(specimen, tmp_path):
    sim = checkpoint.load(specimen)
    checkpoint.save(sim, tmp_path / "again.npz")  # other time stamps, same state
    sim.threads = 2
    checkpoint.save(sim, tmp_path / "two_threads.npz")
    _other_state(specimen, tmp_path / "moved_disk.npz")
    d = checkpoint.state_digest(specimen)
    assert checkpoint.state_digest(tmp_path / "again.npz") == d
    assert checkpoint.state_digest(tmp_path / "two_threads.npz") == d
    assert checkpoint.state_digest(tmp_path / "moved_disk.npz") != d


def test_replaced_specimen_is_refused(specimen, series, tmp_path, capsys):
    import shutil

    out, _ = series
    folder = tmp_path / "criterion-out"
    folder.mkdir()
    _other_state(specimen, folder / "specimen.npz")  # another specimen in the same place
    dest = tmp_path / "shear"
    shutil.copytree(out, dest)
    args = ["shear", "--specimen", str(folder), "--normal-stress", "50,100,200,400", "--out", str(dest),
            "--max-displacement", "0.002", "--workers", "1", "--quiet",
            "--config", str(_cfg(tmp_path))]  # fmt: skip
    with pytest.raises(SystemExit) as exc:
        main(args)
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert "another specimen" in err and "new --out" in err
    assert not (dest / "sn400kPa").exists()  # refused before anything was written


def test_moved_folders_resume_without_recomputing(specimen, series, tmp_path):
    import shutil

    out, r = series
    spec_dir = tmp_path / "elsewhere"
    spec_dir.mkdir()
    shutil.copy(specimen, spec_dir / "specimen.npz")
    dest = tmp_path / "copied"
    shutil.copytree(out, dest)
    done = sorted(dest.glob("sn*/result.json"))
    stamps = [f.stat().st_mtime_ns for f in done]
    again = ShearSeries(
        spec_dir, [50, 100, 200], ShearSettings(**SHORT), store=Store(dest), options=SERIAL,
        keep_peak=False,
    ).run()  # fmt: skip
    assert [f.stat().st_mtime_ns for f in done] == stamps
    assert [t.peak_shear_stress_kpa for t in again.tests] == [t.peak_shear_stress_kpa for t in r.tests]


def test_settings_bind_only_once_a_test_started(specimen, tmp_path):
    # a series stopped before any stage began (only the records written) does not hold its folder
    ShearSeries(
        specimen,
        [50, 100],
        ShearSettings(**dict(SHORT, velocity=0.03)),
        store=Store(tmp_path),
        options=RunOptions(progress=False),
    )
    s = ShearSeries(
        specimen, [50, 100], ShearSettings(**SHORT), store=Store(tmp_path), options=RunOptions(progress=False)
    )
    stored = json.loads((tmp_path / "sn50kPa" / "test.json").read_text())
    assert stored["run"]["settings"]["velocity"] == s.settings.velocity
    assert str(tmp_path) not in json.dumps(stored["run"])  # no paths in what is compared


def test_non_finite_shear_settings_are_refused(specimen, tmp_path):
    with pytest.raises(InputError, match="peak_window"):
        ShearSeries(
            specimen, [50], ShearSettings(**dict(SHORT, peak_window=float("inf"))), store=Store(tmp_path)
        )
    assert not any(tmp_path.iterdir())


def test_stop_after_peak_ends_the_test_with_the_same_peak(specimen):
    """Stopping once the peak is passed changes nothing before the stop: the curve is a prefix
    of the full one, the peak is the same, and the result says why it ended."""
    base = {"max_displacement": 0.004, "peak_window": 5e-4}
    full = DirectShearTest(ShearCase.of(specimen, 100, ShearSettings(**base, stop_after_peak=0.0))).run()
    short = DirectShearTest(ShearCase.of(specimen, 100, ShearSettings(**base, stop_after_peak=5e-4))).run()
    assert full.ended_by == "max_displacement"
    assert short.ended_by.startswith("peak passed by 0.5 mm")
    assert short.records < full.records
    assert short.end_shear_displacement_m >= short.shear_displacement_at_peak_m + 5e-4
    assert short.peak_shear_stress_kpa == full.peak_shear_stress_kpa
    assert short.shear_displacement_at_peak_m == full.shear_displacement_at_peak_m


@pytest.mark.parametrize("value", [-1e-3, 1e-4])
def test_stop_after_peak_shorter_than_the_smoothing_is_refused(value):
    with pytest.raises(InputError, match="stop_after_peak"):
        ShearSettings(stop_after_peak=value)


def test_cli_stop_after_peak_option(specimen, tmp_path):
    """--stop-after-peak reaches the test: it ends past the peak and says so."""
    dest = tmp_path / "out"
    opts = ["--max-displacement", "0.004", "--stop-after-peak", "5e-4", "--config", str(_cfg(tmp_path))]
    main(
        ["shear", "--specimen", str(specimen), "--normal-stress", "100", *opts, "--out", str(dest), "--quiet"]
    )
    r = json.loads((dest / "sn100kPa" / "result.json").read_text())
    assert r["ended_by"].startswith("peak passed") and r["settings"]["stop_after_peak"] == 5e-4
    assert r["end_shear_displacement_m"] < 0.004
