"""A segmented lid that fills the box: the acceptance of a specimen "full of particles".

A rigid flat plate on a granular surface rests on its few highest disks: under the
paper's plate the mean gap is about 0.7 d50 and the plate touches under 1 % of the
width, so the box porosity n' counts a band of empty space that the specimen does not
have (its interior is about 0.02 denser). The lid replaces the plate by ``K`` narrow
segments, about one d50 wide, side by side at the plate's height. Each is servoed
down to its share of a small load (the criterion's force window, so the specimen is
at rest under less than 1 % of its weight) and comes to rest on the grains below it:
the lid follows the surface at the grain scale, and the region under it is the
specimen with one wall layer on top, as at the bottom wall.

The porosity under the lid (:func:`fill_porosity`) is the box porosity of a box that
the specimen fills. The plate ("top") is parked above the lid, out of contact; every
force on the lid counts as the top force (:func:`lid_force`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from poro2d.dem import Simulation
from poro2d.dem.state import Particles, Walls
from poro2d.errors import InputError
from poro2d.measure.surface import lid_height_at
from poro2d.record import Record

#: wall names of the lid's segments: ``lid0``, ``lid1``, ... from left to right
LID_PREFIX = "lid"

#: the segment width, in d50: narrow enough to rest on single grains, wide enough that a
#: segment never falls between two neighbours of the surface (measured on the paper's
#: specimen: widths of 4, 2 and 1 d50 leave n_fill - interior at 0.010, 0.008 and 0.006)
SEGMENT_D50 = 1.0

#: the lid is smooth: a segment pressed sideways into a pit of the surface by its neighbours'
#: grains must not carry them by friction (a wedged segment took the whole specimen's
#: weight in a small frictionless preparation)
LID_FRICTION = 0.0

#: a segment touches the specimen while the grains push it at all: at rest each carries a
#: fraction of a grain's weight, and which fraction is granular chance (on a loose surface the
#: median segment carries several times its share while others barely touch)
TOUCH_SHARE = 0.0

#: a preparation this frictional (mu_prep) or more creeps under the lid for long: its lid is a
#: creeping lid (:class:`SegmentedLid`). Measured per trial (calibration boxes of Toyoura sand and
#: CB-Mix-2, 2 800-4 100 disks, at the paper grading's time step): 17 000-37 000 lid steps at mu_prep
#: 0-0.1, 71 000 at 0.5 and 415 000 at 1.0, where its force flickers in and out of the window
CREEP_FRICTION = 0.5

#: a creeping lid leaves its brisk approach once it rests under less than this many times the force
#: window's limit (its gentle servo takes it into the window): on a loose Toyoura surface the
#: brisk servo kept the lid at 3 to 8 times the limit for hundreds of thousands of steps
CREEP_SWITCH = 10.0

#: a creeping lid is at rest when its mean height moved less than this many d50 over the servo's
#: ``settle_checks`` checks: a creep slower than a grain's size over thousands of such windows,
#: which the held lid's final check at equilibrium then judges
CREEP_D50 = 0.005

#: a held creeping lid is accepted with its specimen's unbalanced-force ratio below this many
#: times the equilibrium ratio: a packing as frictional as mu_prep 1.0 creeps on at ratios of
#: 1e-3 to 1e-2 while its lid and its density no longer move (relation --preset paper, full box:
#: 2 of 3 loose-end seeds held at 0.0019 and 0.0030 against 1e-3 were refused after 600 000 lid
#: steps with F_top inside the window; the lid before the creeping one accepted them)
CREEP_RATIO = 10.0


@dataclass(frozen=True)
class LidProfile:
    """The lid as it stands: segment edges (K + 1 x values, m) and heights (K, m)."""

    edges: np.ndarray
    heights: np.ndarray

    @property
    def widths(self) -> np.ndarray:
        return np.diff(self.edges)

    @property
    def mean_height(self) -> float:
        """Height of the flat box of the same area: sum(w h) / W."""
        return float(np.sum(self.widths * self.heights) / (self.edges[-1] - self.edges[0]))

    @property
    def area(self) -> float:
        return float(np.sum(self.widths * self.heights))

    def height_at(self, x: np.ndarray) -> np.ndarray:
        """The lid's height above each x (the segment that covers it)."""
        return lid_height_at(self.edges, self.heights, x)


