"""``poro2d calibrate``: the statistics on known surfaces, the refusals, and the identifiability
check of the whole command: "laboratory" data made by poro2d at known (f_p, mu_r) on another
seed are recovered within the reported intervals (synthetic data, never measured ones)."""

import json
import math
import shutil

import numpy as np
import pytest

from poro2d.calibration import CalibrationCase, model, run_calibration, synthetic_lab
from poro2d.cli import main
from poro2d.cli.shear import load_shear_config
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.execute.options import RunOptions
from poro2d.report.calibration_figures import draw_calibration
from poro2d.specimen import paper_grading
from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen
from poro2d.store import Store
from tests.calibration import calibrate

QUIET = RunOptions(progress=False)
ONE_WORKER = RunOptions(workers=1, dashboard=None, progress=False)

RANGES = model.Ranges((0.3, 3.0), (0.0, 0.5))


def _quadratic(unit: np.ndarray, a: float, b: float) -> np.ndarray:
    u, v = unit[:, 0], unit[:, 1]
    return 40.0 + a * u + b * v - 10.0 * u * u + 5.0 * u * v


def _surrogates(funcs, design: np.ndarray) -> list[model.Surrogate]:
    # two replicates per point, +-0.5 kPa around the surface: the scatter is 0.5 * sqrt(2)
    return [model.fit_surrogate(design, np.column_stack([f(design) - 0.5, f(design) + 0.5])) for f in funcs]


def _posterior(funcs, truth_unit: np.ndarray) -> model.Posterior:
    design = RANGES.to_unit(*np.array(model.space_filling(RANGES, 12, 0)).T)
    surrogates = _surrogates(funcs, design)
    lab = [float(f(truth_unit)[0]) for f in funcs]
    values = np.stack([np.column_stack([f(design) - 0.5, f(design) + 0.5]) for f in funcs], axis=1)
    cov = model.noise_covariance(surrogates, model.seed_covariance(values), lab, 0.0)
    return model.posterior(RANGES, surrogates, lab, cov)


def test_two_independent_observables_pin_both_parameters_within_narrow_intervals():
    truth = (0.8, 0.15)
    unit = RANGES.to_unit([truth[0]], [truth[1]])
    post = _posterior([lambda x: _quadratic(x, 30.0, 5.0), lambda x: _quadratic(x, 2.0, 40.0)], unit)
    fp_lo, fp_hi = post.interval("fp", 0.95)
    mr_lo, mr_hi = post.interval("mu_r", 0.95)
    assert fp_lo <= truth[0] <= fp_hi and mr_lo <= truth[1] <= mr_hi
    assert math.log(fp_hi / fp_lo) < 0.2 * math.log(10.0) and mr_hi - mr_lo < 0.1
    assert fp_lo <= post.median("fp") <= fp_hi and mr_lo <= post.median("mu_r") <= mr_hi
    best = post.best()
    assert best[0] == pytest.approx(truth[0], rel=0.05) and best[1] == pytest.approx(truth[1], abs=0.01)


def test_one_combination_of_the_parameters_is_a_ridge_with_wide_intervals():
    # both observables depend on u + v only: the data cannot tell f_p from mu_r
    def along(x):
        return 40.0 + 30.0 * (x[:, 0] + x[:, 1])

    def along2(x):
        return 80.0 + 50.0 * (x[:, 0] + x[:, 1])

    post = _posterior([along, along2], RANGES.to_unit([0.8], [0.2]))
    assert post.correlation() < -0.9
    lo, hi = post.interval("mu_r", 0.95)
    assert hi - lo > 0.5 * 0.5


def test_seed_covariance_sees_a_specimen_strong_at_every_stress():
    rng = np.random.default_rng(0)
    level = rng.normal(0.0, 5.0, size=(20, 1, 3))  # one shift per specimen, the same at both stresses
    values = 50.0 + level + np.zeros((20, 2, 3))
    cov = model.seed_covariance(values)
    corr = cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1])
    assert corr == pytest.approx(1.0 - model.SHRINK)


