"""The calibration's first trials: one for all under the paper's plate, per friction under the fill."""

from dataclasses import asdict

import pytest

from poro2d.store import Store
from poro2d.sweep import density as D
from poro2d.sweep.criterion_base import CriterionBase

BASE = {"seed": 0, "specimen": {"width": 0.05, "height": 0.025, "layers": 2}}


def _fill(**criterion):
    return dict(BASE, criterion={"acceptance": "fill", "refine_tolerance": 0.002, **criterion})


def _calibration(cfg, mus, seeds):
    return D.CalibrationCase(CriterionBase(cfg), tuple(mus), seeds).sweep


def _trials(cfg, mus, seeds):
    sweep = _calibration(cfg, mus, seeds)
    return {(c.params["specimen.friction_prep"], c.params["seed"]): c.config["criterion"]["trial_porosity"]
            for c in sweep.cases}  # fmt: skip


def test_under_the_plate_every_case_starts_at_0_19():
    trials = _trials(BASE, [0.0, 0.5, 1.0], 2)
    assert len(trials) == 6 and set(trials.values()) == {D.CALIBRATION_FIRST_TRIAL}
    assert D.first_trial({"acceptance": "plate"}, 0.0) == 0.19


def test_under_the_fill_each_friction_starts_from_its_own_first_trial():
    trials = _trials(_fill(), [0.0, 0.05, 0.5, 0.75, 1.0], 3)
    assert len(trials) == 15
    by_mu = {mu: {t for (m, _), t in trials.items() if m == mu} for mu in (0.0, 0.05, 0.5, 0.75, 1.0)}
    # the table's values at its frictions; linear in between (0.75: halfway from 0.202 to 0.216)
    assert by_mu == {0.0: {0.163}, 0.05: {0.171}, 0.5: {0.202}, 0.75: {0.209}, 1.0: {0.216}}


def test_frictions_above_one_start_from_their_measured_answers():
    """2.0 and 5.0 from the n' they were accepted at; 1.5 between; the frictions up to 1.0 as before."""
    trials = _trials(_fill(), [0.0, 1.0, 1.5, 2.0, 5.0], 1)
    assert {mu: t for (mu, _), t in trials.items()} == {
        0.0: 0.163,
        1.0: 0.216,
        1.5: 0.218,
        2.0: 0.221,
        5.0: 0.222,
    }
    # past its last point the table stays flat (np.interp)
    assert D.first_trial({"acceptance": "fill", "refine_tolerance": 0.002}, 8.0) == D.FILL_FIRST_TRIALS[-1][1]


def test_the_first_trial_lies_on_the_grid_the_criterion_steps_on():
    # the paper's 0.01 grid without refinement, half the refined tolerance with it
    assert D.first_trial({"acceptance": "fill"}, 0.0) == 0.16
    assert D.first_trial({"acceptance": "fill", "refine_tolerance": 0.002}, 0.03) == pytest.approx(0.168)
    assert D.first_trial({"acceptance": "fill", "refine_tolerance": 0.004}, 0.03) == pytest.approx(0.168)
    assert D.first_trial({"acceptance": "fill", "resolution": 0.02}, 1.0) == 0.22


def test_a_fill_calibration_reads_back_per_friction_and_seed():
    sweep = _calibration(_fill(), [0.0, 1.0], 2)
    rows = [{"status": "done", "params": c.params,
             "results": {"converged": True, "last_new_porosity": c.config["criterion"]["trial_porosity"]}}
            for c in sweep.cases]  # fmt: skip
    cal = D.calibration_from_rows(rows, [0.0, 1.0], 2)
    assert cal.samples == [[0.163, 0.163], [0.216, 0.216]]


