"""One biaxial test of a calibration: (specimen, confining stress, f_p, mu_r, settings), cached by content.

The biaxial sibling of :class:`poro2d.calibration.units.CalibrationUnit`: a frozen value whose
key hashes what decides its result (the specimen's content, sigma_3, every biaxial setting with the
two frictions, and the kind of test, so that no biaxial key can equal a shear key), run by the same
runner (:class:`poro2d.calibration.cluster.UnitRunner`) on Dask and kept under ``cache/<key>``.
Inside, :class:`poro2d.biaxial.single.BiaxialTest` binds the folder to its test (``test.json``).

What the fit reads of a finished test (:class:`BiaxialRow`), every value dimensionless:

* ``peak_ratio``: the largest stress ratio (sigma_1 - sigma_3) / (sigma_1 + sigma_3) = sin(phi),
  smoothed over ``smoothing_strain`` as ``poro2d biaxial`` reads its peak;
* ``end_ratio``: the mean stress ratio over the last ``critical_window`` of ``max_strain``, the
  end ``poro2d biaxial`` reports;
* ``end_volumetric``: the volumetric strain (compression positive) averaged over the last
  ``smoothing_strain`` before ``max_strain``;
* readings ``ratio_at_<e>pct`` and ``volumetric_at_<e>pct``: the same averages over
  ``smoothing_strain`` before an axial strain.

The laboratory's curves are read by the same functions (:func:`peak_ratio`, :func:`end_mean`,
:meth:`~poro2d.calibration.units.CurveReadings.at`), so both sides are one reading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from poro2d.biaxial.angles import smoothed
from poro2d.biaxial.case import BiaxialCase
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.biaxial.single import BiaxialTest
from poro2d.calibration.units import (
    CurveReadings,
    FrictionUnit,
    UnitIdentity,
    check_files,
    parse_strain_station,
    window_mean,
)
from poro2d.identity import identity_digest
from poro2d.store import Store


def peak_ratio(axial_strain, ratio, settings: BiaxialSettings) -> float:
    """The peak of the stress ratio smoothed over ``smoothing_strain`` up to where a test ends: its
    last row lies past ``max_strain`` by less than ``record_strain``, so a laboratory curve is read
    as far (the test's own ``peak_sin_phi`` is this reading of its curve)."""
    e1, r = np.asarray(axial_strain, float), np.asarray(ratio, float)
    upto = e1 <= settings.max_strain + settings.record_strain
    return float(np.nanmax(smoothed(e1[upto], r[upto], settings.smoothing_strain)))


def end_mean(axial_strain, y, settings: BiaxialSettings, window: float) -> float:
    """The mean of ``y`` over the readings within ``window`` (axial strain) before ``max_strain``."""
    return window_mean(axial_strain, y, settings.max_strain, window)


def end_window(settings: BiaxialSettings) -> float:
    """The axial strain over which the end stress ratio is averaged: the last ``critical_window``."""
    return settings.critical_window * settings.max_strain


@dataclass(frozen=True)
class BiaxialRow(UnitIdentity):
    """What a finished biaxial unit gives the fit: its observables (dimensionless) and its cost."""

    peak_ratio: float
    end_ratio: float
    end_volumetric: float
    wall_time_s: float
    readings: CurveReadings
    #: kappa = kn / (sigma_3 t) and the mean overlap / d at the peak (None: a test cached before them)
    stiffness_number: float | None = None
    mean_overlap_ratio: float | None = None
    #: a biaxial box has no split box whose plane could carry another load than its plate: never
    #: judged box-dominated (poro2d.shear.box_dominated judges direct shear tests)
    box_dominated: ClassVar[bool] = False
    box_note: ClassVar[str] = ""

    def observable(self, name: str) -> float:
        """The value of the observable ``name`` (:data:`poro2d.calibration.units.BIAXIAL_OBSERVABLES`,
        or a reading, :func:`poro2d.calibration.units.strain_station`)."""
        reading = parse_strain_station(name)
        if reading is not None:
            return self.readings.at(*reading)
        return {"peak_ratio": self.peak_ratio, "end_ratio": self.end_ratio,
                "end_volumetric": self.end_volumetric}.get(name, math.nan)  # fmt: skip


def biaxial_unit_key(specimen_digest: str, sigma: float, settings: dict) -> str:
    """The digest naming a biaxial unit's folder; ``test`` keeps it apart from every shear key."""
    unit = {"test": "biaxial", "specimen": specimen_digest, "sigma": sigma, "settings": settings}
    return identity_digest(unit, tables={"settings": BiaxialSettings}, length=20)


@dataclass(frozen=True)
class BiaxialUnit(FrictionUnit):
    """One biaxial test of a calibration (:class:`~poro2d.calibration.units.FrictionUnit` with
    ``sigma`` the confining stress and the biaxial settings)."""

    #: what the progress display counts
    WHAT = "biaxial tests"
    SETTINGS = BiaxialSettings
    CASE = BiaxialCase
    KEY = staticmethod(biaxial_unit_key)

    def test(self, store: Store | None) -> BiaxialTest:
        return BiaxialTest(self.case(), store)

    def check_entry(self, cache: Store | None) -> None:
        """Refuse a damaged entry on one line (a file where the folder belongs, a file changed since
        written). A folder holding another test is refused by its test (poro2d.store.test_stage)."""
        store = self.store(cache)
        if store is not None:
            check_files(cache, store, "one biaxial test of the cache")

    def row(self, res) -> BiaxialRow:
        s = self.typed_settings
        c = res.curve
        return BiaxialRow(
            key=self.key, sigma=self.sigma, fp=self.fp, mu_r=self.mu_r, specimen=self.specimen,
            peak_ratio=peak_ratio(c.axial_strain, c.sin_phi, s),
            end_ratio=end_mean(c.axial_strain, c.sin_phi, s, end_window(s)),
            end_volumetric=end_mean(c.axial_strain, c.volumetric_strain, s, s.smoothing_strain),
            wall_time_s=float(res.wall_time_s),
            readings=CurveReadings(np.asarray(c.axial_strain, float), {
                "ratio": np.asarray(c.sin_phi, float),
                "volumetric": np.asarray(c.volumetric_strain, float),
            }, s.smoothing_strain),
            stiffness_number=res.stiffness_number,
            mean_overlap_ratio=res.mean_overlap_ratio_at_peak,
        )  # fmt: skip

    def curve(self, cache: Store | None) -> tuple[np.ndarray, np.ndarray] | None:
        """The finished test's (axial strain, stress ratio), or None."""
        row = self.stored_row(cache)
        return None if row is None else (row.readings.x, row.readings.columns["ratio"])


__all__ = [
    "BiaxialRow",
    "BiaxialUnit",
    "biaxial_unit_key",
    "end_mean",
    "end_window",
    "peak_ratio",
]
