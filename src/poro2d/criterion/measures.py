"""What the criterion measures on a trial's specimen: wall forces, the checks, the porosities.

Each measure is a small typed record whose ``to_dict`` gives the keys a trial's row (and so
``trial.json``, ``iterations.csv`` and ``result.json``) has always carried under these
names; the trial (:mod:`poro2d.criterion.trial`) is made of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from poro2d.criterion.lid import lid_force, lid_indices
from poro2d.criterion.settings import CriterionSettings
from poro2d.dem import Simulation
from poro2d.errors import InputError
from poro2d.record import Record

if TYPE_CHECKING:
    from poro2d.specimen.compaction import PreparationReport, SpecimenSpec


@dataclass(frozen=True)
class WallForces(Record):
    """Top, bottom and side wall forces per metre of thickness (N/m).

    ``f_top_n_per_m`` is the upward push of the disks on the top plate (and lid),
    ``f_bottom_n_per_m`` the downward push on the bottom wall, ``side_friction_up_n_per_m``
    the upward friction of the side walls on the disks (what the side walls carry of the
    weight); the horizontal pushes on the side walls are None for forces read back from a
    trial's row, which keeps only the three vertical ones. Its row (:meth:`~poro2d.record.Record.to_dict`)
    has the five forces under their names: a reader of a specimen's check writes them all.
    """

    f_top_n_per_m: Any
    f_bottom_n_per_m: Any
    side_friction_up_n_per_m: Any
    f_left_n_per_m: Any = None
    f_right_n_per_m: Any = None

    @classmethod
    def from_row(cls, row: dict, suffix: str = "") -> WallForces:
        """The vertical forces of a trial's row (``suffix`` "_after": after the plate stage)."""
        return cls(
            row.get(f"f_top{suffix}_n_per_m"),
            row.get(f"f_bottom{suffix}_n_per_m"),
            row.get(f"side_friction_up{suffix}_n_per_m"),
        )


def wall_forces(sim: Simulation) -> WallForces:
    """The wall forces of ``sim`` now (:class:`WallForces`)."""
    t = sim.particles.thickness
    top = sim.wall_force("top") / t
    if lid_indices(sim):  # the fill acceptance's lid carries what the parked plate does not
        top = top + np.array([0.0, lid_force(sim) / t])
    bottom = sim.wall_force("bottom") / t
    left = sim.wall_force("left") / t
    right = sim.wall_force("right") / t
    return WallForces(
        f_top_n_per_m=float(top[1]),
        f_bottom_n_per_m=float(-bottom[1]),
        side_friction_up_n_per_m=float(-(left[1] + right[1])),
        f_left_n_per_m=float(-left[0]),
        f_right_n_per_m=float(right[0]),
    )


# A disk counts as inside the box while it presses into a wall by less than this
# fraction of its radius: contact overlaps under the self-weight and plate forces
# of the paper's stiffnesses are well below 1 % of a radius.
WALL_OVERLAP_FRACTION = 0.05

# checks that say the specimen itself is broken: a trial failing one is refused
# (no n' can be trusted from it) and the run stops
INTEGRITY_CHECKS = (
    "preparation_converged",
    "all_disks_present",
    "disks_inside_box",
    "porosity_after_generation",
)


@dataclass(frozen=True)
class Checks(Record):
    """The checks of a trial, passed (True) or failed, in the order of its ``checks`` table.

    ``plate_settled`` is the plate stage's (False when it did not settle or never ran); a
    check a row read back from an older file lacks is None and left out of its row.
    """

    OMITTED = dict.fromkeys(
        ("preparation_converged", "plate_settled", "all_disks_present", "disks_inside_box",
         "porosity_after_generation", "force_balance")
    )  # fmt: skip

    preparation_converged: bool | None = None
    plate_settled: bool | None = None
    all_disks_present: bool | None = None
    disks_inside_box: bool | None = None
    porosity_after_generation: bool | None = None
    force_balance: bool | None = None

    @property
    def failed(self) -> str:
        """The first check that failed, or "" when every one passed."""
        return next((name for name, ok in self.to_dict().items() if not ok), "")


@dataclass(frozen=True)
class CheckNumbers(Record):
    """The numbers behind the checks (see :func:`specimen_checks`)."""

    planned_particle_count: int | None = None
    disks_outside_box: int | None = None
    porosity_after_generation: float | None = None
    porosity_after_generation_clipped: float | None = None
    generation_porosity_error: float | None = None
    weight_from_masses_n_per_m: float | None = None
    force_balance_error: float | None = None


class SpecimenChecks(NamedTuple):
    """The checks of a trial's specimen and the numbers behind them."""

    checks: Checks
    numbers: CheckNumbers


