"""A direct shear case: what one test's results depend on, as one frozen value.

The specimen (read once, :class:`~poro2d.specimen.saved.Specimen`), the normal stress
and the settings. A series, its rate check, a replicate study and a strength study make
their tests' cases from one case with :func:`dataclasses.replace`; a case travels to a
worker process as it is (it pickles), and it names its test's record (``test.json``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from poro2d.config import check_finite
from poro2d.errors import InputError, check_range
from poro2d.shear.record import TestContent, content_record
from poro2d.shear.settings import NORMAL_STRESS_RANGE_KPA, ShearSettings
from poro2d.specimen.saved import Specimen


@dataclass(frozen=True, eq=False)
class ShearCase:
    """One direct shear test's inputs, checked against each other when made.

    ``normal_stress_kpa`` in :data:`NORMAL_STRESS_RANGE_KPA`; the settings' shear
    displacement at most half the specimen's width and its gap at most a quarter of its
    height (the box refuses a wider one when it is built, in a worker: here it is refused
    before any test starts).
    """

    specimen: Specimen
    normal_stress_kpa: float
    settings: ShearSettings

    def __post_init__(self) -> None:
        sigma = check_range("normal stress (kPa)", self.normal_stress_kpa, *NORMAL_STRESS_RANGE_KPA)
        object.__setattr__(self, "normal_stress_kpa", sigma)
        check_finite("shear", self.settings.to_dict())  # open ranges let an infinity through
        W, H = self.specimen.box()
        if self.settings.max_displacement > W / 2:
            raise InputError(
                "max_displacement", self.settings.max_displacement, f"(0, {W / 2:.4g}] m (half the box width)"
            )
        check_range("gap", self.settings.gap, 0.0, H / 4)

    @classmethod
    def of(
        cls, specimen: Specimen | str | Path, normal_stress_kpa: float, settings: ShearSettings | None = None
    ) -> ShearCase:
        """The case of ``specimen`` (a value, or a path read now) at a stress (default settings)."""
        return cls(
            Specimen.of(specimen), normal_stress_kpa, settings if settings is not None else ShearSettings()
        )

    def at(self, normal_stress_kpa: float) -> ShearCase:
        """The same test at another normal stress."""
        return replace(self, normal_stress_kpa=normal_stress_kpa)

    def with_settings(self, **changes) -> ShearCase:
        """The same test with some settings changed (``velocity=...``)."""
        return replace(self, settings=replace(self.settings, **changes))

    def record(self) -> TestContent:
        """The content a stored test must share with this one (:func:`poro2d.shear.record.content_record`)."""
        return content_record(self.specimen.digest, self.normal_stress_kpa, self.settings)


__all__ = ["ShearCase"]
