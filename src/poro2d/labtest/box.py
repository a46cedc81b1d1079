"""A specimen's disks in a test's box: the one rebuild every box test makes of a saved specimen.

A box test (direct shear, biaxial) takes the specimen's disks into a new simulation of its own
walls. The disks keep their positions and properties, but those the test replaces (friction,
rolling friction, stiffness: the time step is the new simulation's, so it follows the stiffness
held); the walls take the disks' largest mu_r, so that under the engine's rule (a contact takes
the smaller of its two bodies' values) a disk meets a wall with its own mu_r, as it meets
another disk of its kind. The disks are numbered anew in strips
(:func:`poro2d.dem.ordering.strip_order`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from poro2d.dem import ContactModel, Particles, Simulation, Walls
from poro2d.dem.ordering import strip_order
from poro2d.errors import InputError
from poro2d.specimen.box import box_faces

#: a wall of a box: its two ends and its name
Segment = tuple[tuple[float, float], tuple[float, float], str]


def specimen_box(sim: Simulation, hint: str) -> tuple[float, float]:
    """The width and height (m) of the specimen's box; refused unless its lower left corner is at
    (0, 0) and it holds disks (``hint``: where such a specimen comes from)."""
    left, right, bottom, top = box_faces(sim.walls.names, sim.walls.p0, "specimen walls", hint)
    if abs(left) > 1e-9 or abs(bottom) > 1e-9:
        raise InputError("specimen box", (left, bottom), "a box with its lower left corner at (0, 0)")
    if sim.particles.n == 0:
        raise InputError("specimen", "no disks", "a specimen with disks")
    return right, top


def replaced_values(values: np.ndarray, value: float | None) -> np.ndarray:
    """A copy of a per-disk array, every entry ``value`` when given."""
    return values.copy() if value is None else np.full(values.shape, float(value))


def pair_type_contact(contact: ContactModel, mu: float | None, kn: float | None, ks: float | None):
    """The contact model with the disk-disk (kn, ks, mu) replaced where given: under the
    ``per_pair_type`` convention one triple serves every disk pair and the disks' own arrays are
    not read, so a replaced value must go there too (``per_body``: the disks' arrays suffice)."""
    if contact.convention != "per_pair_type" or (mu is None and kn is None and ks is None):
        return contact
    assert contact.pp is not None
    given = (kn, ks, mu)
    pp = tuple(float(old if new is None else new) for old, new in zip(contact.pp, given, strict=True))
    return ContactModel("per_pair_type", pp, contact.pw)


def box_simulation(
    specimen: Simulation, segments: Sequence[Segment], wall: tuple[float, float, float], *,
    particle_friction: float | None, rolling_friction: float | None, particle_kn: float | None,
    particle_ks: float | None, at_rest: bool, gravity, density_scale: float, dt_safety: float, threads: int,
) -> Simulation:  # fmt: skip
    """A new simulation of ``specimen``'s disks inside the walls ``segments``, each of ``wall``'s
    (kn, ks, friction); the engine's settings but gravity are the specimen's.

    ``at_rest``: the disks start without velocity and spin (else they keep the specimen's).
    Disk-disk shear histories are not carried over: the consolidation that follows brings the
    specimen to a new equilibrium.
    """
    p0 = specimen.particles
    mu_r = replaced_values(p0.mu_r, rolling_friction)
    walls = Walls()
    for a, b, name in segments:
        walls.add(a, b, *wall, name=name, mu_r=float(mu_r.max()))
    motion = (np.zeros_like(p0.vel), np.zeros_like(p0.omega)) if at_rest else (p0.vel.copy(), p0.omega.copy())
    particles = Particles(
        pos=p0.pos.copy(), radius=p0.radius.copy(), density=p0.density.copy(), thickness=p0.thickness,
        kn=replaced_values(p0.kn, particle_kn), ks=replaced_values(p0.ks, particle_ks),
        mu=replaced_values(p0.mu, particle_friction), vel=motion[0], theta=p0.theta.copy(), omega=motion[1],
        mode=p0.mode.copy(), mu_r=mu_r,
    )  # fmt: skip
    contact = pair_type_contact(specimen.contact, particle_friction, particle_kn, particle_ks)
    sim = Simulation(
        particles, walls, contact, gravity=gravity, local_damping=specimen.local_damping,
        restitution=specimen.restitution, dt_safety=dt_safety, density_scale=density_scale,
        skin=specimen.skin, threads=threads,
    )  # fmt: skip
    # numbered in strips across the short side, whatever order the specimen came in
    sim.reorder(strip_order(sim.particles.pos, sim.particles.radius))
    return sim


__all__ = ["Segment", "box_simulation", "pair_type_contact", "replaced_values", "specimen_box"]
