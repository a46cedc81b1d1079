"""Bad input at the command line: one line naming it, exit code 2, before any work.

Table-driven: each case is a command line (with files written for it) and words its one
line must hold. The entry points of the work (the sweep runner, the calibration, the
criterion, the shear tests) are replaced by a stand-in that raises, so a case that is not
refused up front fails here at once instead of running a simulation.
"""

from __future__ import annotations

import pytest

import poro2d.critical_state as critical_state
import poro2d.execute.dask_cluster as dask_cluster
import poro2d.sweep.density as density_sweep
import poro2d.sweep.runner as runner
from poro2d.cli import main
from poro2d.criterion.protocol import PorosityCriterion
from poro2d.dem import Particles, Simulation, Walls, checkpoint
from poro2d.shear.replicates import ReplicateShear
from poro2d.shear.series import ShearSeries

EXTREMES = "n_max = 0.4571\nn_min = 0.3253\n"

#: files the cases refer to as {name}; text is written as UTF-8, bytes as they are
FILES: dict[str, str | bytes] = {
    "mu_scalar.toml": "[relation]\nmu_prep = 0.1\n" + EXTREMES,
    "mu_true.toml": "[relation]\nmu_prep = true\n" + EXTREMES,
    "mu_empty.toml": "[relation]\nmu_prep = []\n" + EXTREMES,
    "mu_high.toml": "[relation]\nmu_prep = [0.05, 0.5, 5.5]\n" + EXTREMES,
    "mu_huge.toml": "[relation]\nmu_prep = [0.0, 1e6]\n" + EXTREMES,
    "mu_text.toml": '[relation]\nmu_prep = "abc"\n' + EXTREMES,
    "mu_falling.toml": "[relation]\nmu_prep = [0.5, 0.1]\n" + EXTREMES,
    "n_lab_out.toml": "[relation]\nn_lab = [0.50, 0.30]\n" + EXTREMES,
    "paper_seeds.toml": '[relation]\nmode = "paper"\nseeds = 2\n' + EXTREMES,
    "density_mu.toml": '[density]\nmode = "density"\nmu_prep = 0.1\n' + EXTREMES,
    "density_mu_text.toml": '[density]\nmode = "density"\nmu_prep = "abc"\n' + EXTREMES,
    "sens_mu.toml": "[sensitivity]\nmu_prep = true\n",
    "sens_cu.toml": '[sensitivity]\ncu = "abc"\n',
    "syntax.toml": "[relation]\nn_max = \n",
    "latin1.toml": b"# r\xe9glage\n[relation]\n",
    "unknown.toml": "[relation]\nn_maxx = 0.4\n",
    "sweep_latin1.toml": b'[sweep]\nkind = "criterion"\n# \xff\n',
    "lab_binary.csv": b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR",
    "lab_latin1.csv": b"normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,\xe9\n",
    "lab_wide.csv": "normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,75,3\n",
    "lab_ok.csv": "normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,75\n",
    # beside the specimens that were not accepted (written by _write_files)
    "refused/trial.json": '{"accepted": false}',
    "unconverged/result.json": '{"converged": false, "iterations": []}',
    "shear_empty_item.toml": "[shear]\nnormal_stress_kpa = [50, 1e9]\n",
    "relation_number.toml": "relation = 5\n",
    "density_list.toml": "density = [1, 2]\n",
    "criterion_number.toml": "criterion = 5\n",
    "sensitivity_text.toml": 'sensitivity = "x"\n',
    "title_number.toml": "title = 5\n",
    "dens/density.json": '{"mode": "density", "n_lab": 0.4, "relative_density": 0.4872, "mu_prep": 0.26, '
    '"seeds": 2}',
    "n_lab_twice.toml": "[relation]\nn_lab = [0.40, 0.40]\n" + EXTREMES,
    "n_max_text.toml": '[relation]\nn_max = "0.45"\nn_min = 0.3\n',
    "kn.toml": "[specimen]\nkn_particle = 1e300\n",
    "gravity.toml": "[specimen]\ngravity = 1e300\n",
    "rho.toml": "[specimen]\nsolid_density = 1e300\n",
    "mu_particle.toml": "[specimen]\nfriction_particle = 1e300\n",
    "stage_steps.toml": "[specimen]\nmax_steps_per_stage = 1000000000000\n",
    "plate_steps.toml": "[criterion]\nmax_plate_steps = 1000000000000000\n",
    "record.toml": "[shear]\nrecord_interval = 1e-300\n",
    "checkpoints.toml": "[shear]\ncheckpoint_interval = 1e-300\n",
    "steps.toml": "[shear]\nconsolidation_max_steps = 100000000000\n",
    "density_scale.toml": "[shear]\ndensity_scale = 1e300\n",
    "kn_wall.toml": "[shear]\nkn_wall = 1e300\n",
    "gap.toml": "[shear]\ngap = 0.05\n",
    "friction.toml": "[shear]\nfriction_wall = 1e300\n",
}

