"""Export by laboratory state (relation, density-mode criterion and sand folders) and the
provenance lines of every target. The folders are built by hand from one small specimen:
their JSON files as the relation, the criterion's density mode and the sweep runner write them."""

import json
import os
import shutil

import pytest

from poro2d import __version__
from poro2d.cli import main
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.interop import csv_table, lammps, pfc, yade
from poro2d.interop.check import DEFAULTS
from poro2d.interop.exported import export_specimen
from poro2d.interop.specimen_data import from_checkpoint
from poro2d.interop.state_specimen import state_specimen
from poro2d.store import Store

PROV = {"poro2d_version": "0.0.9", "created_utc": "2026-01-02T03:04:05+00:00"}


def _criterion(folder, specimen, *, n_lab, seed, mu, n2d, converged=True, grading=None, interior=0.1875):
    """A criterion folder as the criterion writes it: specimen.npz, result.json, config.json."""
    folder.mkdir(parents=True)
    shutil.copyfile(specimen, folder / "specimen.npz")
    result = {
        "final_porosity": n2d if converged else None, "converged": converged,
        "message": "accepted" if converged else "no trial in the window after 10 trials",
        "n_lab": n_lab, "seed": seed, "iterations": [{"iteration": 1, "accepted": converged}],
        "settings": {"force_fraction": 0.02}, "specimen": {"friction_prep": mu, "width": 0.06},
        "provenance": PROV, "box_porosity": n2d + 0.0004, "interior_porosity": interior,
        "interior_porosity_std": 0.004,
    }  # fmt: skip
    config = {"seed": seed, "criterion": {"n_lab": n_lab}}
    source = "poro2d/data/paper_grading.csv (reconstruction of the paper's Fig. 4)"
    if grading is not None:  # the table as given; the run records the file as it read it
        config["grading"] = {k: v for k, v in grading.items() if k != "source"}
        source = grading["source"]
    record = {"run": {"grading": {"source": source}, "seed": seed}, "config": config, "provenance": PROV}
    (folder / "result.json").write_text(json.dumps(result))
    (folder / "config.json").write_text(json.dumps(record))
    return folder


def _sweep(folder, specimen, cases):
    """A sweep folder: sweep.json and, per case, params.json, result.json and run/ (the criterion)."""
    folder.mkdir(parents=True, exist_ok=True)
    listed = []
    for cid, params, kw in cases:
        d = folder / "cases" / cid
        _criterion(d / "run", specimen, **kw)
        (d / "params.json").write_text(json.dumps({"id": cid, "kind": "criterion", "params": params}))
        row = {"case_id": cid, "status": "done", "params": params,
               "results": {"n_lab": kw["n_lab"], "converged": kw.get("converged", True)}}  # fmt: skip
        (d / "result.json").write_text(json.dumps(row))
        listed.append({"id": cid, "params": params})
    (folder / "sweep.json").write_text(json.dumps({"status": "finished", "cases": listed}))


def _state_case(cid, n_lab, seed, mu, n2d, converged=True):
    params = {"criterion.n_lab": n_lab, "specimen.friction_prep": round(mu, 6), "seed": seed}
    return cid, params, {"n_lab": n_lab, "seed": seed, "mu": round(mu, 6), "n2d": n2d, "converged": converged}


@pytest.fixture(scope="module")
def relation(tmp_path_factory, specimen):
    """A density-mode relation of two states, two seeds each: the loose state's seed 1 did not
    converge; the dense state's seed 1 is the calibration's case (its twin), in the cache."""
    root = tmp_path_factory.mktemp("states")
    cache = root / "cache" / "calibrations" / "k1"
    _sweep(cache, specimen, [("q7", {"specimen.friction_prep": 0.0, "seed": 1},
                              {"n_lab": 0.3434, "seed": 1, "mu": 0.0, "n2d": 0.171})])  # fmt: skip
    # a later run of other frictions shares the cache: its sweep.json lists only that run's cases
    (cache / "sweep.json").write_text(json.dumps({"status": "finished", "cases": []}))
    rel = root / "rel"
    _sweep(rel / "states", specimen, [
        _state_case("x1", 0.4571, 0, 0.5, 0.226), _state_case("b2", 0.4571, 1, 0.5, 0.23, converged=False),
        _state_case("zz", 0.3253, 0, 0.0, 0.17),
    ])  # fmt: skip
    points = [
        {"n_lab": 0.4571, "relative_density": 0.0, "mu_prep": 0.5, "seeds": 2, "seeds_converged": 1},
        {"n_lab": 0.3253, "relative_density": 1.0, "mu_prep": 0.0, "seeds": 2, "seeds_converged": 2},
    ]
    (rel / "relation.json").write_text(json.dumps({
        "n_max": 0.4571, "n_min": 0.3253, "points": points, "mode": "density",
        "sweeps": {"calibration": {"key": "k1", "cases": str(cache)}}, "config": {"seed": 0},
    }))  # fmt: skip
    return rel


