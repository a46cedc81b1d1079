"""Export to LAMMPS, YADE, PFC2D and CSV, read back exactly; import and the criterion's check."""

import ast
import json
import math
import re

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.dem import checkpoint
from poro2d.dem.contact_law import in_series as series
from poro2d.errors import InputError
from poro2d.interop import csv_table, pfc, yade
from poro2d.interop import lammps as lmp
from poro2d.interop.check import DEFAULTS, check_specimen, read_specimen
from poro2d.interop.specimen_data import from_checkpoint, from_simulation
from poro2d.locks import KIND_NAME


@pytest.fixture(scope="module")
def spec(saved):
    return from_checkpoint(saved.parent)  # a folder holding specimen.npz, as `poro2d export` takes


def _same_disks(a, b):
    for f in ("x", "y", "radius", "density", "kn", "ks", "mu"):
        assert np.array_equal(getattr(a, f), getattr(b, f)), f


def test_checkpoint_reads_as_the_simulation_holds_it(saved, spec):
    sim = checkpoint.load(saved)
    assert np.array_equal(np.column_stack([spec.x, spec.y]), sim.particles.pos)
    assert spec.thickness == 0.008 and spec.dt == sim.dt and spec.gravity == (0.0, -9.81)
    assert spec.box() == (0.0, 0.06, 0.0, 0.03)
    assert spec.contact_parameters().walls["top"] == (series(4e5, 1e7), series(4e5, 1e7), 1.5, 0.0)
    live = from_simulation(sim)  # a running Simulation gives the same numbers
    _same_disks(spec, live)
    assert live.walls == spec.walls and live.dt == spec.dt


def test_csv_round_trip_is_exact(spec, tmp_path):
    paths = csv_table.write_specimen(spec, tmp_path)
    assert [p.name for p in paths] == ["disks.csv", "walls.csv"]
    text = paths[0].read_text()
    assert "thickness t = 0.008 m" in text and "poro2d 0." in text and "SI" in text
    back = csv_table.read_specimen(tmp_path, DEFAULTS)
    _same_disks(spec, back)
    assert back.walls == spec.walls
    assert (back.thickness, back.gravity, back.local_damping, back.dt) == (
        spec.thickness, spec.gravity, spec.local_damping, spec.dt,
    )  # fmt: skip


def test_lammps_data_round_trip_is_exact_and_masses_are_disk_masses(spec, tmp_path):
    lmp.write_specimen(spec, tmp_path)
    raw = lmp.read_data(tmp_path / lmp.DATA_FILE)
    # LAMMPS' sphere mass 4/3 pi r^3 rho' with the per-atom density equals rho pi r^2 t
    assert np.allclose(raw.mass, 2650.0 * np.pi * spec.radius**2 * 0.008, rtol=1e-14, atol=0)
    assert raw.zspan == pytest.approx(0.008)
    back = lmp.read_specimen(tmp_path / lmp.DATA_FILE, DEFAULTS)
    _same_disks(spec, back)
    assert back.walls == spec.walls and back.dt == spec.dt


def test_lammps_data_of_another_origin_takes_its_box_and_the_given_thickness(spec, tmp_path):
    lmp.write_specimen(spec, tmp_path)
    path = tmp_path / lmp.DATA_FILE
    path.write_text("\n".join(ln for ln in path.read_text().splitlines() if not ln.startswith("#")) + "\n")
    back = lmp.read_specimen(path, dict(DEFAULTS, thickness=0.008))
    assert np.array_equal(back.x, spec.x) and np.array_equal(back.radius, spec.radius)
    assert np.allclose(back.density, 2650.0, rtol=1e-12)
    margin = float(spec.radius.max())
    assert back.box() == pytest.approx((-margin, 0.06 + margin, -margin, 0.03 + margin))
    assert back.wall("top").mu == DEFAULTS["friction_wall"] and back.mu[0] == DEFAULTS["friction_particle"]


def _literal(tree: ast.Module, name: str):
    node = next(n for n in tree.body if isinstance(n, ast.Assign) and n.targets[0].id == name)
    return ast.literal_eval(node.value)


def test_yade_script_carries_every_disk_and_parameter(spec, tmp_path):
    (path,) = yade.write_specimen(spec, tmp_path)
    text = path.read_text()
    tree = ast.parse(text)  # valid Python
    compile(text, str(path), "exec")
    disks = np.array(_literal(tree, "DISKS"))
    for k, f in enumerate(("x", "y", "radius", "density", "kn", "ks", "mu")):
        assert np.array_equal(disks[:, k], getattr(spec, f)), f
    walls = _literal(tree, "WALLS")
    assert [w[0] for w in walls] == ["bottom", "right", "top", "left"]
    assert [tuple(w[1:]) for w in walls] == [(w.x0, w.y0, w.x1, w.y1, w.kn, w.ks, w.mu) for w in spec.walls]
    settings = _literal(tree, "SETTINGS")
    assert settings["thickness"] == 0.008 and settings["dt"] == spec.dt and settings["damping"] == 0.7
    assert settings["gravity"] == (0.0, -9.81)
    # the script's materials (young = kn / 2r) combine in YADE's rule 2 Ea ra Eb rb / (Ea ra + Eb rb)
    # to PFC 4.0's springs in series, whatever the two radii
    (ra, ka), (rb, kb) = (disks[0, 2], disks[0, 4]), (disks[1, 2], disks[1, 4])
    ea, eb = ka / (2 * ra), kb / (2 * rb)
    assert 2 * ea * ra * eb * rb / (ea * ra + eb * rb) == pytest.approx(series(ka, kb), rel=1e-15)
    assert 'blockedDOFs = "zXY"' in text and "m = rho * math.pi * r * r * T" in text