#: (command line, words of the one line); {d} is the folder holding FILES, {out} a new folder
CASES = [
    # export by laboratory state: the state and seed named, the ones there are listed
    (["export", "{d}/dens", "--to", "csv", "--out", "x"], ["--n-lab/--dr = None", "n_lab 0.4 (Dr 0.4872)"]),
    (
        ["export", "{d}/dens", "--to", "csv", "--out", "x", "--n-lab", "0.4"],
        ["--seed = 0", "no accepted seed"],
    ),
    (["export", "{d}/dens", "--to", "csv", "--out", "x", "--dr", "0.3"], ["--dr = 0.3", "n_lab 0.4"]),
    (
        ["export", "{d}/sp.npz", "--to", "csv", "--out", "x", "--dr", "0.5"],
        ["--dr = 0.5", "a folder of states"],
    ),
    # list-valued config keys: one check of shape, type and range
    (["relation", "-c", "{d}/mu_scalar.toml"], ["relation.mu_prep = 0.1", "[0, 5]"]),
    (["relation", "-c", "{d}/mu_true.toml"], ["relation.mu_prep = True", "[0, 5]"]),
    (["relation", "-c", "{d}/mu_empty.toml"], ["relation.mu_prep = []", "2 to 20"]),
    (["relation", "-c", "{d}/mu_high.toml"], ["relation.mu_prep", "5.5 is out of range"]),
    (["relation", "-c", "{d}/mu_huge.toml"], ["relation.mu_prep", "1000000.0 is out of range"]),
    (["relation", "--quick", "--n-max", "nan"], ["--n-max = nan", "(0.0, 1.0)"]),
    (["relation", "--quick", "--points", "1"], ["--points = 1", "[2, 50]"]),
    (["relation", "-c", "{d}/mu_text.toml"], ["relation.mu_prep = 'abc'", "[0, 5]"]),
    (["relation", "-c", "{d}/mu_falling.toml"], ["relation.mu_prep", "strictly increasing"]),
    (["relation", "-c", "{d}/n_lab_out.toml"], ["relation.n_lab", "[0.3253, 0.4571]", "0.5 is out"]),
    (["relation", "-c", "{d}/paper_seeds.toml"], ["relation.seeds = 2", "density mode"]),
    (["relation", "--preset", "paper", "--mode", "paper", "--seeds", "2"], ["--seeds = 2", "density mode"]),
    (["criterion", "-c", "{d}/density_mu.toml"], ["density.mu_prep = 0.1", "[0, 5]"]),
    (["criterion", "-c", "{d}/density_mu_text.toml"], ["density.mu_prep = 'abc'"]),
    (["criterion", "--preset", "paper", "--mode", "density", "--n-lab", "0.5"], ["--n-lab = 0.5", "0.4571"]),
    (["sensitivity", "-c", "{d}/sens_mu.toml"], ["sensitivity.mu_prep = True"]),
    (["sensitivity", "-c", "{d}/sens_cu.toml"], ["sensitivity.cu = 'abc'", "(1, 20]"]),
    # tables that are not tables, values of the wrong type even where an option wins
    (["relation", "-c", "{d}/relation_number.toml"], ["relation = 5", "a table"]),
    (["criterion", "-c", "{d}/density_list.toml"], ["density = [1, 2]", "a table"]),
    (["relation", "-c", "{d}/criterion_number.toml", "--n-max", "0.45", "--n-min", "0.3"], ["criterion = 5"]),
    (["sensitivity", "-c", "{d}/sensitivity_text.toml"], ["sensitivity = 'x'", "a table"]),
    (["relation", "-c", "{d}/title_number.toml"], ["title = 5", "a string"]),
    (["relation", "-c", "{d}/n_lab_twice.toml"], ["relation.n_lab = [0.4, 0.4]", "distinct"]),
    (["relation", "-c", "{d}/n_max_text.toml", "--n-max", "0.45"], ["relation.n_max = '0.45'", "a number"]),
    # criterion settings with no physical meaning or no end
    (["criterion", "-c", "{d}/kn.toml"], ["specimen.kn_particle = 1e+300", "1e+12]"]),
    (["criterion", "-c", "{d}/gravity.toml"], ["specimen.gravity = 1e+300", "981]"]),
    (["criterion", "-c", "{d}/rho.toml"], ["specimen.solid_density = 1e+300", "[500, 23000]"]),
    (["criterion", "-c", "{d}/mu_particle.toml"], ["specimen.friction_particle = 1e+300"]),
    (
        ["relation", "-c", "{d}/stage_steps.toml", "--n-max", "0.45", "--n-min", "0.3"],
        ["max_steps_per_stage"],
    ),
    (["sensitivity", "-c", "{d}/plate_steps.toml"], ["criterion.max_plate_steps"]),
    # options of density mode given to paper mode would be ignored
    (["criterion", "--preset", "paper", "--n-max", "0.5"], ["--n-max = 0.5", "--mode density"]),
    (["criterion", "--preset", "paper", "--seeds", "2"], ["--seeds = 2", "--mode density"]),
    (["criterion", "--preset", "paper", "--mode", "density", "--seed", "3"], ["--seed = 3", "paper mode"]),
    (["criterion", "--mode", "density", "--trial-porosity", "0.2"], ["--trial-porosity = 0.2", "paper mode"]),
    # the cluster: the address's form and the number of workers, before anything runs
    (["relation", "--preset", "paper", "--scheduler", "notanaddress"], ["--scheduler = 'notanaddress'"]),
    (["sensitivity", "--scheduler", "http://host:8786"], ["--scheduler", "tcp://host:8786"]),
    (["sweep", "{d}/syntax.toml", "--scheduler", "tcp://host:99999"], ["--scheduler", "port 1-65535"]),
    (["relation", "--preset", "paper", "--scheduler", ""], ["--scheduler = ''"]),
    (["relation", "--preset", "paper", "--workers", "100000"], ["--workers = 100000"]),
    (["sensitivity", "--workers", "-1"], ["--workers = -1"]),
    (
        ["relation", "--preset", "paper", "--workers", "1", "--scheduler", "tcp://h:1"],
        ["--workers", "--scheduler"],
    ),
    # config files: syntax (file, line, column), bytes, keys, missing, a folder
    (["relation", "-c", "{d}/syntax.toml"], ["syntax.toml", "line 2, column 9"]),
    (["relation", "-c", "{d}/latin1.toml"], ["latin1.toml", "0xe9 at line 1, column 4", "UTF-8"]),
    (["sweep", "{d}/sweep_latin1.toml"], ["sweep_latin1.toml", "line 3, column 3"]),
    (["criterion", "-c", "{d}/latin1.toml"], ["latin1.toml", "UTF-8"]),
    (["shear", "-s", "x.npz", "-c", "{d}/latin1.toml"], ["latin1.toml", "UTF-8"]),
    (["relation", "-c", "{d}/unknown.toml"], ["relation.n_maxx", "known keys"]),
    (["relation", "-c", "{d}/missing.toml"], ["missing.toml", "an existing TOML file"]),
    (["sensitivity", "-c", "{d}"], ["a regular file", "it is a folder"]),
    # laboratory files
    (["paper", "--lab", "{d}/lab_binary.csv"], ["lab_binary.csv", "line 1, column 1", "UTF-8"]),
    (["paper", "--lab", "{d}/lab_latin1.csv"], ["lab_latin1.csv", "line 3, column 5"]),
    (["paper", "--lab", "{d}/lab_wide.csv"], ["lab_wide.csv", "line 3, column 3", "2 columns"]),
    (["paper", "--lab", "{d}"], ["a regular file", "it is a folder"]),
    # normal stresses: a physical range, no empty item
    (["shear", "-s", "x.npz", "--normal-stress", "1e9"], ["--normal-stress = '1e9'", "[1, 1000] kPa"]),
    (["shear", "-s", "x.npz", "--normal-stress", "1e-9"], ["--normal-stress", "1e-9 is out of range"]),
    (["shear", "-s", "x.npz", "--normal-stress", "50,,100"], ["--normal-stress = '50,,100'", "'' is not"]),
    (["shear", "-s", "x.npz", "--normal-stress", "50,"], ["--normal-stress = '50,'"]),
    (["shear", "-s", "x.npz", "--normal-stress", "nan"], ["--normal-stress = 'nan'"]),
    (["shear", "-s", "x.npz", "--normal-stress", ""], ["--normal-stress = ''"]),
    (
        ["shear", "-s", "x.npz", "-c", "{d}/shear_empty_item.toml"],
        ["shear.normal_stress_kpa", "out of range"],
    ),
    # shear settings with no physical meaning or no end (a real specimen: 0.1 m x 0.1 m box)
    (["shear", "-s", "{d}/sp.npz", "--max-displacement", "1e300"], ["--max-displacement = 1e+300", "1.0]"]),
    (["shear", "-s", "{d}/sp.npz", "--stop-after-peak", "1e300"], ["--stop-after-peak = 1e+300", "1.0]"]),
    (["shear", "-s", "{d}/sp.npz", "-c", "{d}/record.toml"], ["record_interval = 1e-300", "1000000"]),
    (["shear", "-s", "{d}/sp.npz", "-c", "{d}/checkpoints.toml"], ["checkpoint_interval = 1e-300"]),
    (["shear", "-s", "{d}/sp.npz", "-c", "{d}/steps.toml"], ["consolidation_max_steps", "10000000]"]),
    (["shear", "-s", "{d}/sp.npz", "-c", "{d}/density_scale.toml"], ["density_scale = 1e+300"]),
    (["shear", "-s", "{d}/sp.npz", "-c", "{d}/kn_wall.toml"], ["kn_wall = 1e+300"]),
    (["shear", "-s", "{d}/sp.npz", "-c", "{d}/gap.toml"], ["gap = 0.05", "0.025]"]),
    (["shear", "-s", "{d}/sp.npz", "-c", "{d}/friction.toml"], ["friction_wall = 1e+300", "10.0]"]),
    (["shear", "-s", "{d}/sp.npz", "--normal-stress", "1e9"], ["--normal-stress = '1e9'"]),
    # only specimens the criterion accepted are sheared: a refused trial's, an unconverged criterion's
    (["shear", "-s", "{d}/refused/after_plate.npz"], ["trial.json says accepted = False"]),
    (["shear", "-s", "{d}/unconverged"], ["result.json says converged = False"]),
    (["strength", "{d}/sp.npz", "{d}/refused/after_plate.npz"], ["refused/after_plate.npz", "accepted"]),
    (["strength", "{d}/unconverged"], ["converged = False"]),
    (["calibrate", "--lab", "{d}/lab_ok.csv", "-s", "{d}/refused/after_plate.npz"], ["accepted = False"]),
    (["calibrate", "--lab", "{d}/lab_ok.csv", "-s", "{d}/sp.npz", "-s", "{d}/unconverged"], ["converged"]),
    (
        ["calibrate", "--lab", "{d}/lab_ok.csv", "-s", "{d}/sp.npz", "--discrepancy", "often"],
        ["--discrepancy = 'often'"],
    ),
    (["calibrate", "--lab", "{d}/lab_ok.csv", "-s", "{d}/sp.npz", "--discrepancy", "11"], ["(0, 10]"]),
    (["convert", "--dry-density", "1600", "--solid-density", "1e300"], ["--solid-density = 1e+300", "23000"]),
    # usage errors of the option parser: one line too
    (["shear", "--stop-after-peak", "abc"], ["--stop-after-peak = 'abc'", "a valid number"]),
    (["criterion", "--seed", "1e3"], ["--seed = '1e3'", "integer"]),
    (["criterion", "--n-lab="], ["--n-lab = ''", "a non-empty value"]),
    # an empty path is the current folder to the option parser: refused, not written into
    (["criterion", "--preset", "paper", "--out", ""], ["--out = ''"]),
    (["relation", "--preset", "paper", "-o", ""], ["-o = ''"]),
    (["plot", "relations", "-o", ""], ["-o = ''"]),
    (["shear", "-s", "", "--normal-stress", "50"], ["-s = ''"]),
    (["relation", "--points", "many"], ["--points = 'many'"]),
    (["criterion", "--bogus"], ["--bogus", "--preset"]),
    (["criterion", "--config"], ["--config"]),
    (["sweep"], ["config"]),
    # an option given twice: the parser would keep the last without a word
    (["criterion", "--n-lab", "0.3", "--n-lab=0.4"], ["--n-lab = '--n-lab 0.3, --n-lab=0.4'", "once"]),
    (["relation", "-o", "a", "--out", "b"], ["--out = '-o a, --out b'"]),
    (["plot", "relations", "-o", "a", "--out-dir", "b"], ["--out-dir = '-o a, --out-dir b'"]),
    (["criterion", "--quiet", "--quiet"], ["--quiet = '--quiet, --quiet'"]),
    (["critical-state", "--disks", "5"], ["--disks = 5", "[200, 20000]"]),
    (["critical-state", "--rolling-friction", "3"], ["--rolling-friction"]),
    (["critical-state", "--inertial", "0.5"], ["--inertial = 0.5"]),
    (["critical-state", "--strain", "1", "--window-start", "2"], ["--strain"]),
    (["critical-state", "--seeds", "0"], ["--seeds = 0"]),
    (["critical-state", "--workers", "0"], ["--workers = 0"]),
    (["critical-state", "--grading", "loam"], ["--grading = 'loam'", "wide_cu4"]),
    (["nosuchcommand"], ["nosuchcommand"]),
]