def segment_count(width: float, d50: float) -> int:
    """Segments of about ``SEGMENT_D50`` d50 across the width, at least 4."""
    if not (d50 > 0.0 and width > 0.0):
        raise InputError("lid d50", d50, "(0, inf) m, with a positive box width")
    return max(4, int(round(width / (SEGMENT_D50 * d50))))


def lid_indices(sim: Simulation) -> list[int]:
    """Indices of the lid's segments, left to right (empty when no lid is installed)."""
    named = [(int(n[len(LID_PREFIX) :]), i) for i, n in enumerate(sim.walls.names) if _is_lid(n)]
    return [i for _, i in sorted(named)]


def _is_lid(name: str) -> bool:
    return name.startswith(LID_PREFIX) and name[len(LID_PREFIX) :].isdigit()


def install_lid(sim: Simulation, width: float, d50: float) -> list[int]:
    """Put the lid where the top plate is, and park the plate above it; returns the segments.

    The plate moves up by twice the largest disk diameter (plus a tenth of its height):
    no disk can reach it, and the lid's segments are not collinear with it.
    """
    if lid_indices(sim):
        raise InputError("lid", "already installed", "one lid per specimen")
    w = sim.walls
    top = w.index("top")
    y = float(w.p0[top, 1])
    park = 4.0 * float(sim.particles.radius.max()) + 0.1 * y
    sim.translate_wall("top", 0.0, park)
    # the side walls close the box up to the parked plate and beyond (an over-full specimen's
    # plate may stand above where the box was built): no disk can leave over them
    for side in ("left", "right"):
        sim.extend_wall_up(side, y + 2.0 * park)
    edges = np.linspace(0.0, width, segment_count(width, d50) + 1)
    for k in range(len(edges) - 1):
        # right to left, like the plate: the normal points down into the specimen
        w.add((edges[k + 1], y), (edges[k], y), w.kn[top], w.ks[top], LID_FRICTION, f"{LID_PREFIX}{k}")
    return lid_indices(sim)


def lid_profile(sim: Simulation, width: float) -> LidProfile:
    idx = lid_indices(sim)
    if not idx:
        raise InputError("lid", "not installed", "a specimen with its lid (install_lid)")
    edges = np.linspace(0.0, width, len(idx) + 1)
    return LidProfile(edges=edges, heights=np.array([float(sim.walls.p0[i, 1]) for i in idx]))


def segment_forces(sim: Simulation) -> np.ndarray:
    """Upward push of the disks on each segment (N), left to right."""
    return np.array([float(sim.wall_force(i)[1]) for i in lid_indices(sim)])


def lid_force(sim: Simulation) -> float:
    """Upward push of the disks on the whole lid (N); 0 without a lid."""
    return float(np.sum(segment_forces(sim))) if lid_indices(sim) else 0.0


def touching_share(sim: Simulation, total: float, width: float) -> float:
    """Share of the lid's width whose segments carry more than ``TOUCH_SHARE`` of their target."""
    prof = lid_profile(sim, width)
    target = total * prof.widths / width
    on = segment_forces(sim) > TOUCH_SHARE * target
    return float(np.sum(prof.widths[on]) / width)


def fill_porosity(radius: np.ndarray, profile: LidProfile) -> float:
    """1 - (disk area) / (area under the lid): the porosity of the box the specimen fills."""
    return 1.0 - float(np.sum(np.pi * np.asarray(radius) ** 2)) / profile.area


