"""``poro2d criterion --mode density``: one laboratory state, calibrated friction, seeds."""

import json

import pytest

from poro2d.cli import main
from poro2d.execute.options import RunOptions

QUIET = RunOptions(progress=False)

# a box this small cannot rest the lid of the fill acceptance (its window is the weight of
# one grain): the paper's plate, as the quick look uses
TINY = (
    "seed = 0\n[specimen]\nwidth = 0.05\nheight = 0.025\nlayers = 2\n"
    '[criterion]\nacceptance = "plate"\n'
    '[density]\nmode = "density"\nn_max = 0.4571\nn_min = 0.3253\nmu_prep = [0.0, 0.5]\nseeds = 2\n'
)


def test_density_mode_of_the_criterion(tmp_path, monkeypatch):
    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path / "cache"))
    cfg = tmp_path / "c.toml"
    cfg.write_text(TINY)
    out = tmp_path / "o"
    try:
        main(["criterion", "--config", str(cfg), "--n-lab", "0.40", "--out", str(out), "--quiet"])
    except SystemExit as e:  # a seed that did not converge exits 1 after writing its results
        assert e.code == 1
    res = json.loads((out / "density.json").read_text())
    assert res["mode"] == "density" and res["n_lab"] == 0.40 and res["seeds"] == 2
    # the state lies between the extremes, so its friction lies between the calibrated ones
    assert 0.0 < res["relative_density"] < 1.0
    assert res["n2d_min"] < res["n2d_target"] < res["n2d_max"]
    assert 0.0 < res["mu_prep"] < 0.5
    assert res["calibration"]["mus"] == [0.0, 0.5]
    assert "provenance" in res and res["config"]["specimen"]["width"] == 0.05
    # the call of the command's density mode reads the same run back, typed
    from poro2d.criterion.run import CriterionCase
    from poro2d.io_utils import as_json
    from poro2d.store import Store
    from poro2d.sweep.density_criterion import run_density_criterion
    from poro2d.sweep.results import DensityStateResult

    again = run_density_criterion(CriterionCase.from_config(cfg, n_lab=0.40), Store(out), options=QUIET)
    assert isinstance(again, DensityStateResult) and again.n_lab == 0.40
    assert again.final_porosity_per_seed == res["final_porosity_per_seed"] and again.mu_prep == res["mu_prep"]
    assert as_json(again.to_dict()) == json.loads((out / "density.json").read_text())  # NaN: null


@pytest.mark.parametrize(
    ("extra", "name"),
    [(["--mode", "fast"], "mode"), (["--mode", "density", "--n-lab", "0.30"], "--n-lab"),
     (["--mode", "density", "--seeds", "0"], "seeds")],
)  # fmt: skip
def test_density_mode_errors(tmp_path, capsys, extra, name):
    with pytest.raises(SystemExit) as e:
        main(["criterion", "--preset", "paper", "--out", str(tmp_path / "o"), "--quiet", *extra])
    assert e.value.code == 2 and name in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
