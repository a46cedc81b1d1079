"""The biaxial box: four long walls around the specimen, and what they say about it.

::

            top (the plate: servoed, then driven down)
     left |                          | right
    (servo)|        specimen          |(servo)
          |__________________________|
            bottom (fixed)

Each wall reaches a specimen's size beyond the box on both ends, so that no corner opens
when the side walls move out or the plate moves down. The walls push normal to
themselves; the stresses are their forces over their contact length times the disks'
thickness (the convention of the direct shear test, :mod:`poro2d.shear.single`): sigma_1
is the plate's push over the current width, sigma_3 the mean of the side walls' pushes
over the current height.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poro2d.dem import Particles, Simulation, Walls
from poro2d.dem.ordering import strip_order
from poro2d.errors import InputError
from poro2d.shear.box import pair_type_contact, replaced_values
from poro2d.specimen.box import box_faces

#: the four walls and the way each moves to compress the specimen
COMPRESS = {"left": (1.0, 0.0), "right": (-1.0, 0.0), "top": (0.0, -1.0)}


@dataclass(frozen=True)
class BoxSize:
    """The box's width and height (m) at a moment, and the disks' thickness (m)."""

    width: float
    height: float
    thickness: float


@dataclass(frozen=True)
class BiaxialBox:
    """The box of a biaxial test: its size when built, and its walls read from a simulation."""

    width: float
    height: float
    thickness: float

    @staticmethod
    def size(sim: Simulation) -> BoxSize:
        """The current width (right - left) and height (top - bottom)."""
        w = sim.walls
        x_left = float(w.p0[w.index("left"), 0])
        x_right = float(w.p0[w.index("right"), 0])
        y_bottom = float(w.p0[w.index("bottom"), 1])
        y_top = float(w.p0[w.index("top"), 1])
        return BoxSize(x_right - x_left, y_top - y_bottom, sim.particles.thickness)

    @classmethod
    def stresses(cls, sim: Simulation) -> tuple[float, float, float, float]:
        """(sigma_1, sigma_3, left, right) in Pa: the plate's and the side walls' compressive stresses."""
        s = cls.size(sim)
        top = float(sim.wall_force("top")[1])  # the disks push the plate up: +y
        left = -float(sim.wall_force("left")[0])  # the disks push the left wall to -x
        right = float(sim.wall_force("right")[0])
        area_side = s.height * s.thickness
        return (
            top / (s.width * s.thickness),
            0.5 * (left + right) / area_side,
            left / area_side,
            right / area_side,
        )

    @staticmethod
    def servo(sim: Simulation, wall: str, force: float, settings) -> None:
        """Servo ``wall`` to ``force`` (N) with the test's gains."""
        sim.set_wall_servo(
            wall,
            force,
            COMPRESS[wall],
            settings.servo_max_speed,
            settings.servo_gain,
            settings.servo_integral,
        )


def check_inside(sim: Simulation) -> None:
    """Every disk of ``sim`` inside its box: refused on one line otherwise."""
    s = BiaxialBox.size(sim)
    w = sim.walls
    x0 = float(w.p0[w.index("left"), 0])
    y0 = float(w.p0[w.index("bottom"), 1])
    p = sim.particles.pos
    inside = (p[:, 0] > x0) & (p[:, 0] < x0 + s.width) & (p[:, 1] > y0) & (p[:, 1] < y0 + s.height)
    if not inside.all():
        raise InputError("specimen", f"{int((~inside).sum())} disk centres outside the box", "all inside")


def build_biaxial_box(
    specimen: Simulation,
    kn_wall: float,
    ks_wall: float,
    friction_wall: float,
    particle_friction: float | None = None,
    rolling_friction: float | None = None,
    density_scale: float = 1.0,
    dt_safety: float = 0.8,
    threads: int = 1,
    particle_kn: float | None = None,
    particle_ks: float | None = None,
) -> tuple[Simulation, BiaxialBox]:
    """A new simulation of the specimen's disks in the biaxial box, without gravity.

    The disks keep their positions and properties (``particle_friction`` and
    ``rolling_friction`` replace theirs when given, ``particle_kn`` and ``particle_ks`` their
    stiffness (N/m), as :func:`poro2d.shear.box.build_split_box` replaces them: the time step is
    the new simulation's, so it follows the stiffness; the walls take the disks' largest mu_r,
    as the direct shear box does). Gravity is switched off: a biaxial specimen is a small
    element of soil under its confining stress, and gravity would make its stress vary with
    height. A specimen whose box is not at (0, 0) or whose disks are not all inside it is
    refused.
    """
    hint = "a specimen saved by poro2d criterion, poro2d sand or poro2d.specimen.compaction"
    left, right, bottom, top = box_faces(specimen.walls.names, specimen.walls.p0, "specimen walls", hint)
    if abs(left) > 1e-9 or abs(bottom) > 1e-9:
        raise InputError("specimen box", (left, bottom), "a box with its lower left corner at (0, 0)")
    W, H = right, top
    p0 = specimen.particles
    if p0.n == 0:
        raise InputError("specimen", "no disks", "a specimen with disks")
    mu_r = p0.mu_r.copy() if rolling_friction is None else np.full(p0.n, float(rolling_friction))
    e = max(W, H)
    walls = Walls()
    k = (kn_wall, ks_wall, friction_wall)
    wall_mu_r = float(mu_r.max())
    walls.add((-e, 0.0), (W + e, 0.0), *k, name="bottom", mu_r=wall_mu_r)
    walls.add((W, -e), (W, H + e), *k, name="right", mu_r=wall_mu_r)
    walls.add((W + e, H), (-e, H), *k, name="top", mu_r=wall_mu_r)
    walls.add((0.0, H + e), (0.0, -e), *k, name="left", mu_r=wall_mu_r)
    particles = Particles(
        pos=p0.pos.copy(), radius=p0.radius.copy(), density=p0.density.copy(), thickness=p0.thickness,
        kn=replaced_values(p0.kn, particle_kn), ks=replaced_values(p0.ks, particle_ks),
        mu=p0.mu.copy() if particle_friction is None else np.full(p0.n, float(particle_friction)),
        vel=np.zeros_like(p0.vel), theta=p0.theta.copy(), omega=np.zeros_like(p0.omega), mode=p0.mode.copy(),
        mu_r=mu_r,
    )  # fmt: skip
    contact = pair_type_contact(specimen.contact, particle_friction, particle_kn, particle_ks)
    sim = Simulation(
        particles, walls, contact, gravity=(0.0, 0.0), local_damping=specimen.local_damping,
        restitution=specimen.restitution, dt_safety=dt_safety, density_scale=density_scale,
        skin=specimen.skin, threads=threads,
    )  # fmt: skip
    sim.reorder(strip_order(sim.particles.pos, sim.particles.radius))
    check_inside(sim)
    if not math.isfinite(sim.dt):
        raise InputError("specimen", "no finite time step", "disks with mass and stiffness")
    return sim, BiaxialBox(W, H, p0.thickness)


__all__ = ["COMPRESS", "BiaxialBox", "BoxSize", "build_biaxial_box", "check_inside"]