# --------------------------------------------------------------------------- controllers
class FlatPlate:
    """A box's top plate (the wall ``top``), as the criterion's plate servo and the shear test's
    consolidation drive it: one rigid wall that moves down to compress."""

    name = "plate"
    #: a plate is judged on its force at every check (:class:`SegmentedLid`'s ``creeps``)
    creeps = False

    def __init__(self, sim: Simulation) -> None:
        self.index = sim.walls.index("top")

    def servo(
        self, sim: Simulation, total: float, max_speed: float, gain: float, integral: float = 0.0
    ) -> None:
        """Servo the plate to ``total`` newtons (:meth:`poro2d.dem.Simulation.set_wall_servo`)."""
        sim.set_wall_servo(self.index, total, (0.0, -1.0), max_speed, gain, integral)

    def hold(self, sim: Simulation) -> None:
        sim.set_wall_velocity(self.index, (0.0, 0.0))

    def force(self, sim: Simulation) -> float:
        """Upward push of the disks on the plate (N)."""
        return float(sim.wall_force(self.index)[1])

    def height(self, sim: Simulation) -> float:
        return float(sim.walls.p0[self.index, 1])

    def resting(self, sim: Simulation, total: float) -> bool:
        """A flat plate rests wherever its force is in the window: nothing more to ask."""
        return True


class SegmentedLid:
    """The lid of the fill acceptance (module docstring), driven like the plate.

    ``min_share``: the share of the width whose segments must rest on the specimen
    before the lid counts as resting. ``creeps``: the lid of a frictional preparation
    (mu_prep at least ``CREEP_FRICTION``), whose surface creeps for long: the force on a
    segment there is a fraction of one grain's weight against the grains' shaking, so it
    flickers in and out of the window at every check. Such a lid ends its approach once it
    rests over most of the width, and its settling once its height creeps less than
    ``CREEP_D50`` d50 (:class:`~poro2d.criterion.servo.PlateServo`); the force window is
    asked of it once held, at equilibrium, as of every lid.
    """

    name = "lid"

    def __init__(
        self, sim: Simulation, width: float, d50: float, min_share: float = 0.75, creeps: bool = False
    ) -> None:
        self.width = float(width)
        self.min_share = float(min_share)
        self.creeps = bool(creeps)
        self.d50 = float(d50)
        if not lid_indices(sim):
            install_lid(sim, width, d50)

    def servo(self, sim: Simulation, total: float, max_speed: float, gain: float) -> None:
        """Servo every segment down to its share (by width) of ``total`` newtons."""
        prof = lid_profile(sim, self.width)
        for i, w in zip(lid_indices(sim), prof.widths, strict=True):
            sim.set_wall_servo(i, total * float(w) / self.width, (0.0, -1.0), max_speed, gain)

    def hold(self, sim: Simulation) -> None:
        for i in lid_indices(sim):
            sim.set_wall_velocity(i, (0.0, 0.0))

    def force(self, sim: Simulation) -> float:
        return lid_force(sim)

    def height(self, sim: Simulation) -> float:
        """The mean height of the lid (the flat box of the same area)."""
        return lid_profile(sim, self.width).mean_height

    def resting(self, sim: Simulation, total: float) -> bool:
        return touching_share(sim, total, self.width) >= self.min_share


def contact_switches(touching: np.ndarray) -> int:
    """How often a lid went from resting to not or back along a history of checks (``touching``: one
    flag a check): the chattering of an approach on a surface that creeps away from it."""
    t = np.asarray(touching, dtype=bool)
    return int(np.count_nonzero(t[1:] != t[:-1]))


