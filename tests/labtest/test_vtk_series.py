"""The ParaView time series (``vtk_every``): a direct shear, a biaxial and a periodic run write a
``.pvd`` series that meshio reads back with the very disks, forces and contacts the run had at each
step; asking for it changes no number of the run, and a resumed run continues it as it was."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from poro2d.dem.export import (
    DISK,
    DISK_CONTACT,
    WALL,
    WALL_CONTACT,
    Frame,
    frame_of,
    frame_of_cell,
    step_mesh,
)
from poro2d.dem.reporters import drive_blocks
from poro2d.errors import InputError
from poro2d.identity import identity_digest
from poro2d.shear import DirectShearTest, ShearSettings
from poro2d.shear.case import ShearCase
from poro2d.store import Store

# 1 mm of shear in the 60 mm box of the session's specimen, a checkpoint every 0.25 mm
SHORT = {"max_displacement": 0.001, "peak_window": 2.5e-4, "checkpoint_interval": 2.5e-4}


def _snapshots(monkeypatch, module: str, frame) -> list[dict]:
    """Every state the series is written from, read off the engine's own arrays (not the Frame)."""
    seen: list[dict] = []

    def watched(engine):
        seen.append(_walled(engine) if frame is frame_of else _periodic(engine))
        return frame(engine)

    monkeypatch.setattr(f"{module}.{frame.__name__}", watched)
    return seen


def _walled(sim) -> dict:
    p, c = sim.particles, sim.contacts()
    return {
        "pos": p.pos.copy(), "radius": p.radius.copy(), "vel": p.vel.copy(), "omega": p.omega.copy(),
        "i": c.i, "j": c.j, "wall": c.kind == 1, "fn": c.fn, "fs": c.fs, "force": c.force,
        "wall_force": sim.wall_force_vec.copy(), "walls": sim.walls.n, "end": c.point,
    }  # fmt: skip


def _periodic(cell) -> dict:
    c = cell.contacts()
    return {
        "pos": cell.pos.copy(), "radius": cell.radius.copy(), "vel": cell.absolute_velocity(),
        "omega": cell.omega.copy(), "i": c["i"], "j": c["j"], "wall": np.zeros(len(c["i"]), bool),
        "fn": c["fn"], "fs": c["fs"], "force": np.column_stack([c["fx"], c["fy"]]), "walls": 0,
        "branch": np.column_stack([c["lx"], c["ly"]]),
    }  # fmt: skip


def _entries(folder, measure: str) -> list[dict]:
    """The data sets of ``series.pvd`` (timestep: time) and of the measure's collection, checked alike."""
    by_time = ET.parse(folder / "series.pvd").getroot().findall("./Collection/DataSet")
    by_measure = ET.parse(folder / f"series_{measure}.pvd").getroot().findall("./Collection/DataSet")
    assert [d.get("file") for d in by_time] == [d.get("file") for d in by_measure]
    out = []
    for t, m in zip(by_time, by_measure, strict=True):
        assert float(t.get("timestep")) == float(m.get("time")) and float(m.get("timestep")) == float(
            t.get(measure)
        )
        out.append({"file": t.get("file"), "step": int(t.get("step")), "time": float(t.get("timestep")),
                    measure: float(m.get("timestep"))})  # fmt: skip
    return out


def _resultant(snap: dict) -> np.ndarray:
    """Each disk's summed contact force, one contact at a time (the check of the file's ``contact_force``)."""
    total = np.zeros((len(snap["radius"]), 2))
    for k in range(len(snap["i"])):
        total[snap["i"][k]] += snap["force"][k]
        if not snap["wall"][k]:
            total[snap["j"][k]] -= snap["force"][k]
    return total


