"""Repeats of a laboratory programme: their mean is fitted and the laboratory's share of the
noise is one simulated specimen's scatter over their number, never less than their own scatter."""

import numpy as np
import pytest

from poro2d.calibration import model
from poro2d.calibration.lab_repeats import LabRepeats, lab_scatter_ratio, lab_share, mean_targets
from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.shear import LabData

RANGES = model.Ranges((0.3, 3.0), (0.0, 0.5))


def _peaks(source: str, peaks: dict) -> LabData:
    return LabData(source, peaks)


def test_the_seed_term_of_the_noise_is_the_lab_share_plus_the_replicates_mean():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(3, 3))
    seed = a @ a.T + np.eye(3)
    s = [model.Surrogate(np.zeros(model.N_COEFFICIENTS), 0.0, 0.0, 4) for _ in range(3)]
    one = model.noise_covariance(s, seed, [1.0, 2.0, 3.0], 0.0)
    third = model.noise_covariance(s, seed, [1.0, 2.0, 3.0], 0.0, lab_share=1.0 / 3.0)
    ridge = one - seed * 1.25  # the tiny ridge against a singular matrix is the same in both
    assert np.allclose(third - ridge, seed * (1.0 / 3.0 + 0.25))
    assert np.array_equal(one, model.noise_covariance(s, seed, [1.0, 2.0, 3.0], 0.0, lab_share=1.0))


def test_three_repeats_narrow_a_linear_posterior_by_the_square_root_of_the_noise():
    # two observables linear in the unit coordinates, replicates exactly +-0.5 around them: the
    # misfit covariance is seed x (share + 1/2), and an interval scales with its square root
    design = RANGES.to_unit(*np.array(model.space_filling(RANGES, 12, 0)).T)
    funcs = [lambda x: 40.0 + 6.0 * x[:, 0] + 1.0 * x[:, 1], lambda x: 30.0 + 1.0 * x[:, 0] + 6.0 * x[:, 1]]
    values = np.stack([np.column_stack([f(design) - 0.5, f(design) + 0.5]) for f in funcs], axis=1)
    sg = [model.fit_surrogate(design, values[:, k]) for k in range(2)]
    lab = [float(f(np.array([[0.5, 0.5]]))[0]) for f in funcs]
    seed = model.seed_covariance(values)
    widths = []
    for share in (1.0, 1.0 / 3.0):
        post = model.posterior(RANGES, sg, lab, model.noise_covariance(sg, seed, lab, 0.0, lab_share=share))
        lo, hi = post.interval("mu_r", 0.95)
        widths.append(hi - lo)
    assert widths[1] / widths[0] == pytest.approx(np.sqrt((1 / 3 + 0.5) / 1.5), rel=0.06)


def test_the_mean_of_the_repeats_is_fitted_and_their_values_kept():
    a = [("peak", 50.0, 40.0), ("end", 50.0, 30.0)]
    b = [("peak", 50.0, 44.0), ("end", 50.0, 28.0)]
    targets, values = mean_targets([a, b])
    assert targets == [("peak", 50.0, 42.0), ("end", 50.0, 29.0)]
    assert values.tolist() == [[40.0, 30.0], [44.0, 28.0]]


def test_repeats_noisier_than_the_specimens_widen_the_lab_share():
    rng = np.random.default_rng(3)
    seed = np.diag(np.full(40, 4.0))  # kPa^2
    calm = rng.normal(0.0, 2.0, size=(3, 40))  # the laboratory scatters as a specimen does
    loud = rng.normal(0.0, 6.0, size=(3, 40))  # nine times the variance
    assert lab_scatter_ratio(calm, seed) == pytest.approx(1.0, abs=0.35)
    assert lab_scatter_ratio(loud, seed) == pytest.approx(9.0, rel=0.35)
    assert lab_scatter_ratio(calm[:1], seed) is None
    assert lab_share(3, 0.4) == pytest.approx(1 / 3) and lab_share(3, 9.0) == pytest.approx(3.0)
    assert lab_share(1, None) == 1.0


def test_repeats_of_another_programme_are_refused_naming_the_file():
    a = _peaks("a.csv", {50.0: 40.0, 100.0: 70.0})
    with pytest.raises(InputError, match=r"b\.csv.*normal stresses"):
        LabRepeats.of([a, _peaks("b.csv", {50.0: 41.0, 200.0: 130.0})])
    d = np.linspace(0.0, 2e-3, 5)
    curves = LabData("c.csv", {50.0: 40.0}, {50.0: (d, 20e3 * d)})
    with pytest.raises(InputError, match=r"c\.csv.*kind"):
        LabRepeats.of([_peaks("a.csv", {50.0: 40.0}), curves])
    with pytest.raises(InputError, match="--lab"):
        LabRepeats.of([])
    both = LabRepeats.of([a, _peaks("b.csv", {50.0: 44.0, 100.0: 74.0})])
    assert both.count == 2 and both.source == "a.csv; b.csv" and both.normal_stresses() == [50.0, 100.0]
    assert [p.peak_shear_stress_kpa for p in both.record().peaks] == [42.0, 72.0]
    assert LabRepeats.of(a).record().to_dict() == a.record().to_dict()


def test_the_command_refuses_repeats_of_another_programme_on_one_line(tmp_path, capsys):
    first, other = tmp_path / "a.csv", tmp_path / "b.csv"
    first.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,70\n200,130\n")
    other.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,41\n100,72\n")
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as exc:
        main(["calibrate", "--lab", str(first), "--lab", str(other), "--preset", "paper", "--out", str(out)])
    text, err = capsys.readouterr()
    assert exc.value.code == 2 and not text
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "b.csv" in lines[0] and "normal stresses" in lines[0], lines
    assert not out.exists() or not any(out.iterdir())


def test_the_report_says_how_many_repeats_and_whether_their_share_was_scaled():
    from types import SimpleNamespace

    from poro2d.report.calibration_report import repeats_note

    def result(**posterior):
        return SimpleNamespace(posterior=SimpleNamespace(**{"lab_repeats": None, **posterior}))

    assert repeats_note(result(precision_factor=0.6)) is None
    calm = repeats_note(result(lab_repeats=3, lab_scatter_ratio=0.5))
    assert calm.startswith("3 laboratory repeats") and "0.33 of one" in calm and "scaled" not in calm
    loud = repeats_note(result(lab_repeats=3, lab_scatter_ratio=2.4))
    assert "scaled up by 2.40" in loud and "0.80 of one" in loud
