"""The sensitivity study: statistics and answer on synthetic rows, bad input, the command end to end."""

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.report.document import to_html, to_markdown
from poro2d.report.paper_report import build_blocks
from poro2d.report.sensitivity_report import report_blocks
from poro2d.sweep import sensitivity as S
from poro2d.sweep.criterion_base import CriterionBase

TINY = "seed = 0\n[specimen]\nwidth = 0.05\nheight = 0.025\nlayers = 2\n"


def _grading(label, cu, cu_nominal):
    return {"label": label, "cu": cu, "cu_nominal": cu_nominal, "d50_mm": 4.4, "d_max_mm": 7.1}


def _row(final, measured, f_top=1000.0, weight=800.0, converged=True, status="done"):
    res = {
        "converged": converged,
        "final_porosity": final if converged else None,
        "last_new_porosity": measured,
        "iterations": 2,
        "initial_trial_porosity": 0.14,
        "first_trial_porosity": 0.14,
        "first_f_top_n_per_m": f_top,
        "first_self_weight_n_per_m": weight,
        "first_plate_moved": "up",
        "first_new_porosity": 0.18,
        "f_top_after_n_per_m": 3.0,
        "self_weight_n_per_m": 790.0,
        "message": "m",
    }
    return {"status": status, "results": {} if status == "failed" else res, "error": None, "time_s": 1.0}


def _synthetic_sens():
    grads = [_grading("reference", 1.69, None), _grading("Cu 2", 2.0, 2.0), _grading("Cu 3", 3.0, 3.0)]
    rows = [
        (grads[0], [_row(0.19, 0.188), _row(0.19, 0.191), _row(0.20, 0.197, f_top=3000.0)]),
        (grads[1], [_row(0.17, 0.171), _row(0.16, 0.162), _row(None, 0.2, converged=False)]),
        (grads[2], [_row(0.15, 0.151), _row(0.14, 0.143), _row(0.15, 0.149)]),
    ]
    recs = [S.seed_record(r, g, s) for g, rs in rows for s, r in enumerate(rs)]
    cal = {
        "mus": [0.0, 0.05, 0.5],
        "samples": [[0.17, 0.18, 0.175], [0.19, 0.185, None], [0.21, 0.22, 0.215]],
    }
    sens = {
        "settings": {"mu_prep": 0.05, "seeds": 3, "seed_list": [0, 1, 2], "n_lab": 0.3434,
                     "first_trial": 0.14, "first_trial_from": "Eq. 12", "quick": False},
        "points": {"grading": S.grading_points(recs, grads), "mu_prep": S.mu_points(cal)},
        "paper": S.paper_numbers(),
    }  # fmt: skip
    sens["answer"] = S.answer(sens)
    return sens, recs


def test_points_are_mean_sd_and_n_over_converged_seeds():
    sens, recs = _synthetic_sens()
    ref, cu2, cu3 = sens["points"]["grading"]
    assert ref.n2d_mean == pytest.approx(np.mean([0.19, 0.19, 0.20]))
    assert ref.n2d_sd == pytest.approx(np.std([0.19, 0.19, 0.20], ddof=1))
    assert ref.measured_mean == pytest.approx(np.mean([0.188, 0.191, 0.197]))
    assert (ref.n, ref.unconverged) == (3, 0)
    # an unconverged seed is counted, not averaged
    assert (cu2.n, cu2.unconverged, cu2.seeds) == (2, 1, 3)
    assert cu2.n2d_mean == pytest.approx(0.165)
    assert recs[5].accepted_n2d is None and recs[5].last_estimate_n2d == 0.2
    # first-trial force ratio per seed, then averaged
    assert ref.first_f_top_over_g_mean == pytest.approx(np.mean([1000 / 800, 1000 / 800, 3000 / 800]))
    mu = sens["points"]["mu_prep"]
    assert mu[1].n2d_mean == pytest.approx(0.1875) and mu[1].unconverged == 1
    assert mu[1].n2d_sd == pytest.approx(np.std([0.19, 0.185], ddof=1))


