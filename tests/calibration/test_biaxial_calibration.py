"""Laboratory biaxial tests as a calibration's input (``--biaxial-lab``): the laboratory files, the
targets read off their curves, the biaxial units and their keys, the refusals, the dimensionless
noise block, and a small synthetic calibration end to end (what is fitted, in which units: specimens
of about 110 disks do not identify the frictions, so no recovery is asked of it)."""

import dataclasses
import json
import pickle

import numpy as np
import pytest

from poro2d.biaxial.lab import LabCurve, LabTests, read_lab_tests
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.calibration import model, synthetic_biaxial_lab
from poro2d.calibration.biaxial import base_settings, biaxial_targets
from poro2d.calibration.biaxial_units import BiaxialUnit, biaxial_unit_key
from poro2d.calibration.case import CALIBRATED, shear_base_settings
from poro2d.calibration.run import CalibrationResult
from poro2d.calibration.units import (
    CalibrationUnit,
    observable_unit,
    parse_strain_station,
    strain_station,
)
from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.execute.options import RunOptions
from poro2d.report.calibration_figures import draw_calibration
from poro2d.store import Store
from tests.calibration import calibrate

QUIET = RunOptions(progress=False)
ONE_WORKER = RunOptions(workers=1, dashboard=None, progress=False)

E1 = np.linspace(0.0, 0.10, 101)  # a reading every 0.1 % of axial strain
RATIO = 0.5 * E1 / (0.01 + E1) + 0.1 * np.exp(-(((E1 - 0.03) / 0.01) ** 2))  # a peak near 3 %
EV = 0.004 - 0.3 * E1  # contracts by 0.4 %, then dilates at 0.3


def _csv(path, rows: dict[float, tuple], volumetric: bool = True):
    head = "confining_stress_kpa,axial_strain,stress_ratio" + (",volumetric_strain" if volumetric else "")
    lines = ["# my laboratory", head]
    for s, (e1, ratio, ev) in rows.items():
        for k in range(len(e1)):
            tail = f",{ev[k]:.8f}" if volumetric else ""
            lines.append(f"{s:g},{e1[k]:.6f},{ratio[k]:.8f}{tail}")
    path.write_text("\n".join(lines) + "\n")
    return path


def _lab(scale: float = 1.0) -> LabTests:
    curves = {50.0: LabCurve("a", E1, RATIO, EV), 100.0: LabCurve("a", E1, scale * RATIO, 0.5 * EV)}
    return LabTests(("a",), curves)


def test_one_file_of_several_tests_reads_as_one_file_per_test(tmp_path):
    both = _csv(tmp_path / "both.csv", {50: (E1, RATIO, EV), 100: (E1, 0.9 * RATIO, EV)})
    one = _csv(tmp_path / "s50.csv", {50: (E1, RATIO, EV)})
    two = _csv(tmp_path / "s100.csv", {100: (E1, 0.9 * RATIO, EV)})
    a, b = read_lab_tests(both), read_lab_tests([one, two])
    assert a.confining_stresses() == b.confining_stresses() == [50.0, 100.0]
    for s in (50.0, 100.0):
        assert np.array_equal(a.curves[s].stress_ratio, b.curves[s].stress_ratio)
        assert np.allclose(a.curves[s].volumetric_strain, EV, atol=1e-8)
    assert b.source == f"{one}, {two}"


