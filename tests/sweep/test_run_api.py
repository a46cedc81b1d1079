"""``run_criterion`` and ``run_relation``: the commands as calls on their cases, with the commands' checks."""

import pytest

from poro2d.criterion import run_criterion
from poro2d.criterion.result import CriterionResult
from poro2d.criterion.run import CriterionCase
from poro2d.errors import InputError
from poro2d.execute.options import RunOptions
from poro2d.store import Store
from poro2d.sweep.density_criterion import run_criterion_modes, run_density_criterion
from poro2d.sweep.relation import RelationCase, run_relation

QUIET = RunOptions(progress=False)

SMALL = {
    "seed": 0,
    "specimen": {"width": 0.05, "height": 0.025, "layers": 2},
    "criterion": {"force_fraction": 0.05},
}


@pytest.mark.parametrize(
    ("run", "kw", "name"),
    [(run_criterion, {"seed": -1}, "--seed"), (run_criterion_modes, {"mode": "fast"}, "mode"),
     (run_criterion, {"n_lab": 1.5}, "n_lab"), (run_criterion, {"preset": "paper"}, "config/preset"),
     (run_criterion_modes, {"mode": "density"}, "density.n_max/n_min"),
     (run_density_criterion, {"mode": "density"}, "density.n_max/n_min"),
     (run_density_criterion, {}, "mode"),
     (run_criterion, {"config": dict(SMALL, density={"mode": "density"})}, "density.n_max/n_min"),
     (run_criterion, {"config": dict(SMALL, density={"mode": "density", "n_max": 0.45, "n_min": 0.33})},
      "density.mode")],
)  # fmt: skip
def test_run_criterion_refuses_bad_input_before_writing(tmp_path, run, kw, name):
    out = tmp_path / "o"
    kw = {"config": SMALL, **kw}
    with pytest.raises(InputError) as e:
        run(CriterionCase.from_config(kw.pop("config"), **kw), Store(out), options=QUIET)
    assert e.value.parameter == name
    assert not out.exists()


def test_run_criterion_matches_the_command(tmp_path):
    """The call and ``poro2d criterion`` write the same result for the same config."""
    import json

    from poro2d.cli import main

    res = run_criterion(CriterionCase.from_config(SMALL), Store(tmp_path / "api"), options=QUIET)
    assert isinstance(res, CriterionResult)
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        "seed = 0\n[specimen]\nwidth = 0.05\nheight = 0.025\nlayers = 2\n[criterion]\nforce_fraction = 0.05\n"
    )
    main(["criterion", "--config", str(cfg), "--out", str(tmp_path / "cli"), "--quiet"])
    cli = json.loads((tmp_path / "cli" / "result.json").read_text())
    assert res.final_porosity == cli["final_porosity"] and res.converged
    assert [r.new_porosity for r in res.iterations] == [r["new_porosity"] for r in cli["iterations"]]


@pytest.mark.parametrize(
    ("kw", "name"), [({"points": 1}, "points"), ({"mode": "fast"}, "mode"), ({"seeds": 0}, "seeds")]
)
def test_run_relation_refuses_bad_input_before_writing(tmp_path, kw, name):
    out = tmp_path / "o"
    with pytest.raises(InputError) as e:
        run_relation(RelationCase.from_config(None, quick=True, **kw), Store(out), options=QUIET)
    assert name in e.value.parameter
    assert not out.exists()