def test_space_filling_design_lies_in_the_ranges_and_repeats_with_its_seed():
    a = model.space_filling(RANGES, 10, 3)
    assert a == model.space_filling(RANGES, 10, 3) and a != model.space_filling(RANGES, 10, 4)
    fp, mu_r = np.array(a).T
    assert (fp >= 0.3).all() and (fp <= 3.0).all() and (mu_r >= 0.0).all() and (mu_r <= 0.5).all()
    # a Latin hypercube: one point in each tenth of either axis
    unit = RANGES.to_unit(fp, mu_r)
    assert sorted(np.floor(unit[:, 0] * 10).astype(int).clip(0, 9)) == list(range(10))


# ------------------------------------------------------------------ the command, end to end
SHORT = {"max_displacement": 0.002, "peak_window": 5e-4, "checkpoint_interval": 5e-4, "record_interval": 5e-5}
TRUTH = {"particle_friction": 0.8, "rolling_friction": 0.15}
#: the tests' 110-disk specimens are box-dominated at every design point (their shear planes carry
#: 1.5-2 times the plate's load: docs/calibration.md): the statistics are checked on them as boxes
FIT_BOX = {"keep_box_dominated": True}


@pytest.fixture(scope="module")
def tiny(specimen, tmp_path_factory):
    """Three small specimens (0.06 m x 0.03 m): seeds 0 and 1 calibrate, seed 2 is the 'laboratory'.
    Seed 0 is the session's ``specimen`` (the same box, porosity and seed)."""
    root = tmp_path_factory.mktemp("tiny")
    paths = {0: root / "seed0.npz"}
    shutil.copyfile(specimen, paths[0])
    for seed in (1, 2):
        sim, rep = prepare_specimen(SpecimenSpec(width=0.06, height=0.03, layers=2), paper_grading(), 0.2,
                                    seed=seed)  # fmt: skip
        assert rep.converged
        paths[seed] = root / f"seed{seed}.npz"
        checkpoint.save(sim, paths[seed])
    lab = synthetic_lab(paths[2], [50, 100], TRUTH["particle_friction"], TRUTH["rolling_friction"],
                        root / "lab_dilation.csv", settings=SHORT)  # fmt: skip
    return paths, _without_vertical(lab, root / "lab.csv")


@pytest.fixture(scope="module")
def tiny_dilation(tiny):
    """The 'laboratory' of ``tiny`` as synthetic_lab writes it: with the plate's vertical displacement."""
    paths, plain = tiny
    return paths, plain.with_name("lab_dilation.csv")


def _without_vertical(path, to):
    """A copy of a synthetic curves CSV without its last column (vertical_displacement_mm): the
    peaks and end stresses alone, as laboratory files had before the plate's rise was fitted."""
    lines = path.read_text().splitlines()
    kept = [ln if ln.startswith("#") else ln.rsplit(",", 1)[0] for ln in lines]
    assert lines[4].endswith(",vertical_displacement_mm") and "vertical" not in kept[4]
    to.write_text("\n".join(kept) + "\n")
    return to