@pytest.mark.parametrize(
    ("files", "words"),
    [
        ("no_column", r"lab columns.*confining_stress_kpa"),
        ("twice", r"confining_stress_kpa.*each confining stress in one test.*50 kPa was read from"),
        ("percent", r"lab axial_strain.*line 9.*is the column in percent"),
        ("short", r"curve at 100 kPa.*at least 5 readings"),
    ],
)
def test_bad_biaxial_files_are_refused_naming_the_place(tmp_path, files, words):
    good = _csv(tmp_path / "good.csv", {50: (E1, RATIO, EV)})
    if files == "no_column":
        rows = "\n".join(f"{e},{r}" for e, r in zip(E1, RATIO, strict=True))
        (tmp_path / "x.csv").write_text("axial_strain,stress_ratio\n" + rows + "\n")
        paths = [tmp_path / "x.csv"]
    elif files == "twice":
        paths = [good, _csv(tmp_path / "again.csv", {50: (E1, RATIO, EV)})]
    elif files == "percent":
        paths = [_csv(tmp_path / "pc.csv", {50: (100 * E1, RATIO, EV)})]
    else:
        paths = [_csv(tmp_path / "short.csv", {50: (E1, RATIO, EV), 100: (E1[:3], RATIO[:3], EV[:3])})]
    with pytest.raises(InputError, match=words):
        read_lab_tests(paths)


def _window(y, at, w):
    inside = (E1 >= at - w - 1e-12) & (E1 <= at + 1e-12)
    return float(np.mean(y[inside]))


def test_targets_are_the_lab_curves_read_as_the_tests_are(tmp_path):
    base = base_settings({"max_strain": 0.08, "smoothing_strain": 0.004}, CALIBRATED)
    targets = biaxial_targets(_lab(), base, stations=2)
    names = [(o, s) for o, s, _ in targets]
    assert names == [
        ("peak_ratio", 50.0), ("peak_ratio", 100.0), ("end_ratio", 50.0), ("end_ratio", 100.0),
        ("end_volumetric", 50.0), ("end_volumetric", 100.0),
        ("ratio_at_4pct", 50.0), ("volumetric_at_4pct", 50.0), ("ratio_at_4pct", 100.0),
        ("volumetric_at_4pct", 100.0),
    ]  # fmt: skip
    v = {(o, s): y for o, s, y in targets}
    # the peak: the largest centred mean over 0.4 % (the readings within 0.2 % each side), up to
    # where a test would end (8 %, and a row of 0.1 % past it)
    upto = E1 <= 0.081 + 1e-12
    means = [np.mean(RATIO[upto][np.abs(E1[upto] - e) <= 0.002 + 1e-12]) for e in E1[upto]]
    assert v["peak_ratio", 50.0] == pytest.approx(max(means), rel=1e-9)
    # the end: the mean over the last critical_window (25 %) of 8 %, i.e. 6 % to 8 %
    assert v["end_ratio", 50.0] == pytest.approx(_window(RATIO, 0.08, 0.02), rel=1e-9)
    assert v["end_volumetric", 100.0] == pytest.approx(_window(0.5 * EV, 0.08, 0.004), rel=1e-9)
    assert v["ratio_at_4pct", 50.0] == pytest.approx(_window(RATIO, 0.04, 0.004), rel=1e-9)
    # without the volumetric strain, the stress ratios alone
    plain = LabTests(("b",), {50.0: LabCurve("b", E1, RATIO, None)})
    assert [o for o, *_ in biaxial_targets(plain, base, stations=3)] == [
        "peak_ratio", "end_ratio", "ratio_at_2.667pct", "ratio_at_5.333pct",
    ]  # fmt: skip


def test_biaxial_observables_are_dimensionless_and_their_names_read_back():
    assert strain_station("ratio", 0.04) == "ratio_at_4pct"
    assert parse_strain_station("volumetric_at_2.5pct") == ("volumetric", pytest.approx(0.025))
    assert parse_strain_station("rise_at_4mm") is None and parse_strain_station("peak") is None
    for name in ("peak_ratio", "end_ratio", "end_volumetric", "ratio_at_4pct", "volumetric_at_4pct"):
        assert observable_unit(name) == "ratio"
    assert observable_unit("peak") == "kPa" and observable_unit("rise_at_4mm") == "mm"


