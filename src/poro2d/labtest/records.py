"""The records every box test keeps: its box, its consolidation, and its line in a study.

One :class:`BoxRecord` and one :class:`ConsolidationRecord` serve the direct shear test and the
biaxial test. Each holds the keys every box test writes and, after them in the file's order,
those of one kind of test, written only when set (a biaxial file has no split box; a shear file
no side walls): one class reads and writes both tests' files as they were written before.
:class:`TestSummary` is the base of a test's line in its study's ``result.json``, made from the
test's result by name (:class:`ByName`, as a test's result is made from the reading of its curve).
"""

from __future__ import annotations

import types
import typing
from dataclasses import dataclass, fields
from typing import Any, ClassVar, Self, TypeVar

from poro2d.dem.summary import EngineSummary
from poro2d.io_utils import Provenance
from poro2d.measure.stiffness import ContactStiffness
from poro2d.record import Record
from poro2d.typed_result import TypedResult, with_fields

T = TypeVar("T", bound=type)


def _part_kind(hint: Any) -> type | None:
    """The part class of a field typed ``hint``: a result or record class, alone, optional or in a
    list (None: not a part)."""
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        kinds = [a for a in typing.get_args(hint) if a is not type(None)]
        hint = kinds[0] if len(kinds) == 1 else None
    if typing.get_origin(hint) is list:
        hint = typing.get_args(hint)[0]
    return hint if isinstance(hint, type) and issubclass(hint, TypedResult | Record) else None


def typed_parts(cls: T) -> T:
    """Class decorator of a typed result (above its ``@dataclass``): its ``PARTS`` read off its
    fields' types, so that the file's keys and their classes are declared once, as fields.

    Every field of the file typed as a result or a record class (or an optional one, or a list of
    them) is a part read back as that class.
    """
    hints = typing.get_type_hints(cls)
    kinds = {f.name: _part_kind(hints[f.name]) for f in fields(cls) if f.metadata.get("in_file", True)}
    cls.PARTS = {name: kind for name, kind in kinds.items() if kind is not None and name != "extra"}
    return cls


@dataclass(eq=False, kw_only=True)
class BoxRecord(TypedResult):
    """A test's box as built (m): its width and height and the disks' thickness; a split box
    (:meth:`poro2d.shear.box.SplitBox.record`) also where it splits, its gap, how far its lower
    half may travel and where that half starts."""

    width: float
    height: float
    split_y: float | None = None
    gap: float | None = None
    max_displacement: float | None = None
    thickness: float
    x0_lower: float | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = ("split_y", "gap", "max_displacement", "x0_lower")


#: the keys only a direct shear test's consolidation writes (its plate servoed to the normal stress)
SPLIT_BOX_KEYS = (
    "normal_stress_kpa", "target_force_n", "normal_stress_measured_kpa", "normal_stress_error",
    "plate_height_before_m", "plate_height_m", "plate_settlement_m", "engine",
)  # fmt: skip
#: the keys only a biaxial test's consolidation writes (its plate and side walls servoed to sigma_3)
BIAXIAL_KEYS = (
    "confining_stress_kpa", "sigma_1_kpa", "sigma_3_left_kpa", "sigma_3_right_kpa", "max_stress_error",
    "width_m", "height_m", "porosity",
)  # fmt: skip


@typed_parts
@dataclass(eq=False, kw_only=True)
@with_fields(ContactStiffness, after="contact_kn")
class ConsolidationRecord(TypedResult):
    """How a test's consolidation ended (a shear test's ``consolidation.json``, a ``consolidation`` of
    either test's ``result.json``): the steps, the unbalanced-force ratio, the coordination number,
    the wall time and the box, with the stresses each kind of test servoes.

    Direct shear: the normal stress, the plate's target force, the measured stress and its error,
    the plate's heights and settlement, ``engine`` the simulation's summary after consolidating (not
    in a test's ``result.json``). Biaxial: sigma_3, each wall's stress and the largest error, the
    box's size and porosity; ``contact_kn``, ``stiffness_number`` and ``mean_overlap_ratio``
    (:mod:`poro2d.biaxial.stiffness`: the disk-disk contacts' mean kn in N/m, kappa = kn /
    (sigma_3 t), mean overlap / mean diameter) since the stiffness number was recorded.
    """

    normal_stress_kpa: float | None = None
    target_force_n: float | None = None
    confining_stress_kpa: float | None = None
    steps: int
    max_unbalanced_ratio: float
    normal_stress_measured_kpa: float | None = None
    normal_stress_error: float | None = None
    plate_height_before_m: float | None = None
    plate_height_m: float | None = None
    plate_settlement_m: float | None = None
    sigma_1_kpa: float | None = None
    sigma_3_left_kpa: float | None = None
    sigma_3_right_kpa: float | None = None
    max_stress_error: float | None = None
    width_m: float | None = None
    height_m: float | None = None
    porosity: float | None = None
    coordination_number: float
    wall_time_s: float
    box: BoxRecord
    engine: EngineSummary | None = None
    contact_kn: float | None = None

    OPTIONAL: ClassVar[tuple[str, ...]] = (
        *SPLIT_BOX_KEYS, *BIAXIAL_KEYS, "contact_kn", "stiffness_number", "mean_overlap_ratio",
    )  # fmt: skip


class ByName:
    """Mixin of a typed result made from another value by name (:meth:`of`): a test's line from the
    test's result, a test's result from what its curve says."""

    @classmethod
    def of(cls, source: Any, **given: Any) -> Self:
        """Each field ``given``, the others read off ``source`` by name (those it lacks left at their
        defaults)."""
        names = [f.name for f in fields(cls) if f.name != "extra"]  # type: ignore[arg-type]
        values = {name: given[name] if name in given else getattr(source, name) for name in names
                  if name in given or hasattr(source, name)}  # fmt: skip
        return cls(**values)


@dataclass(eq=False)
class TestSummary(ByName, TypedResult):
    """Base of a test's line in its study's ``result.json``: the test's numbers a study lists, read off
    the test's result by name (:meth:`ByName.of`)."""

    __test__ = False  # not a test class, whatever its name


@dataclass
class StudyRun:
    """How a study of tests ran, the same run of fields in each study's ``result.json`` (put into it
    by :func:`poro2d.typed_result.with_fields`): the processes its tests ran on, its wall time (s),
    the config it was given and its provenance."""

    processes: int
    wall_time_s: float
    config: dict[str, Any]
    provenance: Provenance


__all__ = ["BoxRecord", "ByName", "ConsolidationRecord", "StudyRun", "TestSummary", "typed_parts"]