def test_a_csv_row_is_the_points_columns_then_the_answer_seeds_and_version():
    from poro2d.sweep.sensitivity_records import PointRow

    sens, _ = _synthetic_sens()
    ref, _, cu3 = sens["points"]["grading"]
    rows = [
        PointRow.of(p, 0.15, 0.005, [0, 1, 2], "9.9").to_dict()
        for p in (ref, cu3, sens["points"]["mu_prep"][0])
    ]
    for row, point in zip(rows, (ref, cu3, sens["points"]["mu_prep"][0]), strict=True):
        assert list(row) == [*point.to_dict(), "reproduces_paper", "seed_list", "poro2d_version"]
        assert {k: row[k] for k in point.to_dict()} == point.to_dict()
        assert row["seed_list"] == "0 1 2" and row["poro2d_version"] == "9.9"
    # Cu 3 (0.1467) lies within 0.005 of 0.15, the reference (0.193) does not
    assert [r["reproduces_paper"] for r in rows[:2]] == [False, True]


def test_finite_mean_sd_edge_cases():
    assert S.finite_mean_sd([0.2]) == (0.2, 0.0, 1)
    mean, sd, n = S.finite_mean_sd([None, float("nan")])
    assert n == 0 and math.isnan(mean) and math.isnan(sd)


def test_answer_names_the_matching_width_and_the_closest_friction():
    sens, _ = _synthetic_sens()
    ans = sens["answer"]
    g, mu = ans.grading, ans.mu_prep
    # Cu 3: mean 0.1467, within 0.005 of 0.15; Cu 2 (0.165) is not
    assert g.matches == [3.0] and g.closest == 3.0
    # Cu 2 (0.165) and Cu 3 (0.1467) lie on either side of 0.15: linear interpolation between them
    m2, m3 = 0.165, np.mean([0.15, 0.14, 0.15])
    assert g.crossing == pytest.approx(2.0 + (m2 - 0.15) / (m2 - m3))
    assert g.distance == pytest.approx(np.mean([0.15, 0.14, 0.15]) - 0.15)
    # no friction reaches 0.15: the closest is the lowest, 0.175 - 0.15 above
    assert mu.matches == [] and mu.closest == 0.0
    assert mu.distance == pytest.approx(0.025)
    text = " ".join(ans.lines)
    assert "within 0.005 of 0.15: Cu = 3: 0.1467 +- 0.0058 (n = 3)" in text
    assert "no point within 0.005 of 0.15; the closest is mu_prep = 0 with 0.1750" in text
    assert "0.0250 above" in text
    assert "1 seed(s) did not converge" not in text and "2 seed(s) did not converge" in text
    # the paper's first trial beside poro2d's: 3 854 000 N/m is 3854e3 / 846 G
    assert f"{3854e3 / 846:.4g} G" in text


def test_crossing_is_interpolated_between_neighbours():
    pts = [
        {"cu": 1.5, "n2d_mean": 0.20, "n2d_sd": 0.0, "n": 2},
        {"cu": 2.5, "n2d_mean": 0.16, "n2d_sd": 0.0, "n": 2},
        {"cu": 3.5, "n2d_mean": 0.14, "n2d_sd": 0.0, "n": 2},
        {"cu": 4.0, "n2d_mean": math.nan, "n2d_sd": math.nan, "n": 0},
    ]
    m = S.closest_match(pts, "cu", 0.15)
    assert m.crossing == pytest.approx(3.0) and m.matches == []
    assert m.closest in (2.5, 3.5) and abs(m.distance) == pytest.approx(0.01)
    assert S.closest_match(pts[3:], "cu", 0.15).closest is None


