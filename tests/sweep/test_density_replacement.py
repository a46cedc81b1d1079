"""Density mode of ``poro2d criterion``: a seed not accepted is replaced by the next unused one."""

import json

import pytest

from poro2d.cli import main
from poro2d.sweep import runner
from poro2d.sweep.records import CaseRow
from poro2d.sweep.relation import seeds_record

from .test_density_mode import TINY

REFUSED = "trial 1 (n2D = 0.2400) refused: check force_balance failed"


def refusing(seeds: set[int]):
    """The sweep runner, with the state checks of ``seeds`` refused as the criterion refuses one
    (the calibration's sweeps and every other seed run as they are)."""
    real = runner.run_sweep

    def run_sweep(sweep, store, **kw):
        res = real(sweep, store, **kw)
        if store.root.name == "states":
            for row in res.rows:
                if int(row.params["seed"]) in seeds:
                    row.results = dict(row.results, converged=False, message=REFUSED)
        return res

    return run_sweep


def _criterion(cfg, out, capsys) -> tuple[int, str]:
    try:
        main(["criterion", "--config", str(cfg), "--n-lab", "0.40", "--out", str(out)])
        code = 0
    except SystemExit as exc:
        code = exc.code
    return code, capsys.readouterr().out


@pytest.mark.scenario
def test_a_refused_seed_is_replaced_and_named(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(runner, "run_sweep", refusing({1}))
    cfg = tmp_path / "c.toml"
    cfg.write_text(TINY)
    out = tmp_path / "o"
    code, printed = _criterion(cfg, out, capsys)
    res = json.loads((out / "density.json").read_text())
    assert code == 0, printed
    assert res["converged"] and res["seeds"] == 3 and res["seeds_converged"] == 2
    assert res["sweeps"]["seeds_used"] == [0, 2]
    assert res["sweeps"]["seeds_replaced"] == [{"seed": 1, "reason": REFUSED, "replaced_by": 2}]
    assert len(res["final_porosity_per_seed"]) == 2
    assert "trying seed(s) 2 in their place" in printed
    assert f"seed 1 not accepted ({REFUSED}): replaced by seed 2" in printed
    # no replacement allowed: seeds 0 and 1 read back, one line says the answer is short
    cfg.write_text(TINY + "replacements = 0\n")
    code, printed = _criterion(cfg, out, capsys)
    res = json.loads((out / "density.json").read_text())
    assert code == 1 and "criterion: 1 of 2 seeds accepted" in printed
    assert not res["converged"] and "seeds_used" not in res["sweeps"]  # the file of a run as before


def test_the_record_pairs_each_refused_seed_with_its_replacement():
    def row(seed, ok):
        return CaseRow(str(seed), "criterion", {"seed": seed}, *[None] * 4, "done", None, None, None,
                       {"converged": ok, "message": "" if ok else f"no {seed}"})  # fmt: skip

    rec = seeds_record([row(0, True), row(1, False), row(2, False), row(3, True), row(4, True)], 3)
    assert rec["seeds_used"] == [0, 3, 4]
    assert rec["seeds_replaced"] == [
        {"seed": 1, "reason": "no 1", "replaced_by": 3},
        {"seed": 2, "reason": "no 2", "replaced_by": 4},
    ]
    short = seeds_record([row(0, True), row(1, False), row(2, False), row(3, False)], 3)
    assert [r["replaced_by"] for r in short["seeds_replaced"]] == [3, None, None]