def test_calibration_recovers_synthetic_parameters_within_its_intervals(tiny, tmp_path):
    paths, lab = tiny
    assert lab.read_text().startswith("# SYNTHETIC")
    out = tmp_path / "cal"
    res = calibrate(lab, [paths[0], paths[1]], store=Store(out), points=9, refine=2, settings=SHORT,
                          options=ONE_WORKER, **FIT_BOX)  # fmt: skip
    draw_calibration(res, Store(out))  # the figures and the report, as the command draws them
    for name, value in TRUTH.items():
        lo, hi = getattr(res.intervals, name)
        assert lo <= value <= hi, (name, value, lo, hi)
        assert lo <= getattr(res.posterior.median, name) <= hi
    assert res.to_dict() == json.loads((out / "result.json").read_text())
    assert len(res.evaluations) == 11 and res.cluster.tests_run == 11 * 2 * 2
    assert {o.observable for o in res.posterior.observables} == {"peak", "end"}
    for f in ("calibration_fit.png", "calibration_posterior.png", "calibration.md", "calibration.html"):
        assert (out / f).stat().st_size > 0, f
    # the paper report shows a calibration kept in its output folder (paper-out/calibration)
    from poro2d.calibration.run import CalibrationResult
    from poro2d.report.paper_report import _calibration_blocks

    kept = CalibrationResult.read(Store(out))
    assert isinstance(kept, CalibrationResult) and kept.to_dict() == res.to_dict()
    blocks = _calibration_blocks(kept, out)
    assert blocks[0] == ("h2", "Calibration of particle and rolling friction")
    assert any(b[0] == "img" and str(b[1]).endswith("calibration_posterior.png") for b in blocks)
    assert (
        CalibrationResult.read(Store(tmp_path / "nothing")) is None
        and _calibration_blocks(None, tmp_path) == []
    )
    table, _ = load_shear_config(out / "calibrated.toml")
    assert table["particle_friction"] == res.best.particle_friction
    assert table["rolling_friction"] == res.best.rolling_friction
    again = calibrate(lab, [paths[0], paths[1]], store=Store(out), points=9, refine=2, settings=SHORT,
                            options=ONE_WORKER, **FIT_BOX)  # fmt: skip
    assert again.cluster.tests_run == 0 and again.cluster.tests_reused == 44
    assert again.best.to_dict() == res.best.to_dict()
    # the same series given twice is one measurement, not two repeats that agree: refused before
    # any test, so a copy cannot halve the laboratory's share of the noise and narrow the intervals
    with pytest.raises(InputError, match="the same measurement twice is one laboratory series"):
        calibrate([lab, lab], [paths[0], paths[1]], store=Store(tmp_path / "twice"), points=9,
                  refine=0, settings=SHORT, options=ONE_WORKER, **FIT_BOX)  # fmt: skip
    assert not (tmp_path / "twice").exists()
    # a weaker 'laboratory' (the same specimen at lower frictions) moves the answer to weaker
    # parameters: the calibration follows its data (round 1 comes from the cache)
    weak_lab = synthetic_lab(paths[2], [50, 100], 0.3, 0.0, tmp_path / "weak_dilation.csv", settings=SHORT)
    weak_lab = _without_vertical(weak_lab, tmp_path / "weak.csv")
    weak = calibrate(weak_lab, [paths[0], paths[1]], store=Store(out), points=9, refine=2,
                           settings=SHORT, options=ONE_WORKER, **FIT_BOX)  # fmt: skip
    peaks = {o.normal_stress_kpa: o.model for o in res.posterior.observables if o.observable == "peak"}
    for o in weak.posterior.observables:
        if o.observable == "peak":
            assert o.model < peaks[o.normal_stress_kpa]
    assert weak.posterior.median.particle_friction < res.posterior.median.particle_friction


def test_synthetic_lab_writes_the_plates_rise_of_its_tests(tiny_dilation):
    """The curves CSV carries each test's ``plate_displacement_mm`` as the vertical column; the
    other columns are those of a file without it."""
    import csv

    from poro2d.shear.lab import read_lab_csv

    _, lab = tiny_dilation
    lines = [ln for ln in lab.read_text().splitlines() if not ln.startswith("#")]
    assert lines[0] == "normal_stress_kpa,shear_displacement_mm,shear_stress_kpa,vertical_displacement_mm"
    plain = [ln for ln in lab.with_name("lab.csv").read_text().splitlines() if not ln.startswith("#")]
    assert [ln.rsplit(",", 1)[0] for ln in lines] == plain
    read = read_lab_csv(lab)
    for sigma in (50.0, 100.0):
        with open(lab.with_name("lab_dilation-tests") / f"sn{sigma:g}kPa" / "curve.csv") as f:
            rise = np.array([float(r["plate_displacement_mm"]) for r in csv.DictReader(f)])
        assert np.allclose(read.vertical[sigma] * 1e3, rise, atol=5e-7)
        assert rise[-1] > 0.0  # a dense specimen dilates: the plate rises