def test_a_relation_gives_the_specimen_of_a_state_and_seed(relation):
    cases = relation / "states" / "cases"
    assert state_specimen(relation, n_lab=0.4571).folder == cases / "x1" / "run"
    assert state_specimen(Store(relation), n_lab=0.4571).folder == cases / "x1" / "run"  # a store reads alike
    assert state_specimen(relation, dr=1.0, seed=0).folder == cases / "zz" / "run"
    assert state_specimen(relation, n_lab=0.32531).folder == cases / "zz" / "run"  # 4 decimals
    # the dense state's seed 1 was not run again: the calibration's case of its friction and seed
    twin = state_specimen(relation, dr=1.0, seed=1)
    assert twin.folder.parent.name == "q7" and twin.mode == "density" and twin.n_lab == 0.3253


def test_a_relation_refuses_what_it_does_not_hold(relation):
    with pytest.raises(InputError) as e:  # no state named
        state_specimen(relation)
    assert e.value.parameter == "--n-lab/--dr"
    assert "n_lab 0.4571 (Dr 0.0000): seed 0 (not accepted: 1)" in e.value.allowed
    assert "n_lab 0.3253 (Dr 1.0000): seeds 0, 1" in e.value.allowed
    with pytest.raises(InputError) as e:
        state_specimen(relation, n_lab=0.40)
    assert e.value.parameter == "--n-lab" and e.value.value == 0.40 and "n_lab 0.3253" in e.value.allowed
    with pytest.raises(InputError) as e:
        state_specimen(relation, dr=0.5)
    assert e.value.parameter == "--dr"
    with pytest.raises(InputError) as e:
        state_specimen(relation, n_lab=0.3253, seed=2)
    assert e.value.parameter == "--seed" and e.value.value == 2 and "seeds 0, 1" in e.value.allowed
    with pytest.raises(InputError) as e:  # there, but its criterion did not converge
        state_specimen(relation, n_lab=0.4571, seed=1)
    assert e.value.parameter == "--seed" and "converged = False" in e.value.hint
    with pytest.raises(InputError) as e:
        state_specimen(relation, n_lab=0.4571, dr=0.0)
    assert e.value.parameter == "--n-lab/--dr"
    with pytest.raises(InputError) as e:
        state_specimen(relation, n_lab=0.4571, seed=-1)
    assert e.value.parameter == "--seed"


def test_a_density_criterion_folder_and_a_paper_relation(tmp_path, specimen):
    dens = tmp_path / "dens"
    _sweep(
        dens / "states",
        specimen,
        [_state_case("a9", 0.4, 0, 0.264, 0.246), _state_case("c3", 0.4, 1, 0.264, 0.25)],
    )
    (dens / "density.json").write_text(json.dumps(
        {"mode": "density", "n_lab": 0.4, "relative_density": 0.4872, "mu_prep": 0.264, "seeds": 2}
    ))  # fmt: skip
    got = state_specimen(dens, dr=0.4872, seed=1)
    assert got.folder == dens / "states" / "cases" / "c3" / "run" and got.relative_density == 0.4872
    # paper mode: one case per state at the config's seed, in the relation folder itself
    rel = tmp_path / "paper"
    _sweep(
        rel, specimen, [("p1", {"criterion.n_lab": 0.4}, {"n_lab": 0.4, "seed": 3, "mu": 0.0, "n2d": 0.2})]
    )
    (rel / "relation.json").write_text(json.dumps({"mode": "paper", "config": {"seed": 3}, "points": [
        {"n_lab": 0.4, "relative_density": 0.4872, "case_id": "p1"}]}))  # fmt: skip
    assert state_specimen(rel, n_lab=0.4, seed=3).folder == rel / "cases" / "p1" / "run"
    with pytest.raises(InputError) as e:
        state_specimen(rel, n_lab=0.4)
    assert e.value.parameter == "--seed" and "seed 3" in e.value.allowed


def test_a_sand_folder(tmp_path, specimen):
    sand = tmp_path / "sand"
    _criterion(sand / "crit" / "loose", specimen, n_lab=0.45, seed=0, mu=0.5, n2d=0.23)
    _criterion(sand / "crit" / "dense", specimen, n_lab=0.33, seed=0, mu=0.0, n2d=0.17, converged=False)
    states = [
        {"n_lab": 0.45, "relative_density": 0.05, "seed": 0, "specimen": "crit/loose"},
        {"n_lab": 0.33, "relative_density": 0.96, "seed": 0, "specimen": "crit/dense"},
    ]
    (sand / "sand.json").write_text(json.dumps({"mode": "density", "states": states}))
    got = state_specimen(sand, dr=0.05)
    assert got.folder == sand / "crit" / "loose" and got.mode == "density" and got.seed == 0
    with pytest.raises(InputError) as e:
        state_specimen(sand, n_lab=0.33)
    assert e.value.parameter == "--seed" and "no accepted seed" in e.value.allowed


