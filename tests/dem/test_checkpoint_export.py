"""Checkpoint round trip (continued run == uninterrupted run) and VTU/CSV export."""

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls, checkpoint
from poro2d.dem.export import History, write_vtu
from poro2d.errors import InputError


def _sim(seed=0):
    rng = np.random.default_rng(seed)
    n = 240
    pos = np.column_stack([0.005 + (np.arange(n) % 20) * 0.0048, 0.005 + (np.arange(n) // 20) * 0.0048])
    r = rng.uniform(1.5e-3, 2.3e-3, n)
    p = Particles(pos, r, 2650.0, 0.008, 4e5, 4e5, 0.5)
    w = Walls.box(0, 0, 0.1, 0.2, 1e7, 1e7, 1.5)
    sim = Simulation(p, w)
    sim.set_wall_velocity("top", (0.0, -0.5))
    return sim


def test_continued_run_equals_uninterrupted(tmp_path):
    a = _sim()
    a.run(8000)
    checkpoint.save(a, tmp_path / "c.npz", extra={"stage": "test"})
    a.run(4000)
    b = checkpoint.load(tmp_path / "c.npz")
    assert b.step_count == 8000
    b.run(4000)
    assert len(a.contacts()) > 50  # the comparison covers many live contacts with history
    for name in ("pos", "vel", "omega", "theta"):
        np.testing.assert_array_equal(getattr(a.particles, name), getattr(b.particles, name))
    np.testing.assert_array_equal(a.walls.p0, b.walls.p0)
    np.testing.assert_array_equal(a.wall_force_vec, b.wall_force_vec)
    assert checkpoint.read_meta(tmp_path / "c.npz")["extra"] == {"stage": "test"}
    assert "poro2d_version" in checkpoint.read_meta(tmp_path / "c.npz")["provenance"]


def test_missing_checkpoint_is_a_clear_error(tmp_path):
    with pytest.raises(InputError, match="checkpoint"):
        checkpoint.load(tmp_path / "nope.npz")


def test_vtu_files_open_with_meshio(tmp_path):
    import meshio

    sim = _sim()
    sim.run(15000)
    assert len(sim.contacts()) > 0
    files = write_vtu(sim, tmp_path, "snap")
    assert [f.name for f in files] == ["snap_particles.vtu", "snap_walls.vtu", "snap_contacts.vtu"]
    m = meshio.read(files[0])
    assert m.points.shape == (sim.particles.n, 3)
    np.testing.assert_allclose(m.point_data["radius"], sim.particles.radius)
    c = meshio.read(files[2])
    assert len(c.cells[0].data) == len(sim.contacts())
    np.testing.assert_allclose(np.sort(c.cell_data["fn"][0]), np.sort(sim.contacts().fn))
    assert not list(tmp_path.glob(".*"))  # no temporary leftovers


def test_history_csv(tmp_path):
    h = History()
    h.record(step=1, f=2.0)
    h.record(step=2, f=3.0, extra="x")
    h.write_csv(tmp_path / "h.csv")
    lines = (tmp_path / "h.csv").read_text().splitlines()
    assert lines[0] == "step,f,extra"
    assert np.allclose(h.column("f"), [2.0, 3.0])