@pytest.mark.parametrize("cus", [[1.0, 2.0], [0.5], [2.0, 2.0], ["2"], [], [25.0], [float("inf")]])
def test_bad_cu_lists_are_refused(cus):
    with pytest.raises(InputError) as ei:
        S.study_settings({"cu": cus}, quick=False, seeds=None)
    assert ei.value.parameter == "sensitivity.cu"


def test_settings_defaults_and_seeds():
    s = S.study_settings(None, quick=True, seeds=None)
    assert s.cus == list(S.QUICK_CUS) and s.seeds == S.QUICK_SEEDS
    assert S.study_settings(None, quick=False, seeds=None).cus == list(S.DEFAULT_CUS)
    for bad in (0, 51, True, 2.0):
        with pytest.raises(InputError):
            S.study_settings(None, quick=False, seeds=bad)
    with pytest.raises(InputError):
        S.study_settings({"seeds": 0}, quick=False, seeds=None)
    with pytest.raises(InputError):
        S.study_settings({"cus": [2.0]}, quick=False, seeds=None)  # unknown key


def test_quick_widths_fit_the_quick_box_and_cu_4_does_not():
    from poro2d.criterion.config import paper_preset

    study = S.study_base(CriterionBase(paper_preset().config), quick=True)
    S.check_gradings(study, S.gradings(study, list(S.QUICK_CUS)))
    with pytest.raises(InputError) as ei:
        S.check_gradings(study, S.gradings(study, [4.0]))
    assert ei.value.parameter == "sensitivity.cu" and ei.value.value == 4.0
    # the full box takes Cu = 4 (its bands are 31 mm)
    full = S.study_base(CriterionBase(paper_preset().config), quick=False)
    S.check_gradings(full, S.gradings(full, [4.0]))


def test_family_keeps_the_reference_mean_disk_area():
    from poro2d.criterion.config import paper_preset

    g = S.gradings(S.study_base(CriterionBase(paper_preset().config), quick=False), [1.5, 3.0])
    areas = [x.curve.mean_disk_area() for x in g]
    assert areas == pytest.approx([areas[0]] * 3, rel=1e-9)
    assert [x.describe().cu for x in g[1:]] == pytest.approx([1.5, 3.0])
    assert g[0].params == {"grading.preset": "paper"}


def test_command_refuses_bad_input_before_anything_runs(tmp_path, capsys):
    cases = {
        "cu1": TINY + "[sensitivity]\ncu = [1.0, 1.5]\n",
        "band": TINY + "[sensitivity]\ncu = [1.5, 3.0]\n",  # Cu 3: 16.7 mm disks, 12.5 mm bands
        "key": TINY + "[sensitivity]\ncus = [1.5]\n",
    }
    for name, text in cases.items():
        cfg = tmp_path / f"{name}.toml"
        cfg.write_text(text)
        out = tmp_path / f"out-{name}"
        with pytest.raises(SystemExit) as ei:
            main(["sensitivity", "--config", str(cfg), "--out", str(out), "--quiet"])
        assert ei.value.code == 2, name
        assert not out.exists(), name
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "error:" in err, err
        if name == "band":
            assert "sensitivity.cu = 3.0" in err and "16.75 mm" in err
    with pytest.raises(SystemExit) as ei:
        main(["sensitivity", "--preset", "paper", "--seeds", "0", "--out", str(tmp_path / "o")])
    assert ei.value.code == 2 and not (tmp_path / "o").exists()


