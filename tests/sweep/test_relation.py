"""The n2D(nLab) relation: the fit, the analysis of sweep rows, the files, the command."""

import json
import math
from dataclasses import asdict

import numpy as np
import pandas as pd
import pytest

from poro2d import porosity as P
from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.report.relation_figure import plot_relation
from poro2d.store import Store
from poro2d.sweep import relation as R


def test_fit_recovers_known_coefficients():
    x = np.linspace(0.32, 0.46, 5)
    fit = R.fit_quadratic_origin(x, 0.5 * x**2 + 0.2 * x)
    assert fit.a == pytest.approx(0.5, abs=1e-10) and fit.b == pytest.approx(0.2, abs=1e-10)
    assert fit.rms_residual < 1e-12 and fit.points == 5
    # Eq. 12 itself, with noise: the least-squares answer of the normal equations
    rng = np.random.default_rng(3)
    y = P.parabolic(x) + rng.normal(0, 0.002, x.size)
    fit = R.fit_quadratic_origin(x, y)
    A = np.column_stack([x * x, x])
    a, b = np.linalg.solve(A.T @ A, A.T @ y)
    assert (fit.a, fit.b) == pytest.approx((a, b), rel=1e-9)
    assert np.allclose(fit.residuals, y - (a * x * x + b * x))
    # two points determine the curve exactly
    fit = R.fit_quadratic_origin([0.3, 0.4], [0.42 * 0.09 + 0.25 * 0.3, 0.42 * 0.16 + 0.25 * 0.4])
    assert (fit.a, fit.b) == pytest.approx((0.42, 0.25), abs=1e-12)


@pytest.mark.parametrize("x, y", [([0.3], [0.1]), ([0.3, 0.3], [0.1, 0.11]), ([0.3, math.nan], [0.1, 0.2])])
def test_fit_needs_two_distinct_points(x, y):
    with pytest.raises(InputError):
        R.fit_quadratic_origin(x, y)


def test_lab_porosities_loose_to_dense_and_settings():
    pts = R.lab_porosities(P.PAPER_N_MAX, P.PAPER_N_MIN, 5)
    assert pts[0] == 0.4571 and pts[-1] == 0.3253 and pts == sorted(pts, reverse=True)
    s = R.relation_settings(None, points=3, n_max=None, n_min=None, preset=True)
    assert s == R.RelationSettings(0.4571, 0.3253, (0.4571, 0.3912, 0.3253))
    s = R.relation_settings(
        {"n_max": 0.5, "n_min": 0.3, "n_lab": [0.35, 0.45]}, points=None, n_max=None, n_min=None, preset=False
    )
    assert s.n_lab == (0.45, 0.35)
    with pytest.raises(InputError):
        R.relation_settings({"nmax": 0.5}, points=None, n_max=None, n_min=None, preset=True)
    with pytest.raises(InputError):
        R.relation_settings(None, points=None, n_max=0.3, n_min=0.4, preset=True)
    with pytest.raises(InputError):
        R.relation_settings(None, points=None, n_max=None, n_min=None, preset=False)
    with pytest.raises(InputError):
        R.lab_porosities(0.45, 0.33, 1)


def _row(cid, n_lab, status="done", converged=True, final=None, last=None):
    res = (
        {}
        if status == "failed"
        else {
            "n_lab": n_lab,
            "converged": converged,
            "final_porosity": final,
            "last_new_porosity": last,
            "iterations": 2,
            "message": "m",
            "particle_count": 100,
            "initial_trial_porosity": 0.15,
        }
    )
    return {
        "case_id": cid,
        "status": status,
        "results": res,
        "params": {"criterion.n_lab": n_lab},
        "error": "RuntimeError: x" if status == "failed" else None,
    }


