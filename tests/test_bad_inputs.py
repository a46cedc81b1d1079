"""Bad input anywhere is refused with one line naming it: the size guard before drawing disks,
output folders, damaged checkpoints and grading files, config values of the wrong type,
API arrays, and disks placed on one another, on a wall or outside the box."""

from __future__ import annotations

import logging
import os

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.criterion.protocol import CriterionSettings
from poro2d.dem import Particles, Simulation, Walls, checkpoint
from poro2d.dem.layout import COINCIDENT, coincident_pair
from poro2d.errors import InputError, check_int, check_range
from poro2d.grading import GradingCurve, draw_disks, paper_grading
from poro2d.specimen.compaction import DEFAULT_MAX_DISKS, SpecimenSpec, check_feasible, estimate_size

R = 1e-3
# the probe's grading: fines of 0.1 um up-scaled by 10 mean about 1.5e8 disks in the paper's box
HUGE_GRADING = "[grading]\nsizes_mm = [0.0001, 0.002, 0.7]\npercent_passing = [0, 50, 100]\nupscale = 10\n"


def run(argv, capsys):
    """Run poro2d.cli.main(argv); return (exit code, stdout, stderr)."""
    code = 0
    try:
        main([str(a) for a in argv])
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    out, err = capsys.readouterr()
    return code, out, err


def refused(argv, capsys, *words):
    """The command exits 2 with one line ``error: ...`` holding every word, no traceback."""
    code, _, err = run(argv, capsys)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


def criterion_with(tmp_path, capsys, toml: str, *words):
    cfg = tmp_path / "case.toml"
    cfg.write_text(toml)
    out = tmp_path / "out"
    line = refused(["criterion", "--config", cfg, "--out", out, "--quiet"], capsys, *words)
    assert not out.exists()  # refused before anything was written
    return line


# ------------------------------------------------------------------ size guard
def test_huge_grading_is_refused_before_drawing(tmp_path, capsys):
    line = criterion_with(tmp_path, capsys, HUGE_GRADING, "specimen size", "max_disks = 2000000")
    assert "about 1.48e+08 disks (about 148 GB of memory)" in line
    assert "raise [specimen] max_disks" in line  # printed as text, not taken for markup


def test_estimate_matches_the_drawn_count():
    spec = SpecimenSpec(width=0.08, height=0.04, layers=2)
    est = estimate_size(spec, paper_grading(), 0.19)
    radii = draw_disks(paper_grading(), 0.81 * 0.08 * 0.04, 3)
    assert abs(radii.size - est.disks) < 0.05 * est.disks
    assert est.memory_bytes == pytest.approx(1000 * est.disks)


def test_max_disks_overrides_the_limit(caplog):
    curve = GradingCurve.from_lists([0.0001, 0.002, 0.7], [0, 50, 100], upscale=10)
    with pytest.raises(InputError, match="max_disks = 2000000"):
        check_feasible(SpecimenSpec(), curve, 0.15)
    # a lower limit refuses the paper's own specimen (about 2600 disks) ...
    with pytest.raises(InputError, match="max_disks = 1000 disks"):
        check_feasible(SpecimenSpec(max_disks=1000), paper_grading(), 0.15)
    # ... and a higher one lets a large specimen through, with a warning of its run time
    spec = SpecimenSpec(width=3.05, height=1.24, max_disks=DEFAULT_MAX_DISKS)
    with caplog.at_level(logging.WARNING, logger="poro2d.specimen.compaction"):
        check_feasible(spec, paper_grading(), 0.15)
    assert "large specimen: about 2.56e+05 disks" in caplog.text
    assert "particle-steps/s" in caplog.text and "about 21 min per trial" in caplog.text
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="poro2d.specimen.compaction"):
        check_feasible(SpecimenSpec(), paper_grading(), 0.15)  # the paper's box: no warning
    assert caplog.text == ""
    for bad in (0, 10**9, 2.5, True, "100"):
        with pytest.raises(InputError, match="max_disks"):
            SpecimenSpec(max_disks=bad)


