"""Calibrating the disks' stiffness beside the frictions (``kn_range``, ``ks_range``): a
four-parameter calibration of tiny specimens recovers a synthetic laboratory's known truth within
its intervals, and says how little the curves tell of the stiffness."""

from __future__ import annotations

import json
import shutil

import pytest

from poro2d.calibration import synthetic_lab
from poro2d.calibration.run import CalibrationResult
from poro2d.cli.shear import load_shear_config
from poro2d.dem import checkpoint
from poro2d.execute.options import RunOptions
from poro2d.report.calibration_figures import draw_calibration
from poro2d.specimen import paper_grading
from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen
from poro2d.store import Store
from tests.calibration import calibrate

ONE_WORKER = RunOptions(workers=1, dashboard=None, progress=False)

SHORT = {"max_displacement": 0.002, "peak_window": 5e-4, "checkpoint_interval": 5e-4, "record_interval": 5e-5}
#: the synthetic laboratory's truth: Table 1's disks are 4e5 N/m in both directions
TRUTH = {"particle_friction": 0.8, "rolling_friction": 0.15, "particle_kn": 8e5, "particle_ks": 2e5}
KN_RANGE, KS_RANGE = (1e5, 4e6), (5e4, 2e6)


@pytest.fixture(scope="module")
def stiff_lab(specimen, tmp_path_factory):
    """Two tiny specimens (seeds 0 and 1) and a synthetic laboratory's curves on seed 2 at ``TRUTH``
    (stresses only: the rise is left out, so that 10 observables suit 2 replicates of 18 points)."""
    root = tmp_path_factory.mktemp("stiff")
    paths = [root / "seed0.npz", root / "seed1.npz", root / "seed2.npz"]
    shutil.copyfile(specimen, paths[0])
    for seed in (1, 2):
        sim, rep = prepare_specimen(SpecimenSpec(width=0.06, height=0.03, layers=2), paper_grading(), 0.2,
                                    seed=seed)  # fmt: skip
        assert rep.converged
        checkpoint.save(sim, paths[seed])
    made = synthetic_lab(paths[2], [50, 100], 0.8, 0.15, root / "lab_rise.csv", settings=SHORT,
                         particle_kn=TRUTH["particle_kn"], particle_ks=TRUTH["particle_ks"])  # fmt: skip
    lines = made.read_text().splitlines()
    assert "particle_kn = 800000.0" in lines[2]
    lab = root / "lab.csv"
    lab.write_text("\n".join(ln if ln.startswith("#") else ln.rsplit(",", 1)[0] for ln in lines) + "\n")
    return paths[:2], lab


@pytest.mark.scenario
def test_four_parameters_recover_a_known_truth_within_their_intervals(stiff_lab, tmp_path):
    specimens, lab = stiff_lab
    out = tmp_path / "cal"
    kw = dict(points=18, refine=4, settings=SHORT, stations=4, kn_range=KN_RANGE, ks_range=KS_RANGE,
              options=ONE_WORKER, keep_box_dominated=True)  # fmt: skip
    res = calibrate(lab, specimens, store=Store(out), **kw)
    draw_calibration(res, Store(out))  # the figures and the report, as the command draws them
    for name, value in TRUTH.items():
        lo, hi = getattr(res.intervals, name)
        assert lo <= value <= hi, (name, value, lo, hi)
        assert lo <= getattr(res.posterior.median, name) <= hi
    # the stiffness moves the curve's first slope, hardly its peak: its interval spans decades
    for name, (r_lo, r_hi) in (("particle_kn", KN_RANGE), ("particle_ks", KS_RANGE)):
        lo, hi = getattr(res.intervals, name)
        assert r_lo <= lo < hi <= r_hi and hi / lo > 2.0
    chain = res.posterior.chain
    assert chain.walkers == 32 and chain.steps - chain.burn_in >= 50 * max(chain.autocorrelation_steps)
    assert res.posterior.grid is None and "log(kn)" in res.posterior.prior
    assert all(e.particle_kn is not None and e.particle_ks is not None for e in res.evaluations)
    assert len(res.evaluations) <= 22 and res.cluster.tests_run == len(res.evaluations) * 2 * 2
    # the file reads back as written, kn and ks in every record
    data = json.loads((out / "result.json").read_text())
    assert res.to_dict() == data and CalibrationResult.from_dict(data).to_dict() == data
    assert data["ranges"]["particle_kn"] == list(KN_RANGE) and "particle_ks" in data["best"]
    # calibrated.toml: a [shear] table poro2d shear reads, and the [specimen] stiffness
    table, _ = load_shear_config(out / "calibrated.toml")
    assert table["particle_kn"] == res.best.particle_kn
    text = (out / "calibrated.toml").read_text()
    assert f"kn_particle = {res.best.particle_kn!r}" in text and "ks_particle = " in text
    assert (out / "calibration_posterior.png").stat().st_size > 0
    assert "disk normal stiffness" in (out / "calibration.md").read_text()
    # the same inputs give the same numbers bit for bit (every test from the cache, the same chain)
    again = calibrate(lab, specimens, store=Store(out), **kw)
    assert (
        again.cluster.tests_run == 0
        and again.best.to_dict() == res.best.to_dict()
        and again.intervals.to_dict() == res.intervals.to_dict()
    )
    assert again.posterior.median.to_dict() == res.posterior.median.to_dict()
