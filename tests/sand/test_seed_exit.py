"""``poro2d sand`` exits 0 once its seeds are accepted, replaced ones included, else 1 with one line."""

from types import SimpleNamespace

import pytest

from poro2d.cli import main
from poro2d.cli import sand as cli_sand
from poro2d.lab_state import lab_state_from_table
from poro2d.report import grading_figure
from poro2d.sand import run as sand_run
from poro2d.sand.result import SeedReplaced, SeedSpecimen
from poro2d.sand.spread import AnswerError

REASON = "trial 1 (n2D = 0.1720) refused: check force_balance failed"
LAB = {"e_max": 0.977, "e_min": 0.597, "dr": 0.8}


def _seed(s: int, ok: bool) -> SeedSpecimen:
    folder = f"specimens/Dr0.800-seed{s}" if ok else None
    return SeedSpecimen(s, ok, 0.2, 0.17, 100, 1, folder, "" if ok else REASON)


def _result(accepted: list[int], refused: dict[int, int | None]) -> SimpleNamespace:
    """What print_result reads of a run of 3 seeds: ``refused`` maps a seed to its replacement."""
    return SimpleNamespace(
        state=lab_state_from_table(LAB),
        soil=SimpleNamespace(name="sand"),
        interior_porosity_mean=0.17,
        interior_porosity_sd=0.001,
        box_porosity_mean=0.2,
        box_porosity_sd=0.001,
        seeds=3,
        seeds_accepted=len(accepted),
        seeds_used=accepted,
        specimens=[_seed(s, s in accepted) for s in sorted([*accepted, *refused])],
        seeds_replaced=[SeedReplaced(s, REASON, by) for s, by in refused.items()],
        converged=len(accepted) == 3,
        mu_prep=0.1,
        n2d_min=0.16,
        n2d_max=0.22,
        jamming_porosity=0.15,
        state_map=None,
        calibration=SimpleNamespace(dropped_ends=[], mus=[0.0, 1.0]),
        answer_error=AnswerError(0.0003, 0.004, 0.1, 0.0004, 0.0005),
        state_reached=None,
    )


@pytest.mark.parametrize(
    "accepted, refused, code",
    [([0, 2, 3], {1: 3}, 0), ([0, 2], {1: None}, 1), ([2, 3], {0: 3, 1: None}, 1)],
)
def test_the_exit_says_whether_the_seeds_asked_for_were_reached(
    tmp_path, monkeypatch, capsys, accepted, refused, code
):
    res = _result(accepted, refused)

    def run_sand(case, store, *, on_preflight, **kw):
        on_preflight(case, None)
        return res

    monkeypatch.setattr(sand_run, "run_sand", run_sand)
    monkeypatch.setattr(cli_sand, "print_preflight", lambda case, pf: None)
    monkeypatch.setattr(grading_figure, "draw_grading", lambda *a: None)
    monkeypatch.setattr("poro2d.sand.case.load_sand_case", lambda *a, **kw: None)
    try:
        main(["sand", str(tmp_path / "sand.toml"), "--out", str(tmp_path / "out")])
        exit_code = 0
    except SystemExit as e:
        exit_code = e.code
    assert exit_code == code
    out = capsys.readouterr().out
    assert f"seed 1 not accepted: {REASON}" in out
    assert "the answer's standard error 0.0005 (specimens 0.0003; the calibration's seeds 0.0004" in out
    errors = [line for line in out.splitlines() if line.startswith("error:")]
    if code == 0:
        assert errors == [] and "; replaced by seed 3" in out and "(3 of 3 seeds: 0, 2, 3)" in out
        return
    (line,) = errors
    assert line.startswith(f"error: {len(accepted)} of 3 seeds accepted, with {len(refused) - 1} replaced")
    assert "([sand] replacements at most)" in line