@pytest.mark.scenario
def test_a_calibration_fits_the_dilation_in_mm_from_the_same_cached_tests(tiny, tiny_dilation, tmp_path):
    """With the plate's rise in the lab curves, the calibration fits ``dilation_<s>kPa`` (mm) beside
    the peaks and end stresses, from the same shear tests (their keys do not change: a calibration
    on the plain file reuses them all)."""
    from poro2d.calibration.case import lab_targets, shear_base_settings
    from poro2d.calibration.specimens import replicate_unit
    from poro2d.calibration.units import CalibrationUnit, end_rise_mm
    from poro2d.shear.lab import read_lab_csv
    from poro2d.specimen.specimen_set import SpecimenSet

    paths, plain = tiny
    _, lab = tiny_dilation
    out = tmp_path / "cal"
    kw = dict(
        store=Store(out),
        points=9,
        refine=0,
        settings=SHORT,
        options=ONE_WORKER,
        **FIT_BOX,
    )
    res = calibrate(lab, [paths[0], paths[1]], **kw)
    draw_calibration(res, Store(out))
    keys = [f"{o}_{s}kPa" for o in ("peak", "end", "dilation") for s in (50, 100)]
    assert list(res.fit) == keys
    saved = json.loads((out / "result.json").read_text())
    for s in (50, 100):
        fit = saved["fit"][f"dilation_{s}kPa"]
        assert "seed_scatter_mm" in fit and "surrogate_residual_mm" in fit and "seed_scatter_kpa" not in fit
        assert 0.0 < fit["seed_scatter_mm"] < 1.0  # mm, not kPa: a 3 cm specimen rises by tenths of mm
        assert "seed_scatter_kpa" in saved["fit"][f"peak_{s}kPa"]
    fitted = {(o["observable"], o["normal_stress_kpa"]): o for o in saved["posterior"]["observables"]}
    targets = lab_targets(read_lab_csv(lab), shear_base_settings(SHORT))
    for obs, s, y in targets:
        o = fitted[(obs, s)]
        unit = "mm" if obs == "dilation" else "kpa"
        assert o[f"lab_{unit}"] == y and {f"model_{unit}", f"noise_sd_{unit}"} <= set(o)
        assert not ({"lab_kpa", "lab_mm"} - {f"lab_{unit}"}) & set(o)
    assert 0.0 < fitted[("dilation", 50.0)]["lab_mm"] < 2.0
    # each design point's dilation is the stored test's plate rise at its end, smoothed as its end stress
    first = res.evaluations[0]
    dilation = first.to_dict()["dilation_50kPa"]  # a design point is read by attribute, its row by key
    assert len(dilation) == 2 and all(0.0 < v < 2.0 for v in dilation)
    digest = res.specimens  # labels -> files; the units of the first point, specimen by specimen
    found = SpecimenSet.named([paths[0], paths[1]]).read()
    for k, label in enumerate(found):
        unit = replicate_unit(found, label, 50.0, shear_base_settings(SHORT), first.particle_friction,
                              first.rolling_friction)  # fmt: skip
        assert isinstance(unit, CalibrationUnit) and str(found[label]) == digest[label]
        row = unit.stored_row(Store(out).child("cache"))
        assert row.dilation == dilation[k]
        test = json.loads((out / "cache" / unit.key / "result.json").read_text())
        assert row.dilation == pytest.approx(test["end"]["plate_displacement_mm"], rel=1e-12)
    # the mean over the last window (2 mm: the readings at 1 and 2 mm)
    curve = {
        "shear_displacement_mm": np.array([0.0, 1.0, 2.0]),
        "plate_displacement_mm": np.array([0, 0.1, 0.3]),
    }
    assert end_rise_mm(curve, 2e-3) == pytest.approx(0.2)
    report = (out / "calibration.md").read_text()
    assert "| dilation | 50 | mm |" in report and "| peak | 50 | kPa |" in report
    assert (out / "calibration_fit.png").stat().st_size > 0
    again = calibrate(plain, [paths[0], paths[1]], **kw)
    assert again.cluster.tests_run == 0 and again.cluster.tests_reused == 9 * 2 * 2
    assert list(again.fit) == keys[:4]
    peaks = [[e.to_dict()["peak_50kPa"] for e in r.evaluations] for r in (again, res)]
    assert peaks[0] == peaks[1]


