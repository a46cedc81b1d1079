"""A split shear box made of moving wall segments around a loaded specimen.

The specimen comes from the criterion (walls ``bottom``, ``right``, ``top``, ``left``
around ``0..W x 0..H``). Its side walls are replaced by four half walls, split at
``ys = H / 2``::

                 top (servo plate, fixed in x)
    upper_left |                            | upper_right
               |        upper half          |________  upper_lip (fixed)
    ___________|............................|
    lower_lip  |        lower half          | lower_right
    lower_left |____________________________|
                 bottom (moves with the lower half)

The lower half (``bottom``, ``lower_left``, ``lower_right``, ``lower_lip``) moves
in +x; the upper half (``upper_left``, ``upper_right``, ``upper_lip``) stays; the
top plate is servo-controlled vertically. When the lower half has moved by ``d``,
two openings appear along the shear plane: ``[0, d]`` under the upper half, closed
by ``lower_lip`` (it runs left from the top of ``lower_left``), and
``[W, W + d]`` above the lower half, closed by ``upper_lip`` (it runs right from
the bottom of ``upper_right``). Both lips are as long as the largest shear
displacement plus one largest disk diameter.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from poro2d.dem import Simulation
from poro2d.dem.contact_law import MAX_ROLLING_FRICTION
from poro2d.errors import InputError, check_range
from poro2d.labtest.box import box_simulation, specimen_box
from poro2d.labtest.records import BoxRecord
from poro2d.paper_data import TABLE_1

LOWER = ("bottom", "lower_left", "lower_right", "lower_lip")
UPPER = ("upper_left", "upper_right", "upper_lip", "top")
#: the upper half's side walls: their friction holds up part of the plate's load
UPPER_SIDE_WALLS = ("upper_left", "upper_right")


class PlaneForce(NamedTuple):
    """What crosses the shear plane (:meth:`SplitBox.plane_force`): forces (N, x and y) and contacts."""

    across: np.ndarray
    unbalanced: np.ndarray
    contacts_across: int


@dataclass(frozen=True)
class SplitBox:
    """Geometry of a split box and the force bookkeeping on its two halves.

    ``width`` W and ``height`` H are those of the specimen's box (the top plate's
    height when the box was built); ``split_y`` is the shear plane, ``gap`` the
    opening between the lower walls' top and the upper walls' bottom.
    """

    width: float
    height: float
    split_y: float
    gap: float
    max_displacement: float
    thickness: float
    x0_lower: float = 0.0

    def record(self) -> BoxRecord:
        """The geometry as a file keeps it (a consolidation's ``box``)."""
        return BoxRecord(
            width=self.width, height=self.height, split_y=self.split_y, gap=self.gap,
            max_displacement=self.max_displacement, thickness=self.thickness, x0_lower=self.x0_lower,
        )  # fmt: skip

    # ------------------------------------------------------------ kinematics
    def shear_displacement(self, sim: Simulation) -> float:
        """How far the lower half has moved in +x (m)."""
        return float(sim.walls.p0[sim.walls.index("lower_left"), 0]) - self.x0_lower

    def plate_height(self, sim: Simulation) -> float:
        return float(sim.walls.p0[sim.walls.index("top"), 1])

    # ---------------------------------------------------------------- forces
    @staticmethod
    def _sum(sim: Simulation, names) -> np.ndarray:
        f = np.zeros(2)
        for name in names:
            f += sim.wall_force(name)
        return f

    def upper_force(self, sim: Simulation) -> np.ndarray:
        """Force of the disks on the upper half: upper walls, upper lip, top plate (N)."""
        return self._sum(sim, UPPER)

    def lower_force(self, sim: Simulation) -> np.ndarray:
        """Force of the disks on the lower half: bottom, lower walls, lower lip (N)."""
        return self._sum(sim, LOWER)

    def plate_force(self, sim: Simulation) -> float:
        """Upward push of the disks on the top plate (N)."""
        return float(sim.wall_force("top")[1])

    def plane_force(self, sim: Simulation, contacts=None) -> PlaneForce:
        """Forces carried across the shear plane ``y = split_y`` (N).

        The disks are split by their centres into an upper set (``y >= split_y``)
        and a lower set. ``across`` is the force that the lower body (lower disks
        and lower walls) exerts on the upper body (upper disks and upper walls):
        disk-disk contacts whose branch vector crosses the plane, upper disks on
        lower walls, and lower disks on upper walls. ``unbalanced`` is the summed
        unbalanced force on the upper disks; exactly,
        ``upper_force = across - unbalanced`` (the upper disks' balance), so the
        three agree when the specimen is in quasi-static equilibrium. ``contacts``
        (from ``sim.contacts()`` of the current step) saves recomputing them.
        """
        c = sim.contacts() if contacts is None else contacts
        pos = sim.particles.pos
        up = pos[:, 1] >= self.split_y
        names = sim.walls.names
        is_lower_wall = np.array([n in LOWER for n in names])
        is_upper_wall = np.array([n in UPPER for n in names])
        pp = c.kind == 0
        jj = np.where(pp, c.j, 0)
        ui = up[c.i]
        uj = up[jj]
        across = np.zeros(2)
        # disk-disk: force on the upper member from the lower one
        m1 = pp & ~ui & uj  # i lower, j upper: force on j is -force on i
        m2 = pp & ui & ~uj  # i upper: force on i
        across -= c.force[m1].sum(axis=0)
        across += c.force[m2].sum(axis=0)
        # walls: upper disks on lower walls (force on the disk), lower disks on upper walls
        wl = ~pp & is_lower_wall[np.where(pp, 0, c.j)]
        wu = ~pp & is_upper_wall[np.where(pp, 0, c.j)]
        across += c.force[wl & ui].sum(axis=0)
        across -= c.force[wu & ~ui].sum(axis=0)
        unbalanced = sim.force[up].sum(axis=0) - sim.particles.mass[up].sum() * np.asarray(sim.gravity)
        n_cross = int(np.count_nonzero(m1 | m2))
        return PlaneForce(across, unbalanced, n_cross)


def build_split_box(
    specimen: Simulation,
    max_displacement: float,
    kn_wall: float = TABLE_1.kn_wall,
    ks_wall: float = TABLE_1.ks_wall,
    friction_wall: float = TABLE_1.friction_wall,
    gap: float = 0.0,
    particle_friction: float | None = None,
    density_scale: float = 1.0,
    dt_safety: float = 0.8,
    threads: int = 1,
    rolling_friction: float | None = None,
    particle_kn: float | None = None,
    particle_ks: float | None = None,
) -> tuple[Simulation, SplitBox]:
    """A new simulation of the specimen's disks in a split box (all walls at rest), the disks
    keeping their velocities (:func:`poro2d.labtest.box.box_simulation`: ``particle_friction``,
    ``rolling_friction``, ``particle_kn`` and ``particle_ks`` replace the disks' values when
    given; the walls take the disks' largest mu_r); gravity and the engine's settings are the
    specimen's. ``max_displacement`` may not exceed W / 2.
    """
    W, H = specimen_box(specimen, "a specimen saved by poro2d criterion or poro2d.specimen.compaction")
    check_range("max_displacement", max_displacement, 0.0, W / 2, lo_open=True)
    check_range("gap", gap, 0.0, H / 4)
    check_range("kn_wall", kn_wall, 0.0, None, lo_open=True)
    check_range("ks_wall", ks_wall, 0.0, None)
    check_range("friction_wall", friction_wall, 0.0, None)
    if particle_friction is not None:
        check_range("particle_friction", particle_friction, 0.0, None)
    if rolling_friction is not None:
        check_range("rolling_friction", rolling_friction, 0.0, MAX_ROLLING_FRICTION)
    for name, k in (("particle_kn", particle_kn), ("particle_ks", particle_ks)):
        if k is not None:
            check_range(name, k, 0.0, None, lo_open=True)
    p0 = specimen.particles
    inside = (p0.pos[:, 0] > 0.0) & (p0.pos[:, 0] < W) & (p0.pos[:, 1] > 0.0) & (p0.pos[:, 1] < H)
    if not inside.all():
        raise InputError("specimen", f"{int((~inside).sum())} disk centres outside the box", "all inside")
    ys = 0.5 * H
    e = max(W, H)
    lip = max_displacement + 2.0 * float(p0.radius.max())
    segments = [
        ((-e, 0.0), (W + max_displacement + e, 0.0), "bottom"),
        ((0.0, -e), (0.0, ys), "lower_left"),
        ((W, -e), (W, ys), "lower_right"),
        ((-lip, ys), (0.0, ys), "lower_lip"),
        ((0.0, ys + gap), (0.0, H + e), "upper_left"),
        ((W, ys + gap), (W, H + e), "upper_right"),
        ((W, ys + gap), (W + lip, ys + gap), "upper_lip"),
        ((W + e, H), (-e, H), "top"),
    ]
    sim = box_simulation(
        specimen, segments, (kn_wall, ks_wall, friction_wall), particle_friction=particle_friction,
        rolling_friction=rolling_friction, particle_kn=particle_kn, particle_ks=particle_ks, at_rest=False,
        gravity=specimen.gravity, density_scale=density_scale, dt_safety=dt_safety, threads=threads,
    )  # fmt: skip
    return sim, SplitBox(W, H, ys, float(gap), float(max_displacement), p0.thickness)


__all__ = ["LOWER", "UPPER", "PlaneForce", "SplitBox", "build_split_box"]