def work(*args, **kwargs):
    """Stands in for an entry point of real work: reaching it means the input was not refused in time."""
    raise AssertionError("work started before the input was refused")


@pytest.fixture
def no_work(monkeypatch):
    """Every entry point of real work raises: a case that gets there was not refused in time."""
    stop_real_work(monkeypatch)


def stop_real_work(monkeypatch) -> None:
    """Make every entry point of the commands' real work raise (see :func:`work`)."""
    monkeypatch.setattr(runner, "run_sweep", work)
    monkeypatch.setattr(density_sweep, "calibrate", work)
    monkeypatch.setattr(PorosityCriterion, "run", work)
    monkeypatch.setattr(ShearSeries, "run", work)
    monkeypatch.setattr(ReplicateShear, "run", work)
    monkeypatch.setattr(critical_state, "run_critical_states", work)


def _write_files(folder) -> None:
    _specimen(folder / "sp.npz")
    for name, content in FILES.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content, encoding="utf-8")
    _specimen(folder / "refused" / "after_plate.npz")
    _specimen(folder / "unconverged" / "specimen.npz")


def _specimen(path) -> None:
    """A two-disk specimen in a 0.1 m x 0.1 m box: enough for the checks made before a test."""
    p = Particles(pos=[[0.02, 0.02], [0.05, 0.02]], radius=1e-3, density=2650.0, thickness=0.01, kn=1e5,
                  ks=1e5, mu=0.5)  # fmt: skip
    checkpoint.save(Simulation(p, Walls.box(0.0, 0.0, 0.1, 0.1, 1e5, 1e5, 0.5)), path)