def test_a_dimensionless_block_of_the_noise_is_scaled_by_itself():
    """Stresses (kPa) and stress ratios: the posterior does not depend on writing the ratios in
    per cent; a block of zeros (no scatter) still inverts."""
    rng = np.random.default_rng(1)
    ranges = model.Ranges((0.3, 3.0), (0.0, 0.5))
    design = ranges.to_unit(*np.array(model.space_filling(ranges, 12, 0)).T)
    truth = ranges.to_unit([0.8], [0.15])

    def surfaces(x, pct):
        u, v = x[:, 0], x[:, 1]
        return [60 + 30 * u + 20 * v, (0.4 + 0.1 * u - 0.05 * v) * pct, (0.3 + 0.02 * u + 0.1 * v) * pct]

    def post(pct):
        noise = rng.normal(size=(12, 3, 3)) * np.array([2.0, 0.01 * pct, 0.01 * pct])[None, :, None]
        values = np.stack(surfaces(design, pct), axis=1)[:, :, None] + noise
        sg = [model.fit_surrogate(design, values[:, k]) for k in range(3)]
        lab = [float(f[0]) for f in surfaces(truth, pct)]
        cov = model.noise_covariance(sg, model.seed_covariance(values), lab, 0.0, ["kPa", "ratio", "ratio"])
        return model.posterior(ranges, sg, lab, cov).density

    rng = np.random.default_rng(1)
    a = post(1.0)
    rng = np.random.default_rng(1)
    b = post(100.0)
    assert np.allclose(a, b, rtol=1e-6, atol=1e-12)
    zero = model.Surrogate(np.zeros(6), 0.0, 0.0, 2)
    cov = model.noise_covariance([zero, zero], np.zeros((2, 2)), [0.4, 0.3], 0.0, ["ratio", "ratio"])
    assert np.all(np.diag(cov) > 0) and np.isfinite(np.linalg.inv(cov)).all()


def test_a_biaxial_units_key_is_stable_and_never_a_shear_key():
    base = BiaxialSettings(max_strain=0.05)
    unit = BiaxialUnit.at("s.npz", "ab" * 32, 100.0, base, 0.8, 0.15)
    assert unit.key == "766f1c8f2871f6a77ed1"  # the name of its cache folder: it must not move
    assert unit.key == biaxial_unit_key("ab" * 32, 100.0, unit.settings)
    assert BiaxialUnit.at("elsewhere.npz", "ab" * 32, 100.0, base, 0.8, 0.15).key == unit.key  # content only
    assert dataclasses.replace(unit, sigma=50.0).key != unit.key
    assert (
        BiaxialUnit.at("s.npz", "ab" * 32, 100.0, BiaxialSettings(max_strain=0.06), 0.8, 0.15).key != unit.key
    )
    assert pickle.loads(pickle.dumps(unit)) == unit and (unit.fp, unit.mu_r) == (0.8, 0.15)
    shear = CalibrationUnit.at(
        "s.npz", "ab" * 32, 100.0, shear_base_settings({"max_displacement": 0.002}), 0.8, 0.15
    )
    assert shear.key == "47911f67c9214a97b5a2"  # the shear keys are those of earlier calibrations
    assert shear.key != unit.key


def _refused(**kw):
    with pytest.raises(InputError) as exc:
        calibrate(options=QUIET, **kw)
    return str(exc.value)