def test_analysis_flags_points_and_writes_files(tmp_path):
    a, b = 0.6, 0.1
    xs = [0.4571, 0.4242, 0.3912, 0.3582]
    rows = [_row(f"c{i}", x, final=a * x * x + b * x) for i, x in enumerate(xs)]
    rows.append(_row("nc", 0.3253, converged=False, final=None, last=0.2))
    rows.append(_row("bad", 0.34, status="failed"))
    rel = R.analyse(rows, P.PAPER_N_MAX, P.PAPER_N_MIN)
    assert rel.fit.a == pytest.approx(a) and rel.fit.b == pytest.approx(b)
    assert rel.converged_points == 4 and rel.flagged_points == 2
    pts = {p.case_id: p for p in rel.points}
    assert not pts["nc"].converged and pts["nc"].n2d_dem == 0.2 and "not converged" in pts["nc"].flag
    assert pts["nc"].residual == pytest.approx(0.2 - (a * 0.3253**2 + b * 0.3253))
    assert pts["bad"].n2d_dem is None and pts["bad"].flag == "case failed"
    assert pts["c0"].relative_density == pytest.approx(0.0) and pts["nc"].relative_density == pytest.approx(
        1.0
    )
    assert pts["c0"].n2d_parabolic == pytest.approx(float(P.parabolic(0.4571)))
    assert pts["c0"].n2d_lim_3d == pytest.approx(float(P.lim_3d(0.4571)))
    files = R.write_relation(rel, Store(tmp_path))
    for f in files:
        assert f.stat().st_size > 0
    df = pd.read_csv(tmp_path / "relation.csv")
    assert len(df) == 6 and set(df["converged"]) == {True, False}
    saved = json.loads((tmp_path / "relation.json").read_text())
    assert saved["fit"]["form"] == "n2D = a nLab^2 + b nLab" and "provenance" in saved


def test_no_fit_with_one_converged_point():
    rows = [_row("a", 0.45, final=0.2), _row("b", 0.35, converged=False, last=0.21)]
    rel = R.analyse(rows, P.PAPER_N_MAX, P.PAPER_N_MIN)
    assert rel.fit is None and "no fit" in rel.fit_note
    assert all(p.n2d_fit is None for p in rel.points)
    plot_relation(rel)  # draws without a fitted curve


def test_relation_command_on_tiny_specimens(tmp_path):
    cfg = tmp_path / "rel.toml"
    cfg.write_text(
        "seed = 0\n[specimen]\nwidth = 0.05\nheight = 0.025\nlayers = 2\n"
        "[criterion]\nmax_iterations = 1\nmax_plate_steps = 5000\n"
        "[relation]\nn_max = 0.4571\nn_min = 0.3253\n"
    )
    out = tmp_path / "out"
    main(["relation", "--config", str(cfg), "--points", "3", "--out", str(out), "--workers", "2", "--quiet",
          "--mode", "paper"])  # fmt: skip
    for f in ("relation.png", "relation.svg", "relation.csv", "relation.json", "results.csv", "sweep.json"):
        assert (out / f).stat().st_size > 0, f
    df = pd.read_csv(out / "relation.csv")
    assert list(df["n_lab"]) == [0.4571, 0.3912, 0.3253]
    expected = [float(P.relative_density(x, P.PAPER_N_MAX, P.PAPER_N_MIN)) for x in df["n_lab"]]
    assert (
        list(df["relative_density"]) == pytest.approx(expected) and expected[0] == 0.0 and expected[2] == 1.0
    )
    # every point is reported, converged or flagged
    assert all(c or f for c, f in zip(df["converged"], df["flag"].fillna(""), strict=True))


def test_relation_cli_errors(tmp_path):
    with pytest.raises(SystemExit) as ei:
        main(["relation", "--preset", "paper", "--points", "1", "--out", str(tmp_path)])
    assert ei.value.code == 2
    cfg = tmp_path / "c.toml"
    cfg.write_text("[relation]\npoints = 3\nnmin = 0.3\n")
    with pytest.raises(SystemExit) as ei:
        main(["relation", "--config", str(cfg), "--out", str(tmp_path)])
    assert ei.value.code == 2


def _state_row(n_lab, seed, final, last, converged=True):
    return {
        "case_id": f"s{n_lab}-{seed}",
        "status": "done",
        "params": {"criterion.n_lab": n_lab, "seed": seed},
        "results": {
            "converged": converged,
            "final_porosity": final,
            "last_new_porosity": last,
            "message": "m",
        },
    }


