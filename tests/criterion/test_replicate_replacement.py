"""A replicate seed the criterion does not accept is replaced by the next unused seed."""

import pytest

from poro2d.criterion import replicates
from poro2d.criterion.protocol import BALANCE_MARGIN, CriterionSettings
from poro2d.criterion.replicates import ReplicateCase, run_replicates
from poro2d.criterion.result import ReplicateRow
from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.specimen import paper_grading
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.store import Store

SERIAL = RunOptions(workers=1, progress=False)
SMALL = SpecimenSpec(width=0.06, height=0.03, layers=2)
#: the seeds the stand-in run refuses
REFUSED = {2, 3}


def stand_in(case, seed, store, report):
    """A replicate run that refuses the seeds in REFUSED (module level: the executor pickles it)."""
    ok = seed not in REFUSED
    return ReplicateRow(
        seed, 0.2 if ok else None, ok, 1, "" if ok else "check x failed", store.root.name, 0.0
    )


def case(seeds, replacements, **settings) -> ReplicateCase:
    return ReplicateCase(SMALL, paper_grading(), CriterionSettings(**settings), 0.21, seeds, replacements)


def test_a_refused_seed_is_replaced_until_the_number_asked_is_accepted(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(replicates, "_run_one", stand_in)
    res = run_replicates(case((1, 2), 3), Store(tmp_path), options=SERIAL)
    # 2 refused: 3 in its place, refused too: 4 in its place; 5 never runs
    assert [r.seed for r in res.rows] == [1, 2, 3, 4]
    assert res.seeds_used == [1, 4] and res.seeds_replaced == [2, 3]
    printed = capsys.readouterr().out
    assert "replicate seed 2 not accepted (check x failed): seed 3 in its place" in printed
    assert "replicate seed 3 not accepted (check x failed): seed 4 in its place" in printed
    assert "only" not in printed


def test_no_seed_is_tried_when_all_are_accepted(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(replicates, "_run_one", stand_in)
    res = run_replicates(case((1, 4), 3), Store(tmp_path), options=SERIAL)
    assert [r.seed for r in res.rows] == [1, 4] and res.seeds_replaced == []
    assert capsys.readouterr().out == ""


def test_replacements_spent_say_so_on_one_line(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(replicates, "_run_one", stand_in)
    res = run_replicates(case((1, 2), 1), Store(tmp_path), options=SERIAL)
    assert [r.seed for r in res.rows] == [1, 2, 3] and res.seeds_used == [1]
    printed = capsys.readouterr().out
    assert "only 1 of 2 replicate seeds accepted (1 replacement(s) tried, at most 1)" in printed


def test_a_real_refusal_is_replaced_by_the_next_seed(tmp_path, capsys):
    """A force-balance limit of 1e-6: seed 3 ends 1.3e-4 out of balance (past the re-check's
    margin) and is refused by the criterion itself; seed 4, 3.9e-11, is accepted in its place.
    (Chaotic packings: before the engine fused its products and sums, seeds 0 and 1.)"""
    assert 1e-6 * BALANCE_MARGIN < 1.3e-4
    limit = {"trial_porosity": 0.21, "force_fraction": 0.05, "balance_tolerance": 1e-6}
    res = run_replicates(case((3,), 1, **limit), Store(tmp_path), options=SERIAL)
    assert [r.seed for r in res.rows] == [3, 4] and res.seeds_used == [4] and res.seeds_replaced == [3]
    assert "vertical forces out of balance" in res.rows[0].message
    assert list(res.specimens) == ["seed4"] and res.specimens["seed4"].is_file()
    printed = capsys.readouterr().out
    assert "replicate seed 3 not accepted (" in printed and "seed 4 in its place" in printed
    assert "only" not in printed
    # a rerun reads both seeds back and tries no third
    again = run_replicates(case((3,), 1, **limit), Store(tmp_path), options=SERIAL)
    assert [(r.seed, r.converged, r.final_porosity) for r in again.rows] == [
        (3, False, None),
        (4, True, 0.21),
    ]


def test_replacements_are_checked():
    with pytest.raises(InputError, match="replacements"):
        case((1,), -1)