@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"fp_range": (0.0, 3.0)}, "--fp-range"),
        ({"fp_range": (2.0, 1.0)}, "--fp-range"),
        ({"mu_r_range": (0.0, 1.5)}, "--mu-r-range"),
        ({"points": 5}, "--points"),
        ({"refine": -1}, "--refine"),
        ({"lab_error": 2.0}, "--lab-error"),
        ({"level": 1.0}, "--level"),
        ({"settings": {"particle_friction": 1.0}}, "settings.particle_friction"),
        ({"settings": {"max_displacement": 0.05}}, "max_displacement"),
        ({"quick": True}, "--quick"),
        ({"preset": "other"}, "--preset"),
        ({"kn_range": (0.0, 1e6)}, "--kn-range"),
        ({"ks_range": (2e6, 1e6)}, "--ks-range"),
        ({"ks_range": (1e5, 1e11)}, "--ks-range"),
        ({"kn_range": (1e5, 1e6), "points": 12}, "--points"),  # 10 coefficients + 3
        ({"kn_range": (1e5, 1e6), "ks_range": (1e5, 1e6), "points": 17}, "--points"),  # 15 + 3
        ({"kn_range": (1e5, 1e6), "points": 13, "settings": {"particle_kn": 1e6}}, "settings.particle_kn"),
    ],
)
def test_bad_input_is_refused_before_any_test(tiny, tmp_path, kw, name):
    paths, lab = tiny
    out = tmp_path / "out"
    args = {"settings": SHORT, "options": QUIET} | kw
    with pytest.raises(InputError, match=name):
        calibrate(lab, [paths[0]], store=Store(out), **args)
    assert not (out / "result.json").exists() and not (out / "cache").exists()


def test_a_bad_worker_count_is_refused_before_the_calibration_is_called():
    with pytest.raises(InputError, match="--workers"):  # the options check themselves when made
        RunOptions(workers=0)


def _refusal(argv: list[str], capsys) -> str:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    out, err = capsys.readouterr()
    assert exc.value.code == 2 and not out
    lines = err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        ([], ["line 3", "lab.csv"]),
        (["--fp-range", "1"], ["--fp-range"]),
        (["--mu-r-range", "0.2,0.1"], ["--mu-r-range"]),
        (["--points", "2"], ["--points"]),
        (["--kn-range", "1e5"], ["--kn-range"]),
        (["--ks-range", "1e5,1e12"], ["--ks-range"]),
        (["--kn-range", "1e5,1e6", "--points", "12"], ["--points", "13"]),
        (["--preset", "paper"], ["--specimen"]),
        (["--specimen", "damaged"], ["checkpoint"]),
    ],
)
def test_the_command_refuses_bad_input_on_one_line(tiny, tmp_path, capsys, extra, words):
    paths, _ = tiny
    bad = tmp_path / "lab.csv"
    bad.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,abc\n" if not extra else
                   "normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,70\n")  # fmt: skip
    (tmp_path / "damaged.npz").write_bytes(paths[0].read_bytes()[:100])
    extra = [str(tmp_path / "damaged.npz") if e == "damaged" else e for e in extra]
    out = tmp_path / "out"
    line = _refusal(["calibrate", "--lab", str(bad), "--specimen", str(paths[0]), "--out", str(out), *extra],
                    capsys)  # fmt: skip
    assert all(w in line for w in words), line
    assert not (out / "cache").exists() and not (out / "specimens").exists()


def test_shear_settings_take_a_rolling_friction_for_every_disk(tiny):
    from poro2d.shear import ShearSettings, build_split_box

    with pytest.raises(InputError, match="rolling_friction"):
        ShearSettings(rolling_friction=1.5)
    spec = checkpoint.load(tiny[0][0])
    sim, _ = build_split_box(spec, 0.002, rolling_friction=0.25)
    assert (sim.particles.mu_r == 0.25).all()
    spec.particles.mu_r[:] = 0.1  # a specimen prepared with rolling resistance keeps it in the box
    kept, _ = build_split_box(spec, 0.002)
    assert (kept.particles.mu_r == 0.1).all()