def _check_step(path, snap: dict) -> None:
    """The file holds the snapshot's disks, walls and contacts, each with its own numbers."""
    mesh = meshio.read(path)
    n = len(snap["radius"])
    disks = mesh.cells_dict["vertex"].ravel()
    np.testing.assert_array_equal(disks, np.arange(n))
    np.testing.assert_array_equal(mesh.points[:n, :2], snap["pos"])
    np.testing.assert_array_equal(mesh.points[:, 2], 0.0)
    pd = mesh.point_data
    np.testing.assert_array_equal(pd["radius"][:n], snap["radius"])
    np.testing.assert_array_equal(pd["radius"][n:], 0.0)
    np.testing.assert_array_equal(pd["velocity"][:n, :2], snap["vel"])
    np.testing.assert_array_equal(pd["angular_velocity"][:n], snap["omega"])
    np.testing.assert_allclose(pd["contact_force"][:n, :2], _resultant(snap), rtol=1e-12, atol=1e-12)
    cd = {k: v[1] for k, v in mesh.cell_data.items()}  # the block of lines
    lines = mesh.cells_dict["line"]
    kind = cd["cell_kind"]
    assert np.all(mesh.cell_data["cell_kind"][0] == DISK)
    assert np.count_nonzero(kind == WALL) == snap["walls"]
    if snap["walls"]:
        np.testing.assert_array_equal(cd["force"][kind == WALL, :2], snap["wall_force"])
    contact = kind != WALL
    np.testing.assert_array_equal(kind[contact] == WALL_CONTACT, snap["wall"])
    np.testing.assert_array_equal(cd["body_i"][contact], snap["i"])
    np.testing.assert_array_equal(cd["body_j"][contact], snap["j"])
    np.testing.assert_array_equal(cd["normal_force"][contact], snap["fn"])
    np.testing.assert_array_equal(cd["tangential_force"][contact], np.abs(snap["fs"]))
    np.testing.assert_array_equal(cd["force"][contact, :2], snap["force"])
    np.testing.assert_array_equal(lines[contact, 0], snap["i"])  # each line starts at its disk i
    ends = mesh.points[lines[contact, 1], :2]
    if "branch" in snap:  # periodic: drawn to the touching image, as long as the branch
        np.testing.assert_allclose(ends - snap["pos"][snap["i"]], snap["branch"], atol=1e-15)
        gap = np.hypot(*snap["branch"].T) - snap["radius"][snap["i"]] - snap["radius"][snap["j"]]
        assert np.all(gap <= 0.0)
    else:
        pair = ~snap["wall"]
        np.testing.assert_array_equal(ends[pair], snap["pos"][snap["j"][pair]])
        np.testing.assert_array_equal(ends[~pair], snap["end"][~pair])


def _shear(specimen, store: Store, **settings):
    return DirectShearTest(ShearCase.of(specimen, 100, ShearSettings(**SHORT, **settings)), store).run()


def test_a_direct_shear_series_reads_back_as_the_run(specimen, tmp_path, monkeypatch):
    """Every step file holds the run's arrays at that step; curve.csv is the same byte for byte."""
    plain = _shear(specimen, Store(tmp_path / "plain"))
    every = 3 * int(plain.curve.step[1] - plain.curve.step[0])  # every third row of the curve
    snaps = _snapshots(monkeypatch, "poro2d.shear.shear_stage", frame_of)
    _shear(specimen, Store(tmp_path / "vtk"), vtk_every=every)
    assert (tmp_path / "vtk/curve.csv").read_bytes() == (tmp_path / "plain/curve.csv").read_bytes()
    entries = _entries(tmp_path / "vtk/vtk", "shear_displacement")
    steps = [e["step"] for e in entries]
    assert steps == list(range(0, every * len(steps), every)) and len(steps) == len(snaps) >= 3
    assert np.all(np.diff([e["time"] for e in entries]) > 0)
    curve = {int(s): x for s, x in zip(plain.curve.step, plain.curve.shear_displacement_mm, strict=True)}
    for e in entries[1:]:  # the measure is the curve's shear displacement at the same step
        assert e["shear_displacement"] == pytest.approx(curve[e["step"]] * 1e-3, rel=1e-12)
    for e, snap in zip(entries, snaps, strict=True):
        _check_step(tmp_path / "vtk/vtk" / e["file"], snap)


class _Stop(Exception):
    pass


def test_a_resumed_shear_continues_its_series(specimen, tmp_path):
    """Killed past its second checkpoint and run again, the test leaves the uninterrupted series."""
    _shear(specimen, Store(tmp_path / "whole"), vtk_every=700)

    def stop(phase, fraction):
        if phase == "shearing" and fraction > 0.6:
            raise _Stop

    case = ShearCase.of(specimen, 100, ShearSettings(**SHORT, vtk_every=700))
    with pytest.raises(_Stop):
        DirectShearTest(case, Store(tmp_path / "cut"), progress=stop).run()
    assert (tmp_path / "cut/shear_checkpoint.npz").is_file()
    DirectShearTest(case, Store(tmp_path / "cut")).run()
    whole, cut = tmp_path / "whole/vtk", tmp_path / "cut/vtk"
    assert (cut / "series.pvd").read_bytes() == (whole / "series.pvd").read_bytes()
    files = sorted(p.name for p in whole.glob("step_*.vtu"))
    assert files == sorted(p.name for p in cut.glob("step_*.vtu")) and len(files) >= 5
    for name in files:
        assert (cut / name).read_bytes() == (whole / name).read_bytes(), name


