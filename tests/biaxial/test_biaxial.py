"""The biaxial test on the quick specimen (0.05 m x 0.10 m, about 320 disks, f_p 0.5) at 100 kPa:
its physics (sigma_3 held, an isotropic and stiff start, a dense specimen that dilates, the end
stress ratio of frictional disks), repeatability, its files and its refusals. The full test runs
once for the module (seconds); the other runs stop at a few per cent of strain."""

import json
import math

import numpy as np
import pytest

from poro2d.biaxial import (
    BiaxialCase,
    BiaxialResult,
    BiaxialSettings,
    BiaxialTest,
    BiaxialTestResult,
    run_biaxial,
)
from poro2d.biaxial.angles import read_angles
from poro2d.biaxial.curve import BiaxialCurve
from poro2d.biaxial.lab import read_lab_curve
from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.report.biaxial_figures import draw_biaxial
from poro2d.store import Store

SHORT = {"max_strain": 0.03, "critical_window": 0.34}


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """The quick specimen of seed 0 at 100 kPa to the default 20 % axial strain, kept in a store."""
    out = tmp_path_factory.mktemp("biaxial")
    lab = out.parent / "lab.csv"
    lab.write_text("# my own test\naxial_strain,sigma_1_kpa,sigma_3_kpa,volumetric_strain\n"
                   "0,100,100,0\n0.01,200,100,0.003\n0.02,250,100,0.004\n0.05,230,100,-0.01\n"
                   "0.1,210,100,-0.02\n")  # fmt: skip
    result = run_biaxial(BiaxialCase.quick(100.0, seed=0), Store(out), lab=lab)
    draw_biaxial(result, Store(out), read_lab_curve(lab))  # as the command draws it, after the run
    return out, result


def test_sigma_3_is_held_while_the_plate_moves(full):
    _, r = full
    c = r.tests[0].curve
    later = c.axial_strain >= 0.01
    err = np.abs(c.sigma_3_kpa[later] / 100.0 - 1.0)
    assert err.max() < 0.03 and err.mean() < 0.01, (err.max(), err.mean())
    # each side wall on its own, not only their mean
    for side in (c.sigma_3_left_kpa, c.sigma_3_right_kpa):
        assert np.abs(side[later] / 100.0 - 1.0).max() < 0.05
    assert r.tests[0].checks.sigma_3_held
    assert c.sigma_1_kpa.max() > 200.0  # the plate does carry the deviator


def test_the_start_is_isotropic_and_stiff(full):
    _, r = full
    c = r.tests[0].curve
    assert abs(c.sin_phi[0]) < 0.02  # consolidated under sigma_1 = sigma_3
    assert abs(c.axial_strain[0]) < 1e-12 and abs(c.volumetric_strain[0]) < 1e-12
    # stiff: half of the peak's mobilized friction is reached within 0.5 % of axial strain
    at = np.interp(0.005, c.axial_strain, c.sin_phi)
    assert at > 0.5 * r.tests[0].peak_sin_phi, at
    # and it contracts first (elastic compression) before it dilates
    assert c.volumetric_strain[c.axial_strain <= 0.005].max() > 0.0


def test_a_dense_specimen_dilates_and_peaks_above_its_end(full):
    _, r = full
    t = r.tests[0]
    assert t.end_volumetric_strain < -0.01  # the area has grown by more than 1 %
    assert t.max_dilatancy_angle_deg > 5.0
    assert t.max_dilatancy_angle_deg > abs(t.end_dilatancy_angle_deg) + 5.0  # dilation slows down at the end
    assert t.peak_friction_angle_deg > t.critical_state_friction_angle_deg + 3.0
    assert 20.0 < t.peak_friction_angle_deg < 35.0  # dense disks at mu 0.5: 25-35 deg (docs/biaxial.md)


def test_the_end_stress_ratio_is_that_of_frictional_disks(full):
    # steady shear of frictional disks without rolling resistance: tau / sigma_n about 0.25-0.30
    # (sin phi here); the walls of a small box read somewhat higher, the noise of 320 disks both ways
    _, r = full
    s = r.tests[0].critical_state_sin_phi
    assert 0.20 < s < 0.36, s
    assert r.tests[0].critical_state_mean_stress_kpa > 100.0