def test_max_disks_is_a_config_key(tmp_path, capsys):
    criterion_with(tmp_path, capsys, "[specimen]\nmax_disks = 1000\n", "max_disks = 1000", "specimen size")


def test_draw_disks_ceiling_uses_the_expected_count():
    curve = GradingCurve.from_lists([0.0001, 0.002, 0.7], [0, 50, 100], upscale=10)
    with pytest.raises(InputError, match="about 1.46e\\+08 disks"):
        draw_disks(curve, 0.85 * 0.305 * 0.124, 0)


# ------------------------------------------------------------------ output folders
@pytest.mark.parametrize(
    "argv",
    [
        ["criterion", "--preset", "paper", "--quiet", "--out"],
        ["paper", "--quick", "--quiet", "--out"],
        ["shear", "--specimen", "nowhere.npz", "--out"],
        ["plot", "relations", "-o"],
        ["critical-state", "--quiet", "--out"],
    ],
)
def test_out_that_is_a_file(argv, tmp_path, capsys):
    f = tmp_path / "taken"
    f.write_text("not a folder")
    refused([*argv, f], capsys, "--out", "a file of that name exists")
    refused([*argv, f / "sub"], capsys, "--out", "is a file")
    assert f.read_text() == "not a folder"


def test_out_in_a_read_only_folder(tmp_path, capsys, monkeypatch):
    real = os.access

    def access(path, mode, **kw):  # tests run as root, where permission bits do not stop writes
        return False if str(path) == str(tmp_path) else real(path, mode, **kw)

    monkeypatch.setattr(os, "access", access)
    refused(["criterion", "--preset", "paper", "--out", tmp_path / "new"], capsys, "read-only")
    refused(["plot", "relations", "-o", tmp_path / "figs"], capsys, "read-only")
    assert not (tmp_path / "new").exists() and not (tmp_path / "figs").exists()


# ------------------------------------------------------------------ damaged files
def _small_sim():
    p = Particles(
        pos=[[0.02, 0.02], [0.05, 0.02]], radius=R, density=2650.0, thickness=0.01, kn=1e5, ks=1e5, mu=0.5
    )
    return Simulation(p, Walls.box(0.0, 0.0, 0.1, 0.1, 1e5, 1e5, 0.5))