def test_lab_curves_shorter_than_the_tests_are_refused_and_their_end_is_the_last_window(tiny, tmp_path):
    from poro2d.calibration.case import lab_targets, shear_base_settings
    from poro2d.shear.lab import read_lab_csv

    paths, _ = tiny
    short = tmp_path / "short.csv"
    short.write_text("normal_stress_kpa,shear_displacement_mm,shear_stress_kpa\n"
                     "50,0.2,10\n50,0.4,20\n50,0.6,25\n50,0.8,28\n50,1.0,30\n")  # fmt: skip
    with pytest.raises(InputError, match="settings.max_displacement"):
        run_calibration(
            CalibrationCase.of(short, [paths[0]], settings=SHORT), Store(tmp_path / "o"), options=QUIET
        )
    assert not (tmp_path / "o" / "cache").exists()
    curves = tmp_path / "curves.csv"
    curves.write_text("normal_stress_kpa,shear_displacement_mm,shear_stress_kpa\n"
                      "50,0.5,40\n50,1.0,30\n50,1.7,22\n50,2.0,18\n50,2.5,5\n")  # fmt: skip
    base = shear_base_settings({"max_displacement": 0.002, "peak_window": 5e-4})
    targets = lab_targets(read_lab_csv(curves), base)
    # the peak, and the mean of the readings within the last window before 2 mm (1.5 to 2 mm)
    assert targets == [("peak", 50.0, 40.0), ("end", 50.0, 20.0)]


def test_a_units_identity_is_the_digest_its_cache_folder_was_named_by():
    """A unit is a value; its key (its cache folder's name) hashes what it did when units were
    dicts, so the shear tests of earlier calibrations are found again."""
    import dataclasses
    import pickle

    from poro2d.calibration.case import shear_base_settings
    from poro2d.calibration.units import CalibrationUnit

    unit = CalibrationUnit.at(
        "s.npz", "ab" * 32, 100.0, shear_base_settings({"max_displacement": 0.002}), 0.8, 0.15
    )
    assert unit.key == "47911f67c9214a97b5a2"
    assert (unit.fp, unit.mu_r) == (0.8, 0.15) and pickle.loads(pickle.dumps(unit)) == unit
    assert dataclasses.replace(unit, sigma=50.0).key != unit.key
    with pytest.raises(dataclasses.FrozenInstanceError):
        unit.sigma = 1.0  # type: ignore[misc]


def test_the_preset_needs_a_store_to_keep_its_specimens(tiny):
    _, lab = tiny
    case = CalibrationCase.of(lab, preset="paper", quick=True, settings=SHORT)  # a case that is right
    with pytest.raises(InputError, match="store"):
        run_calibration(case, None, options=QUIET)


def test_a_laboratory_poro2d_did_not_write_gets_the_discrepancy_term(tiny, tmp_path):
    """The same values without poro2d's synthetic header: ``auto`` adds the model-discrepancy term
    (poro2d.calibration.discrepancy), the result and the report say what it found, and every noise
    sd is at least the plain one; poro2d's own file keeps the plain posterior (no term recorded).
    Every fitted observable carries the design's kappa and overlap at the peak."""
    paths, lab = tiny
    real = tmp_path / "real.csv"
    real.write_text("".join(ln for ln in lab.read_text().splitlines(keepends=True) if not ln.startswith("#")))
    kw = dict(store=Store(tmp_path / "cal"), points=9, refine=0, settings=SHORT, options=ONE_WORKER,
              **FIT_BOX)  # fmt: skip
    own = calibrate(lab, [paths[0], paths[1]], **kw)
    other = calibrate(real, [paths[0], paths[1]], **kw)  # the same tests, from the cache
    draw_calibration(other, kw["store"])  # its report, as the command draws it
    assert other.cluster.tests_run == 0
    assert "discrepancy" not in own.posterior.to_dict() and "discrepancy" not in own.config
    term = other.posterior.discrepancy
    assert term.prior.startswith("uniform over 41 levels from 0 to 4")
    assert 0.0 <= term.interval[0] <= term.median <= term.interval[1] <= 4.0
    assert other.config["discrepancy"] == "estimate"
    for a, b in zip(own.posterior.observables, other.posterior.observables, strict=True):
        assert b.noise_sd >= a.noise_sd
        # kappa = kn / (sigma t): halved from 50 to 100 kPa; the overlap at the peak a small fraction of d
        assert b.stiffness_number == pytest.approx(a.stiffness_number)
        assert 0.0 < b.mean_overlap_ratio_at_peak < 0.05
    kappa = {o.normal_stress_kpa: o.stiffness_number for o in other.posterior.observables}
    assert kappa[50.0] == pytest.approx(2.0 * kappa[100.0], rel=1e-6)
    assert "Model discrepancy" in (tmp_path / "cal" / "calibration.md").read_text()