def test_a_biaxial_series_reads_back_as_the_run(tmp_path, monkeypatch):
    from poro2d.biaxial import BiaxialCase, BiaxialSettings, BiaxialTest

    short = {"max_strain": 0.005, "record_strain": 0.0005, "critical_window": 0.3}
    plain = BiaxialTest(
        BiaxialCase.quick(100.0, seed=0, settings=BiaxialSettings(**short)), Store(tmp_path / "a")
    ).run()
    every = 2 * int(plain.curve.step[1] - plain.curve.step[0]) + 1  # not on the rows: blocks end elsewhere
    snaps = _snapshots(monkeypatch, "poro2d.biaxial.stages", frame_of)
    settings = BiaxialSettings(**short, vtk_every=every)
    BiaxialTest(BiaxialCase.quick(100.0, seed=0, settings=settings), Store(tmp_path / "b")).run()
    assert (tmp_path / "b/curve.csv").read_bytes() == (tmp_path / "a/curve.csv").read_bytes()
    entries = _entries(tmp_path / "b/vtk", "axial_strain")
    assert [e["step"] for e in entries] == [every * k for k in range(len(entries))] and len(entries) >= 3
    strain = np.array([e["axial_strain"] for e in entries])
    assert strain[0] == 0.0 and np.all(np.diff(strain) > 0) and strain[-1] <= plain.curve.axial_strain[-1]
    for e, snap in zip(entries, snaps, strict=True):
        assert snap["walls"] == 4
        _check_step(tmp_path / "b/vtk" / e["file"], snap)


def test_a_periodic_series_draws_contacts_to_their_images(tmp_path, monkeypatch):
    from poro2d.critical_state import CriticalStateCase
    from poro2d.critical_state.run import run_critical_state

    cell = {"disks": 200, "inertial_number": 1e-2, "strain": 0.5, "window_start": 0.25, "blocks": 3}
    run_critical_state(CriticalStateCase(**cell), Store(tmp_path / "a"))
    snaps = _snapshots(monkeypatch, "poro2d.critical_state.run", frame_of_cell)
    run_critical_state(CriticalStateCase(**cell, vtk_every=1), Store(tmp_path / "b"))  # every row
    assert (tmp_path / "b/series.csv").read_bytes() == (tmp_path / "a/series.csv").read_bytes()
    entries = _entries(tmp_path / "b/vtk", "shear_strain")
    gamma = np.array([e["shear_strain"] for e in entries])
    assert gamma[0] == 0.0 and np.all(np.diff(gamma) > 0) and gamma[-1] == pytest.approx(0.5, rel=0.02)
    crossing = 0
    for e, snap in zip(entries, snaps, strict=True):
        _check_step(tmp_path / "b/vtk" / e["file"], snap)
        ends = snap["pos"][snap["i"]] + snap["branch"]
        crossing += np.count_nonzero(np.any(np.abs(ends - snap["pos"][snap["j"]]) > 1e-12, axis=1))
    assert crossing > 0  # contacts across the boundary were drawn, to their images


def _rows_without_times(path) -> list[dict]:
    import csv

    with open(path, newline="") as fh:
        return [{k: v for k, v in row.items() if not k.startswith("time_")} for row in csv.DictReader(fh)]


def test_a_criterion_trial_keeps_its_plate_stage_as_a_series(tmp_path, monkeypatch):
    """A dense trial (over-full: the plate rises) writes its plate stage; the trial's numbers stay."""
    from poro2d.criterion import CriterionCase, run_criterion
    from poro2d.execute import RunOptions

    box = {"width": 0.05, "height": 0.025, "layers": 2}
    quiet = RunOptions(workers=1, progress=False)

    def run(folder, **extra):
        criterion = {"force_fraction": 0.05, "trial_porosity": 0.20, "max_iterations": 1, **extra}
        config = {"seed": 0, "specimen": box, "criterion": criterion}
        return run_criterion(CriterionCase.from_config(config), Store(tmp_path / folder), options=quiet)

    run("a")
    snaps = _snapshots(monkeypatch, "poro2d.criterion.servo", frame_of)
    run("b", vtk_every=4000)
    assert _rows_without_times(tmp_path / "b/iterations.csv") == _rows_without_times(
        tmp_path / "a/iterations.csv"
    )
    (trial,) = (tmp_path / "b/trials").iterdir()
    entries = _entries(trial / "vtk", "plate_height")
    assert len(entries) == len(snaps) >= 3 and all(e["step"] % 4000 == 0 for e in entries)
    heights = [e["plate_height"] for e in entries]
    assert heights[-1] > heights[0]  # the plate of an over-full box rises
    for e, snap in zip(entries, snaps, strict=True):
        _check_step(trial / "vtk" / e["file"], snap)