def test_files_and_typed_results(full):
    out, r = full
    for name in (
        "result.json",
        "curves.csv",
        "biaxial.png",
        "replicate1/result.json",
        "replicate1/curve.csv",
    ):
        assert (out / name).stat().st_size > 0, name
    stored = json.loads((out / "result.json").read_text())
    assert r.to_dict() == stored
    assert BiaxialResult.from_dict(stored).to_dict() == stored
    assert stored["provenance"]["poro2d_version"] and stored["settings"]["max_strain"] == 0.2
    assert stored["lab"]["rows"] == 5 and stored["lab"]["peak_friction_angle_deg"] == pytest.approx(
        math.degrees(math.asin(150 / 350))
    )
    one = BiaxialTestResult.read(Store(out / "replicate1"))
    for k in one.curve:
        assert np.array_equal(one.curve[k], r.tests[0].curve[k]), k
    assert one.to_dict() == r.tests[0].to_dict()


def test_the_contacts_turn_towards_the_compression_axis(full):
    """Axial compression adds contacts along the vertical (the major principal stress) and takes
    them from the horizontal: a_c grows from its consolidated value and theta_c nears 90 degrees;
    the rose at the peak and at the end is kept and drawn."""
    from poro2d.measure.fabric import FabricRoses
    from poro2d.report.fabric_figures import draw_biaxial_fabric

    out, r = full
    c = r.tests[0].curve
    roses = FabricRoses.from_dict(json.loads((out / "replicate1" / "fabric_rose.json").read_text()))
    k = roses.peak.record
    assert c["a_c"][k] > c["a_c"][0] + 0.05
    assert abs(c["theta_c"][k] - 90.0) < 25.0
    assert roses.end.record == c["a_c"].size - 1 and roses.peak.at == c["axial_strain"][k]
    draw_biaxial_fabric(r, Store(out))
    assert (out / "fabric.png").stat().st_size > 0 and (out / "replicate1" / "fabric_rose.png").exists()


def test_the_critical_state_check_can_say_not_yet(full):
    _, r = full
    c = r.tests[0].curve
    # cut the curve where the specimen still dilates fast: not a critical state
    k = int(np.searchsorted(c.axial_strain, 0.04))
    early = BiaxialCurve(**{name: c[name][:k] for name in c})
    a = read_angles(early, 100.0, 0.01, 0.25, 0.1)
    assert not a.critical_state_reached and a.critical_state_note.startswith("not yet at critical state")
    assert a.end_dilatancy_rate < -0.1


def test_same_seed_same_curve_bit_for_bit():
    settings = BiaxialSettings(**SHORT)
    a = BiaxialTest(BiaxialCase.quick(100.0, seed=4, settings=settings)).run()
    b = BiaxialTest(BiaxialCase.quick(100.0, seed=4, settings=settings)).run()
    c = BiaxialTest(BiaxialCase.quick(100.0, seed=5, settings=settings)).run()
    for k in a.curve:
        assert np.array_equal(a.curve[k], b.curve[k]), k
    assert not np.array_equal(a.curve.sigma_1_kpa, c.curve.sigma_1_kpa)


def test_replicates_are_seeds_and_their_spread(tmp_path):
    res = run_biaxial(BiaxialCase.quick(50.0, seed=7, settings=BiaxialSettings(**SHORT)), replicates=2,
                      options=RunOptions(workers=1))  # fmt: skip
    assert res.specimens == ["quick specimen (seed 7)", "quick specimen (seed 8)"]
    values = [s.peak_friction_angle_deg for s in res.summaries]
    assert res.peak_friction_angle.values == values and res.peak_friction_angle.mean == pytest.approx(
        np.mean(values)
    )
    assert res.peak_friction_angle.sd == pytest.approx(np.std(values, ddof=1))
    assert res.peak_friction_angle.min == min(values) and res.peak_friction_angle.max == max(values)
    assert res.headline().startswith("biaxial at sigma_3 = 50 kPa, 2 replicates: phi_peak = ")


def test_a_specimen_file_runs_and_is_its_own_only_replicate(specimen):
    case = BiaxialCase.of(specimen, 100.0, BiaxialSettings(**SHORT))
    r = BiaxialTest(case).run()
    assert r.specimen.endswith("specimen.npz") and r.consolidation.box.width == pytest.approx(0.06)
    assert r.checks.quasi_static and r.peak_sin_phi > 0.2
    with pytest.raises(InputError, match="replicates"):
        run_biaxial(case, replicates=2)


