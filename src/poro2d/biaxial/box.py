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

from poro2d.dem import Simulation
from poro2d.errors import InputError
from poro2d.labtest.box import box_simulation, specimen_box

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
    """A new simulation of the specimen's disks in the biaxial box, at rest and without gravity
    (:func:`poro2d.labtest.box.box_simulation`: ``particle_friction``, ``rolling_friction``,
    ``particle_kn`` and ``particle_ks`` replace the disks' values when given, as in the direct
    shear box). Gravity is off: a biaxial specimen is a small element of soil under its confining
    stress, and gravity would make its stress vary with height. A specimen whose box is not at
    (0, 0) or whose disks are not all inside it is refused.
    """
    hint = "a specimen saved by poro2d criterion, poro2d sand or poro2d.specimen.compaction"
    W, H = specimen_box(specimen, hint)
    e = max(W, H)
    segments = [
        ((-e, 0.0), (W + e, 0.0), "bottom"),
        ((W, -e), (W, H + e), "right"),
        ((W + e, H), (-e, H), "top"),
        ((0.0, H + e), (0.0, -e), "left"),
    ]
    sim = box_simulation(
        specimen, segments, (kn_wall, ks_wall, friction_wall), particle_friction=particle_friction,
        rolling_friction=rolling_friction, particle_kn=particle_kn, particle_ks=particle_ks, at_rest=True,
        gravity=(0.0, 0.0), density_scale=density_scale, dt_safety=dt_safety, threads=threads,
    )  # fmt: skip
    check_inside(sim)
    if not math.isfinite(sim.dt):
        raise InputError("specimen", "no finite time step", "disks with mass and stiffness")
    return sim, BiaxialBox(W, H, specimen.particles.thickness)


__all__ = ["COMPRESS", "BiaxialBox", "BoxSize", "build_biaxial_box", "check_inside"]