def test_density_states_are_averaged_over_seeds_and_the_spread_is_measured():
    from poro2d.criterion.density import Calibration, state_target

    cal = Calibration([0.0, 0.1, 0.5], [[0.17, 0.172], [0.19, 0.19], [0.22, 0.224]])
    labs = [0.4571, 0.3912, 0.3253]
    targets = [state_target(x, P.PAPER_N_MAX, P.PAPER_N_MIN, cal) for x in labs]
    rows = [
        _state_row(0.4571, 0, 0.22, 0.221), _state_row(0.4571, 1, 0.23, 0.226),
        _state_row(0.3912, 0, 0.20, 0.199), _state_row(0.3912, 1, None, 0.25, converged=False),
        _state_row(0.3253, 0, 0.17, 0.171), _state_row(0.3253, 1, 0.17, 0.169),
    ]  # fmt: skip
    rel = R.analyse_states(rows, targets, cal, P.PAPER_N_MAX, P.PAPER_N_MIN)
    pts = {p.n_lab: p for p in rel.points}
    assert pts[0.4571].n2d_dem == pytest.approx(0.225)
    assert pts[0.4571].n2d_sd == pytest.approx(np.std([0.22, 0.23], ddof=1))
    assert pts[0.4571].n2d_measured == pytest.approx(0.2235)
    assert pts[0.3912].seeds_converged == 1 and "1 seed(s)" in pts[0.3912].flag
    assert pts[0.3912].n2d_dem == pytest.approx(0.20)  # the unconverged seed is not averaged
    assert pts[0.4571].mu_prep == pytest.approx(0.5) and pts[0.3253].mu_prep == pytest.approx(0.0)
    sp = rel.spread
    assert sp.n2d_loose_minus_dense == pytest.approx(0.055) and sp.monotone
    assert rel.mode == "density" and rel.n2d_min == pytest.approx(0.171)


@pytest.mark.scenario  # three relations end to end, each with its calibration and Dask cluster
def test_density_relation_command_on_tiny_specimens(tmp_path, monkeypatch):
    """Calibration, mapping and checks end to end; the calibration is reused from the cache."""
    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path / "cache"))
    cfg = tmp_path / "rel.toml"
    cfg.write_text(
        "seed = 0\n[specimen]\nwidth = 0.05\nheight = 0.025\nlayers = 2\n"
        # a box this small cannot rest the lid of the fill acceptance (its window is the weight
        # of one grain): the paper's plate, as the quick look uses
        '[criterion]\nacceptance = "plate"\n'
        "[relation]\nn_max = 0.4571\nn_min = 0.3253\nmu_prep = [0.0, 0.5]\n"
    )
    out = tmp_path / "out"
    args = ["relation", "--config", str(cfg), "--points", "3", "--seeds", "2", "--workers", "2", "--quiet"]
    main([*args, "--out", str(out)])
    rel = json.loads((out / "relation.json").read_text())
    assert rel["mode"] == "density"
    cal = json.loads((out / "calibration.json").read_text())
    assert cal["source"] == "computed" and cal["calibration"]["mus"] == [0.0, 0.5]
    pts = rel["points"]
    assert [p["mu_prep"] for p in pts][0] == pytest.approx(0.5) and pts[-1]["mu_prep"] == pytest.approx(0.0)
    assert all(p["seeds"] == 2 for p in pts)
    # the loosest preparation gives a looser calibrated state than the densest (physics, not the fit)
    assert rel["n2d_max"] > rel["n2d_min"]
    out2 = tmp_path / "out2"
    main([*args, "--out", str(out2)])
    again = json.loads((out2 / "calibration.json").read_text())
    assert again["source"] == "cache" and again["ran"] == 0 and again["reused"] == 4
    assert again["calibration"] == cal["calibration"]
    assert "state_maps" not in rel
    # a [state] table adds the state parameter of every state beside its answer, and nothing else
    stated = tmp_path / "stated.toml"
    stated.write_text(cfg.read_text() + '[state]\nlab_line = "toyoura"\ntest_stress_kpa = 100\n')
    main(["relation", "--config", str(stated), *args[3:], "--out", str(tmp_path / "out4")])
    rel4 = json.loads((tmp_path / "out4" / "relation.json").read_text())
    assert [p["n2d_target"] for p in rel4["points"]] == [p["n2d_target"] for p in pts]
    maps = rel4["state_maps"]
    assert len(maps) == len(pts) and all(m["e2d_by_state"] is None for m in maps)
    e = [p["n_lab"] / (1.0 - p["n_lab"]) for p in pts]
    assert [m["psi_lab"] for m in maps] == pytest.approx([v - maps[0]["e_cs_lab"] for v in e])
    # one more seed runs only that seed's cases; the others are read back
    args3 = [a if a != "2" or args[i - 1] != "--seeds" else "3" for i, a in enumerate(args)]
    main([*args3, "--out", str(tmp_path / "out3")])
    third = json.loads((tmp_path / "out3" / "calibration.json").read_text())
    assert third["ran"] == 2 and third["reused"] == 4