def specimen_checks(
    sim: Simulation,
    spec: SpecimenSpec,
    prep: PreparationReport,
    trial: float,
    plate_height: float | np.ndarray,
    forces: WallForces,
    settings: CriterionSettings,
) -> SpecimenChecks:
    """The checks a trial must pass to be accepted, and the numbers behind them.

    * ``preparation_converged``: every layer and the working-friction stage reached
      equilibrium (with the fallback of :func:`poro2d.specimen.compaction.equilibrate`);
    * ``all_disks_present``: as many disks as drawn for the trial porosity;
    * ``disks_inside_box``: every disk between the side walls, above the bottom and
      below the top plate (at ``plate_height``), pressing into a wall by less than
      ``WALL_OVERLAP_FRACTION`` of its radius;
    * ``porosity_after_generation``: the porosity of the built specimen, 1 - (area of
      its disks) / (W H) with whole disks and overlaps not subtracted (as PFC measures),
      is the trial porosity within ``generation_tolerance``: every disk drawn for the
      trial is in, at its drawn size. The porosity with disks clipped by the box
      (``porosity_after_generation_clipped``) is recorded beside it: it is higher by the
      area the disks press into the walls, which grows with the plate force (a dense
      trial of a frictional preparation pushes hard) and with the box's perimeter over
      its area; ``disks_inside_box`` bounds that penetration instead;
    * ``force_balance``: on the state the decision is taken on, F_bottom + side
      friction = weight + F_top within ``balance_tolerance`` of the right-hand side.
      Signs: F_bottom > 0 when the disks push the bottom wall down, side friction > 0
      when the side walls hold the disks up, F_top > 0 when the disks push the top
      plate up; the weight is sum(m) g / t from the disks' masses. With local damping,
      a specimen that still moves does not balance: damping forces carry the rest.

    ``plate_settled`` is the plate stage's, not the specimen's: the trial sets it.
    """
    p = sim.particles
    x, y, r = p.pos[:, 0], p.pos[:, 1], p.radius
    slack = WALL_OVERLAP_FRACTION * r
    outside = (
        (x - r < -slack) | (x + r > spec.width + slack) | (y - r < -slack) | (y + r > plate_height + slack)
    )
    weight = float(np.sum(p.mass)) * spec.gravity / p.thickness
    rhs = weight + forces.f_top_n_per_m
    lhs = forces.f_bottom_n_per_m + forces.side_friction_up_n_per_m
    balance_error = abs(lhs - rhs) / rhs if rhs > 0.0 else math.inf
    built = 1.0 - float(np.sum(np.pi * r * r)) / (spec.width * spec.height)
    generation_error = abs(built - trial)
    numbers = CheckNumbers(
        planned_particle_count=int(prep.planned_count),
        disks_outside_box=int(np.count_nonzero(outside)),
        porosity_after_generation=built,
        porosity_after_generation_clipped=float(prep.measured_porosity),
        generation_porosity_error=float(generation_error),
        weight_from_masses_n_per_m=weight,
        force_balance_error=float(balance_error),
    )
    checks = Checks(
        preparation_converged=bool(prep.converged),
        all_disks_present=bool(p.n == prep.planned_count),
        disks_inside_box=bool(not outside.any()),
        porosity_after_generation=bool(generation_error <= settings.generation_tolerance),
        force_balance=bool(balance_error <= settings.balance_tolerance),
    )
    return SpecimenChecks(checks, numbers)


#: the measures of a trial's decision state that its row carries (see :func:`porosity_numbers`)
POROSITY_KEYS = (
    "box_porosity", "interior_porosity", "interior_porosity_std", "interior_regions",
    "laguerre_interior_porosity", "surface_gap_mean_d50", "plate_contact_fraction",
)  # fmt: skip


@dataclass(frozen=True)
class PorosityNumbers(Record):
    """A trial's porosities beside the paper's n' (keys :data:`POROSITY_KEYS`).

    A specimen too small to measure has only ``box_porosity``, ``interior_porosity = None``
    and the reason in ``interior_porosity_note``.
    """

    box_porosity: Any = None
    interior_porosity: Any = None
    interior_porosity_std: Any = None
    interior_regions: Any = None
    laguerre_interior_porosity: Any = None
    surface_gap_mean_d50: Any = None
    plate_contact_fraction: Any = None
    interior_porosity_note: str | None = None

    #: the row of a specimen too small to measure
    UNMEASURED = ("box_porosity", "interior_porosity", "interior_porosity_note")

    def layout(self) -> tuple:
        return POROSITY_KEYS if self.interior_porosity_note is None else self.UNMEASURED

    @classmethod
    def from_row(cls, row: dict) -> PorosityNumbers | None:
        """The porosities of a trial's row; None for a row without them (a trial that did not converge)."""
        if "box_porosity" not in row:
            return None
        return cls.from_dict(row)


def porosity_numbers(
    sim: Simulation, width: float, plate_y: float, lid: tuple[np.ndarray, np.ndarray] | None = None
) -> PorosityNumbers:
    """The specimen's porosities beside the paper's n' (:mod:`poro2d.measure.specimen_porosity`).

    ``box_porosity`` is the paper's: W x plate height, the gap under the plate included;
    ``interior_porosity`` (mean over measurement circles 2 d50 clear of every wall and of the
    free surface, with its spread) is the packing's own. A specimen too small to measure
    gets ``interior_porosity = None`` and the reason in ``interior_porosity_note``. With a
    ``lid`` (edges, heights), the box porosity and the gap are those under the lid.
    """
    from poro2d.measure.porosity import box_porosity
    from poro2d.measure.specimen_porosity import measure_specimen

    p = sim.particles
    try:
        m = measure_specimen(p.pos, p.radius, width, plate_y, lid=lid).to_dict()
    except (InputError, RuntimeError) as e:  # too small to measure; a degenerate tessellation
        return PorosityNumbers(
            box_porosity=box_porosity(p.area(), width, plate_y), interior_porosity_note=str(e)
        )
    return PorosityNumbers(**{k: m[k] for k in POROSITY_KEYS})


__all__ = [
    "INTEGRITY_CHECKS", "POROSITY_KEYS", "WALL_OVERLAP_FRACTION", "CheckNumbers", "Checks", "PorosityNumbers",
    "SpecimenChecks", "WallForces", "porosity_numbers", "specimen_checks", "wall_forces",
]  # fmt: skip
