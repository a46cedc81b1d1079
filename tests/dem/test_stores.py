"""The engine's public stores, and the structure they make possible.

Other modules read a simulation's contact lists, masses and kernel settings through
``Simulation.pairs``, ``wall_pairs``, ``masses``, ``kernel_params`` and ``work``
(:mod:`poro2d.dem.stores`); ``tests/test_architecture.py`` checks that no module reads
another object's private names and that no import circle remains.
"""

from __future__ import annotations

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls, checkpoint
from poro2d.dem.stores import ContactStore
from poro2d.errors import InputError


def _heap() -> Simulation:
    """Two rows of disks falling onto a floor: after a few thousand steps they touch."""
    r = 1e-3
    bottom = [(2.0 * r * i + r, 1.5 * r) for i in range(6)]
    top = [(2.0 * r * i + 2 * r, 3.5 * r) for i in range(5)]
    p = Particles(
        pos=np.array(bottom + top), radius=r, density=2650.0, thickness=0.01, kn=1e5, ks=1e5, mu=0.5
    )
    return Simulation(p, Walls.box(0.0, 0.0, 12 * r, 10 * r, 1e5, 1e5, 0.3))


def test_contact_store_grows_keeping_the_first_slots():
    store = ContactStore.empty(3, 4, with_cross=True)
    assert store.capacity == 4 and store.used == 0 and store.cross.shape == (4,)
    store.start[:] = [0, 2, 3, 3]
    store.other[:3] = [1, 2, 2]
    store.fs[:3] = [0.5, -0.25, 1.0]
    store.grow(10, keep=3)
    assert store.capacity == 10 and store.used == 3
    assert store.other[:3].tolist() == [1, 2, 2] and store.fs[:3].tolist() == [0.5, -0.25, 1.0]
    assert not store.fs[3:].any()
    # the rebuild scratch follows the capacity
    assert store.new_other.shape == store.new_fs.shape == store.new_mr.shape == store.cross.shape == (10,)
    assert store.rows().tolist() == [0, 0, 1]
    assert ContactStore.empty(3, 4).cross.shape == (0,)  # only the disk-disk list has cross pairs


def test_contact_store_notes_an_overflow():
    store = ContactStore.empty(2, 4)
    store.note_demand(9)
    assert store.overflow and store.needed == 9
    store.note_demand(0)
    assert not store.overflow and store.needed == 0


def test_a_full_list_is_grown_by_the_driver():
    ref, sim = _heap(), _heap()
    sim.grow_pairs(2)  # far too small: the first list build overflows
    sim.grow_wall_pairs(1)
    for s in (ref, sim):
        s.run(3000)
    assert sim.pairs.capacity > 2 and sim.wall_pairs.capacity > 1
    assert not (sim.pairs.overflow or sim.wall_pairs.overflow)  # the last call fitted
    assert sim.pairs.used == ref.pairs.used > 2
    assert np.array_equal(sim.pairs.fs[: sim.pairs.used], ref.pairs.fs[: ref.pairs.used])
    assert np.array_equal(sim.particles.pos, ref.particles.pos)


def test_touching_slots_are_those_of_the_contact_set():
    sim = _heap()
    sim.run(3000)
    contacts = sim.contacts()
    assert len(contacts) == len(sim.pairs.touching()) + len(sim.wall_pairs.touching()) > 0


def test_check_threads_is_public():
    assert Simulation.check_threads(1) == 1
    with pytest.raises(InputError, match="threads"):
        Simulation.check_threads(0)


def test_checkpoint_keys_are_those_of_the_first_format(tmp_path):
    sim = _heap()
    sim.run(50)
    path = checkpoint.save(sim, tmp_path / "c.npz")
    with np.load(path) as z:
        keys = {k for k in z.files if k.startswith("sim.")}
    assert keys == {
        "sim.force", "sim.moment", "sim.wall_force_vec", "sim._wstat", "sim._pos_build",
        "sim._wall_build", "sim._nb_start", "sim._nb_j", "sim._nb_fs", "sim._nb_fn", "sim._nb_ov",
        "sim._nb_nx", "sim._nb_ny", "sim._wb_start", "sim._wb_w", "sim._wb_fs", "sim._wb_fn",
        "sim._wb_ov", "sim._wb_nx", "sim._wb_ny", "sim._iprm",
    }  # fmt: skip
    loaded = checkpoint.load(path)
    assert np.array_equal(loaded.pairs.fs, sim.pairs.fs) and loaded.pairs.new_fs.shape == sim.pairs.fs.shape