def lid_shape(sim: Simulation, width: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The lid's (edges, heights) when ``sim`` has one, else None (a flat top plate)."""
    if not lid_indices(sim):
        return None
    profile = lid_profile(sim, width)
    return profile.edges, profile.heights


def top_height(sim: Simulation, width: float) -> float:
    """The height of the top: the plate's, or the highest lid segment's."""
    lid = lid_shape(sim, width)
    return float(sim.walls.p0[sim.walls.index("top"), 1]) if lid is None else float(lid[1].max())


@dataclass(frozen=True)
class LidNumbers(Record):
    """What a trial's row records of its lid: segments, heights, and the share of the width it rests on."""

    ROW = (
        ("lid_segments", "segments"), ("lid_height_min_m", "height_min_m"),
        ("lid_height_max_m", "height_max_m"), ("lid_contact_share", "contact_share"),
    )  # fmt: skip

    segments: int
    height_min_m: float
    height_max_m: float
    contact_share: float

    @classmethod
    def from_row(cls, row: dict) -> LidNumbers | None:
        """The lid numbers of a trial's row; None for a trial without a lid."""
        if "lid_segments" not in row:
            return None
        return cls(row["lid_segments"], row.get("lid_height_min_m"), row.get("lid_height_max_m"),
                   row.get("lid_contact_share"))  # fmt: skip


def lid_numbers(sim: Simulation, profile: LidProfile, total: float) -> LidNumbers:
    """What a trial's row records of its lid (:class:`LidNumbers`)."""
    return LidNumbers(
        int(profile.heights.size),
        float(profile.heights.min()),
        float(profile.heights.max()),
        touching_share(sim, total, float(profile.edges[-1])),
    )


#: the lid's segments rest on single grains: a window narrower than this many grain weights
#: per segment leaves each segment a fraction of a grain's weight to rest with, below the
#: granular noise of the surface (seen in a 0.05 m box: 11 segments, window 0.6 grains)
GRAINS_PER_SEGMENT = 0.25


def lid_window_note(sim: Simulation, profile: LidProfile, limit_n_per_m: float) -> str:
    """Why a lid may not settle: '' or a note when the window is too fine for its segments."""
    p = sim.particles
    grain = float(np.mean(p.mass)) * 9.81 / p.thickness  # N/m
    grains = limit_n_per_m / grain
    k = int(profile.heights.size)
    if grains >= GRAINS_PER_SEGMENT * k:
        return ""
    return (
        f"; the force window is the weight of {grains:.2g} grain(s) for {k} lid segments: too fine"
        " for this box; use a larger box, a wider force_fraction or acceptance = 'plate'"
    )


def flat_top(sim: Simulation, width: float) -> Simulation:
    """The specimen under the lid as a box of four walls: the plate back on the highest segment.

    What leaves the criterion (``specimen.npz``: shear tests, exports, imports) is a box
    with one top plate, as every DEM code builds it. The plate rests where the highest
    segment rests, so every disk is inside; the disks keep their state, and the contact
    history starts afresh (shear tests and exports start from disks at rest anyway).
    """
    prof = lid_profile(sim, width)
    old_w, p = sim.walls, sim.particles
    wall_mu_r = old_w.rolling_friction()
    walls = Walls()
    for k, name in enumerate(old_w.names):
        if _is_lid(name):
            continue
        a, b = old_w.p0[k].copy(), old_w.p1[k].copy()
        if name == "top":
            a[1] = b[1] = float(prof.heights.max())
        walls.add(a, b, old_w.kn[k], old_w.ks[k], old_w.mu[k], name, mu_r=float(wall_mu_r[k]))
    particles = Particles(
        p.pos.copy(), p.radius.copy(), p.density.copy(), p.thickness, p.kn.copy(), p.ks.copy(), p.mu.copy(),
        vel=p.vel.copy(), theta=p.theta.copy(), omega=p.omega.copy(), mode=p.mode.copy(), mu_r=p.mu_r.copy(),
    )  # fmt: skip
    return Simulation(
        particles, walls, sim.contact, gravity=sim.gravity, local_damping=sim.local_damping,
        restitution=sim.restitution, dt=sim.dt, dt_safety=sim.dt_safety, density_scale=sim.density_scale,
        mass_scaling_dt=sim.mass_scaling_dt, skin=sim.skin, threads=sim.threads, partitions=sim.partitions,
    )  # fmt: skip