def test_the_api_refuses_a_biaxial_calibration_that_cannot_be_run(specimen, tmp_path):
    lab = _csv(tmp_path / "lab.csv", {50: (E1, RATIO, EV), 100: (E1, 0.9 * RATIO, EV)})
    shear = tmp_path / "peaks.csv"
    shear.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,70\n")
    assert "exactly one of --lab" in _refused(specimens=[specimen])
    assert "both" in _refused(lab=shear, biaxial_lab=lab, specimens=[specimen])
    assert "settings.max_strain" in _refused(
        biaxial_lab=lab, specimens=[specimen], settings={"max_strain": 0.2}
    )
    assert "settings.rolling_friction" in _refused(
        biaxial_lab=lab, specimens=[specimen], settings={"rolling_friction": 0.1}
    )
    assert "settings.max_displacement" in _refused(
        biaxial_lab=lab, specimens=[specimen], settings={"max_displacement": 0.002}
    )  # a shear setting is not a biaxial one
    assert "--stations" in _refused(biaxial_lab=lab, specimens=[specimen], stations=11)
    # a strain rate too fast for the specimen (its inertial number) is refused before any test
    fast = _refused(biaxial_lab=lab, specimens=[specimen], settings={"max_strain": 0.05, "strain_rate": 50.0},
                    store=Store(tmp_path / "fast"))  # fmt: skip
    assert "strain_rate" in fast and "quasi-static" in fast and not (tmp_path / "fast" / "cache").exists()
    # 2 stresses x (3 end values + 4 stations x 2 readings): 22 observables on 9 points x 2 replicates
    words = _refused(biaxial_lab=lab, specimens=[specimen, specimen], stations=5, points=9,
                     settings={"max_strain": 0.05})  # fmt: skip
    assert "--points" in words and "22 observables" in words


def _one_line(argv, capsys) -> str:
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
        ([], ["--lab", "neither", "--biaxial-lab"]),
        (["--biaxial-lab", "LAB", "--max-displacement", "0.002"], ["--max-displacement", "--max-strain"]),
        (["--lab", "LAB", "--max-strain", "0.05"], ["--max-strain", "only with --biaxial-lab"]),
        (["--biaxial-lab", "LAB", "--lab", "LAB"], ["--lab", "both"]),
        (
            ["--biaxial-lab", "LAB", "--max-strain", "0.3"],
            ["max_strain", "where the lab curve at 50 kPa ends"],
        ),
        (["--biaxial-lab", "LAB", "--kn-range", "1e5,1e6"], ["--kn-range", "not given with --biaxial-lab"]),
        (["--biaxial-lab", "LAB", "--ks-range", "1e5,1e6"], ["--ks-range", "direct shear only"]),
    ],
)
def test_the_command_refuses_on_one_line_before_any_work(specimen, tmp_path, capsys, extra, words):
    lab = _csv(tmp_path / "lab.csv", {50: (E1, RATIO, EV)})
    extra = [str(lab) if e == "LAB" else e for e in extra]
    out = tmp_path / "out"
    line = _one_line(["calibrate", "--specimen", str(specimen), "--out", str(out), *extra], capsys)
    assert all(w in line for w in words), line
    assert not (out / "cache").exists()


# ------------------------------------------------------------------ DEM: one unit, then end to end
FAST = {"max_strain": 0.02, "smoothing_strain": 0.004, "critical_window": 0.5}


def test_a_biaxial_unit_runs_once_and_is_read_back_from_its_cache_folder(specimen, tmp_path):
    from poro2d.specimen.specimen_set import SpecimenSet

    found = SpecimenSet.named([specimen]).read()
    label = next(iter(found))
    base = base_settings(FAST, CALIBRATED)
    unit = BiaxialUnit.at(found[label], found.digest(label), 50.0, base, 0.5, 0.1)
    cache = Store(tmp_path / "cache")
    assert unit.stored_row(cache) is None
    unit.check_entry(cache)  # nothing there yet: nothing to refuse
    row = unit.compute(cache)
    assert (tmp_path / "cache" / unit.key / "result.json").is_file()
    again = unit.stored_row(cache)
    assert (
        again is not None
        and again.peak_ratio == row.peak_ratio
        and again.end_volumetric == row.end_volumetric
    )
    assert 0.0 < row.end_ratio <= row.peak_ratio < 1.0  # a stress ratio: sin(phi)
    assert abs(row.end_volumetric) < 0.05 and row.observable("ratio_at_1pct") > 0.0
    done = json.loads((tmp_path / "cache" / unit.key / "result.json").read_text())
    assert row.peak_ratio == pytest.approx(done["peak_sin_phi"], rel=1e-12)  # the test's own peak
    e1, ratio = unit.curve(cache)
    assert len(e1) == len(ratio) >= 20
    (tmp_path / "cache" / unit.key / "curve.csv").write_text("edited by hand\n")
    with pytest.raises(InputError, match="curve.csv"):
        unit.check_entry(cache)