_NUM = r"([-+0-9.eE]+)"


def test_pfc_command_files_carry_every_ball_wall_and_property(spec, tmp_path):
    pfc.write_specimen(spec, tmp_path)
    cur = (tmp_path / pfc.CURRENT_FILE).read_text()
    balls = re.findall(rf"^ball create id (\d+) position \({_NUM},{_NUM}\) radius {_NUM}$", cur, re.M)
    assert [int(b[0]) for b in balls] == list(range(1, spec.n + 1))
    got = np.array([[float(v) for v in b[1:]] for b in balls])
    assert np.array_equal(got, np.column_stack([spec.x, spec.y, spec.radius]))
    dens = re.findall(rf"^ball attribute density {_NUM} damp {_NUM} range id (\d+)$", cur, re.M)
    assert [float(d[0]) for d in dens] == list(spec.density * spec.thickness) and dens[0][1] == "0.7"
    walls = re.findall(
        rf"^wall create vertices {_NUM} {_NUM} {_NUM} {_NUM} id (\d+) name '(\w+)'$", cur, re.M
    )
    assert [(tuple(map(float, w[:4])), w[5]) for w in walls] == [
        ((w.x0, w.y0, w.x1, w.y1), w.name) for w in spec.walls
    ]
    pp = re.search(rf"type 'ball-ball' model 'linear' property kn {_NUM} ks {_NUM} fric {_NUM}", cur)
    assert tuple(map(float, pp.groups())) == (2e5, 2e5, 3.0)
    pw = re.search(rf"type 'ball-facet' model 'linear' property kn {_NUM} ks {_NUM} fric {_NUM}", cur)
    assert tuple(map(float, pw.groups())) == (series(4e5, 1e7), series(4e5, 1e7), 1.5)

    old = (tmp_path / pfc.PFC4_FILE).read_text()
    b4 = re.findall(rf"^ball id=(\d+) x={_NUM} y={_NUM} rad={_NUM}$", old, re.M)
    assert np.array_equal(np.array([[float(v) for v in b[1:]] for b in b4]), got)
    props = re.findall(
        rf"^property density={_NUM} kn={_NUM} ks={_NUM} friction={_NUM} range id=(\d+)$", old, re.M
    )
    assert len(props) == spec.n and tuple(map(float, props[0][1:4])) == (4e5, 4e5, 3.0)  # per body, Table 1
    w4 = re.findall(rf"^wall id=(\d+) kn={_NUM} ks={_NUM} friction={_NUM} nodes \({_NUM},{_NUM}\)", old, re.M)
    assert [tuple(map(float, w[1:4])) for w in w4] == [(1e7, 1e7, 1.5)] * 4
    assert "set disk on" in old and "thickness t = 0.008 m" in old


def test_export_refuses_what_a_target_cannot_hold(spec, tmp_path):
    varied = type(spec)(**{**spec.__dict__, "kn": spec.kn * np.linspace(1, 2, spec.n)})
    with pytest.raises(InputError, match="disk kn"):
        lmp.write_specimen(varied, tmp_path)
    csv_table.write_specimen(varied, tmp_path)  # a table holds per-disk values
    assert np.array_equal(csv_table.read_specimen(tmp_path, DEFAULTS).kn, varied.kn)


def test_export_cli_writes_each_target_and_refuses_bad_input(saved, tmp_path, capsys):
    for target, names in (("lammps", {"specimen.data", "in.specimen"}), ("csv", {"disks.csv", "walls.csv"})):
        main(["export", str(saved.parent), "--to", target, "--out", str(tmp_path / target)])
        files = {p.name for p in (tmp_path / target).iterdir()}
        assert files == names | {KIND_NAME}  # the folder is marked as an export's

    for argv, word in (
        (["export", str(saved), "--to", "gromacs", "--out", str(tmp_path / "x")], "--to"),
        (["export", str(tmp_path / "none.npz"), "--to", "csv", "--out", str(tmp_path / "x")], "SPECIMEN"),
    ):
        with pytest.raises(SystemExit) as e:
            main(argv)
        assert e.value.code == 2
        err = capsys.readouterr().err.strip()
        assert word in err and len(err.splitlines()) == 1
    assert not (tmp_path / "x").exists()