def test_damaged_specimen_is_refused(tmp_path, capsys):
    good = checkpoint.save(_small_sim(), tmp_path / "good.npz")
    data = good.read_bytes()
    truncated = tmp_path / "truncated.npz"
    truncated.write_bytes(data[: len(data) // 2])
    garbage = tmp_path / "garbage.npz"
    garbage.write_bytes(os.urandom(3000))
    for bad, why in ((truncated, "File is not a zip file"), (garbage, "not an .npz archive")):
        refused(["shear", "--specimen", bad, "--out", tmp_path / "s"], capsys, "checkpoint", str(bad), why)
        with pytest.raises(InputError, match="checkpoint"):
            checkpoint.load(bad)
        with pytest.raises(InputError, match="checkpoint"):
            checkpoint.read_meta(bad)
    assert not (tmp_path / "s").exists()
    assert checkpoint.load(good).particles.n == 2


def test_binary_grading_csv(tmp_path, capsys):
    (tmp_path / "png.csv").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe\x00")
    (tmp_path / "nul.csv").write_bytes(b"size_mm,percent_passing\n0.1\x00,0\n1,100\n")
    for name in ("png.csv", "nul.csv"):
        line = criterion_with(tmp_path, capsys, f'[grading]\ncsv = "{name}"\n', "csv", name)
        assert "text" in line
        with pytest.raises(InputError, match="csv"):
            GradingCurve.from_csv(tmp_path / name)


# ------------------------------------------------------------------ config types
@pytest.mark.parametrize(
    "toml, words",
    [
        ("specimen = 5\n", ["specimen = 5", "a table"]),
        ("grading = 5\n", ["grading = 5", "a table"]),
        ("criterion = 'x'\n", ["criterion = 'x'", "a table"]),
        ('[specimen]\nwidth = "0.08"\n', ["specimen.width = '0.08'", "a number"]),
        ("[specimen]\nlayers = true\n", ["specimen.layers = True", "an integer"]),
        ("[specimen]\nlayers = 2.0\n", ["specimen.layers = 2.0", "an integer"]),
        ('[criterion]\nn_lab = "0.33"\n', ["criterion.n_lab = '0.33'", "a number"]),
        ("[criterion]\nn_lab = true\n", ["criterion.n_lab = True", "a number"]),
        ("seed = true\n", ["seed = True", "an integer"]),
        ("seed = 1.5\n", ["seed = 1.5", "an integer"]),
        ("title = 3\n", ["title = 3", "a string"]),
        ('[grading]\npreset = "paper"\nupscale = "10"\n', ["grading.upscale = '10'", "a number"]),
        ('[grading]\nsizes_mm = ["0.2", "1"]\npercent_passing = [0, 100]\n', ["sizes_mm", "numbers"]),
        ("[grading]\nsizes_mm = 1.0\npercent_passing = [0, 100]\n", ["grading.sizes_mm", "a list"]),
        ("[grading]\ncsv = 5\n", ["grading.csv = 5", "a string"]),
    ],
)
def test_config_values_of_the_wrong_type(tmp_path, capsys, toml, words):
    criterion_with(tmp_path, capsys, toml, *words)


@pytest.mark.parametrize("value", ["2.0", "1e6", "-0.1"])
def test_rolling_friction_of_a_specimen_is_held_to_the_range_shear_prints(tmp_path, capsys, value):
    """[specimen] rolling_friction takes the range --rolling-friction prints: [0, 1]."""
    criterion_with(tmp_path, capsys, f"[specimen]\nrolling_friction = {value}\n", "rolling_friction", "1.0]")


def test_integers_are_accepted_for_floats(tmp_path):
    from poro2d.config import dataclass_from_table

    spec = dataclass_from_table(SpecimenSpec, "specimen", {"width": 1, "layers": 2})
    assert spec.width == 1 and spec.layers == 2


def test_shear_config_extras(tmp_path, capsys):
    good = checkpoint.save(_small_sim(), tmp_path / "good.npz")
    for toml, word in (
        ("[shear]\nworkers = true\n", "shear.workers"),
        ('[shear]\nrate_check = "yes"\n', "shear.rate_check"),
        ('[shear]\nnormal_stress_kpa = ["50"]\n', "shear.normal_stress_kpa"),
        ('[shear]\nvelocity = "0.01"\n', "shear.velocity"),
    ):
        cfg = tmp_path / "shear.toml"
        cfg.write_text(toml)
        refused(["shear", "--specimen", good, "--config", cfg, "--out", tmp_path / "s"], capsys, word)


# ------------------------------------------------------------------ Python API
def test_strings_and_booleans_are_not_numbers():
    with pytest.raises(InputError, match="width"):
        SpecimenSpec(width="0.08")
    with pytest.raises(InputError, match="layers"):
        SpecimenSpec(layers=True)
    with pytest.raises(InputError, match="n_lab"):
        CriterionSettings(n_lab="0.33")
    with pytest.raises(InputError, match="x"):
        check_range("x", "0.3")
    with pytest.raises(InputError, match="x"):
        check_range("x", False)
    assert check_range("x", np.float32(0.5), 0.0, 1.0) == 0.5
    assert check_range("x", np.array(0.25), 0.0, 1.0) == 0.25
    assert check_int("k", np.int64(3), 1) == 3
    with pytest.raises(InputError, match="k"):
        check_int("k", 3.0, 1)


def test_particle_arrays_of_the_wrong_length_or_type():
    pos = np.array([[0.0, 0.0], [0.01, 0.0], [0.02, 0.0]])
    kw = dict(density=2650.0, thickness=0.01, kn=1e5, ks=1e5, mu=0.5)
    for field, value in (("radius", [R, R]), ("radius", ["0.001"] * 3), ("kn", [1e5] * 4), ("mu", "0.5")):
        args = {"pos": pos, "radius": R, **kw, field: value}
        with pytest.raises(InputError) as e:
            Particles(**args)
        assert e.value.parameter == field
    with pytest.raises(InputError) as e:
        Particles(pos=[["0", "0"]], radius=R, **kw)
    assert e.value.parameter == "positions"
    with pytest.raises(InputError) as e:
        Particles(pos=pos, radius=R, **kw, mode=[0, 1])
    assert e.value.parameter == "mode"
    with pytest.raises(InputError) as e:
        Particles(pos=pos, radius=R, **{**kw, "thickness": "0.01"})
    assert e.value.parameter == "thickness"


def test_grading_arrays_of_the_wrong_length_or_type():
    with pytest.raises(InputError, match="sizes_m"):
        GradingCurve(sizes_m=("0.001", "0.002"), percent_passing=(0, 100))
    with pytest.raises(InputError, match="percent_passing"):
        GradingCurve(sizes_m=(0.001, 0.002), percent_passing=(0, 50, 100))
    with pytest.raises(InputError, match="sizes_mm"):
        GradingCurve.from_lists(["0.2", "1"], [0, 100])
    with pytest.raises(InputError, match="percent_passing"):
        GradingCurve.from_lists([0.2, 1], [0, True])


# ------------------------------------------------------------------ disk layout
def _disks(pos, radius=R):
    return Particles(pos=pos, radius=radius, density=2650.0, thickness=0.01, kn=1e5, ks=1e5, mu=0.5)


def _box():
    return Walls.box(0.0, 0.0, 0.1, 0.05, 1e5, 1e5, 0.5)


def _layout_error(pos, walls=None):
    with pytest.raises(InputError) as e:
        Simulation(_disks(pos), walls)
    return e.value


def test_coincident_disks():
    err = _layout_error([[0.01, 0.01], [0.03, 0.01], [0.01 + 1e-7, 0.01]], _box())
    assert err.parameter == "disk 2 position" and "disk 0" in str(err)
    err = _layout_error([[0.01, 0.01], [0.01, 0.01]])  # no walls: still refused
    assert err.parameter == "disk 1 position"
    Simulation(_disks([[0.01, 0.01], [0.01 + 0.5 * R, 0.01]]), _box())  # overlapping a lot, not coincident


def test_disk_on_a_wall():
    err = _layout_error([[0.02, 0.02], [0.05, 0.0]], _box())
    assert err.parameter == "disk 1 position" and "'bottom'" in str(err)
    err = _layout_error([[0.1, 0.03]], _box())
    assert "'right'" in str(err)


@pytest.mark.parametrize(
    "where, wall",
    [((-0.01, 0.02), "left"), ((0.12, 0.02), "right"), ((0.05, 0.06), "top"), ((0.05, -0.01), "bottom")],
)
def test_disk_outside_the_box(where, wall):
    err = _layout_error([[0.02, 0.02], list(where)], _box())
    assert err.parameter == "disk 1 position" and f"beyond wall '{wall}'" in str(err)


def test_open_walls_are_not_a_box():
    floor = Walls()
    floor.add((-1.0, 0.0), (1.0, 0.0), 1e5, 1e5, 0.5, "floor")
    Simulation(_disks([[0.0, 0.01], [0.0, -0.01]]), floor)  # either side of a lone wall is fine
    cup = Walls()
    cup.add((-1.0, 0.0), (1.0, 0.0), 1e5, 1e5, 0.5, "bottom")
    cup.add((0.1, -0.1), (0.1, 0.5), 1e5, 1e5, 0.5, "right")
    cup.add((0.0, 0.5), (0.0, -0.1), 1e5, 1e5, 0.5, "left")
    Simulation(_disks([[0.05, 0.01], [0.05, 0.9]]), cup)  # in the cup and above its open top


def test_added_disks_are_checked_and_nothing_changes_on_refusal():
    sim = Simulation(_disks([[0.02, 0.02], [0.05, 0.02]]), _box())
    with pytest.raises(InputError) as e:
        sim.add_particles(_disks([[0.07, 0.02], [0.05, 0.02]]))
    assert e.value.parameter == "disk 3 position"
    with pytest.raises(InputError, match="beyond wall 'top'"):
        sim.add_particles(_disks([[0.07, 0.07]]))
    assert sim.particles.n == 2
    assert sim.add_particles(_disks([[0.07, 0.02]])).tolist() == [2]


def test_coincident_pair_equals_brute_force():
    rng = np.random.default_rng(5)
    for _ in range(100):
        n = int(rng.integers(2, 60))
        pos = rng.uniform(0.0, 0.01, (n, 2))
        rad = rng.uniform(1e-4, 1e-3, n)
        for _ in range(int(rng.integers(0, 3))):
            i, j = rng.integers(0, n, 2)
            pos[j] = pos[i] + rng.uniform(-2e-6, 2e-6, 2)
        close = [
            (i, j)
            for i in range(n)
            for j in range(i + 1, n)
            if np.hypot(*(pos[i] - pos[j])) < COINCIDENT * min(rad[i], rad[j])
        ]
        got = coincident_pair(pos, rad)
        assert (got[:2] if got else None) == (close[0] if close else None)


@pytest.mark.parametrize("value", [float("nan"), float("inf")])
def test_a_non_finite_upscale_is_refused_as_not_finite(value):
    """NaN was refused with the range (0.0, inf], which reads as if inf were allowed (it is not)."""
    with pytest.raises(InputError, match="upscale.*a finite number > 0"):
        GradingCurve.from_lists([0.1, 1.0], [0, 100], upscale=value)
    with pytest.raises(InputError, match="upscale.*a finite number > 0"):
        GradingCurve((1e-4, 1e-3), (0.0, 100.0), upscale=value)


def test_a_missing_biaxial_lab_file_is_named_as_the_option(tmp_path, capsys):
    """It was named ``lab``, a name the user never typed."""
    out = tmp_path / "b"
    refused(["biaxial", "--quick", "--lab", tmp_path / "nope.csv", "--out", out, "--quiet"], capsys,
            "--lab = ", "nope.csv")  # fmt: skip
    assert not out.exists()


def test_laboratory_extremes_are_named_as_typed(tmp_path, capsys):
    """``--n-max nan`` was refused as ``n_max``, a name the user never typed; a config's value is
    named by its table's key."""
    out = tmp_path / "o"
    argv = [
        "criterion",
        "--preset",
        "paper",
        "--mode",
        "density",
        "--n-max",
        "nan",
        "--n-min",
        "0.3",
        "--out",
        out,
    ]
    refused(argv, capsys, "--n-max = nan")
    criterion_with(
        tmp_path, capsys, '[density]\nmode = "density"\nn_max = 1.5\nn_min = 0.3\n', "density.n_max = 1.5"
    )
    assert not out.exists()


@pytest.mark.parametrize(("option", "value"), [("--n-lab", "nan"), ("--trial-porosity", "inf")])
def test_criterion_options_are_named_as_typed(option, value, tmp_path, capsys):
    """``--n-lab nan`` was refused as ``n_lab``, a name the user never typed."""
    out = tmp_path / "o"
    refused(["criterion", "--preset", "paper", option, value, "--out", out], capsys, f"{option} = ")
    assert not out.exists()
