"""A specimen just out of balance is cycled further and checked again before it is refused."""

import pytest

from poro2d.criterion import CriterionSettings, PorosityCriterion
from poro2d.criterion.protocol import BALANCE_MARGIN, balance_budget
from poro2d.specimen import paper_grading
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.store import Store

SMALL = SpecimenSpec(width=0.06, height=0.03, layers=2)


def _run(store=None, **kw):
    settings = CriterionSettings(trial_porosity=0.21, force_fraction=0.05, **kw)
    return PorosityCriterion(SMALL, paper_grading(), settings, seed=0, store=store).run()


@pytest.fixture(scope="module")
def balanced():
    """The trial as the default tolerance accepts it at once, with its force-balance error."""
    res = _run()
    (trial,) = res.iterations
    assert res.converged and trial.balance_steps is None
    return trial.check_numbers.force_balance_error


def test_a_specimen_just_past_the_balance_limit_is_cycled_and_accepted(balanced, tmp_path):
    # the same specimen held to a limit it misses by a third: before, refused at once
    res = _run(Store(tmp_path), balance_tolerance=balanced / 1.5)
    (trial,) = res.iterations
    assert res.converged, res.message
    assert 0 < trial.balance_steps <= balance_budget(res.settings)
    assert trial.check_numbers.force_balance_error <= res.settings.balance_tolerance
    assert f"at most {BALANCE_MARGIN:g} x its tolerance" in trial.decision.reason
    row = trial.to_dict()
    assert row["balance_steps"] == trial.balance_steps and row["checks"]["force_balance"]
    # the accepted specimen is the state cycled further, kept beside the prepared one
    assert (tmp_path / "trials" / "01_n0.2100" / "after_plate.npz").is_file()
    assert (tmp_path / "specimen.npz").is_file()
    # a rerun reads the trial back as it was decided
    again = _run(Store(tmp_path), balance_tolerance=balanced / 1.5)
    assert again.iterations[0].to_dict() == row


def test_a_specimen_far_out_of_balance_is_refused_without_cycling(balanced):
    res = _run(balance_tolerance=balanced / (2 * BALANCE_MARGIN))
    (trial,) = res.iterations
    assert not res.converged and trial.decision.refused and trial.balance_steps is None
    assert "balance_steps" not in trial.to_dict()
    assert "vertical forces out of balance" in res.message