def test_bad_files_name_line_and_column(spec, tmp_path, capsys):
    csv_table.write_specimen(spec, tmp_path)
    disks = tmp_path / "disks.csv"
    lines = disks.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.startswith("3,"))
    cells = lines[k].split(",")
    cells[3] = "0.0o2"
    lines[k] = ",".join(cells)
    disks.write_text("\n".join(lines) + "\n")
    with pytest.raises(SystemExit) as e:
        main(["import", str(disks), "--out", str(tmp_path / "out")])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert f"line {k + 1} column 4" in err and "0.0o2" in err and len(err.strip().splitlines()) == 1

    lmp.write_specimen(spec, tmp_path)
    data = tmp_path / lmp.DATA_FILE
    text = data.read_text().splitlines()
    k = next(i for i, ln in enumerate(text) if ln.startswith("5 1 "))
    words = text[k].split()
    words[4] = "x4"
    text[k] = " ".join(words)
    data.write_text("\n".join(text) + "\n")
    with pytest.raises(InputError, match=rf"line {k + 1} column 5"):
        read_specimen(data)


def test_import_checks_the_window_and_balances_the_weight(spec, tmp_path):
    csv_table.write_specimen(spec, tmp_path / "csv")
    sim, rep = check_specimen(read_specimen(tmp_path / "csv"), ratio=1e-5)
    g = rep["self_weight_n_per_m"]
    assert g == pytest.approx(2650 * (1 - 0.21) * 0.06 * 0.03 * 9.81, rel=1e-9)
    # at rest the floor and the side walls carry the weight and the plate's push
    up = rep["f_bottom_n_per_m"] + rep["side_friction_up_n_per_m"]
    assert up == pytest.approx(g + rep["f_top_n_per_m"], rel=1e-4)
    assert rep["f_top_n_per_m"] > 0.01 * g and not rep["passes"]  # above the window: the plate goes up
    assert rep["plate"]["moved"] == "up" and rep["plate"]["plate_settled"]
    assert 0.0 < rep["plate"]["f_top_after_n_per_m"] < 0.01 * g
    assert rep["plate"]["new_porosity"] > 0.21


def test_import_of_a_loose_box_moves_the_plate_down(spec, tmp_path, capsys):
    csv_table.write_specimen(spec, tmp_path)
    walls = tmp_path / "walls.csv"
    text = walls.read_text().replace(",0.03,", ",0.032,")  # the plate 2 mm above the disks
    walls.write_text(text)
    with pytest.raises(SystemExit) as e:
        main(["import", str(tmp_path / "disks.csv"), "--out", str(tmp_path / "out"), "--quiet"])
    assert e.value.code == 1  # the specimen fails the check as it stands
    rep = json.loads((tmp_path / "out" / "check.json").read_text())
    assert rep["f_top_n_per_m"] == 0.0 and rep["box_m"]["height"] == 0.032
    assert rep["plate"]["moved"] == "down" and rep["plate"]["new_porosity"] < rep["box_porosity"]
    assert math.isfinite(rep["plate"]["plate_height_m"]) and "poro2d_version" in rep["provenance"]
    assert (tmp_path / "out" / "specimen.npz").is_file() and (tmp_path / "out" / "after_plate.npz").is_file()
    assert "moving down" in capsys.readouterr().out


def test_result_lines_read_as_numbers_by_key():
    """The last ``poro2d-result`` line a LAMMPS or YADE script prints, one number per key."""
    from poro2d.interop.lammps_run import LammpsError
    from poro2d.interop.settled import result_numbers

    log = "poro2d-result ratio 9 f_top 9 f_bottom 9 side_friction_up 9 f_left 9 f_right 9 coordination 9\n"
    log += "poro2d-result ratio 1e-4 f_top 1.5 f_bottom 800 side_friction_up 2 f_left 3 f_right 4 "
    log += "coordination 3.5"
    line = result_numbers(log, LammpsError, "the LAMMPS log")
    assert (line["ratio"], line["f_top"], line["f_bottom"], line["coordination"]) == (1e-4, 1.5, 800.0, 3.5)
    out = "poro2d-result f_top_n_per_m 1.0 f_bottom_n_per_m 2.0 side_friction_up_n_per_m 0.5 "
    out += "unbalanced_force 1e-05 steps 1200"
    res = result_numbers(out, LammpsError, "YADE's output")
    assert (res["f_bottom_n_per_m"], res["unbalanced_force"], res["steps"]) == (2.0, 1e-5, 1200.0)
    with pytest.raises(LammpsError, match="no 'poro2d-result' line in the LAMMPS log"):
        result_numbers("Loop time of 1.0", LammpsError, "the LAMMPS log")


def test_export_prints_a_folder_name_as_typed(saved, tmp_path, capsys):
    """A folder named like rich markup is printed as its name, not read as styling."""
    out = tmp_path / "run[bold]2[/bold]"
    main(["export", str(saved.parent), "--to", "csv", "--out", str(out)])
    printed = capsys.readouterr().out
    assert "run[bold]2[/bold]" in printed.replace("\n", "")