@pytest.mark.scenario  # 10 criterion runs and a calibration on a Dask cluster, then the rerun
def test_command_end_to_end_on_tiny_specimens(tmp_path, monkeypatch):
    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path / "cache"))
    cfg = tmp_path / "s.toml"
    cfg.write_text(TINY + "[sensitivity]\ncu = [1.5, 2.0]\nmu_prep = [0.0, 0.05]\n")
    out = tmp_path / "out"
    args = [
        "sensitivity",
        "--config",
        str(cfg),
        "--out",
        str(out),
        "--seeds",
        "2",
        "--workers",
        "2",
        "--quiet",
    ]
    main(args)
    for f in (
        "sensitivity.json",
        "sensitivity.csv",
        "sensitivity_seeds.csv",
        "sensitivity.png",
        "sensitivity.svg",
    ):
        assert (out / f).stat().st_size > 0, f
    sens = json.loads((out / "sensitivity.json").read_text())
    assert sens["settings"]["seed_list"] == [0, 1] and sens["settings"]["first_trial"] == 0.14
    assert sens["provenance"]["poro2d_version"] and sens["config"]["specimen"]["width"] == 0.05
    assert [p["label"] for p in sens["points"]["grading"]] == ["reference", "Cu 1.5", "Cu 2"]
    assert [p["mu_prep"] for p in sens["points"]["mu_prep"]] == [0.0, 0.05]
    for p in sens["points"]["grading"] + sens["points"]["mu_prep"]:
        assert p["n"] + p["unconverged"] == p["seeds"] == 2
    # the first trial of every seed is the Eq. 12 trial, over-filled: a positive plate force
    seeds = pd.read_csv(out / "sensitivity_seeds.csv")
    assert len(seeds) == 6 and (seeds["first_trial_porosity"] == 0.14).all()
    assert (seeds["first_f_top_n_per_m"] > 0).all() and (seeds["first_self_weight_n_per_m"] > 0).all()
    table = pd.read_csv(out / "sensitivity.csv")
    assert len(table) == 5 and set(table["axis"]) == {"grading", "mu_prep"}
    assert sens["answer"]["lines"] and sens["answer"]["target"] == 0.15
    # the report section renders, figure included
    blocks = report_blocks(sens)
    assert any(b[0] == "img" and b[1].is_file() for b in blocks)
    assert "Why the paper gets 0.15" in to_markdown(blocks, out)
    # a rerun reuses every case and the cached calibration, and gives the same numbers
    main(args)
    again = json.loads((out / "sensitivity.json").read_text())
    assert again["points"] == sens["points"] and again["calibration"]["source"] == "cache"
    assert again["sweeps"]["grading"]["reused"] == 6


def test_paper_report_shows_the_section_only_with_results(tmp_path):
    from poro2d.criterion.result import CriterionOutputs, CriterionResult
    from poro2d.paper import PAPER, PaperSummary

    sens, _ = _synthetic_sens()
    parts = {"conversions": {"methods": []}, "criterion": {}, "paper": PAPER, "timings": {}, "provenance": {}}
    summary = PaperSummary(quick=False, seed=0, replicate_specimens=None, shear=None, **parts)
    stored = Path(__file__).parents[1] / "data" / "before_typed_results" / "criterion_result.json"
    crit = CriterionOutputs(CriterionResult.from_dict(json.loads(stored.read_text())))
    without = to_markdown(build_blocks(tmp_path, summary, crit), tmp_path)
    assert "Why the paper gets 0.15" not in without
    blocks = build_blocks(tmp_path, summary, crit, sensitivity=sens)
    md, html = to_markdown(blocks, tmp_path), to_html(blocks, "t")
    assert "Why the paper gets 0.15" in md and "Why the paper gets 0.15" in html
    assert "within 0.005 of 0.15: Cu = 3" in md


def test_the_protocol_line_names_the_calibrations_own_first_trial():
    """The calibration (fill acceptance by default) starts mu_prep 0.05 at 0.171, the plate at 0.19."""
    sens, _ = _synthetic_sens()
    ref = {"measured_mean": 0.19, "first_trial_porosity": 0.14}
    fill = " ".join(S._protocol_lines(dict(sens, config={}), ref))
    assert "starting from 0.171 (the calibration)" in fill
    plate = " ".join(S._protocol_lines(dict(sens, config={"criterion": {"acceptance": "plate"}}), ref))
    assert "starting from 0.19 (the calibration)" in plate