@pytest.mark.parametrize(("argv", "words"), CASES, ids=[" ".join(a)[:60] for a, _ in CASES])
def test_refused_on_one_line(argv, words, tmp_path, capsys, no_work, monkeypatch):
    files = tmp_path / "files"
    files.mkdir()
    _write_files(files)
    monkeypatch.chdir(tmp_path)  # default --out folders land here, and must not appear
    args = [a.format(d=files) for a in argv]
    with pytest.raises(SystemExit) as exc:
        main(args)
    out, err = capsys.readouterr()
    assert exc.value.code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert out == ""  # no banner before the refusal
    for w in words:
        assert w.format(d=files) in lines[0], (w, lines[0])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["files"]  # nothing written


@pytest.mark.parametrize(
    "argv",
    [
        ["relation", "--preset", "paper", "--quick"],
        ["sensitivity", "--quick"],
        ["sweep", "{d}/sweep.toml"],
    ],
)
def test_unreachable_scheduler_is_the_only_line(argv, tmp_path, capsys, no_work, monkeypatch):
    monkeypatch.setattr(dask_cluster, "CONNECT_TIMEOUT_S", 1)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sweep.toml").write_text(
        '[specimen]\nlayers = 2\n[sweep]\nkind = "criterion"\nseed = [0, 1]\n'
    )
    args = [a.format(d=tmp_path) for a in argv] + ["--scheduler", "tcp://127.0.0.1:1"]
    with pytest.raises(SystemExit) as exc:
        main(args)
    out, err = capsys.readouterr()
    assert exc.value.code == 2 and out == "", (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(
        "error: --scheduler = 'tcp://127.0.0.1:1' is invalid; allowed: a running Dask scheduler that answers "
        "within 1 s ("
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sweep.toml"]
