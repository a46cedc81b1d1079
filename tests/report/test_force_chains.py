"""Force-chain figures from plain arrays (a ContactSet, disks, wall segments) and from a simulation."""

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls
from poro2d.dem.contacts import ContactSet
from poro2d.errors import InputError
from poro2d.report.force_chains import plot_force_chains, plot_simulation_force_chains, wall_segments


def _contacts():
    """Two disks pressed together and the first one on a wall below it."""
    return ContactSet(
        i=np.array([0, 0]), j=np.array([1, 0]), kind=np.array([0, 1]),
        point=np.array([[0.02, 0.02], [0.01, 0.0]]), normal=np.array([[1.0, 0.0], [0.0, -1.0]]),
        fn=np.array([3.0, 5.0]), fs=np.array([0.0, 1.0]), force=np.array([[-3.0, 0.0], [1.0, 5.0]]),
        branch=np.array([[0.02, 0.0], [0.0, -0.02]]),
    )  # fmt: skip


POS = np.array([[0.01, 0.01], [0.03, 0.01]])
RADIUS = np.array([0.0105, 0.0105])
WALLS = np.array([[[0.0, 0.0], [0.04, 0.0]]])


def test_force_chains_from_arrays(tmp_path):
    png = plot_force_chains(_contacts(), POS, RADIUS, WALLS, tmp_path / "f.png", thickness=0.01, title="t")
    assert png.stat().st_size > 0
    # without a thickness the forces are in N, without walls none are drawn, empty contacts draw too
    assert plot_force_chains(_contacts(), POS.tolist(), RADIUS, None, tmp_path / "n.png").stat().st_size > 0
    empty = ContactSet(**{k: v[:0] for k, v in vars(_contacts()).items()})
    assert plot_force_chains(empty, POS, RADIUS, WALLS, tmp_path / "e.png", box=(0, 0, 0.04, 0.02)).is_file()


@pytest.mark.parametrize(
    ("args", "name"),
    [
        ((POS, RADIUS, WALLS), None),  # the first argument is not a ContactSet (set below)
        ((POS[:, :1], RADIUS, WALLS), "pos"),
        ((POS, RADIUS[:1], WALLS), "radius"),
        ((POS, -RADIUS, WALLS), "radius"),
        ((POS, RADIUS, WALLS[0]), "walls"),
        ((POS[:1], RADIUS[:1], WALLS), "contacts"),  # contact 0 touches disk 1, which is not given
    ],
)
def test_bad_arrays_are_refused(tmp_path, args, name):
    contacts = _contacts() if name is not None else {"i": [0]}
    with pytest.raises(InputError, match=name or "contacts") as exc:
        plot_force_chains(contacts, *args, tmp_path / "f.png")
    if name is None:
        assert "plot_simulation_force_chains" in str(exc.value)  # points a Simulation's caller on
    assert not (tmp_path / "f.png").exists()


def test_bad_thickness_is_refused(tmp_path):
    with pytest.raises(InputError, match="thickness"):
        plot_force_chains(_contacts(), POS, RADIUS, WALLS, tmp_path / "f.png", thickness=0.0)


def test_force_chains_of_a_simulation(tmp_path):
    p = Particles(
        pos=[[0.02, 0.0105], [0.041, 0.0105]], radius=0.0105, density=2650.0, thickness=0.01, kn=1e5,
        ks=1e5, mu=0.5,
    )  # fmt: skip
    sim = Simulation(p, Walls.box(0.0, 0.0, 0.1, 0.1, 1e5, 1e5, 0.5))
    sim.run(10)
    segs = wall_segments(sim.walls)
    assert segs.shape == (sim.walls.n, 2, 2)
    np.testing.assert_array_equal(segs[:, 0], sim.walls.p0)
    assert plot_simulation_force_chains(sim, tmp_path / "s.png", per_thickness=False).stat().st_size > 0