def test_the_series_is_outside_the_identity_and_checked():
    assert identity_digest(ShearSettings(vtk_every=50), tables={}) == identity_digest(ShearSettings())
    assert (
        "vtk_every" not in ShearSettings().to_dict()
        and ShearSettings(vtk_every=5).to_dict()["vtk_every"] == 5
    )
    from poro2d.biaxial import BiaxialSettings
    from poro2d.critical_state import CriticalStateCase

    # a file written without the key reads it as its default: no series, not None
    assert BiaxialSettings.from_dict(BiaxialSettings().to_dict()).vtk_every == 0
    assert CriticalStateCase.from_dict(CriticalStateCase().to_dict()).vtk_every == 0
    for bad in (-1, 10**9, 2.5, True):
        with pytest.raises(InputError) as err:
            ShearSettings(vtk_every=bad)
        assert err.value.parameter == "vtk_every"


@pytest.mark.parametrize("command", ["shear", "biaxial", "critical-state", "criterion"])
@pytest.mark.parametrize("value", ["-3", "1000000000"])
def test_the_commands_refuse_a_bad_interval_on_one_line(command, value, tmp_path, capsys):
    from poro2d.cli import main

    extra = {"shear": ["-s", "missing.npz"], "biaxial": ["--quick"]}.get(command, [])
    with pytest.raises(SystemExit) as exc:
        main([command, *extra, "--vtk-every", value, "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "--vtk-every" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_a_step_mesh_of_a_hand_made_frame():
    """Two disks touching each other and a wall: the cells, their kinds and the points as laid out."""
    f = Frame(
        pos=np.array([[0.0, 1.0], [2.0, 1.0]]), radius=np.array([1.0, 1.0]),
        velocity=np.array([[1.0, 0], [0, 2.0]]), omega=np.array([3.0, 4.0]), theta=np.zeros(2),
        contact_force=np.array([[-5.0, 0.0], [5.0, 7.0]]),
        wall_p0=np.array([[-1.0, 0.0]]), wall_p1=np.array([[3.0, 0.0]]), wall_force=np.array([[0.0, -7.0]]),
        contact_i=np.array([0, 1]), contact_j=np.array([1, 0]), contact_wall=np.array([False, True]),
        contact_end=np.array([[2.0, 1.0], [2.0, 0.0]]), fn=np.array([5.0, 7.0]), fs=np.array([0.0, -0.5]),
        contact_vector=np.array([[-5.0, 0.0], [0.0, 7.0]]),
    )  # fmt: skip
    m = step_mesh(f)
    assert m.points.shape == (2 + 2 + 2, 3)
    np.testing.assert_array_equal(m.cells_dict["line"], [[2, 3], [0, 4], [1, 5]])
    np.testing.assert_array_equal(m.cell_data["cell_kind"][1], [WALL, DISK_CONTACT, WALL_CONTACT])
    np.testing.assert_array_equal(m.cell_data["tangential_force"][1], [0.0, 0.0, 0.5])
    np.testing.assert_array_equal(m.cell_data["force_magnitude"][0], [5.0, np.hypot(5.0, 7.0)])
    lonely = step_mesh(Frame(**{**f.__dict__, **_no_lines(f)}))  # no walls, no contacts: disks only
    assert list(lonely.cells_dict) == ["vertex"] and len(lonely.cell_data["cell_kind"]) == 1


def _no_lines(f: Frame) -> dict:
    none2, none = np.zeros((0, 2)), np.zeros(0)
    return {
        "wall_p0": none2, "wall_p1": none2, "wall_force": none2, "contact_i": none.astype(int),
        "contact_j": none.astype(int), "contact_wall": none.astype(bool), "contact_end": none2, "fn": none,
        "fs": none, "contact_vector": none2,
    }  # fmt: skip


def test_a_reporter_with_a_start_is_due_where_its_stage_would_have_it():
    """Resumed 3 steps into its stage, a reporter of period 5 is told at stage steps 5, 10, 15."""

    class Told:
        period, start = 5, 3

        def __init__(self):
            self.steps = []

        def report(self, engine, step):
            self.steps.append(step)

    told = Told()
    ran = drive_blocks(lambda n: (n, False), 14, [told], engine=None)
    assert ran == 14 and [s + 3 for s in told.steps] == [5, 10, 15]