def test_consolidation_without_equilibrium_is_refused_loudly():
    s = BiaxialSettings(consolidation_ratio=1e-9, consolidation_max_steps=1000, **SHORT)
    with pytest.raises(RuntimeError, match="did not reach equilibrium"):
        BiaxialTest(BiaxialCase.quick(100.0, settings=s)).run()


def test_a_fast_strain_rate_is_refused_by_its_inertial_number():
    with pytest.raises(InputError, match="strain_rate.*quasi-static limit"):
        BiaxialTest(BiaxialCase.quick(100.0, settings=BiaxialSettings(strain_rate=20.0))).build()


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--quick", "--confining", "0"], "--confining"),
        (["--quick", "--confining", "nan"], "--confining"),
        (["--quick", "--strain", "0.9"], "--strain"),
        (["--quick", "--strain-rate", "-1"], "--strain-rate"),
        (["--quick", "--replicates", "0"], "--replicates"),
        (["--quick", "--seed", "-3"], "--seed"),
        (["SPEC", "--seed", "3"], "--seed"),
        (["SPEC", "--replicates", "3"], "--replicates"),
        (["SPEC", "--quick"], "--quick"),
        ([], "--quick"),
        (["--quick", "--lab", "LAB_BACK"], "axial_strain"),
        (["--quick", "--lab", "LAB_COLUMNS"], "lab columns"),
        (["--quick", "--lab", "missing.csv"], "lab"),
        (["--quick", "--particle-friction", "-1"], "--particle-friction"),
    ],
)
def test_bad_input_is_refused_on_one_line(argv, words, specimen, tmp_path, capsys, monkeypatch):
    import poro2d.biaxial.single as single

    def no_work(self):
        raise AssertionError("a test started before the input was checked")

    monkeypatch.setattr(single.BiaxialTest, "run", no_work)
    back = tmp_path / "back.csv"
    back.write_text("axial_strain,stress_ratio\n0,0\n0.01,0.2\n0.02,0.3\n0.01,0.35\n0.04,0.3\n")
    cols = tmp_path / "cols.csv"
    cols.write_text("strain,q\n0.01,0.3\n0.02,0.35\n")
    files = {"SPEC": str(specimen), "LAB_BACK": str(back), "LAB_COLUMNS": str(cols)}
    args = ["biaxial", *(files.get(a, a) for a in argv), "--out", str(tmp_path / "out"), "--quiet"]
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err, err
    assert not (tmp_path / "out").exists()


def test_a_folder_of_another_kind_is_refused_before_any_work(tmp_path, capsys):
    from poro2d.locks import output_folder

    out = tmp_path / "shear-out"
    with output_folder("--out", out, kind="shear"):
        (out / "result.json").write_text("{}")
    with pytest.raises(SystemExit) as exc:
        main(["biaxial", "--quick", "--out", str(out), "--quiet"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "shear" in err and "biaxial" in err, err
    assert (out / "result.json").read_text() == "{}"


@pytest.mark.parametrize(
    ("make", "name"),
    [
        (lambda: run_biaxial("crit"), "case"),
        (lambda: run_biaxial(BiaxialCase.quick(100.0), replicates=0), "replicates"),
        (lambda: run_biaxial(BiaxialCase.quick(100.0), replicates="2"), "replicates"),
        (lambda: run_biaxial(BiaxialCase.quick(100.0), lab=5), "lab"),
        (lambda: run_biaxial(BiaxialCase.quick(100.0), store="out"), "store"),
        (lambda: run_biaxial(BiaxialCase.quick(100.0), options=RunOptions(progress=None)), "progress"),
        (lambda: run_biaxial([BiaxialCase.quick(100.0), BiaxialCase.quick(50.0, seed=1)]), "case"),
        (lambda: BiaxialSettings(max_strain=0.9), "max_strain"),
        (lambda: BiaxialSettings(record_strain=0.2, max_strain=0.1), "record_strain"),
        (lambda: BiaxialSettings(strain_rate=float("nan")), "strain_rate"),
        (lambda: BiaxialSettings(critical_window=0.01), "critical_window"),
        (lambda: BiaxialCase.quick(5000.0), "confining stress"),
        (lambda: BiaxialCase.quick(100.0, seed=-1), "seed"),
        (lambda: BiaxialCase("crit", 100.0, BiaxialSettings()), "specimen"),
    ],
)
def test_bad_api_input_names_its_parameter(make, name):
    with pytest.raises(InputError) as exc:
        make()
    assert exc.value.parameter.startswith(name), exc.value