def test_a_sand_folder_that_does_not_say_the_mode_takes_that_of_its_case(relation, tmp_path):
    sand = tmp_path / "sand"
    shutil.copytree(relation, sand / "rel")  # a specimen names a folder inside its sand folder
    case = sand / "rel" / "states" / "cases" / "zz" / "run"
    rel_path = os.path.relpath(case, sand)  # the specimen's folder, relative to the sand folder
    states = [{"n_lab": 0.3253, "relative_density": 1.0, "seed": 0, "specimen": rel_path}]
    (sand / "sand.json").write_text(json.dumps({"states": states}))
    spec, state = export_specimen(str(sand), tmp_path / "out", n_lab=0.3253)
    assert state.folder.resolve() == case.resolve() and state.mode is None
    assert any("mode density" in ln for ln in spec.origin)
    assert any(f"state read from {sand / 'sand.json'}" in ln for ln in spec.origin)


def _export_refused(args, tmp_path, capsys, *words) -> None:
    """``poro2d export ARGS --to csv`` exits 2 with one line holding every word, writing nothing."""
    with pytest.raises(SystemExit) as e:
        main(["export", *map(str, args), "--to", "csv", "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err
    assert e.value.code == 2 and len(err.strip().splitlines()) == 1, err
    for word in words:
        assert word in err, (word, err)
    assert not (tmp_path / "x").exists()


def test_a_sand_record_that_leaves_its_folder_or_mislabels_a_seed_is_refused(tmp_path, specimen, capsys):
    """With its manifest gone and ``sand.json`` edited, a state's specimen path that leaves the
    sand folder, or that names the specimen of another seed, is refused rather than exported."""
    other = _criterion(tmp_path / "other" / "crit", specimen, n_lab=0.45, seed=1, mu=0.5, n2d=0.23)
    sand = tmp_path / "sand"
    _criterion(sand / "crit" / "seed1", specimen, n_lab=0.45, seed=1, mu=0.5, n2d=0.23)
    outside = os.path.relpath(other, sand)
    for path, words in (
        (outside, ["sand.json states[0] specimen = '../other/crit'", f"a path inside {sand}"]),
        (str(other), ["sand.json states[0] specimen", "this one leaves it"]),  # absolute, too
        ("crit/seed1", ["--seed = 0", "records seed 1, not the seed 0 of", "sand.json states[0]"]),
    ):
        states = [{"n_lab": 0.45, "relative_density": 0.8, "seed": 0, "specimen": path}]
        (sand / "sand.json").write_text(json.dumps({"mode": "density", "states": states}))
        _export_refused([sand, "--dr", "0.8", "--seed", "0"], tmp_path, capsys, *words)
    _export_refused([sand, "--dr", "nan"], tmp_path, capsys, "--dr = nan", "allowed: [0, 1]")


PROVENANCE = (
    "provenance: grading preset 'paper'", "up-scaling factor 10.0; no d_min/d_max cut",
    "n_lab = 0.3253, relative density Dr = 1.0000; mode density",
    "mu_prep (specimen.friction_prep) = 0.0", "accepted n2D = 0.17, box porosity n' = 0.1704",
    "interior porosity = 0.1875 +- 0.004", "seed 0; criterion run by poro2d 0.0.9", "state read from",
)  # fmt: skip
FILES = {"lammps": ("specimen.data", "in.specimen"), "yade": ("specimen_yade.py",),
         "pfc": ("specimen.p2dat", "specimen_pfc4.dat"), "csv": ("disks.csv", "walls.csv")}  # fmt: skip


@pytest.mark.parametrize("target", sorted(FILES))
def test_export_by_state_names_the_soil_in_every_file(relation, tmp_path, capsys, target):
    out = tmp_path / target
    main(["export", str(relation), "--to", target, "--out", str(out), "--dr", "1", "--seed", "0"])
    for name in FILES[target]:
        text = (out / name).read_text()
        comment = ";" if target == "pfc" else "#"
        lines = [ln for ln in text.splitlines() if ln.startswith(f"{comment} provenance:")]
        for words in PROVENANCE:
            assert any(words in ln for ln in lines), (name, words)
        assert f"poro2d {__version__}" in text  # the exporting version, as before
    # the files read back as before the provenance lines (round trip)
    spec = from_checkpoint(relation / "states" / "cases" / "zz" / "run")
    if target in ("csv", "lammps"):
        reader = csv_table.read_specimen if target == "csv" else lammps.read_specimen
        back = reader(out / FILES[target][0], DEFAULTS)
        assert (back.x == spec.x).all() and (back.radius == spec.radius).all() and back.walls == spec.walls


def test_the_same_specimen_by_its_folder_gets_the_same_provenance(relation, tmp_path):
    """Exported by the case's own folder, the state is looked up above it; with the provenance
    lines left out, the files are those of a specimen without provenance."""
    by_state, state = export_specimen(str(relation), tmp_path / "a", dr=1.0)
    by_path, none = export_specimen(str(relation / "states" / "cases" / "zz" / "run"), tmp_path / "b")
    assert by_state.origin == by_path.origin and none is None and state.seed == 0
    bare = from_checkpoint(relation / "states" / "cases" / "zz" / "run")
    bare.origin = None
    for write in (lambda s, o: lammps.write_specimen(s, o), csv_table.write_specimen, pfc.write_specimen,
                  yade.write_specimen):  # fmt: skip
        for p_new, p_old in zip(write(by_path, tmp_path / "new"), write(bare, tmp_path / "old"), strict=True):
            new = [ln for ln in p_new.read_text().splitlines() if "provenance:" not in ln]
            old = [ln for ln in p_old.read_text().splitlines() if "provenance:" not in ln]
            assert new == old, p_new.name


def test_provenance_of_a_csv_grading_and_of_a_bare_checkpoint(tmp_path, specimen):
    grading = {"csv": "sand.csv", "upscale": 5.0, "d_min_mm": 1.5, "source": "/data/sand.csv"}
    crit = _criterion(tmp_path / "crit", specimen, n_lab=0.38, seed=2, mu=0.3, n2d=0.2, grading=grading,
                      interior=None)  # fmt: skip
    lines = from_checkpoint(crit).header("#")
    text = "\n".join(lines)
    assert (
        "# provenance: grading CSV file /data/sand.csv, up-scaling factor 5.0; cut at d_min_mm = 1.5 mm"
        in text
    )
    assert "relative density Dr = unknown; mode paper (a criterion folder of its own)" in text
    # the laboratory extremes of the config's [density] give the relative density
    record = json.loads((crit / "config.json").read_text())
    record["config"]["density"] = {"n_max": 0.4571, "n_min": 0.3253}
    (crit / "config.json").write_text(json.dumps(record))
    assert "n_lab = 0.38, relative density Dr = 0.6366; mode paper" in "\n".join(
        from_checkpoint(crit).header("#")
    )
    assert "interior porosity unknown" in text and "seed 2;" in text
    # a checkpoint with no criterion record beside it: said, not made up
    (tmp_path / "bare").mkdir()
    shutil.copyfile(specimen, tmp_path / "bare" / "state.npz")
    lines = from_checkpoint(tmp_path / "bare" / "state.npz").header(";")
    prov = [ln for ln in lines if "provenance:" in ln]
    assert len(prov) == 1 and prov[0].startswith("; provenance: unknown")


def test_export_cli_refusals_name_the_option(relation, specimen, tmp_path, capsys):
    cases = [
        ([str(relation)], "--n-lab/--dr"),
        ([str(relation), "--n-lab", "0.41"], "--n-lab = 0.41"),
        ([str(relation), "--dr", "0", "--seed", "1"], "--seed = 1"),
        ([str(specimen), "--n-lab", "0.4"], "--n-lab = 0.4"),
        ([str(specimen.parent), "--seed", "1"], "--seed = 1"),
    ]
    for args, words in cases:
        with pytest.raises(SystemExit) as e:
            main(["export", *args, "--to", "csv", "--out", str(tmp_path / "x")])
        err = capsys.readouterr().err
        assert e.value.code == 2 and words in err and len(err.strip().splitlines()) == 1, err
        assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("target", ["lammps", "pfc", "yade", "csv"])
def test_a_refused_export_leaves_a_folder_of_other_files_as_it_was(tmp_path, specimen, capsys, target):
    """A target's own refusal (disks of differing properties; YADE and CSV take them, so a state
    that leaves its folder stands in for them) comes before the output folder is claimed:
    a non-empty ``--out`` is left without a kind marker, and an import may still use it."""
    sim = checkpoint.load(specimen)
    sim.particles.kn[0] *= 2.0
    mixed = checkpoint.save(sim, tmp_path / "mixed" / "specimen.npz")
    sand = tmp_path / "sand"
    sand.mkdir()
    states = [{"n_lab": 0.45, "relative_density": 0.8, "seed": 0, "specimen": str(mixed.parent)}]
    (sand / "sand.json").write_text(json.dumps({"mode": "density", "states": states}))
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    given = [mixed] if target in ("lammps", "pfc") else [sand, "--dr", "0.8"]
    with pytest.raises(SystemExit) as e:
        main(["export", *map(str, given), "--to", target, "--out", str(out)])
    err = capsys.readouterr().err
    assert e.value.code == 2 and len(err.strip().splitlines()) == 1, err
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
