"""A biaxial case: what one test's results depend on, as one frozen value.

The specimen (a :class:`~poro2d.specimen.saved.Specimen` read once from a file made by
``poro2d criterion`` or ``poro2d sand``, or the recipe of a quick specimen,
:class:`~poro2d.biaxial.quick.QuickSpecimen`), the confining stress and the settings. A
replicate study makes its cases from one case with :meth:`BiaxialCase.replicate`; a case
travels to a worker process as it is (it pickles).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from poro2d.biaxial.quick import QuickSpecimen
from poro2d.biaxial.settings import CONFINING_RANGE_KPA, BiaxialSettings
from poro2d.config import check_finite
from poro2d.errors import InputError, check_range
from poro2d.specimen.saved import Specimen


@dataclass(frozen=True, eq=False)
class BiaxialCase:
    """One biaxial test's inputs: ``confining_kpa`` in :data:`CONFINING_RANGE_KPA`."""

    specimen: Specimen | QuickSpecimen
    confining_kpa: float
    settings: BiaxialSettings

    def __post_init__(self) -> None:
        if not isinstance(self.specimen, Specimen | QuickSpecimen):
            raise InputError("specimen", type(self.specimen).__name__, "a Specimen or a QuickSpecimen")
        if not isinstance(self.settings, BiaxialSettings):
            raise InputError("settings", type(self.settings).__name__, "a BiaxialSettings")
        sigma = check_range("confining stress (kPa)", self.confining_kpa, *CONFINING_RANGE_KPA)
        object.__setattr__(self, "confining_kpa", sigma)
        check_finite("biaxial", self.settings.to_dict())

    @classmethod
    def of(
        cls, specimen: Specimen | QuickSpecimen | str | Path, confining_kpa: float,
        settings: BiaxialSettings | None = None,
    ) -> BiaxialCase:  # fmt: skip
        """The case of ``specimen`` (a value, or a path read now) at a confining stress."""
        value = specimen if isinstance(specimen, QuickSpecimen) else Specimen.of(specimen)
        return cls(value, confining_kpa, settings if settings is not None else BiaxialSettings())

    @classmethod
    def quick(
        cls, confining_kpa: float, seed: int = 0, settings: BiaxialSettings | None = None
    ) -> BiaxialCase:
        """The quick specimen of ``seed`` at a confining stress."""
        return cls(
            QuickSpecimen(seed), confining_kpa, settings if settings is not None else BiaxialSettings()
        )

    def replicate(self, k: int) -> BiaxialCase:
        """The ``k``-th replicate (0: this case): the quick specimen of seed + k. A specimen file has
        only itself: replicates of one file would be the same test (give one file per replicate)."""
        if k == 0:
            return self
        if not isinstance(self.specimen, QuickSpecimen):
            raise InputError(
                "replicates",
                k + 1,
                "1 for a specimen file (give one specimen file per replicate, or --quick)",
            )
        return replace(self, specimen=self.specimen.with_seed(self.specimen.seed + k))

    def grains(self) -> tuple[float, np.ndarray, np.ndarray]:
        """(box width in m, radii, densities) of the specimen's disks, with no step run: a file's as
        saved, a quick specimen's as its recipe draws them."""
        if isinstance(self.specimen, QuickSpecimen):
            return self.specimen.grains()
        arrays = self.specimen.arrays
        return self.specimen.box()[0], arrays["particles.radius"], arrays["particles.density"]

    def with_settings(self, **changes) -> BiaxialCase:
        return replace(self, settings=replace(self.settings, **changes))


__all__ = ["BiaxialCase"]