def test_under_the_fill_a_check_at_a_calibration_friction_is_its_calibration_case(tmp_path):
    """Seed for seed, whatever its first trial; a check at a friction between is run."""
    from poro2d.criterion.density import StateTarget
    from poro2d.io_utils import write_json

    cfg = _fill()
    cal = _calibration(cfg, [0.0, 1.0], 2)
    folder = tmp_path / "cal"
    for c in cal.cases:
        row = {"id": c.id, "status": "done", "params": c.params,
               "results": {"n_lab": 0.3434, "converged": True, "final_porosity": c.params["seed"] + 0.1,
                           "last_new_porosity": 0.1631}}  # fmt: skip
        write_json(folder / "cases" / c.id / "params.json", asdict(c), config=True)
        write_json(folder / "cases" / c.id / "result.json", row)
    dense = StateTarget(0.3253, 1.0, 0.1632, 0.0)  # rounds to 0.163, the frictionless first trial
    loose = StateTarget(0.4571, 0.0, 0.2130, 1.0)  # 0.213: not the calibration's 0.216
    between = StateTarget(0.40, 0.5, 0.19, 0.5)
    states = D.StateChecks(CriterionBase(cfg), (dense, loose, between), 2, 0.001).sweep
    twins = D.calibration_twins(cal, states, None, Store(folder))
    assert len(twins) == 4
    got = {(r.params["criterion.n_lab"], r.params["seed"]): r for r in twins}
    assert set(got) == {(0.3253, 0), (0.3253, 1), (0.4571, 0), (0.4571, 1)}
    for (n_lab, seed), r in got.items():
        assert r.results["n_lab"] == n_lab and r.results["final_porosity"] == seed + 0.1
    # under the paper's plate only the same first trial makes a twin (none here: 0.19 vs 0.213)
    plate = dict(BASE, criterion={"refine_tolerance": 0.002})
    cal_p = _calibration(plate, [0.0, 1.0], 2)
    for c in cal_p.cases:
        row = {"id": c.id, "status": "done", "params": c.params, "results": {"converged": True}}
        write_json(tmp_path / "p" / "cases" / c.id / "params.json", asdict(c), config=True)
        write_json(tmp_path / "p" / "cases" / c.id / "result.json", row)
    states_p = D.StateChecks(CriterionBase(plate), (loose,), 2, 0.001).sweep
    assert D.calibration_twins(cal_p, states_p, None, Store(tmp_path / "p")) == []


# Toyoura sand's calibration box, 30 Nov 2026: the ends' accepted n' at mu_prep 0 and 1
TOYOURA_ENDS = ((0.0, 0.16325), (1.0, 0.21941))


def test_a_friction_between_measured_ends_starts_one_tolerance_looser_than_they_place_it():
    fill = {"acceptance": "fill", "refine_tolerance": 0.002}
    (mu_lo, n_lo), (mu_hi, n_hi) = TOYOURA_ENDS
    for mu, table_share in (
        (0.05, (0.171 - 0.163) / (0.216 - 0.163)),
        (0.1, (0.176 - 0.163) / (0.216 - 0.163)),
    ):
        placed = n_lo + table_share * (n_hi - n_lo)
        trial = D.bracket_first_trial(fill, mu, TOYOURA_ENDS)
        # on the grid (half the tolerance), within half a grid step of the placed value + tolerance
        assert trial == pytest.approx(round((placed + 0.002) / 0.001) * 0.001)
        assert trial > placed + 0.0015
    # the measured answers of that box (seeds 0, 1): 0.1736 / 0.1723 at 0.05, 0.1778 / 0.1788 at 0.1
    assert D.bracket_first_trial(fill, 0.05, TOYOURA_ENDS) == pytest.approx(0.174)
    assert D.bracket_first_trial(fill, 0.1, TOYOURA_ENDS) == pytest.approx(0.179)
    # without a refined tolerance, the paper's 0.005 on its 0.01 grid
    assert D.bracket_first_trial({"acceptance": "fill"}, 0.05, TOYOURA_ENDS) == pytest.approx(0.18)


def test_measured_ends_move_the_frictions_between_them_and_keep_the_ends_cases():
    cfg = _fill()
    plain = D.CalibrationCase(CriterionBase(cfg), (0.0, 0.05, 0.1, 1.0), 2)
    placed = D.CalibrationCase(CriterionBase(cfg), (0.0, 0.05, 0.1, 1.0), 2, ends=TOYOURA_ENDS)

    def by_mu(case):
        out = {}
        for c in case.sweep.cases:
            p = c.params
            out[p["specimen.friction_prep"], p["seed"]] = (c.id, p["criterion.trial_porosity"])
        return out

    a, b = by_mu(plain), by_mu(placed)
    for key in a:
        if key[0] in (0.0, 1.0):  # the ends: the same cases, already run
            assert a[key] == b[key]
        else:
            assert b[key][1] == D.bracket_first_trial(cfg["criterion"], key[0], TOYOURA_ENDS)
            assert b[key][0] != a[key][0]
    assert placed.key == plain.key  # one cache entry: the calibration is the same


def test_ends_where_the_table_is_flat_place_a_friction_halfway():
    fill = {"acceptance": "fill", "refine_tolerance": 0.002}
    trial = D.bracket_first_trial(fill, 6.0, ((5.0, 0.220), (8.0, 0.224)))
    assert trial == pytest.approx(0.224)  # 0.222 halfway, + 0.002