@pytest.mark.scenario
def test_a_small_synthetic_biaxial_calibration_fits_the_ratios_and_the_volumetric_strain(specimen, tmp_path):
    from poro2d.dem import checkpoint
    from poro2d.specimen import paper_grading
    from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen

    paths = [specimen]
    for seed in (1, 2):
        sim, rep = prepare_specimen(SpecimenSpec(width=0.06, height=0.03, layers=2), paper_grading(), 0.2,
                                    seed=seed)  # fmt: skip
        assert rep.converged
        paths.append(tmp_path / f"seed{seed}.npz")
        checkpoint.save(sim, paths[-1])
    lab = synthetic_biaxial_lab(paths[2], [50], 0.8, 0.15, tmp_path / "lab.csv", settings=FAST)
    text = lab.read_text()
    assert (
        text.startswith("# SYNTHETIC")
        and "confining_stress_kpa,axial_strain,stress_ratio,volumetric_strain" in text
    )
    out = tmp_path / "cal"
    kw = dict(specimens=paths[:2], store=Store(out), points=9, refine=0, settings=FAST, options=ONE_WORKER)
    res = calibrate(biaxial_lab=lab, **kw)
    draw_calibration(res, Store(out))  # the figures and the report, as the command draws them
    assert res.test == "biaxial" and res.cluster.tests_run == 9 * 2 and res.box_scale is None
    assert list(res.fit) == ["peak_ratio_50kPa", "end_ratio_50kPa", "end_volumetric_50kPa"]
    saved = json.loads((out / "result.json").read_text())
    assert saved["test"] == "biaxial" and saved["lab"]["kind"] == "biaxial curves"
    assert saved["settings"]["max_strain"] == 0.02 and "max_displacement" not in saved["settings"]
    for key, fit in saved["fit"].items():
        assert {"seed_scatter_ratio", "surrogate_residual_ratio"} <= set(
            fit
        ) and "seed_scatter_kpa" not in fit
        assert 0.0 <= fit["seed_scatter_ratio"] < 0.3, key  # a ratio, not kPa
    for o in saved["posterior"]["observables"]:
        assert {"lab_ratio", "model_ratio", "noise_sd_ratio"} <= set(o) and "lab_kpa" not in o
        assert o["normal_stress_kpa"] == 50.0  # the test's stress: sigma_3
    peak = next(o for o in saved["posterior"]["observables"] if o["observable"] == "peak_ratio")
    assert 0.2 < peak["lab_ratio"] < 0.9 and 0.0 < peak["noise_sd_ratio"] < 0.5
    kept = CalibrationResult.read(Store(out))
    assert kept.to_dict() == saved and kept.biaxial and type(kept.settings).__name__ == "BiaxialSettings"
    report = (out / "calibration.md").read_text()
    assert "| peak_ratio | 50 | 1 |" in report and "Biaxial tests: 18 run" in report
    assert "confining stress (kPa)" in report
    toml = (out / "calibrated.toml").read_text()
    assert "[biaxial]" in toml and "confining_kpa = [50.0]" in toml
    from poro2d.biaxial.config import load_biaxial_config

    table = load_biaxial_config(out / "calibrated.toml")
    assert table.build().particle_friction == res.best.particle_friction
    assert (out / "calibration_fit.png").stat().st_size > 0
    again = calibrate(biaxial_lab=lab, **kw)
    assert (
        again.cluster.tests_run == 0
        and again.cluster.tests_reused == 18
        and again.best.to_dict() == res.best.to_dict()
    )
