"""Direct shear over replicate specimens: seed statistics and the fit's confidence intervals."""

import json
import math

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.shear.replicates import mohr_coulomb_ci, summarize_replicate_peaks


@pytest.mark.parametrize("through_origin", [False, True])
def test_intervals_cover_the_true_angle_at_their_level(through_origin):
    """Monte Carlo: lines of known phi and c plus Gaussian noise; the 95 % interval of phi
    must contain the true angle in about 95 % of the draws (binomial bounds for 2000)."""
    rng = np.random.default_rng(7)
    phi, c = 35.0, 0.0 if through_origin else 8.0
    sig = np.repeat([50.0, 100.0, 200.0], 3)
    hits_phi = hits_c = 0
    n = 2000
    for _ in range(n):
        tau = c + sig * math.tan(math.radians(phi)) + rng.normal(0.0, 6.0, sig.size)
        f = mohr_coulomb_ci(sig, tau, through_origin=through_origin)
        lo, hi = f.friction_angle_ci_deg
        hits_phi += lo <= phi <= hi
        if not through_origin:
            clo, chi = f.cohesion_ci_kpa
            hits_c += clo <= c <= chi
    # 95 % +- 3.5 standard errors of a binomial proportion over 2000 draws
    assert abs(hits_phi / n - 0.95) < 3.5 * math.sqrt(0.95 * 0.05 / n)
    if not through_origin:
        assert abs(hits_c / n - 0.95) < 3.5 * math.sqrt(0.95 * 0.05 / n)


def test_exact_points_give_a_zero_width_interval_and_two_points_none():
    sig = [50.0, 100.0, 200.0]
    f = mohr_coulomb_ci(sig, [10 + 0.7 * s for s in sig])
    assert f.friction_angle_deg == pytest.approx(math.degrees(math.atan(0.7)))
    assert f.friction_angle_ci_deg == pytest.approx([f.friction_angle_deg] * 2)
    f2 = mohr_coulomb_ci([50.0, 100.0], [40.0, 75.0])
    assert f2.dof == 0 and f2.friction_angle_ci_deg is None
    with pytest.raises(InputError):
        mohr_coulomb_ci(sig, [1.0, 2.0, 3.0], level=1.5)


def _series(peaks, phi):
    return {"tests": [{"normal_stress_kpa": s, "peak_shear_stress_kpa": p} for s, p in peaks.items()],
            "friction_angle_deg": phi}  # fmt: skip


def test_summary_over_specimens():
    series = {
        "seed0": _series({50.0: 40.0, 100.0: 75.0, 200.0: 150.0}, 36.0),
        "seed1": _series({50.0: 44.0, 100.0: 71.0, 200.0: 140.0}, 34.0),
        "seed2": _series({50.0: 42.0, 100.0: 79.0, 200.0: 145.0}, 35.0),
    }
    s = summarize_replicate_peaks(series)
    rows = {r.normal_stress_kpa: r for r in s.per_normal_stress}
    assert rows[50.0].peak_mean_kpa == pytest.approx(42.0)
    assert rows[50.0].peak_sd_kpa == pytest.approx(2.0)
    assert rows[200.0].n == 3
    assert s.fit.n_points == 9 and s.fit.dof == 7
    lo, hi = s.fit.friction_angle_ci_deg
    assert lo < s.fit.friction_angle_deg < hi
    assert s.friction_angle_mean_deg == pytest.approx(35.0) and s.friction_angle_sd_deg == pytest.approx(1.0)
    with pytest.raises(InputError):
        summarize_replicate_peaks({})


def test_replicate_series_on_small_specimens(tmp_path):
    """Two specimens (two seeds), two stresses each, one pool: the summary matches each series."""
    from poro2d.dem import checkpoint
    from poro2d.report.shear_figures import draw_replicate_shear
    from poro2d.shear import ShearSettings
    from poro2d.shear.replicates import ReplicateShear
    from poro2d.shear.results import ReplicateShearResult
    from poro2d.specimen import paper_grading
    from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen
    from poro2d.specimen.specimen_set import SpecimenSet
    from poro2d.store import Store

    specimens = {}
    for seed in (0, 1):
        sim, rep = prepare_specimen(
            SpecimenSpec(width=0.06, height=0.03, layers=2), paper_grading(), 0.2, seed
        )
        assert rep.converged
        specimens[f"seed{seed}"] = tmp_path / f"s{seed}.npz"
        checkpoint.save(sim, specimens[f"seed{seed}"])
    short = {"max_displacement": 0.002, "peak_window": 5e-4, "checkpoint_interval": 5e-4}
    out = tmp_path / "rep"
    res = ReplicateShear(
        SpecimenSet.accepted(specimens),
        [50, 100],
        ShearSettings(**short),
        store=Store(out),
        options=RunOptions(workers=2, progress=False),
    ).run()
    assert isinstance(res, ReplicateShearResult) and "series" not in res.to_dict()
    assert res.to_dict() == json.loads((out / "replicates.json").read_text())
    peaks = {k: [t.peak_shear_stress_kpa for t in s.tests] for k, s in res.series.items()}
    assert peaks["seed0"] != peaks["seed1"]  # two specimens, two samples of the strength
    row = res.per_normal_stress[0]
    assert row.normal_stress_kpa == 50.0
    assert row.peak_mean_kpa == pytest.approx(np.mean([peaks["seed0"][0], peaks["seed1"][0]]))
    assert res.fit.n_points == 4
    draw_replicate_shear(res, Store(out))  # the figures, as the command draws them after the run
    files = [
        "replicates.json",
        "replicates.csv",
        "fig8a_shear_curves_replicates.png",
        "fig8b_peak_strength_replicates.png",
        "seed0/result.json",
        "seed1/sn100kPa/result.json",
    ]
    for f in files:
        assert (out / f).stat().st_size > 0, f
