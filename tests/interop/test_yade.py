"""The exported YADE script runs in YADE (Debian's ``yade``) and agrees with poro2d at rest.

The specimen is the paper's accepted one (``poro2d criterion --preset paper``: 2440 disks at
n2D = 0.19, G = 796.4 N/m), rebuilt from its accepted trial: the criterion seeds each trial by
its porosity, so a run whose first trial is 0.19 builds the very same packing in one trial.
"""

import os
import shutil

import pytest

from poro2d.criterion.config import paper_preset
from poro2d.criterion.protocol import PorosityCriterion
from poro2d.interop.agreement import settle_poro2d
from poro2d.interop.settled import RestCase
from poro2d.interop.specimen_data import from_checkpoint
from poro2d.interop.yade_run import settle_yade
from poro2d.store import Store

pytestmark = pytest.mark.scenario

ACCEPTED_N2D = 0.19  # the paper preset's accepted trial (docs/criterion.md)


def _yade() -> None:
    """CI (CI=true) must have YADE; elsewhere the test is skipped without it."""
    if shutil.which("yade") is None and not os.environ.get("YADE_EXE"):
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("CI=true but Debian's yade is not installed (apt-get install -y yade)")
        pytest.skip("YADE is not installed (Debian: apt-get install -y yade; or set YADE_EXE)")


@pytest.fixture(scope="module")
def paper_specimen(tmp_path_factory):
    _yade()
    cfg = paper_preset()
    cfg = cfg.with_tables(criterion=dict(cfg.table("criterion"), trial_porosity=ACCEPTED_N2D))
    spec, grading, settings, seed = cfg.build()
    out = tmp_path_factory.mktemp("paper_criterion")
    result = PorosityCriterion(spec, grading, settings, seed=seed, store=Store(out)).run()
    assert result.converged
    return from_checkpoint(out)


def test_exported_paper_specimen_runs_in_yade_and_agrees_with_poro2d_at_rest(paper_specimen, tmp_path):
    spec = paper_specimen
    g = spec.weight_per_thickness()
    assert spec.n == 2440 and g == pytest.approx(796.4, abs=0.05)  # the paper preset's specimen
    # YADE to a mean unbalanced-force ratio of 1e-6 (about 2500 steps, 3 s); poro2d to a
    # largest ratio of 1e-8: both at rest, the wall forces steady to 1e-5 of G
    theirs = settle_yade(RestCase(spec, ratio=1e-6, max_steps=200_000), tmp_path)
    ours = settle_poro2d(RestCase(spec, ratio=1e-8))
    assert theirs.converged and ours.converged
    assert theirs.yade_version not in (None, "unknown")
    # YADE's walls carry the disks' weight and the plate's push: the masses are the disk masses
    up = theirs.f_bottom_n_per_m + theirs.side_friction_up_n_per_m
    assert up == pytest.approx(g + theirs.f_top_n_per_m, rel=1e-4)
    assert ours.f_top_n_per_m > 0.002 * g  # the plate carries a force: a real comparison
    for key in ("f_top_n_per_m", "f_bottom_n_per_m", "side_friction_up_n_per_m"):
        # the criterion judges F_top against 1 % of G: 1e-4 G is 1 % of that window
        # (measured: 1.2e-7 G for F_top, 8.1e-6 G for F_bottom, 7.4e-6 G for the side friction;
        # stopped as written, at YADE's ratio 1e-3 after 500 steps, F_bottom is 4.8e-4 G off)
        assert abs(getattr(theirs, key) - getattr(ours, key)) < 1e-4 * g, (
            key,
            getattr(theirs, key),
            getattr(ours, key),
        )
    # the plate's force itself to 0.1 % (measured 3e-5)
    assert theirs.f_top_n_per_m == pytest.approx(ours.f_top_n_per_m, rel=1e-3)