def test_a_state_table_needs_density_mode(tmp_path):
    cfg = tmp_path / "rel.toml"
    cfg.write_text(
        '[relation]\nn_max = 0.4571\nn_min = 0.3253\nmode = "paper"\n[state]\nlab_line = "toyoura"\n'
    )
    with pytest.raises(SystemExit) as ei:
        main(["relation", "--config", str(cfg), "--out", str(tmp_path / "o")])
    assert ei.value.code == 2 and not (tmp_path / "o").exists()


def test_density_mode_errors(tmp_path):
    with pytest.raises(SystemExit) as ei:
        main(["relation", "--preset", "paper", "--mode", "fast", "--out", str(tmp_path / "o")])
    assert ei.value.code == 2
    with pytest.raises(SystemExit) as ei:
        main(["relation", "--preset", "paper", "--seeds", "0", "--out", str(tmp_path / "o")])
    assert ei.value.code == 2


def test_a_state_check_that_is_a_calibration_case_is_read_back(tmp_path):
    """The densest state's check (lowest friction, the calibration's first trial) is the same
    criterion run as a calibration case: it is read back, relabelled, not run again. A check
    at another friction or first trial is not."""
    from poro2d.criterion.density import StateTarget
    from poro2d.io_utils import write_json
    from poro2d.sweep import density as D
    from poro2d.sweep.criterion_base import CriterionBase

    base = CriterionBase({"seed": 0, "specimen": {"width": 0.05, "height": 0.025, "layers": 2}})
    cal = D.CalibrationCase(base, (0.05, 0.5), 2).sweep
    folder = tmp_path / "cal"
    for c in cal.cases:
        mu = c.params["specimen.friction_prep"]
        row = {"id": c.id, "status": "done", "params": c.params,
               "results": {"n_lab": 0.3434, "converged": True, "final_porosity": 0.19 + mu / 10,
                           "last_new_porosity": 0.188 + mu / 10}}  # fmt: skip
        write_json(folder / "cases" / c.id / "params.json", asdict(c), config=True)  # the runner binds so
        write_json(folder / "cases" / c.id / "result.json", row)
    dense = StateTarget(0.33, 1.0, 0.1883, 0.05)  # first trial rounds to 0.19, the calibration's
    other = StateTarget(0.40, 0.4, 0.2, 0.3)
    loose_trial = StateTarget(0.45, 0.0, 0.2095, 0.5)  # a calibration friction, another first trial
    states = D.StateChecks(base, (dense, other, loose_trial), 2, 0.01).sweep
    twins = D.calibration_twins(cal, states, None, Store(folder))
    assert len(twins) == 2
    # in the order of the state checks, each relabelled with its check's id
    assert [row.case_id for row in twins] == [
        c.id for c in states.cases if c.id in {r.case_id for r in twins}
    ]
    for row in twins:
        assert row.params["criterion.n_lab"] == 0.33 and row.results["n_lab"] == 0.33
        assert row.params["specimen.friction_prep"] == 0.05
        assert row.results["final_porosity"] == pytest.approx(0.195)
        assert row.extra["reused_calibration_case"] in {c.id for c in cal.cases}
    assert {r.params["seed"] for r in twins} == {0, 1}
    # an unfinished calibration case is not a twin: the check then runs
    (folder / "cases" / cal.cases[0].id / "result.json").unlink()
    assert len(D.calibration_twins(cal, states, None, Store(folder))) == 1
