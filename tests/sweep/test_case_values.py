"""Cases are values: read once from a config, varied with ``replace``, named as before.

The ids pinned here name the folders that ``poro2d relation --preset paper --quick`` wrote
before its cases were values (the calibration's cases in ``$PORO2D_CACHE`` and the state
checks in ``states/cases``): a changed id would lose every user's cached cases.
"""

import json
from dataclasses import FrozenInstanceError, replace

import pytest

from poro2d.criterion.config import paper_preset
from poro2d.criterion.density import DEFAULT_MUS, StateTarget
from poro2d.paper_data import QUICK_SPECIMEN
from poro2d.sweep.criterion_base import CriterionBase
from poro2d.sweep.density import CalibrationCase, StateChecks, with_density_defaults
from poro2d.sweep.relation import relation_base

QUICK_CALIBRATION_CASES = [
    "00ec77aceddb", "1292d5ae9290", "1d3fd41d677c", "3fbdd92ed62b", "50bf11cf79ac", "677573621e63",
    "6fd61f51db39", "75124bacab82", "819288dda6c9", "824df1ec5ddb", "8709fac4173a", "9b4f8dd06611",
    "9c70064d2f6b", "bdd643522293", "c15cb1f71860", "c284076ca3f6", "d2c6c7d2f4fc", "ff0235861318",
]  # fmt: skip


def _quick_states_base() -> CriterionBase:
    return with_density_defaults(
        relation_base(CriterionBase.from_config(paper_preset().as_config()), quick=True)
    )


def test_the_quick_relations_cases_keep_the_ids_naming_their_folders():
    calibration = CalibrationCase(_quick_states_base(), DEFAULT_MUS, 3)
    assert sorted(c.id for c in calibration.sweep.cases) == QUICK_CALIBRATION_CASES
    loose = StateTarget(0.4571, 0.0, 0.2561, 1.0)  # first trial 0.256 on the 0.001 grid
    (check,) = StateChecks(_quick_states_base(), (loose,), 1, 0.001).sweep.cases
    assert check.id == "42f1517e793a"
    assert check.params == {"criterion.n_lab": 0.4571, "specimen.friction_prep": 1.0,
                            "criterion.trial_porosity": 0.256, "seed": 0}  # fmt: skip


def test_a_base_is_varied_never_changed():
    given = paper_preset().as_config()
    base = CriterionBase.from_config(dict(given, relation={"n_max": 0.45}))
    quick = relation_base(base, quick=True)
    assert base.config == given and "relation" not in base.config
    assert quick.config["specimen"] == QUICK_SPECIMEN and "n_lab" not in quick.config["criterion"]
    assert list(quick.config) == list(given)  # the tables keep their places
    with pytest.raises(FrozenInstanceError):
        base.base_dir = None  # type: ignore[misc]


def test_fewer_frictions_are_the_same_calibrations_cases():
    calibration = CalibrationCase(_quick_states_base(), DEFAULT_MUS, 3)
    ends = replace(calibration, mus=(0.0, 1.0), seeds=2)
    assert ends.key == calibration.key  # one cache entry: its finished cases are read back
    assert {c.id for c in ends.sweep.cases} < {c.id for c in calibration.sweep.cases}


def test_a_cases_merged_config_and_id_are_pinned():
    """A case's parameters set on the base in their order (new tables and keys after the given
    ones): its config as ``params.json`` records it and its id (its folder's name) are pinned."""
    from poro2d.sweep.cases import parse_sweep

    axes = {"n_lab": [0.33, 0.36], "specimen": {"friction_particle": [1.0, 3.0]}, "seed": [0, 4]}
    grid = {"seed": 1, "specimen": {"width": 0.1}, "criterion": {"n_lab": 0.35}, "sweep": axes}
    ids = [c.id for c in parse_sweep(grid, validate=False).cases]
    assert ids[:4] == ["c99f95fb9d5a", "25d70fb850e2", "b8df56b1f5d7", "922fa686999d"]
    cases = [{"n_lab": 0.33, "specimen.kn_particle": 2e5}, {"seed": 3, "grading.upscale": 2.0}]
    listed = {"title": "t", "criterion": {"resolution": 0.01}, "sweep": {"cases": cases, "figures": True}}
    first, second = parse_sweep(listed, validate=False).cases
    assert (first.id, second.id) == ("50a322f82efc", "0b07a550582f")
    assert json.dumps(first.config) == (
        '{"criterion": {"resolution": 0.01, "n_lab": 0.33}, "specimen": {"kn_particle": 200000.0}, '
        '"sweep_options": {"figures": true}}'
    )
    assert json.dumps(second.config) == (
        '{"criterion": {"resolution": 0.01}, "seed": 3, "grading": {"upscale": 2.0}, '
        '"sweep_options": {"figures": true}}'
    )
