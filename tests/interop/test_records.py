"""The interop readers hand typed records on, never a file's raw JSON or a dump as a dict."""

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.interop.lammps_run import LammpsError, read_dump
from poro2d.interop.provenance_records import GradingFacts
from poro2d.interop.run_records import CaseParams, SandRecord, StatePoint, StatesRecord
from poro2d.specimen.accepted import CriterionOutcome

_DUMP = """ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS pp pp pp
0 1
0 1
-0.5 0.5
ITEM: ATOMS id x y radius
1 0.1 0.2 0.01
2 0.3 0.4 0.02
ITEM: TIMESTEP
100
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS pp pp pp
0 1
0 1
-0.5 0.5
ITEM: ATOMS id x y radius
2 0.35 0.45 0.02
1 0.15 0.25000000000000006 0.01
"""


def test_a_dump_is_read_as_its_last_frame_with_columns_by_name(tmp_path):
    path = tmp_path / "final.dump"
    path.write_text(_DUMP)
    frame = read_dump(path)
    assert frame.columns == ("id", "x", "y", "radius")
    assert frame.values.shape == (2, 4)
    assert np.array_equal(frame.column("id"), [2.0, 1.0])  # the last snapshot, in its own order
    assert frame.column("y")[1] == 0.25000000000000006  # every digit as written
    frame.column("x")[0] = -1.0  # a copy: the frame is not changed through it
    assert frame.column("x")[0] == 0.35
    with pytest.raises(LammpsError, match=r"no column 'vx' \(it has id x y radius\)"):
        frame.column("vx")


def test_a_criterion_outcome_keeps_what_acceptance_needs_and_quotes_values_as_written():
    ok = CriterionOutcome.from_json(
        {"converged": True, "iterations": [{"accepted": False}, {"accepted": True}]}
    )
    assert ok.converged.true and ok.accepted_trial and ok.converged.said == "True" and not ok.names_seed
    odd = CriterionOutcome.from_json({"converged": "yes", "iterations": "all", "seed": 1.5, "message": None})
    assert not odd.converged.true and odd.converged.said == "yes" and not odd.accepted_trial
    assert odd.names_seed and odd.seed is None and odd.message == "None"  # a seed of another kind: unknown
    assert CriterionOutcome.from_json({}).converged.said is None  # not a criterion's result


def test_case_parameters_given_later_win_key_by_key():
    sweep = CaseParams.from_json({"criterion.n_lab": 0.4, "seed": 2, "other": 1})
    row = CaseParams.from_json({"seed": "two"})
    merged = sweep.then(row)
    assert merged.n_lab == 0.4 and merged.seed == "two"  # the row names a seed: its own, as written
    assert merged.given == {"criterion.n_lab", "seed"}
    assert CaseParams.from_json(["not", "an", "object"]) == CaseParams(frozenset())


def test_a_states_record_reads_points_seed_and_calibration_place():
    data = {
        "mode": "density",
        "points": [
            {"n_lab": 0.4, "relative_density": 0.5, "mu_prep": 0.3, "seeds": 2},
            "junk",
            {"n_lab": "x"},
        ],
        "config": {"seed": 3},
        "sweeps": {"calibration": {"cases": "/cache/cal"}},
    }
    rec = StatesRecord.from_json(data)
    assert rec.mode == "density" and rec.config_seed == 3 and rec.calibration_cases == "/cache/cal"
    assert rec.points == (StatePoint(0.4, 0.5, 0.3, 2), StatePoint(None, None, None, None))
    assert StatesRecord.from_json({"points": 7}).points == ()  # a record of another shape names nothing
    assert StatesRecord.from_json({}).config_seed == 0  # no seed in the config: the config's default
    assert StatesRecord.from_json({"config": {"seed": True}}).config_seed is None
    one = StatesRecord.from_json({"n_lab": 0.41, "seeds": 1}, one_state=True)
    assert one.points == (StatePoint(0.41, None, None, 1),)


def test_a_sand_record_refuses_a_state_without_n_lab_naming_it(tmp_path):
    record = tmp_path / "sand.json"
    rec = SandRecord.from_json(
        {"states": [{"n_lab": 0.4, "seed": 0, "specimen": "s0", "accepted": False}]}, record
    )
    assert rec.states[0].refusal == "sand.json says accepted = False" and rec.states[0].specimen == "s0"
    with pytest.raises(InputError, match=r"sand.json states\[0\] = 'x' is invalid"):
        SandRecord.from_json({"states": ["x"]}, record)
    with pytest.raises(InputError, match="has a list 'states'"):
        SandRecord.from_json({"states": {}}, record)


def test_grading_facts_of_each_kind_of_config():
    preset = GradingFacts.from_json({"config": {}, "run": {"grading": {"source": "data/paper.csv"}}})
    assert (preset.kind, preset.name, preset.source, preset.upscale) == (
        "preset",
        "paper",
        "data/paper.csv",
        10.0,
    )
    csv = GradingFacts.from_json({"config": {"grading": {"csv": "s.csv", "upscale": 5, "d_min_mm": 1.5}}})
    assert (csv.kind, csv.upscale, csv.cuts) == ("csv", 5.0, (("d_min_mm", 1.5),))
    sizes = GradingFacts.from_json({"config": {"grading": {"sizes_mm": [1, 2, 4], "upscale": "big"}}})
    assert (sizes.kind, sizes.sizes, sizes.upscale) == ("sizes", 3, None)
    assert GradingFacts.from_json({"run": {}}).kind == "unknown"  # no config given
