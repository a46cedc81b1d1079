"""The engine's summary: the settings of a simulation that every output file records.

:meth:`poro2d.dem.simulation.Simulation.summary` gives it as an :class:`EngineSummary`, a
typed record whose ``to_dict()`` holds the keys files have always kept under ``engine``, in
their order; ``from_dict()`` reads those of earlier files back. The rolling frictions are
written only when some disk has one, and the per-disk density scaling only when set, so files
of runs without them keep the keys they had.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class ContactRecord(TypedResult):
    """The contact convention (:class:`poro2d.dem.model.ContactModel`) as a file keeps it.

    ``pp`` and ``pw``: (kn, ks, mu) of disk-disk and disk-wall contacts under
    ``per_pair_type``, None under ``per_body``.
    """

    convention: str
    pp: tuple[float, float, float] | list[float] | None
    pw: tuple[float, float, float] | list[float] | None


@dataclass(eq=False)
class RollingFrictionRecord(TypedResult):
    """The rolling frictions of a simulation: the disks' range, each wall's value, and the rule."""

    disks: list[float]
    walls: list[float]
    combination: str
    stiffness: str


@dataclass(eq=False)
class MassScalingRecord(TypedResult):
    """Per-disk density scaling (``Simulation.set_mass_scaling``): the time step the light disks'
    inertial masses were raised for, how many, by how much at most, the inertial mass added over
    the true total, and that gravity acts on the true mass."""

    time_step_s: float
    disks_scaled: int
    largest_ratio: float
    added_mass_fraction: float
    gravity_on: str


@dataclass(eq=False)
class EngineSummary(TypedResult):
    """What a simulation ran with: disks, walls, contact law, damping, time step, threads, clock.

    ``dt_mode`` says whether the step was fixed or automatic (with its safety factor);
    ``threads_used`` is what the kernel's last call used (0: none yet); ``step`` and
    ``time_s`` are the simulation's clock when the summary was taken. ``sort_every_steps``
    is there only when the disks are renumbered along the curve every that many steps
    (:meth:`poro2d.dem.simulation.Simulation.set_sorting`).
    """

    OPTIONAL: ClassVar[tuple[str, ...]] = ("rolling_friction", "mass_scaling", "sort_every_steps")

    n_particles: int
    n_walls: int
    wall_names: list[str]
    thickness_m: float
    contact: ContactRecord
    gravity: list[float]
    local_damping: float
    restitution: float | None
    rolling_friction: RollingFrictionRecord | None
    dt_s: float
    dt_critical_s: float
    dt_mode: str
    density_scale: float
    density_scaling: bool
    skin_m: float
    threads: int
    threads_intended: int
    threads_used: int
    partitions: int
    step: int
    time_s: float
    mass_scaling: MassScalingRecord | None = None
    sort_every_steps: int | None = None

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {
        "contact": ContactRecord,
        "rolling_friction": RollingFrictionRecord,
        "mass_scaling": MassScalingRecord,
    }


__all__ = ["ContactRecord", "EngineSummary", "MassScalingRecord", "RollingFrictionRecord"]
