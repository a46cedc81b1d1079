"""A laboratory test's settings: one class that is checked when made and is also its file's table.

A test's settings are written with every result of the test (its ``settings``) and read back
from files of any poro2d version. :class:`TestSettings` gives a settings dataclass both
sides, so no record class twins it: its fields are the file's keys, in order
(:meth:`~poro2d.record.Record.to_dict`, optional ones left out while None through
``OMITTED``), and :meth:`TestSettings.from_dict` reads a file back as it is. A file written
before a setting existed lacks its key: the setting reads as None and stays out of the file
written back, so a finished test's files and cache keys do not change. What a file holds is
what was run, so it is not checked again against today's ranges.

The ranges the box tests share (consolidation, the walls' servo, the box's walls, the disks'
frictions and the engine's) are here, in one table (:data:`LAB_RANGES`), that each test's
table takes its entries from (:func:`lab_ranges`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, Self

from poro2d.dem.contact_law import MAX_ROLLING_FRICTION
from poro2d.errors import Integer, Ranges, Real
from poro2d.identity import outside_fields
from poro2d.record import Record

#: the normal (or confining) stresses (kPa) a box test may be run at. A contact carries about
#: sigma d t, so two disks of the paper's stiffness (kn = 4e5 N/m each, in series 2e5; 8 mm
#: thick) overlap by sigma t / k = 4 % of their diameter at 1 MPa, and more above: beyond what a
#: soft-contact model describes. Below 1 kPa the plate pushes less than the specimen's own weight
#: does at mid-height (about 1.3 kPa in the paper's box), so the stress held is not the one the
#: specimen feels. docs/shear.md has the reasoning.
NORMAL_STRESS_RANGE_KPA = (1.0, 1000.0)
#: 30 times the default step budget of the consolidation (hours of one core for the paper's box)
MAX_CONSOLIDATION_STEPS = 10_000_000
#: wall stiffness (N/m): 1000 times Table 1's; the time step falls with its square root
MAX_WALL_STIFFNESS = 1e10
#: friction coefficients beyond 10 hold as a rough wall does; larger ones are typos
MAX_FRICTION = 10.0
#: inertial masses up to 1000 times the real ones: the inertial number grows with its root
MAX_DENSITY_SCALE = 1000.0

#: the longest interval (steps) between two steps of a run's ParaView series: beyond the steps of
#: any test (the longest run about 4e7 steps), so a larger one is a typo
MAX_VTK_EVERY = 100_000_000

#: what the settings every box test has may be (a test's table takes them with :func:`lab_ranges`)
LAB_RANGES: Ranges = {
    "consolidation_ratio": Real(0.0, 1.0, lo_open=True),
    "consolidation_max_steps": Integer(1000, MAX_CONSOLIDATION_STEPS),
    "stress_tolerance": Real(0.0, 1.0, lo_open=True),
    "servo_gain": Real(0.0, 1.0, lo_open=True),
    "servo_integral": Real(0.0, 0.1),
    "servo_max_speed": Real(0.0, 10.0, lo_open=True),
    "kn_wall": Real(0.0, MAX_WALL_STIFFNESS, lo_open=True),
    "ks_wall": Real(0.0, MAX_WALL_STIFFNESS),
    "friction_wall": Real(0.0, MAX_FRICTION),
    "particle_friction": Real(0.0, MAX_FRICTION, or_none=True),
    "rolling_friction": Real(0.0, MAX_ROLLING_FRICTION, or_none=True),
    "local_damping": Real(0.0, 1.0, hi_open=True, or_none=True),
    "density_scale": Real(1.0, MAX_DENSITY_SCALE),
    "dt_safety": Real(0.0, 1.0, lo_open=True),
    # steps between two steps of the ParaView series (poro2d.labtest.vtk_series); 0: none
    "vtk_every": Integer(0, MAX_VTK_EVERY),
}
#: the servo and the box's walls, in the order both tests check them
SERVO_AND_WALLS = ("servo_gain", "servo_integral", "servo_max_speed", "kn_wall", "ks_wall", "friction_wall")


@dataclass
class DisksAndEngine:
    """The settings of the disks' frictions and of the engine that every box test has, in this order
    (put into each test's settings by :func:`poro2d.typed_result.with_fields`): the disks' sliding
    and rolling friction and the local damping for the test (None: the specimen's), the inertial
    masses' scale and the time step's safety factor."""

    particle_friction: float | None = None
    rolling_friction: float | None = None
    local_damping: float | None = None
    density_scale: float = 1.0
    dt_safety: float = 0.8


def lab_ranges(*names: str) -> Ranges:
    """The entries ``names`` of :data:`LAB_RANGES`, in that order (a test's table splices them in
    where it checks them)."""
    return {name: LAB_RANGES[name] for name in names}


class TestSettings(Record):
    """Mixin of a test's settings dataclass: the settings are also the table its files keep.

    The class checks its values in ``__post_init__`` (:func:`poro2d.errors.check_fields`); this
    mixin writes them (every field in order, ``OMITTED`` keys left out while None) and reads them
    back from a file (:meth:`from_dict`).
    """

    __test__ = False  # not a test class, whatever its name

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Self:
        """The settings a file keeps, as kept: a setting the file lacks reads as None (one outside
        the run's identity, an output such as ``vtk_every``, as its default) and is left out when
        written back; a key of another version is written back after the settings."""
        names = [f.name for f in fields(cls)]  # type: ignore[arg-type]
        outputs = {f.name: f.default for f in fields(cls) if f.name in outside_fields(cls)}  # type: ignore[arg-type]
        obj = cls.__new__(cls)  # not checked again: a file holds what was run
        for name in names:
            object.__setattr__(obj, name, data.get(name, outputs.get(name)))
        object.__setattr__(obj, "_absent", frozenset(n for n in names if n not in data))
        object.__setattr__(obj, "_extra", {k: v for k, v in data.items() if k not in names})
        return obj

    def to_dict(self) -> dict[str, Any]:
        """The settings as a file keeps them: every setting in order, but those a file read back
        lacked and ``OMITTED`` ones while None, then the keys of another version it had."""
        absent = getattr(self, "_absent", frozenset())
        row = {k: v for k, v in super().to_dict().items() if k not in absent}
        row.update(getattr(self, "_extra", {}))
        return row


__all__ = [
    "LAB_RANGES", "MAX_CONSOLIDATION_STEPS", "MAX_DENSITY_SCALE", "MAX_FRICTION", "MAX_VTK_EVERY",
    "MAX_WALL_STIFFNESS", "NORMAL_STRESS_RANGE_KPA", "SERVO_AND_WALLS", "DisksAndEngine", "TestSettings",
    "lab_ranges",
]  # fmt: skip
